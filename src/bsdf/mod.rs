//! BSDFs in the local shading frame (z = shading normal).
//!
//! Contract: `f` excludes the cosine factor; `pdf(wo, wi)` is exactly the solid-angle density
//! `sample` draws from (the chi² tests check this); delta lobes report `delta = true` with
//! `pdf = 1` by convention and are never evaluated by `f`/`pdf` (they return 0).
//! The integrator builds the frame with the shading normal flipped toward `wo`, so `wo.z ≥ 0`
//! for every call; transmissive BSDFs are told which side they are entered from at construction.

pub mod lambert;

pub use lambert::Lambert;

use crate::Rgb;
use glam::{Vec2, Vec3};

/// One sampled direction.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Sampled incident direction (local frame, unit).
    pub wi: Vec3,
    /// BSDF value f(wo, wi) (no cosine).
    pub f: Rgb,
    /// Solid-angle pdf of `wi` (1 for delta lobes).
    pub pdf: f32,
    /// True if drawn from a delta (specular) lobe.
    pub delta: bool,
}

/// The interface every BSDF implements.
pub trait Bxdf {
    /// f(wo, wi) without the cosine.
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb;
    /// Draw wi given wo: `uc` picks a lobe, `u` warps within it.
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample>;
    /// Density of `sample` at wi.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// True if every lobe is a delta (mirror, smooth glass): light sampling cannot help.
    fn is_delta(&self) -> bool {
        false
    }
}

/// Closed set of BSDFs (enum dispatch keeps the per-sample path free of virtual calls).
#[derive(Clone, Debug)]
pub enum Bsdf {
    /// Ideal diffuse.
    Lambert(Lambert),
}

impl Bxdf for Bsdf {
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match self {
            Bsdf::Lambert(b) => b.f(wo, wi),
        }
    }
    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            Bsdf::Lambert(b) => b.sample(wo, uc, u),
        }
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Lambert(b) => b.pdf(wo, wi),
        }
    }
    #[inline]
    fn is_delta(&self) -> bool {
        match self {
            Bsdf::Lambert(b) => b.is_delta(),
        }
    }
}
