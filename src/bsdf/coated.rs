//! Coated diffuse (pbrt-v4 `coateddiffuse`, Mitsuba `roughplastic`): a GGX dielectric coat
//! over a Lambertian base, in the closed-form approximation of Mitsuba's plastic models.
//!
//! f = D·F(wo·wm)·G / (4 cos θo cos θi)                                (coat reflection)
//!   + R/π · (1 − F(θi))(1 − F(θo)) / (η² (1 − R·F_dr,int))            (diffuse base)
//!
//! The base term counts light refracted in, bouncing between base and coat (geometric series
//! with the internal diffuse Fresnel reflectance F_dr,int) and refracted out. With a smooth coat
//! its albedo is (1 − F(θo))·R(1 − F_dr,int)/(1 − R·F_dr,int) ≤ 1 − F(θo), so the total albedo
//! stays ≤ 1; with a rough coat it is an approximation (the coat's transmission is taken as
//! smooth), checked numerically by the furnace tests.

use super::fresnel::{diffuse_fresnel_internal, fr_dielectric};
use super::ggx::{TrowbridgeReitz, is_smooth};
use super::{BsdfSample, Bxdf, LobeSampling, reflect, reflect_z};
use crate::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Diffuse base `reflectance` under a dielectric coat of index `eta` and GGX roughness `alpha`.
#[derive(Clone, Copy, Debug)]
pub struct CoatedDiffuse {
    /// Albedo of the diffuse base.
    pub reflectance: Rgb,
    /// Coat GGX widths (αx, αy); below 1e-3 the coat reflection is a delta lobe.
    pub alpha: Vec2,
    /// Index of refraction of the coat (≥ 1).
    pub eta: f32,
    /// Precomputed internal diffuse Fresnel reflectance of the coat.
    fdr_int: f32,
    /// How `sample` draws directions of the non-delta lobes.
    pub sampling: LobeSampling,
}

impl CoatedDiffuse {
    /// Coated diffuse; `reflectance` is clamped to [0, 1] and `eta` to ≥ 1.
    pub fn new(reflectance: Rgb, alpha: Vec2, eta: f32) -> Self {
        let eta = if eta.is_finite() { eta.max(1.0) } else { 1.5 };
        Self {
            reflectance: reflectance.clamp(Rgb::ZERO, Rgb::ONE),
            alpha,
            eta,
            fdr_int: diffuse_fresnel_internal(eta),
            sampling: LobeSampling::Importance,
        }
    }

    /// Probability of sampling the coat lobe: its Fresnel weight against the base's albedo.
    #[inline]
    fn spec_prob(&self, wo: Vec3) -> f32 {
        let fo = fr_dielectric(wo.z, self.eta);
        let wd = (1.0 - fo) * luminance(self.reflectance);
        if fo + wd <= 0.0 { 1.0 } else { fo / (fo + wd) }
    }

    /// The diffuse base term (no cosine).
    #[inline]
    fn f_diffuse(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let ti = 1.0 - fr_dielectric(wi.z, self.eta);
        let to = 1.0 - fr_dielectric(wo.z, self.eta);
        let r = self.reflectance;
        let denom = (Rgb::ONE - r * self.fdr_int) * (self.eta * self.eta);
        r * (ti * to * FRAC_1_PI) / denom
    }

    /// The rough coat term (no cosine).
    #[inline]
    fn f_coat(&self, wo: Vec3, wi: Vec3) -> f32 {
        let wm = (wo + wi).normalize_or_zero();
        if wm == Vec3::ZERO {
            return 0.0;
        }
        let d = TrowbridgeReitz::new(self.alpha);
        fr_dielectric(wo.dot(wm).abs(), self.eta) * d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z)
    }

    /// Density of the coat lobe's visible-normal sampling at wi.
    #[inline]
    fn pdf_coat(&self, wo: Vec3, wi: Vec3) -> f32 {
        let wm = (wo + wi).normalize_or_zero();
        let wdm = wo.dot(wm);
        if wm == Vec3::ZERO || wdm <= 0.0 {
            return 0.0;
        }
        TrowbridgeReitz::new(self.alpha).pdf(wo, wm) / (4.0 * wdm)
    }
}

impl Bxdf for CoatedDiffuse {
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let base = self.f_diffuse(wo, wi);
        if is_smooth(self.alpha) {
            base
        } else {
            base + Rgb::splat(self.f_coat(wo, wi))
        }
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let smooth = is_smooth(self.alpha);
        if smooth {
            let ps = self.spec_prob(wo);
            if uc < ps {
                // Delta coat reflection chosen with probability ps: weight F / ps.
                let fo = fr_dielectric(wo.z, self.eta);
                return Some(BsdfSample {
                    wi: reflect_z(wo),
                    f: Rgb::splat(fo / (ps * wo.z)),
                    pdf: 1.0,
                    delta: true,
                });
            }
            return super::reflection_sample(self, wo, self.sampling.sample_hemisphere(u));
        }
        if self.sampling != LobeSampling::Importance {
            return super::sample_by_hemisphere(self, self.sampling, wo, u);
        }
        let wi = if uc < self.spec_prob(wo) {
            let wm = TrowbridgeReitz::new(self.alpha).sample_wm(wo, u);
            reflect(wo, wm)
        } else {
            cosine_hemisphere(u)
        };
        super::reflection_sample(self, wo, wi)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.spec_prob(wo);
        if is_smooth(self.alpha) {
            return (1.0 - ps) * self.sampling.hemisphere_pdf(wi);
        }
        if self.sampling != LobeSampling::Importance {
            return self.sampling.hemisphere_pdf(wi);
        }
        ps * self.pdf_coat(wo, wi) + (1.0 - ps) * cosine_hemisphere_pdf(wi)
    }
}
