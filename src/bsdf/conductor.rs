//! Rough conductor: GGX microfacets with the complex (RGB) Fresnel of a metal; below
//! [`SMOOTH_ALPHA`](super::ggx::SMOOTH_ALPHA) a delta mirror with the same Fresnel.

use super::fresnel::fr_complex_rgb;
use super::ggx::{TrowbridgeReitz, is_smooth};
use super::{BsdfSample, Bxdf, LobeSampling, reflect, reflect_z};
use crate::Rgb;
use glam::{Vec2, Vec3};

/// Metal with complex index `eta + i·k` per RGB channel and GGX roughness `alpha` (x, y).
#[derive(Clone, Copy, Debug)]
pub struct Conductor {
    /// Real part of the index of refraction (per channel).
    pub eta: Rgb,
    /// Extinction coefficient (per channel).
    pub k: Rgb,
    /// GGX widths (αx, αy); both below 1e-3 → smooth mirror.
    pub alpha: Vec2,
    /// How `sample` draws directions of the rough lobe.
    pub sampling: LobeSampling,
}

impl Conductor {
    /// Conductor with importance sampling.
    pub fn new(eta: Rgb, k: Rgb, alpha: Vec2) -> Self {
        Self {
            eta,
            k,
            alpha,
            sampling: LobeSampling::Importance,
        }
    }

    /// Fresnel reflectance at incidence cosine `cos`.
    #[inline]
    pub fn fresnel(&self, cos: f32) -> Rgb {
        fr_complex_rgb(cos, self.eta, self.k)
    }

    /// Microfacet density of the sampled reflected direction: D_wo(wm) / (4 |wo·wm|).
    #[inline]
    fn pdf_rough(distrib: &TrowbridgeReitz, wo: Vec3, wi: Vec3) -> f32 {
        let wm = (wo + wi).normalize_or_zero();
        if wm == Vec3::ZERO {
            return 0.0;
        }
        let wdm = wo.dot(wm);
        if wdm <= 0.0 {
            return 0.0;
        }
        distrib.pdf(wo, wm) / (4.0 * wdm)
    }
}

impl Bxdf for Conductor {
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 || is_smooth(self.alpha) {
            return Rgb::ZERO;
        }
        let wm = (wo + wi).normalize_or_zero();
        if wm == Vec3::ZERO {
            return Rgb::ZERO;
        }
        let d = TrowbridgeReitz::new(self.alpha);
        let fr = self.fresnel(wo.dot(wm).abs());
        fr * (d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z))
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        if is_smooth(self.alpha) {
            let wi = reflect_z(wo);
            return Some(BsdfSample {
                wi,
                f: self.fresnel(wo.z) / wo.z,
                pdf: 1.0,
                delta: true,
            });
        }
        if self.sampling != LobeSampling::Importance {
            return super::sample_by_hemisphere(self, self.sampling, wo, u);
        }
        let d = TrowbridgeReitz::new(self.alpha);
        let wm = d.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        // Visible normals can still reflect below the horizon (multiple scattering is ignored):
        // those samples have zero weight.
        super::reflection_sample(self, wo, wi)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 || is_smooth(self.alpha) {
            return 0.0;
        }
        if self.sampling != LobeSampling::Importance {
            return self.sampling.hemisphere_pdf(wi);
        }
        Self::pdf_rough(&TrowbridgeReitz::new(self.alpha), wo, wi)
    }

    fn is_delta(&self) -> bool {
        is_smooth(self.alpha)
    }
}

/// RGB (η, k) of a pbrt-v4 named metal spectrum, sampled at ≈650 / 550 / 450 nm (R, G, B).
///
/// Accepts "metal-Cu-eta" / "metal-Cu-k" style names (either half returns the pair) and bare
/// element names ("Cu"). Values (2–3 significant digits) from the tabulated optical constants
/// that pbrt ships: Cu from Palik's *Handbook of Optical Constants of Solids* (as in pbrt's
/// `Cu_eta`/`Cu_k`), Au and Ag from Johnson & Christy, Phys. Rev. B 6, 4370 (1972), Al from
/// Rakić, Appl. Opt. 34, 4755 (1995) (see refractiveindex.info). Sampling three wavelengths
/// instead of integrating the spectra against the sRGB matching functions shifts colours
/// slightly; it is the documented approximation of this RGB renderer.
pub fn named_metal(name: &str) -> Option<(Rgb, Rgb)> {
    let base = name
        .strip_prefix("metal-")
        .unwrap_or(name)
        .trim_end_matches("-eta")
        .trim_end_matches("-k");
    let (eta, k) = match base {
        "Cu" => ([0.213, 0.77, 1.16], [4.05, 2.62, 2.42]),
        "Au" => ([0.166, 0.43, 1.40], [3.15, 2.455, 1.88]),
        "Ag" => ([0.052, 0.059, 0.040], [4.41, 3.59, 2.65]),
        "Al" => ([1.47, 0.958, 0.618], [7.79, 6.69, 5.47]),
        _ => return None,
    };
    Some((Rgb::from_array(eta), Rgb::from_array(k)))
}
