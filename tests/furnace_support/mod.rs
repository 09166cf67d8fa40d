//! The expected answer of a white furnace through a slab: two parallel, identical, infinite
//! interfaces (z = 0 with the medium below, z = −d with the medium above) under a uniform sky
//! of radiance Le, seen from outside along a direction at cos θo = `mu_o`. For the path
//! tracer's and the BSDFs' furnace tests (`mod furnace_support;`), with the small generator
//! their Monte Carlo loops draw from; nothing here renders.
//!
//! Derivation. Everything is invariant under translations along the slab and rotations about
//! its normal (isotropic BSDFs, uniform sky), so radiance depends only on μ = |cos θ| and on
//! which way it travels. Let L_i(μ) be the radiance inside the slab leaving an interface
//! toward the other one; by the slab's mirror symmetry it is the same function at both
//! interfaces, and with no absorption inside, what arrives at one interface at μ is what left
//! the other at μ. The rendering equation at the top interface, for a viewer inside (its BSDF
//! `f_in`, local z toward the inside) and outside (`f_out`, z toward the outside), gives
//!   L_i(μo) = ∫_inside f_in(ωo, ωi) L_i(μi) μi dωi + Le ∫_outside f_in(ωo, ωi) μi dωi,
//!   L(μo)   = Le ∫_outside f_out(ωo, ωi) μi dωi + ∫_inside f_out(ωo, ωi) L_i(μi) μi dωi,
//! a Fredholm equation of the second kind for L_i (its Neumann series is the sum over the
//! number of internal reflections). It is solved on `n` μ-bins with L_i constant per bin and
//! the kernel integrated over each bin (sub-points in μ, midpoint in φ), the bins split at
//! `mu_split` (the critical angle, where L_i has a kink), by Gaussian elimination.
//!
//! A lossless interface would give L = Le exactly; the microfacet model's single-scattering
//! loss makes a rough slab darker, which is what this computes. Two diffuse-transmission sheets
//! (R, T) have the closed form Le (R + T² / (1 − R)), which checks the solver.

#![allow(dead_code)] // Each test file uses part of this module.

use glam::Vec3;
use std::f64::consts::PI;

/// A small PCG-style generator for a test's own draws: uniform in [0, 1).
pub struct Rng(pub u64);

impl Rng {
    /// The next number in [0, 1).
    pub fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32).min(0.999_999_9)
    }
}

/// A BSDF evaluator f(wo, wi) (no cosine) in its viewer's local frame.
pub type Eval<'a> = &'a dyn Fn(Vec3, Vec3) -> f64;

/// Bin edges of (0, 1] in μ, `n` bins, with `mu_split` (if inside) an edge.
fn edges(n: usize, mu_split: Option<f64>) -> Vec<f64> {
    match mu_split.filter(|&s| s > 0.05 && s < 0.95) {
        None => (0..=n).map(|i| i as f64 / n as f64).collect(),
        Some(s) => {
            let below = ((n as f64 * s).round() as usize).clamp(1, n - 1);
            let mut e: Vec<f64> = (0..=below).map(|i| s * i as f64 / below as f64).collect();
            let above = n - below;
            e.extend((1..=above).map(|i| s + (1.0 - s) * i as f64 / above as f64));
            e
        }
    }
}

/// ∫ over μi in [a, b] (on the side `sign`: +1 the viewer's side, −1 the other) and φ of
/// f(wo, wi) μi, with `sub` midpoints in μ and `nphi` in φ ∈ [0, π] (doubled: wo lies in the
/// xz-plane and isotropic BSDFs are even in φ).
fn cell(f: Eval, wo: Vec3, a: f64, b: f64, sign: f64, sub: usize, nphi: usize) -> f64 {
    let mut s = 0.0;
    for p in 0..sub {
        let mu = a + (b - a) * (p as f64 + 0.5) / sub as f64;
        let r = (1.0 - mu * mu).max(0.0).sqrt();
        for q in 0..nphi {
            let phi = PI * (q as f64 + 0.5) / nphi as f64;
            let wi = Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                (sign * mu) as f32,
            );
            s += f(wo, wi) * mu;
        }
    }
    s * ((b - a) / sub as f64) * (2.0 * PI / nphi as f64)
}

