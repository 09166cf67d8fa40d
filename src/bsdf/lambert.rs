//! Ideal diffuse reflection, sampled cosine-weighted.

use super::{BsdfSample, Bxdf};
use crate::Rgb;
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Lambertian reflector with albedo `r` (f = r/π).
#[derive(Clone, Copy, Debug)]
pub struct Lambert {
    /// Albedo (reflectance), each channel in [0, 1].
    pub r: Rgb,
}

impl Bxdf for Lambert {
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.r * FRAC_1_PI
    }

    #[inline]
    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.r * FRAC_1_PI,
            pdf,
            delta: false,
        })
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }
}
