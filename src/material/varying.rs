//! Materials whose GGX roughness is a float texture (pbrt-v4 `"texture roughness"` and its
//! `u`/`v`/`interface.`/`conductor.` forms): the base material with its widths replaced at
//! each hit by the remapped texture values; and materials with a normal map or a bump map,
//! which replace the shading normal (pbrt-v4's `NormalMap` and `BumpMap`).

use super::Material;
use super::float_texture::FloatTexture;
use super::texture::ImageRgb;
use crate::bsdf::roughness_to_alpha;
use glam::{Vec2, Vec3};
use std::sync::Arc;

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
    /// How the shading normal is perturbed, if it is.
    pub normal: Option<NormalPerturbation>,
}

/// pbrt-v4's two ways of changing the shading normal.
#[derive(Clone, Debug)]
pub enum NormalPerturbation {
    /// `"string normalmap"` (and glTF's `normalTexture`): a tangent-space normal (x along
    /// ∂p/∂u, z along the shading normal) encoded as RGB = (n + 1)/2, linear, bilinearly
    /// filtered.
    NormalMap {
        /// The encoded normals.
        image: Arc<ImageRgb>,
        /// glTF's `normalTexture.scale` on the tangent-space x and y (1 for pbrt).
        scale: f32,
        /// y of the frame along ∂p/∂v's side of n × ∂p/∂u, as MikkTSpace tangents (glTF) make
        /// it on mirrored uvs; pbrt-v4 always takes n × ∂p/∂u.
        uv_handed: bool,
    },
    /// `"texture displacement"`: the surface moved along its normal by a float texture.
    Bump(FloatTexture),
}

/// uv step of the bump map's finite differences: pbrt-v4's fallback when a hit has no ray
/// differentials (penumbra's never do).
pub const BUMP_DELTA: f32 = 0.0005;

impl NormalPerturbation {
    /// The perturbed shading normal at texture coordinates `uv`, for shading normal `ns`,
    /// geometric normal `ng` (the result is on its side) and surface derivatives ∂p/∂u, ∂p/∂v.
    /// Bump mapping leaves out pbrt-v4's displacement·∂n/∂u term (zero on flat triangles).
    pub fn shading_normal(&self, uv: Vec2, ns: Vec3, ng: Vec3, dpdu: Vec3, dpdv: Vec3) -> Vec3 {
        let n = match self {
            NormalPerturbation::NormalMap {
                image,
                scale,
                uv_handed,
            } => {
                let c = image.bilinear(uv);
                let mut local = 2.0 * c - Vec3::ONE;
                if *scale != 1.0 {
                    local *= Vec3::new(*scale, *scale, 1.0);
                }
                let local = local.normalize_or_zero();
                // pbrt-v4's Frame::FromXZ: x = ∂p/∂u (made perpendicular to the shading
                // normal, as pbrt's shading ∂p/∂u already is), z = ns, y = z × x.
                let x = (dpdu - ns * ns.dot(dpdu)).normalize_or_zero();
                if local == Vec3::ZERO || x == Vec3::ZERO {
                    return ns;
                }
                let mut y = ns.cross(x);
                if *uv_handed && y.dot(dpdv) < 0.0 {
                    y = -y;
                }
                // Unit to rounding (an orthonormal frame times a unit vector), and left
                // unnormalised so that a flat texel, local = +z exactly, gives back ns bit
                // for bit.
                x * local.x + y * local.y + ns * local.z
            }
            NormalPerturbation::Bump(d) => {
                let du = BUMP_DELTA;
                let h = d.eval(uv);
                let hu = d.eval(uv + Vec2::new(du, 0.0));
                let hv = d.eval(uv + Vec2::new(0.0, du));
                // The displaced surface p + h·ns differentiated by forward differences.
                let pu = dpdu + ns * ((hu - h) / du);
                let pv = dpdv + ns * ((hv - h) / du);
                let n = pu.cross(pv).normalize_or_zero();
                // ∂p/∂u × ∂p/∂v follows the uv winding, not the surface's side: face it to
                // the shading normal it perturbs.
                if n.dot(ns) < 0.0 { -n } else { n }
            }
        };
        if n == Vec3::ZERO || !n.is_finite() {
            return ns;
        }
        // pbrt-v4's SetShadingGeometry keeps the geometric normal and faces the new shading
        // normal to its side.
        if n.dot(ng) < 0.0 { -n } else { n }
    }
}

/// GGX widths that replace a material's constant ones at one hit.
#[derive(Clone, Copy, Debug, Default)]
pub struct AlphaOverride {
    /// The (only, or conductor) layer's widths.
    pub alpha: Option<Vec2>,
    /// A coated conductor's coat widths.
    pub coat_alpha: Option<Vec2>,
}