fn wo_at(mu: f64) -> Vec3 {
    Vec3::new((1.0 - mu * mu).max(0.0).sqrt() as f32, 0.0, mu as f32)
}

/// Solve A x = b in place (Gaussian elimination with partial pivoting).
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        let (top, rest) = a.split_at_mut(c + 1);
        let pivot = &top[c];
        for (i, row) in rest.iter_mut().enumerate() {
            let m = row[c] / pivot[c];
            if m != 0.0 {
                for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                    *x -= m * p;
                }
                b[c + 1 + i] -= m * b[c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

/// Radiance seen from outside at cos θo = `mu_o` on a slab of interfaces `f_out` / `f_in`
/// under a uniform sky `le` (see the module comment); `n` μ-bins (split at `mu_split`),
/// `sub` × `nphi` points per kernel cell.
pub fn slab_furnace(
    f_out: Eval,
    f_in: Eval,
    le: f64,
    mu_o: f64,
    mu_split: Option<f64>,
    (n, sub, nphi): (usize, usize, usize),
) -> f64 {
    let e = edges(n, mu_split);
    let mid: Vec<f64> = e.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    // Rows: the inside viewer at each bin centre; (I − K) L_i = Le · A.
    let mut a = vec![vec![0.0; n]; n];
    let mut b = vec![0.0; n];
    for (k, &mu) in mid.iter().enumerate() {
        let wo = wo_at(mu);
        for j in 0..n {
            let kr = cell(f_in, wo, e[j], e[j + 1], 1.0, sub, nphi);
            a[k][j] = if j == k { 1.0 - kr } else { -kr };
            b[k] += le * cell(f_in, wo, e[j], e[j + 1], -1.0, sub, nphi);
        }
    }
    let li = solve(a, b);
    let wo = wo_at(mu_o);
    (0..n)
        .map(|j| {
            le * cell(f_out, wo, e[j], e[j + 1], 1.0, sub, nphi)
                + li[j] * cell(f_out, wo, e[j], e[j + 1], -1.0, sub, nphi)
        })
        .sum()
}

/// The furnace scene for a path tracer, in pbrt-v4 format: the slab (thickness 0.2, 2000 wide,
/// the material given as a pbrt `Material` line) under `LightSource "infinite"` of L = 1,
/// seen from outside at 40° from the normal through a 2° field of view, 16 × 16 pixels.
pub fn slab_scene_pbrt(material: &str, spp: u32) -> String {
    let (s, c) = (40f64.to_radians().sin(), 40f64.to_radians().cos());
    format!(
        r#"LookAt 0 {y} {z}  0 0 0  0 0 1
Camera "perspective" "float fov" [ 2 ]
Sampler "independent" "integer pixelsamples" [ {spp} ]
PixelFilter "box" "float xradius" [ 0.5 ] "float yradius" [ 0.5 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Integrator "path" "integer maxdepth" [ 1000 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
AttributeBegin
    {material}
    # Top interface, normal +z (counter-clockwise seen from above): the medium is below.
    Shape "trianglemesh" "point3 P" [ -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0 ]
        "integer indices" [ 0 1 2  0 2 3 ]
    # Bottom interface, normal −z (clockwise seen from above): the medium is above.
    Shape "trianglemesh" "point3 P" [ -1000 -1000 -0.2  -1000 1000 -0.2  1000 1000 -0.2  1000 -1000 -0.2 ]
        "integer indices" [ 0 1 2  0 2 3 ]
AttributeEnd
"#,
        y = -10.0 * s,
        z = 10.0 * c,
    )
}

/// cos θo of [`slab_scene_pbrt`]'s central view direction.
pub fn slab_scene_mu() -> f64 {
    40f64.to_radians().cos()
}
