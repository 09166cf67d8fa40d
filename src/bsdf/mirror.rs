//! Ideal specular reflector with a constant reflectance (no Fresnel falloff).

use super::{BsdfSample, Bxdf, reflect_z};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// Perfect mirror reflecting a fraction `r` of the light (delta lobe).
#[derive(Clone, Copy, Debug)]
pub struct Mirror {
    /// Reflectance per channel.
    pub r: Rgb,
}

impl Bxdf for Mirror {
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::ZERO
    }

    fn sample(&self, wo: Vec3, _uc: f32, _u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        // f·cos/pdf = r: the delta convention of the module.
        Some(BsdfSample {
            wi: reflect_z(wo),
            f: self.r / wo.z,
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
