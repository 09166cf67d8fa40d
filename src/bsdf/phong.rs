//! Modified (energy-conserving) Phong: f = kd/π + ks·(n+2)/(2π)·cosⁿα, α the angle between wi
//! and the mirror direction of wo (Lafortune & Willems 1994), sampled as in the lecture.

use super::{BsdfSample, Bxdf, LobeSampling, reflect_z};
use crate::sampling::{Frame, cosine_hemisphere, cosine_hemisphere_pdf, cosine_power_hemisphere};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Modified Phong BRDF with diffuse `kd`, specular `ks` and exponent `n`.
///
/// With the (n+2)/(2π) normalisation the glossy lobe's albedo at normal incidence is exactly
/// `ks` and smaller elsewhere (the lobe is cut by the horizon), so kd + ks ≤ 1 conserves energy.
#[derive(Clone, Copy, Debug)]
pub struct Phong {
    /// Diffuse reflectance.
    pub kd: Rgb,
    /// Specular reflectance.
    pub ks: Rgb,
    /// Phong exponent (≥ 0).
    pub n: f32,
    /// How `sample` draws directions.
    pub sampling: LobeSampling,
}

impl Phong {
    /// Validated constructor: every channel of kd, ks in [0, 1], kd + ks ≤ 1 per channel, and a
    /// finite n ≥ 0. The error says what is wrong; the caller decides whether to clamp.
    pub fn new(kd: Rgb, ks: Rgb, n: f32) -> Result<Self, String> {
        if !kd.is_finite() || !ks.is_finite() || kd.min_element() < 0.0 || ks.min_element() < 0.0 {
            return Err(format!(
                "phong: kd {kd} and ks {ks} must be finite and non-negative"
            ));
        }
        let sum = kd + ks;
        // A little slack for values written with 3 decimals (e.g. 0.333 + 0.667).
        if sum.max_element() > 1.0 + 1e-4 {
            return Err(format!(
                "phong: kd + ks = {sum} exceeds 1 in some channel (not energy conserving)"
            ));
        }
        if !n.is_finite() || n < 0.0 {
            return Err(format!("phong: exponent n = {n} must be finite and >= 0"));
        }
        Ok(Self {
            kd,
            ks,
            n,
            sampling: LobeSampling::Importance,
        })
    }

    /// Always-valid version of [`Phong::new`]: negative/NaN values become 0, channels with
    /// kd + ks > 1 are scaled down proportionally, and n is clamped to [0, 1e6].
    pub fn clamped(kd: Rgb, ks: Rgb, n: f32) -> Self {
        let fix = |c: Rgb| Rgb::new(c.x.max(0.0), c.y.max(0.0), c.z.max(0.0)); // max() drops NaN
        let (mut kd, mut ks) = (fix(kd), fix(ks));
        let sum = kd + ks;
        for i in 0..3 {
            if sum[i] > 1.0 {
                kd[i] /= sum[i];
                ks[i] /= sum[i];
            }
        }
        let n = if n.is_nan() { 0.0 } else { n.clamp(0.0, 1e6) };
        Self {
            kd,
            ks,
            n,
            sampling: LobeSampling::Importance,
        }
    }

    /// Probability of picking the diffuse lobe: the luminance share of kd in kd + ks.
    #[inline]
    fn diffuse_prob(&self) -> f32 {
        let (d, s) = (luminance(self.kd), luminance(self.ks));
        if d + s <= 0.0 { 1.0 } else { d / (d + s) }
    }

    /// Cosine-power pdf (n+1)/(2π)·cosⁿα of the glossy lobe, from cos α.
    #[inline]
    fn glossy_pdf(&self, cos_alpha: f32) -> f32 {
        if cos_alpha <= 0.0 {
            return 0.0;
        }
        (self.n + 1.0) * 0.5 * FRAC_1_PI * cos_alpha.powf(self.n)
    }
}

impl Bxdf for Phong {
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let cos_alpha = wi.dot(reflect_z(wo));
        let spec = if cos_alpha > 0.0 {
            (self.n + 2.0) / (2.0 * PI) * cos_alpha.powf(self.n)
        } else {
            0.0
        };
        self.kd * FRAC_1_PI + self.ks * spec
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if self.sampling != LobeSampling::Importance {
            return super::sample_by_hemisphere(self, self.sampling, wo, u);
        }
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if uc < self.diffuse_prob() {
            cosine_hemisphere(u)
        } else {
            Frame::from_normal(reflect_z(wo)).to_world(cosine_power_hemisphere(u, self.n))
        };
        // Below the horizon the glossy lobe has zero weight (the lecture's C_digon point).
        super::reflection_sample(self, wo, wi)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        if self.sampling != LobeSampling::Importance {
            return self.sampling.hemisphere_pdf(wi);
        }
        let pd = self.diffuse_prob();
        // cos α via the same frame the sampler used, so sample and pdf agree to rounding.
        let cos_alpha = Frame::from_normal(reflect_z(wo)).to_local(wi).z;
        pd * cosine_hemisphere_pdf(wi) + (1.0 - pd) * self.glossy_pdf(cos_alpha)
    }
}
