//! `many-open`: N small quad and triangle lights (default 10,000; `--light-count` up to 1M)
//! hovering over a large floor with box occluders, seen by a camera looking across the floor.
//! The floor grows with N so the light density stays about one light per square metre.

use super::many_util::{
    add_box, add_triangle_light, diffuse, emission, log_uniform, radiance_for_power, random_colour,
    scene_rng, uniform,
};
use super::{BuiltinOptions, Scene};
use crate::camera::Camera;
use crate::scene::{FilmSpec, Filter, SceneBuilder};
use anyhow::ensure;
use glam::{UVec2, Vec2, Vec3};

/// Default number of lights.
pub const DEFAULT_LIGHTS: u32 = 10_000;
/// Most lights accepted.
pub const MAX_LIGHTS: u32 = 1_000_000;

/// Build `many-open`.
pub fn many_open(opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let n = opts.light_count.unwrap_or(DEFAULT_LIGHTS);
    ensure!(
        (1..=MAX_LIGHTS).contains(&n),
        "--light-count must be between 1 and {MAX_LIGHTS}, got {n}"
    );
    let half = (n as f32).sqrt().max(4.0) * 0.5;
    let mut rng = scene_rng(1);
    let mut b = SceneBuilder::new();
    let floor = diffuse(&mut b, 0.5);
    let grey = diffuse(&mut b, 0.6);
    let black = diffuse(&mut b, 0.0);
    b.add_quad(
        Vec3::new(-half, 0.0, -half),
        Vec3::Z * (2.0 * half),
        Vec3::X * (2.0 * half),
        floor,
        None,
    )?;
    // Occluders: pillars and low walls, about one per 100 m².
    let boxes = ((n / 100).clamp(4, 2000)) as usize;
    for _ in 0..boxes {
        let c = Vec3::new(
            uniform(&mut rng, -half, half),
            0.0,
            uniform(&mut rng, -half, half),
        );
        let s = Vec3::new(
            uniform(&mut rng, 0.3, 3.0),
            uniform(&mut rng, 1.0, 4.0),
            uniform(&mut rng, 0.3, 3.0),
        );
        let lo = c - Vec3::new(s.x, 0.0, s.z) * 0.5;
        add_box(&mut b, lo, lo + s, grey)?;
    }
    for i in 0..n {
        let p = Vec3::new(
            uniform(&mut rng, -half, half),
            uniform(&mut rng, 0.5, 3.0),
            uniform(&mut rng, -half, half),
        );
        let size = uniform(&mut rng, 0.1, 0.4);
        let phi = log_uniform(&mut rng, 0.02, 20.0);
        let c = random_colour(&mut rng);
        // X × Z = −Y: both kinds face the floor.
        let (ex, ez) = (Vec3::X * size, Vec3::Z * size);
        if i % 2 == 0 {
            let l = radiance_for_power(phi, size * size, c);
            b.add_quad(p, ex, ez, black, emission(l))?;
        } else {
            let l = radiance_for_power(phi, 0.5 * size * size, c);
            add_triangle_light(&mut b, [p, p + ex, p + ez], l, black)?;
        }
    }
    let eye = Vec3::new(0.0, 5.0, -half * 0.9);
    let camera = Camera::look_at(eye, Vec3::new(0.0, 0.0, -half * 0.4), Vec3::Y, 60.0)?;
    b.build(camera, film())
}

/// 320×240, box filter, 16 spp: the many-light scenes are for comparing selectors, quickly.
pub fn film() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(320, 240),
        filter: Filter::Box {
            radius: Vec2::splat(0.5),
        },
        filename: None,
        spp: Some(16),
        sensor: Default::default(),
    }
}
