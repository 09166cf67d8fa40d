//! Dielectric interface (glass, water): Fresnel-weighted choice between reflection and
//! refraction. Smooth (delta) below [`SMOOTH_ALPHA`](super::ggx::SMOOTH_ALPHA); otherwise a GGX
//! rough interface (Walter et al. 2007, "Microfacet Models for Refraction through Rough
//! Surfaces") sampled with visible normals. The rough lobe is always importance sampled
//! ([`LobeSampling`](super::LobeSampling) modes only cover the reflection hemisphere).
//! One index for every channel; a dispersive glass is [`DispersiveDielectric`](super::DispersiveDielectric).

use super::fresnel::fr_dielectric;
use super::ggx::{TrowbridgeReitz, is_smooth};
use super::{BsdfSample, Bxdf, reflect, reflect_z};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// Dielectric with index `eta` (inside relative to outside). The integrator flips the frame
/// toward wo, so the BSDF must be told which side wo is on: `entering` = wo is outside.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// Index of refraction of the inside relative to the outside.
    pub eta: f32,
    /// GGX widths; both below 1e-3 → smooth.
    pub alpha: Vec2,
    /// True if wo is on the outside (the ray arrived from outside).
    pub entering: bool,
}

impl Dielectric {
    /// Relative index η_t / η_i seen by light arriving along wo.
    #[inline]
    pub fn eta_rel(&self) -> f32 {
        let eta = if self.eta.is_finite() && self.eta > 0.0 {
            self.eta
        } else {
            1.0
        };
        if self.entering { eta } else { 1.0 / eta }
    }

    /// Fresnel reflectance for wo (1 under total internal reflection): the probability that
    /// `sample` reflects.
    #[inline]
    pub fn reflectance(&self, wo: Vec3) -> f32 {
        fr_dielectric(wo.z, self.eta_rel())
    }
}

/// Refract `wo` (wo.z > 0) through the z = 0 interface with relative index `eta`;
/// `None` under total internal reflection.
#[inline]
pub fn refract_z(wo: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.z;
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + Vec3::Z * (cos_i / eta - cos_t)).normalize())
}

/// Refract `wo` through a microfacet with normal `wm` (wo·wm > 0), relative index `eta`.
#[inline]
fn refract_about(wo: Vec3, wm: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(wm);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + wm * (cos_i / eta - cos_t)).normalize())
}

impl Dielectric {
    /// Generalised half vector of a rough transmission (oriented to +z), or `None` for
    /// configurations no microfacet can produce (back-facing to wo or wi).
    #[inline]
    fn transmission_half(wo: Vec3, wi: Vec3, eta: f32) -> Option<Vec3> {
        let wm = (wi * eta + wo).normalize_or_zero();
        if wm == Vec3::ZERO {
            return None;
        }
        let wm = if wm.z < 0.0 { -wm } else { wm };
        // wo must see the facet's front, wi must leave through its back.
        if wm.dot(wo) <= 0.0 || wm.dot(wi) >= 0.0 {
            return None;
        }
        Some(wm)
    }

    /// Rough f and pdf together (they share the half vector and Fresnel term).
    pub(super) fn rough_eval(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        if wo.z <= 0.0 || wi.z == 0.0 {
            return (0.0, 0.0);
        }
        let eta = self.eta_rel();
        let d = TrowbridgeReitz::new(self.alpha);
        if wi.z > 0.0 {
            let wm = (wo + wi).normalize_or_zero();
            let wdm = wo.dot(wm);
            if wm == Vec3::ZERO || wdm <= 0.0 {
                return (0.0, 0.0);
            }
            let r = fr_dielectric(wdm, eta);
            let f = d.d(wm) * r * d.g(wo, wi) / (4.0 * wo.z * wi.z);
            let pdf = d.pdf(wo, wm) / (4.0 * wdm) * r;
            return (f, pdf);
        }
        let Some(wm) = Self::transmission_half(wo, wi, eta) else {
            return (0.0, 0.0);
        };
        let (odm, idm) = (wo.dot(wm), wi.dot(wm));
        let t = 1.0 - fr_dielectric(odm, eta);
        let denom = (idm + odm / eta).powi(2);
        if denom <= 0.0 || t <= 0.0 {
            return (0.0, 0.0);
        }
        // Jacobian of the generalised half vector: dωm/dωi = |wi·wm| / (wi·wm + wo·wm/η)².
        let dwm_dwi = idm.abs() / denom;
        let f = d.d(wm) * t * d.g(wo, wi) * (idm * odm).abs()
            / (wi.z.abs() * wo.z * denom)
            / (eta * eta);
        (f, d.pdf(wo, wm) * dwm_dwi * t)
    }

    /// Smooth interface: the event `uc` picks, reflection with probability R (Fresnel) and
    /// refraction otherwise (`None` where refraction has no direction).
    #[inline]
    pub(super) fn smooth_event(&self, wo: Vec3, uc: f32) -> Option<SmoothEvent> {
        let eta = self.eta_rel();
        if uc < fr_dielectric(wo.z, eta) {
            return Some(SmoothEvent::Reflect(reflect_z(wo)));
        }
        Some(SmoothEvent::Refract {
            wi: refract_z(wo, eta)?,
            eta,
        })
    }

    /// Smooth interface: the delta reflection or refraction chosen by Fresnel.
    fn sample_smooth(&self, wo: Vec3, uc: f32) -> Option<BsdfSample> {
        // Choosing the event with probability R (resp. T) makes the weight f·|cos|/pdf equal to 1
        // for reflection and to the radiance scaling 1/η² for refraction.
        let (wi, f) = match self.smooth_event(wo, uc)? {
            SmoothEvent::Reflect(wi) => (wi, 1.0 / wi.z),
            // Radiance is compressed into the smaller solid angle on the dense side (pbrt's
            // TransportMode::Radiance factor 1/η²).
            SmoothEvent::Refract { wi, eta } => (wi, 1.0 / (eta * eta * wi.z.abs())),
        };
        Some(BsdfSample {
            wi,
            f: Rgb::splat(f),
            pdf: 1.0,
            delta: true,
        })
    }
}

/// What a smooth dielectric interface does with a ray: its delta reflection or refraction.
#[derive(Clone, Copy, Debug)]
pub(super) enum SmoothEvent {
    /// Mirror reflection into `wi`.
    Reflect(Vec3),
    /// Refraction into `wi` with relative index `eta` (η_t / η_i).
    Refract {
        /// The refracted direction.
        wi: Vec3,
        /// Relative index of the interface as the ray sees it.
        eta: f32,
    },
}

impl Bxdf for Dielectric {
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
        let eta = self.eta_rel();
        let wm = TrowbridgeReitz::new(self.alpha).sample_wm(wo, u);
        let r = fr_dielectric(wo.dot(wm), eta);
        let wi = if uc < r {
            let wi = reflect(wo, wm);
            if wi.z <= 0.0 {
                return None;
            }
            wi
        } else {
            let wi = refract_about(wo, wm, eta)?;
            if wi.z >= 0.0 {
                return None;
            }
            wi
        };
        let (f, pdf) = self.rough_eval(wo, wi);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: Rgb::splat(f),
            pdf,
            delta: false,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_pdf(wo, wi).1
    }

    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if is_smooth(self.alpha) {
            return (Rgb::ZERO, 0.0);
        }
        let (f, pdf) = self.rough_eval(wo, wi);
        (Rgb::splat(f), pdf)
    }

    fn is_delta(&self) -> bool {
        is_smooth(self.alpha)
    }

    fn transmits(&self) -> bool {
        true
    }
}
