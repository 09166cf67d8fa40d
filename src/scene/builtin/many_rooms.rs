//! `many-rooms`: R×R rooms (default 8×8, `--rooms`) with a doorway in every inner wall and
//! several ceiling lights per room (default 4; `--light-count` sets the total). The camera
//! stands in a corner of a middle room and looks through a doorway into the neighbour: almost
//! every light is occluded, which only visibility-aware selection can know.

use super::many_open::film;
use super::many_util::{
    diffuse, emission, log_uniform, radiance_for_power, random_colour, scene_rng, uniform,
};
use super::{BuiltinOptions, Scene};
use crate::camera::Camera;
use crate::scene::SceneBuilder;
use anyhow::ensure;
use glam::Vec3;

/// Room edge (m).
const ROOM: f32 = 4.0;
/// Ceiling height (m).
const HEIGHT: f32 = 3.0;
/// Doorway width and height (m).
const DOOR: (f32, f32) = (1.0, 2.2);

/// Build `many-rooms`.
pub fn many_rooms(opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let r = opts.rooms.unwrap_or(8);
    ensure!(
        (1..=64).contains(&r),
        "--rooms must be between 1 and 64, got {r}"
    );
    let per_room = match opts.light_count {
        Some(n) => n.div_ceil(r * r).clamp(1, 256),
        None => 4,
    };
    let mut rng = scene_rng(2);
    let mut b = SceneBuilder::new();
    let floor = diffuse(&mut b, 0.5);
    let wall = diffuse(&mut b, 0.7);
    let black = diffuse(&mut b, 0.0);
    let side = r as f32 * ROOM;
    b.add_quad(Vec3::ZERO, Vec3::Z * side, Vec3::X * side, floor, None)?;
    b.add_quad(Vec3::Y * HEIGHT, Vec3::X * side, Vec3::Z * side, wall, None)?;
    // Walls along x = i·ROOM (axis 0) and z = i·ROOM (axis 1), one segment per room.
    let mut doors = Vec::new();
    for axis in 0..2 {
        for i in 0..=r {
            for j in 0..r {
                let inner = i > 0 && i < r;
                let door =
                    inner.then(|| uniform(&mut rng, 0.3 + DOOR.0 * 0.5, ROOM - 0.3 - DOOR.0 * 0.5));
                let at = |along: f32, y: f32| {
                    let a = i as f32 * ROOM;
                    let s = j as f32 * ROOM + along;
                    if axis == 0 {
                        Vec3::new(a, y, s)
                    } else {
                        Vec3::new(s, y, a)
                    }
                };
                let run = if axis == 0 { Vec3::Z } else { Vec3::X };
                let mut seg = |from: f32, to: f32, y0: f32, y1: f32| {
                    b.add_quad(
                        at(from, y0),
                        run * (to - from),
                        Vec3::Y * (y1 - y0),
                        wall,
                        None,
                    )
                };
                match door {
                    None => seg(0.0, ROOM, 0.0, HEIGHT)?,
                    Some(c) => {
                        let (d0, d1) = (c - DOOR.0 * 0.5, c + DOOR.0 * 0.5);
                        seg(0.0, d0, 0.0, HEIGHT)?;
                        seg(d1, ROOM, 0.0, HEIGHT)?;
                        seg(d0, d1, DOOR.1, HEIGHT)?;
                        doors.push((axis, i, j, c));
                    }
                }
            }
        }
    }
    for rx in 0..r {
        for rz in 0..r {
            for _ in 0..per_room {
                let s = uniform(&mut rng, 0.3, 0.6);
                let p = Vec3::new(
                    rx as f32 * ROOM + uniform(&mut rng, 0.3, ROOM - 0.3 - s),
                    HEIGHT - 0.01,
                    rz as f32 * ROOM + uniform(&mut rng, 0.3, ROOM - 0.3 - s),
                );
                let l = radiance_for_power(
                    log_uniform(&mut rng, 5.0, 50.0),
                    s * s,
                    random_colour(&mut rng),
                );
                b.add_quad(p, Vec3::X * s, Vec3::Z * s, black, emission(l))?;
            }
        }
    }
    // Camera room (m, m); look through the doorway in its +x wall, or across the room if the
    // grid is a single room.
    let m = r / 2;
    let (x0, z0) = (m as f32 * ROOM, m as f32 * ROOM);
    let eye = Vec3::new(x0 + 0.4, 1.6, z0 + 0.4);
    let target = doors
        .iter()
        .find(|&&(axis, i, j, _)| axis == 0 && i == m + 1 && j == m)
        .map(|&(_, _, _, c)| Vec3::new(x0 + ROOM + 1.0, 1.0, z0 + c))
        .unwrap_or(Vec3::new(x0 + ROOM, 1.0, z0 + ROOM * 0.5));
    let camera = Camera::look_at(eye, target, Vec3::Y, 75.0)?;
    b.build(camera, film())
}
