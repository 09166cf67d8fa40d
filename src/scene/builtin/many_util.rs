//! Helpers shared by the many-light built-in scenes: seeded random numbers, random light
//! colours and powers, boxes and emitters.

use crate::Rgb;
use crate::luminance;
use crate::material::{Material, Texture};
use crate::sampling::hash::{next_f32, pcg_from_keys};
use crate::scene::{AreaEmission, SceneBuilder, TriangleMesh};
use glam::Vec3;
use rand_pcg::Pcg32;
use std::f32::consts::PI;

/// The scene generator's random stream (scenes are fixed: no dependence on the render seed).
pub fn scene_rng(tag: u64) -> Pcg32 {
    pcg_from_keys(&[0x6d61_6e79, tag])
}

/// Uniform in [a, b).
#[inline]
pub fn uniform(rng: &mut Pcg32, a: f32, b: f32) -> f32 {
    a + (b - a) * next_f32(rng)
}

/// A saturated random colour with luminance 1.
pub fn random_colour(rng: &mut Pcg32) -> Rgb {
    let h = next_f32(rng) * 6.0;
    let s = uniform(rng, 0.2, 0.8);
    // Hue wheel in RGB, desaturated toward white by 1 − s.
    let k = |n: f32| {
        let x = (n + h) % 6.0;
        1.0 - (x.min(4.0 - x).clamp(0.0, 1.0))
    };
    let c = Rgb::new(k(5.0), k(3.0), k(1.0)) * s + Rgb::splat(1.0 - s);
    c / luminance(c).max(1e-3)
}

/// Radiance of a one-sided diffuse emitter of `area` with total power `phi` and colour `c`
/// (luminance 1): Φ = L · A · π.
pub fn radiance_for_power(phi: f32, area: f32, c: Rgb) -> Rgb {
    c * (phi / (area * PI))
}

/// Log-uniform power in [lo, hi).
pub fn log_uniform(rng: &mut Pcg32, lo: f32, hi: f32) -> f32 {
    (lo.ln() + (hi.ln() - lo.ln()) * next_f32(rng)).exp()
}

/// A diffuse material of reflectance `r`.
pub fn diffuse(b: &mut SceneBuilder, r: f32) -> u32 {
    b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(r)),
    })
}

/// An axis-aligned box [lo, hi] without a bottom face (it stands on the floor).
pub fn add_box(b: &mut SceneBuilder, lo: Vec3, hi: Vec3, material: u32) -> anyhow::Result<()> {
    let d = hi - lo;
    let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
    // Outward normals (e1 × e2) for every face.
    b.add_quad(Vec3::new(lo.x, hi.y, lo.z), z, x, material, None)?;
    b.add_quad(lo, x, y, material, None)?;
    b.add_quad(Vec3::new(lo.x, lo.y, hi.z), y, x, material, None)?;
    b.add_quad(lo, y, z, material, None)?;
    b.add_quad(Vec3::new(hi.x, lo.y, lo.z), z, y, material, None)?;
    Ok(())
}

/// One emissive triangle (one light), emitting on the side of (p1 − p0) × (p2 − p0).
pub fn add_triangle_light(
    b: &mut SceneBuilder,
    p: [Vec3; 3],
    l: Rgb,
    material: u32,
) -> anyhow::Result<()> {
    add_mesh_light(b, p.to_vec(), vec![0, 1, 2], l, material)
}

/// A one-sided emissive triangle mesh (one light per triangle) of radiance `l`.
pub fn add_mesh_light(
    b: &mut SceneBuilder,
    positions: Vec<Vec3>,
    indices: Vec<u32>,
    l: Rgb,
    material: u32,
) -> anyhow::Result<()> {
    let mesh = TriangleMesh {
        positions,
        normals: None,
        uvs: None,
        indices,
        flip_normals: false,
    };
    b.add_mesh(mesh, material, emission(l))
}

/// Emission of a one-sided light.
pub fn emission(l: Rgb) -> Option<AreaEmission> {
    Some(AreaEmission {
        l,
        two_sided: false,
    })
}
