//! `dense`: the Cornell box around a procedurally displaced sphere of ≥ 1M triangles, so that
//! benchmarks measure the BVH on a large mesh while the lighting stays the default scene's.

use super::cornell::{add_cornell_box, cornell_camera, cornell_film};
use super::{BuiltinOptions, Scene};
use crate::Rgb;
use crate::material::{Material, Texture};
use crate::scene::{SceneBuilder, TriangleMesh};
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Default triangle count (2·u·(v−1) for the u × v lat-long grid below).
const DEFAULT_TRIANGLES: u32 = 1_050_000;

/// Build the scene; `opts.triangles` overrides the triangle count.
pub fn dense(opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let mut b = SceneBuilder::new();
    add_cornell_box(&mut b, false)?;
    let m = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::new(0.7, 0.65, 0.6)),
    });
    let count = opts.triangles.unwrap_or(DEFAULT_TRIANGLES);
    anyhow::ensure!(
        (64..=20_000_000).contains(&count),
        "--triangles must be between 64 and 20000000, got {count}"
    );
    let target = count as f32;
    // u = 2v gives square-ish cells: 2·2v·v ≈ target.
    let v = (target / 4.0).sqrt().ceil().max(4.0) as u32;
    let u = 2 * v;
    let (center, radius) = (Vec3::new(0.0, 0.75, 0.0), 0.55);
    let mut positions = Vec::with_capacity((u * (v + 1)) as usize);
    for j in 0..=v {
        let theta = PI * j as f32 / v as f32;
        for i in 0..u {
            let phi = TAU * i as f32 / u as f32;
            let dir = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            // Bumps at several frequencies: a fine, irregular surface (no flat BVH shortcuts).
            let bump = 0.06 * (7.0 * phi).sin() * (5.0 * theta).sin()
                + 0.02 * (31.0 * phi + 3.0 * theta).sin() * (23.0 * theta).cos();
            positions.push(center + dir * radius * (1.0 + bump));
        }
    }
    let mut indices = Vec::with_capacity((6 * u * v) as usize);
    for j in 0..v {
        for i in 0..u {
            let a = j * u + i;
            let b2 = j * u + (i + 1) % u;
            let c = a + u;
            let d = b2 + u;
            if j != 0 {
                indices.extend_from_slice(&[a, b2, c]);
            }
            if j != v - 1 {
                indices.extend_from_slice(&[b2, d, c]);
            }
        }
    }
    b.add_mesh(
        TriangleMesh {
            positions,
            normals: None,
            uvs: None,
            indices,
            flip_normals: false,
        },
        m,
        None,
    )?;
    b.build(cornell_camera(), cornell_film())
}
