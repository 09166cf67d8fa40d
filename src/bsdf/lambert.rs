//! Ideal diffuse reflection, sampled cosine-weighted.

use super::{BsdfSample, Bxdf, LobeSampling};
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Lambertian reflector with albedo `r` (f = r/π).
#[derive(Clone, Copy, Debug)]
pub struct Lambert {
    /// Albedo (reflectance), each channel in [0, 1].
    pub r: Rgb,
    /// Sampling mode (Importance and Cosine coincide here).
    pub sampling: LobeSampling,
}

impl Lambert {
    /// Lambertian reflector with importance (cosine) sampling.
    pub fn new(r: Rgb) -> Self {
        Self {
            r,
            sampling: LobeSampling::Importance,
        }
    }
}

impl Bxdf for Lambert {
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.r * FRAC_1_PI
    }

    #[inline(always)]
    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        super::sample_by_hemisphere(self, self.sampling, wo, u)
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.sampling.hemisphere_pdf(wi)
    }
}
