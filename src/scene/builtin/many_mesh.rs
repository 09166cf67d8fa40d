//! `many-mesh`: an emissive tessellated torus (thousands of triangle lights, in coloured bands
//! of different brightness; `--light-count` sets the triangle count, default 8192) above a
//! floor, with long strip lights on the back wall and a diffuse box.

use super::many_open::film;
use super::many_util::{add_box, diffuse, emission, random_colour, scene_rng, uniform};
use super::{BuiltinOptions, Scene};
use crate::camera::Camera;
use crate::scene::{AreaEmission, SceneBuilder, TriangleMesh};
use anyhow::ensure;
use glam::{Quat, Vec3};
use std::f32::consts::TAU;

/// Bands of different emission around the torus.
const BANDS: u32 = 8;

/// Build `many-mesh`.
pub fn many_mesh(opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let tris = opts.light_count.or(opts.triangles).unwrap_or(8192);
    ensure!(
        (64..=2_000_000).contains(&tris),
        "--light-count of many-mesh must be between 64 and 2000000, got {tris}"
    );
    // tris = 2 · nu · nv with nu = 2 nv (the ring is twice as long as the tube's girth).
    let nv = ((tris as f32 / 4.0).sqrt().round() as u32).max(4);
    let nu = (2 * nv).div_ceil(BANDS) * BANDS;
    let mut rng = scene_rng(3);
    let mut b = SceneBuilder::new();
    let floor = diffuse(&mut b, 0.5);
    let wall = diffuse(&mut b, 0.6);
    let black = diffuse(&mut b, 0.05);
    b.add_quad(
        Vec3::new(-6.0, 0.0, -6.0),
        Vec3::Z * 12.0,
        Vec3::X * 12.0,
        floor,
        None,
    )?;
    b.add_quad(
        Vec3::new(-6.0, 0.0, 3.0),
        Vec3::Y * 5.0,
        Vec3::X * 12.0,
        wall,
        None,
    )?;
    add_box(
        &mut b,
        Vec3::new(1.2, 0.0, -1.0),
        Vec3::new(2.0, 0.8, -0.2),
        wall,
    )?;
    // Torus: ring radius 1, tube radius 0.3, centre (0, 1.3, 0.5), tilted toward the camera.
    let (big, small) = (1.0f32, 0.3f32);
    let rot = Quat::from_rotation_x(1.2);
    let centre = Vec3::new(0.0, 1.3, 0.5);
    let point = |u: f32, v: f32| {
        let (su, cu) = (u * TAU).sin_cos();
        let (sv, cv) = (v * TAU).sin_cos();
        let radial = Vec3::new(cu, 0.0, su);
        let n = radial * cv + Vec3::Y * sv;
        (centre + rot * (radial * big + n * small), rot * n)
    };
    let per_band = nu / BANDS;
    for band in 0..BANDS {
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        for i in 0..=per_band {
            for j in 0..=nv {
                let (p, n) = point(
                    (band * per_band + i) as f32 / nu as f32,
                    j as f32 / nv as f32,
                );
                positions.push(p);
                normals.push(n);
            }
        }
        let mut indices = Vec::new();
        let row = nv + 1;
        for i in 0..per_band {
            for j in 0..nv {
                let a = i * row + j;
                let (bb, c, d) = (a + row, a + row + 1, a + 1);
                indices.extend_from_slice(&[a, bb, c, a, c, d]);
            }
        }
        let brightness = if band % 2 == 0 { 4.0 } else { 0.4 } * uniform(&mut rng, 0.5, 2.0);
        let mesh = TriangleMesh {
            positions,
            normals: Some(normals),
            uvs: None,
            indices,
            flip_normals: false,
        };
        let e = AreaEmission {
            l: random_colour(&mut rng) * brightness,
            two_sided: false,
        };
        b.add_mesh(mesh, black, Some(e))?;
    }
    // Strip lights on the back wall (facing −z) and one along the ceiling line.
    for k in 0..4 {
        let y = 0.8 + k as f32 * 1.0;
        let l = random_colour(&mut rng) * 6.0;
        b.add_quad(
            Vec3::new(-5.0, y, 2.99),
            Vec3::X * 10.0,
            Vec3::Y * 0.05,
            black,
            emission(l),
        )?;
    }
    let eye = Vec3::new(0.0, 2.2, -5.0);
    let camera = Camera::look_at(eye, Vec3::new(0.0, 1.0, 0.5), Vec3::Y, 55.0)?;
    b.build(camera, film())
}
