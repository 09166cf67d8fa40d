//! glTF's `alphaMode` as a cut-out: the coverage α = `baseColorFactor.a` × the base-colour
//! texture's alpha. `MASK` keeps the surface where α ≥ `alphaCutoff` (default 0.5) and removes
//! it elsewhere (foliage, fences, chains); `BLEND` becomes a surface of coverage α under the
//! stochastic alpha test ([`Alpha`]), which is what a physically based renderer can do with
//! "partly there" (a fraction α of the light is stopped); `OPAQUE` ignores α, as the spec says.

use crate::geometry::{Alpha, AlphaTexture};
use crate::material::FloatTexture;
use crate::material::texture::ImageRgb;
use ::gltf::material::AlphaMode;
use glam::Vec2;
use std::sync::Arc;

/// `MASK`'s test on a varying α: full coverage where α ≥ `cutoff`, none elsewhere.
#[derive(Debug)]
struct Cutoff {
    /// α over uv.
    alpha: FloatTexture,
    /// `alphaCutoff`.
    cutoff: f32,
}

impl AlphaTexture for Cutoff {
    #[inline]
    fn alpha(&self, uv: Vec2) -> f32 {
        if self.alpha.eval(uv) >= self.cutoff {
            1.0
        } else {
            0.0
        }
    }
}

/// The cut-out of a material with alpha mode `mode`, `cutoff` (`None`: the spec's 0.5),
/// base-colour factor alpha `factor` and, if its base-colour texture has an alpha channel that
/// is not 1 everywhere, that channel (`alpha_image`, α in every channel, bilinearly read as the
/// base colour is). `None`: the surface is opaque everywhere.
pub(crate) fn material_alpha(
    mode: AlphaMode,
    cutoff: Option<f32>,
    factor: f32,
    alpha_image: Option<Arc<ImageRgb>>,
) -> Option<Alpha> {
    let factor = if factor.is_finite() {
        factor.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let cutoff = match cutoff {
        Some(c) if c.is_finite() => c,
        _ => 0.5,
    };
    let varying = alpha_image.map(|image| FloatTexture::Image {
        image,
        scale: factor,
        invert: false,
    });
    match (mode, varying) {
        (AlphaMode::Opaque, _) => None,
        (AlphaMode::Mask, None) => (factor < cutoff).then_some(Alpha::Constant(0.0)),
        (AlphaMode::Mask, Some(alpha)) => Some(Alpha::Texture(Arc::new(Cutoff { alpha, cutoff }))),
        (AlphaMode::Blend, None) => (factor < 1.0).then_some(Alpha::Constant(factor)),
        (AlphaMode::Blend, Some(alpha)) => Some(Alpha::Texture(Arc::new(alpha))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;

    /// A 2 × 1 image: α = `left` on the left half (u < ½), `right` on the right.
    fn halves(left: f32, right: f32) -> Arc<ImageRgb> {
        Arc::new(ImageRgb {
            width: 2,
            height: 1,
            pixels: vec![Rgb::splat(left), Rgb::splat(right)],
        })
    }

    #[test]
    fn mask_keeps_exactly_where_alpha_reaches_the_cutoff() {
        let a = material_alpha(AlphaMode::Mask, Some(0.4), 1.0, Some(halves(0.3, 0.9))).unwrap();
        // Texel centres (bilinear lookups there read the texel itself).
        assert_eq!(a.coverage(Vec2::new(0.25, 0.5)), 0.0);
        assert_eq!(a.coverage(Vec2::new(0.75, 0.5)), 1.0);
        // The factor scales α before the test: 0.9 × 0.4 < 0.4.
        let a = material_alpha(AlphaMode::Mask, Some(0.4), 0.4, Some(halves(0.3, 0.9))).unwrap();
        assert_eq!(a.coverage(Vec2::new(0.75, 0.5)), 0.0);
    }

    #[test]
    fn constant_alpha_and_opaque_modes() {
        assert!(material_alpha(AlphaMode::Opaque, None, 0.1, Some(halves(0.0, 0.0))).is_none());
        assert!(material_alpha(AlphaMode::Mask, None, 0.5, None).is_none());
        let Some(Alpha::Constant(c)) = material_alpha(AlphaMode::Mask, None, 0.49, None) else {
            panic!("below the default cutoff the surface is cut away");
        };
        assert_eq!(c, 0.0);
        let Some(Alpha::Constant(c)) = material_alpha(AlphaMode::Blend, None, 0.25, None) else {
            panic!("a blended surface is a constant coverage");
        };
        assert_eq!(c, 0.25);
        assert!(material_alpha(AlphaMode::Blend, None, 1.0, None).is_none());
        let b = material_alpha(AlphaMode::Blend, None, 0.5, Some(halves(0.2, 1.0))).unwrap();
        assert!((b.coverage(Vec2::new(0.25, 0.5)) - 0.1).abs() < 1e-6);
    }
}
