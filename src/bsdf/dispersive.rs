//! Dispersive dielectric (glass whose index varies with wavelength) for an RGB renderer: one
//! index per channel, and the way spectral renderers terminate secondary wavelengths
//! (pbrt-v4's `SampledWavelengths::TerminateSecondary`) carried over to the three channels.
//!
//! - Smooth: a channel c is picked with probability 1/3 by the lobe number `uc` (remapped to
//!   [0, 1) so no sampler dimension is added), then that channel's [`Dielectric`] chooses
//!   between reflection (probability R_c) and refraction. The three channels reflect into the
//!   same mirror direction, so a reflection keeps every channel: its probability is the mean
//!   R̄ of the channels' R and its weight R_k / R̄ per channel. A refraction leaves in channel
//!   c's own direction, which no other channel reaches: the weight is 3× channel c's
//!   (3 / η_c², probability T_c / 3 against value T_c / η_c²) and 0 in the others, so the path
//!   carries that channel alone from there on. Both are unbiased (the expectation is R_k plus
//!   T_k / η_k² for each channel k).
//! - Rough: `f` is each channel's GGX dielectric with its own index (the spectral BSDF, no
//!   termination needed for a continuous lobe); `sample` draws from channel c's lobe with c
//!   uniform, so its density is the mixture `pdf` = mean of the three channels' pdfs, which is
//!   what [`Bxdf::pdf`] reports for MIS and what `sample` returns (tests/bsdf_chi2.rs).
//!
//! A material whose index does not vary is a plain [`Dielectric`], untouched by all this.

use super::dielectric::{Dielectric, SmoothEvent};
use super::ggx::is_smooth;
use super::{BsdfSample, Bxdf};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// Dielectric with one index of refraction per RGB channel (inside relative to outside).
#[derive(Clone, Copy, Debug)]
pub struct DispersiveDielectric {
    /// Index of refraction of the inside relative to the outside, per channel.
    pub eta: Rgb,
    /// GGX widths; both below 1e-3 → smooth.
    pub alpha: Vec2,
    /// True if wo is on the outside (the ray arrived from outside).
    pub entering: bool,
}

/// Largest f32 below 1 (a remapped random number must stay in [0, 1)).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Split a uniform number in [0, 1) into a channel (each with probability 1/3) and a uniform
/// number in [0, 1) for the rest of the sampling decision.
#[inline]
pub fn pick_channel(uc: f32) -> (usize, f32) {
    let s = uc * 3.0;
    let c = (s as usize).min(2);
    (c, (s - c as f32).clamp(0.0, ONE_MINUS_EPSILON))
}

impl DispersiveDielectric {
    /// Channel `c` as a plain dielectric.
    #[inline]
    pub fn channel(&self, c: usize) -> Dielectric {
        Dielectric {
            eta: self.eta[c],
            alpha: self.alpha,
            entering: self.entering,
        }
    }

    /// Fresnel reflectance for wo per channel (1 under total internal reflection).
    #[inline]
    pub fn reflectance(&self, wo: Vec3) -> Rgb {
        Rgb::from_array([0, 1, 2].map(|c| self.channel(c).reflectance(wo)))
    }

    /// Smooth interface: a channel, then its reflection or refraction (module comment).
    fn sample_smooth(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        let (c, u) = pick_channel(uc);
        let (wi, f) = match self.channel(c).smooth_event(wo, u)? {
            SmoothEvent::Reflect(wi) => {
                let r = self.reflectance(wo);
                let mean = (r.x + r.y + r.z) / 3.0;
                (wi, r / (mean * wi.z))
            }
            SmoothEvent::Refract { wi, eta } => {
                let mut f = Rgb::ZERO;
                // Channel c's refraction weight 1/η² (pbrt's radiance scaling) over the
                // probability 1/3 of having picked it; the others' light does not go this way.
                f[c] = 3.0 / (eta * eta * wi.z.abs());
                (wi, f)
            }
        };
        Some(BsdfSample {
            wi,
            f,
            pdf: 1.0,
            delta: true,
        })
    }
}

impl Bxdf for DispersiveDielectric {
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.f_pdf(wo, wi).0
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        if is_smooth(self.alpha) {
            return self.sample_smooth(wo, uc);
        }
        let (c, uc) = pick_channel(uc);
        let wi = self.channel(c).sample(wo, uc, u)?.wi;
        let (f, pdf) = self.f_pdf(wo, wi);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            delta: false,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_pdf(wo, wi).1
    }

    /// Each channel's rough f (its own [`Dielectric`]) and the mixture pdf, the mean of the
    /// channels' pdfs.
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if is_smooth(self.alpha) {
            return (Rgb::ZERO, 0.0);
        }
        let e = [0, 1, 2].map(|c| self.channel(c).rough_eval(wo, wi));
        (
            Rgb::new(e[0].0, e[1].0, e[2].0),
            (e[0].1 + e[1].1 + e[2].1) / 3.0,
        )
    }

    fn is_delta(&self) -> bool {
        is_smooth(self.alpha)
    }

    fn transmits(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pick_channel_splits_the_unit_interval() {
        assert_eq!(pick_channel(0.0), (0, 0.0));
        assert_eq!(pick_channel(0.5).0, 1);
        assert!((pick_channel(0.5).1 - 0.5).abs() < 1e-6);
        let (c, u) = pick_channel(ONE_MINUS_EPSILON);
        assert!(c == 2 && u < 1.0, "{c} {u}");
        let (c, u) = pick_channel(2.0 / 3.0);
        assert!(c >= 1 && (0.0..1.0).contains(&u), "{c} {u}");
    }
}
