//! Coated conductor (pbrt-v4 `coatedconductor`): a dielectric coat over a GGX conductor,
//! evaluated by the stochastic layered algorithm of [`Layered`](super::layered::Layered).
//! The conductor's η and k are taken relative to the coat (divided by the coat's index, as
//! pbrt-v4's `CoatedConductorMaterial` does), since the metal sits under the coat, not in air.

use super::conductor::Conductor;
use super::layered::{Base, Coat, LayerParams, Layered};
use crate::Rgb;
use glam::Vec2;

/// A coat of index `coat_eta` and GGX widths `coat_alpha` over a conductor with (η, k) in air
/// and GGX widths `alpha`.
pub fn coated_conductor(
    coat_eta: f32,
    coat_alpha: Vec2,
    eta: Rgb,
    k: Rgb,
    alpha: Vec2,
    params: LayerParams,
) -> Layered {
    let coat = coat(coat_eta, coat_alpha);
    let base = Base::Conductor(Conductor::new(eta / coat.eta, k / coat.eta, alpha));
    Layered::new(coat, base, params)
}

/// pbrt-v4's layered `coateddiffuse`: a coat over a Lambertian base of `reflectance`.
pub fn layered_diffuse(
    reflectance: Rgb,
    coat_eta: f32,
    coat_alpha: Vec2,
    params: LayerParams,
) -> Layered {
    let base = Base::Diffuse(reflectance.clamp(Rgb::ZERO, Rgb::ONE));
    Layered::new(coat(coat_eta, coat_alpha), base, params)
}

/// The coat of index `coat_eta` (1.5 where that is not a positive finite number) and GGX
/// widths `coat_alpha`.
fn coat(coat_eta: f32, coat_alpha: Vec2) -> Coat {
    let eta = if coat_eta.is_finite() && coat_eta > 0.0 {
        coat_eta
    } else {
        1.5
    };
    Coat {
        eta,
        alpha: coat_alpha,
    }
}
