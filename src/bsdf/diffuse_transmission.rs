//! Diffuse transmission (pbrt-v4 `diffusetransmission`): a thin sheet (curtain, lampshade,
//! paper) that reflects R/π on the viewer's side and transmits T/π to the other side, both
//! Lambertian. Sampled by choosing the lobe with probability ∝ max(R) : max(T) (pbrt-v4's
//! choice) and drawing the hemisphere of that lobe with the [`LobeSampling`] density (cosine
//! unless uniform is asked for).

use super::{BsdfSample, Bxdf, LobeSampling};
use crate::Rgb;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Lambertian reflection `r` and Lambertian transmission `t` (each channel in [0, 1]).
#[derive(Clone, Copy, Debug)]
pub struct DiffuseTransmission {
    /// Reflectance (albedo of the reflected lobe).
    pub r: Rgb,
    /// Transmittance (albedo of the transmitted lobe).
    pub t: Rgb,
    /// Hemisphere density of each lobe (Importance and Cosine coincide).
    pub sampling: LobeSampling,
}

impl DiffuseTransmission {
    /// A sheet with reflectance `r` and transmittance `t`, each clamped to [0, 1] per channel
    /// as pbrt-v4 does (NaN → 0; R + T may exceed 1 there too, and is rendered as given).
    pub fn new(r: Rgb, t: Rgb) -> Self {
        let unit = |c: Rgb| {
            let u = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
            Rgb::new(u(c.x), u(c.y), u(c.z))
        };
        Self {
            r: unit(r),
            t: unit(t),
            sampling: LobeSampling::Importance,
        }
    }

    /// Probability that `sample` picks the reflected lobe (`None` if both lobes are black).
    #[inline]
    fn reflect_probability(&self) -> Option<f32> {
        let (pr, pt) = (self.r.max_element(), self.t.max_element());
        (pr + pt > 0.0).then(|| pr / (pr + pt))
    }
}

impl Bxdf for DiffuseTransmission {
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z == 0.0 {
            return Rgb::ZERO;
        }
        if wi.z > 0.0 {
            self.r * FRAC_1_PI
        } else {
            self.t * FRAC_1_PI
        }
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let pr = self.reflect_probability()?;
        let w = self.sampling.sample_hemisphere(u);
        let pdf = self.sampling.hemisphere_pdf(w);
        if pdf <= 0.0 {
            return None;
        }
        let (wi, f, p) = if uc < pr {
            (w, self.r * FRAC_1_PI, pr)
        } else {
            (Vec3::new(w.x, w.y, -w.z), self.t * FRAC_1_PI, 1.0 - pr)
        };
        Some(BsdfSample {
            wi,
            f,
            pdf: pdf * p,
            delta: false,
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let Some(pr) = self.reflect_probability() else {
            return 0.0;
        };
        if wi.z > 0.0 {
            pr * self.sampling.hemisphere_pdf(wi)
        } else {
            (1.0 - pr) * self.sampling.hemisphere_pdf(Vec3::new(wi.x, wi.y, -wi.z))
        }
    }

    fn transmits(&self) -> bool {
        true
    }
}
