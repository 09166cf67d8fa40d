//! Smooth dielectric interface (glass, water): Fresnel-weighted choice between specular
//! reflection and refraction.
//!
//! Rough dielectrics are not implemented: a non-zero `alpha` is stored but the interface is
//! rendered as smooth (documented approximation; the GGX transmission lobe is future work).

use super::fresnel::fr_dielectric;
use super::{BsdfSample, Bxdf, reflect_z};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// Dielectric with index `eta` (inside relative to outside). The integrator flips the frame
/// toward wo, so the BSDF must be told which side wo is on: `entering` = wo is outside.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// Index of refraction of the inside relative to the outside.
    pub eta: f32,
    /// GGX widths (stored for the loaders; rendered as smooth, see the module docs).
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

impl Bxdf for Dielectric {
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn sample(&self, wo: Vec3, uc: f32, _u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let eta = self.eta_rel();
        let r = fr_dielectric(wo.z, eta);
        // Choosing the event with probability R (resp. T) makes the weight f·|cos|/pdf equal to 1
        // for reflection and to the radiance scaling 1/η² for refraction.
        if uc < r {
            let wi = reflect_z(wo);
            return Some(BsdfSample {
                wi,
                f: Rgb::splat(1.0 / wi.z),
                pdf: 1.0,
                delta: true,
            });
        }
        let wi = refract_z(wo, eta)?;
        Some(BsdfSample {
            wi,
            // Radiance is compressed into the smaller solid angle on the dense side (pbrt's
            // TransportMode::Radiance factor 1/η²).
            f: Rgb::splat(1.0 / (eta * eta * wi.z.abs())),
            pdf: 1.0,
            delta: true,
        })
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn is_delta(&self) -> bool {
        true
    }
}
