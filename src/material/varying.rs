//! Materials whose GGX roughness is a float texture (pbrt-v4 `"texture roughness"` and its
//! `u`/`v`/`interface.`/`conductor.` forms): the base material with its widths replaced at
//! each hit by the remapped texture values.

use super::Material;
use super::float_texture::FloatTexture;
use crate::bsdf::roughness_to_alpha;
use glam::Vec2;

/// Per-axis roughness textures and how they become GGX widths.
#[derive(Clone, Debug)]
pub struct RoughnessTextures {
    /// (u, v) roughness as the file gives it.
    pub uv: [FloatTexture; 2],
    /// pbrt's `remaproughness`: widths are `roughness_to_alpha(r)`, else r itself.
    pub remap: bool,
}

impl RoughnessTextures {
    /// GGX widths at texture coordinates `uv` (negative roughness clamps to 0, as the
    /// constant path does).
    #[inline]
    pub fn alpha(&self, uv: Vec2) -> Vec2 {
        let r = Vec2::new(self.uv[0].eval(uv), self.uv[1].eval(uv)).max(Vec2::ZERO);
        if self.remap {
            Vec2::new(roughness_to_alpha(r.x), roughness_to_alpha(r.y))
        } else {
            r
        }
    }
}

/// A material with textured roughness.
#[derive(Clone, Debug)]
pub struct VaryingMaterial {
    /// The material (its constant widths are replaced where a texture is given).
    pub base: Material,
    /// Roughness of the base's (only, or conductor) microfacet layer.
    pub roughness: Option<RoughnessTextures>,
    /// Roughness of a coated conductor's coat (`interface.*roughness`).
    pub coat_roughness: Option<RoughnessTextures>,
}

/// GGX widths that replace a material's constant ones at one hit.
#[derive(Clone, Copy, Debug, Default)]
pub struct AlphaOverride {
    /// The (only, or conductor) layer's widths.
    pub alpha: Option<Vec2>,
    /// A coated conductor's coat widths.
    pub coat_alpha: Option<Vec2>,
}
