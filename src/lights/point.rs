//! Isotropic point light: a delta distribution in position.

use super::{
    LightBounds, LightLiSample, LightSampleContext, LightSource, SamplingMode, is_positive,
};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A point at `p` radiating intensity `intensity` (W/sr-equivalent) equally in all directions.
#[derive(Clone, Copy, Debug)]
pub struct PointLight {
    /// Position.
    pub p: Vec3,
    /// Radiant intensity I.
    pub intensity: Rgb,
}

impl PointLight {
    /// A point light at `p` with intensity `intensity`.
    pub fn new(p: Vec3, intensity: Rgb) -> Self {
        Self { p, intensity }
    }
}

impl LightSource for PointLight {
    /// Deterministic: the only direction is toward the light; Li = I / r², pdf = 1 (delta).
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        _mode: SamplingMode,
    ) -> Option<LightLiSample> {
        let d = self.p - ctx.p;
        let r2 = d.length_squared();
        if !is_positive(r2) || !r2.is_finite() {
            return None;
        }
        Some(LightLiSample {
            wi: d / r2.sqrt(),
            li: self.intensity / r2,
            pdf: 1.0,
            p_light: self.p,
            delta: true,
        })
    }

    fn power(&self) -> f32 {
        4.0 * PI * luminance(self.intensity)
    }

    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds {
            min: self.p,
            max: self.p,
            w: Vec3::Z,
            phi: self.power(),
            // Emits in every direction.
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }
}
