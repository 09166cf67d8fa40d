//! Spot light: a point light whose intensity falls off with the angle from its axis, with
//! pbrt-v4's smoothstep between the falloff start and the total width.

use super::{
    LightBounds, LightLiSample, LightSampleContext, LightSource, SamplingMode, is_positive,
};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A spot at `p` pointing along `dir`: full intensity inside `cos_falloff_start`, zero outside
/// `cos_total_width`, smoothstep in cos θ between.
#[derive(Clone, Copy, Debug)]
pub struct SpotLight {
    /// Position.
    pub p: Vec3,
    /// Unit axis.
    pub dir: Vec3,
    /// Intensity on the axis.
    pub intensity: Rgb,
    /// Cosine of the angle where the falloff starts.
    pub cos_falloff_start: f32,
    /// Cosine of the total cone half-angle (no light beyond).
    pub cos_total_width: f32,
}

/// Hermite smoothstep of `x` between `a` and `b` (0 below a, 1 above b).
#[inline]
fn smoothstep(x: f32, a: f32, b: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl SpotLight {
    /// A spot light. A zero `dir` falls back to −z; cosines are clamped to [−1, 1] and the start
    /// is kept inside the total width, so odd input degrades gracefully instead of panicking.
    pub fn new(
        p: Vec3,
        dir: Vec3,
        intensity: Rgb,
        cos_falloff_start: f32,
        cos_total_width: f32,
    ) -> Self {
        let clamp = |c: f32| {
            if c.is_finite() {
                c.clamp(-1.0, 1.0)
            } else {
                1.0
            }
        };
        let cos_total_width = clamp(cos_total_width);
        let cos_falloff_start = clamp(cos_falloff_start).max(cos_total_width);
        Self {
            p,
            dir: dir.try_normalize().unwrap_or(Vec3::NEG_Z),
            intensity,
            cos_falloff_start,
            cos_total_width,
        }
    }

    /// Intensity toward unit direction `w` (from the light).
    #[inline]
    pub fn intensity_toward(&self, w: Vec3) -> Rgb {
        self.intensity
            * smoothstep(
                self.dir.dot(w),
                self.cos_total_width,
                self.cos_falloff_start,
            )
    }
}

impl LightSource for SpotLight {
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
        let wi = d / r2.sqrt();
        let li = self.intensity_toward(-wi) / r2;
        if li == Rgb::ZERO {
            return None;
        }
        Some(LightLiSample {
            wi,
            li,
            pdf: 1.0,
            p_light: self.p,
            delta: true,
        })
    }

    /// ∫ I(ω) dω: full intensity over the inner cap, and the smoothstep integrates to half the
    /// band's solid angle (it is symmetric about its midpoint in cos θ) — pbrt-v4's formula.
    fn power(&self) -> f32 {
        luminance(self.intensity)
            * 2.0
            * PI
            * (1.0 - 0.5 * (self.cos_falloff_start + self.cos_total_width))
    }

    /// pbrt-v4 convention: `phi` bounds 4π·I (the angular cone terms do the rest).
    fn bounds(&self) -> Option<LightBounds> {
        let theta_e = self.cos_total_width.acos() - self.cos_falloff_start.acos();
        Some(LightBounds {
            min: self.p,
            max: self.p,
            w: self.dir,
            phi: 4.0 * PI * luminance(self.intensity),
            cos_theta_o: self.cos_falloff_start,
            cos_theta_e: theta_e.cos(),
            two_sided: false,
        })
    }
}
