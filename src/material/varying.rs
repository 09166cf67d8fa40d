//! Materials whose GGX roughness is a float texture (pbrt-v4 `"texture roughness"` and its
//! `u`/`v`/`interface.`/`conductor.` forms): the base material with its widths replaced at
//! each hit by the remapped texture values; and materials with a normal map or a bump map,
//! which replace the shading normal (pbrt-v4's `NormalMap` and `BumpMap`).

use super::float_texture::FloatTexture;
use super::texture::{ImageRgb, TexCoord};
use super::{Material, Texture};
use crate::Rgb;
use crate::bsdf::LayerParams;
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
        self.alpha_at(&super::TexCoord::point(uv))
    }

    /// [`RoughnessTextures::alpha`] over the footprint `tc`.
    #[inline]
    pub fn alpha_at(&self, tc: &super::TexCoord) -> Vec2 {
        let r = Vec2::new(self.uv[0].eval_at(tc), self.uv[1].eval_at(tc)).max(Vec2::ZERO);
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
    /// A coated material's textured layer parameters.
    pub layer: Option<LayerTextures>,
}

/// A coated material's `thickness`, `g` and `albedo` as textures (pbrt-v4 evaluates them per
/// hit); each present one replaces the constant parameter.
#[derive(Clone, Debug, Default)]
pub struct LayerTextures {
    /// Slab thickness (clamped to ≥ 0).
    pub thickness: Option<FloatTexture>,
    /// Henyey–Greenstein asymmetry (clamped to [−0.99, 0.99]).
    pub g: Option<FloatTexture>,
    /// Slab single-scattering albedo (clamped to [0, 1]).
    pub albedo: Option<Texture>,
}

impl LayerTextures {
    /// `base` with the textured parameters evaluated over `tc`.
    pub fn apply(&self, base: LayerParams, tc: &TexCoord) -> LayerParams {
        let mut p = base;
        if let Some(t) = &self.thickness {
            let v = t.eval_at(tc);
            p.thickness = if v.is_finite() {
                v.max(0.0)
            } else {
                base.thickness
            };
        }
        if let Some(g) = &self.g {
            let v = g.eval_at(tc);
            p.g = if v.is_finite() {
                v.clamp(-0.99, 0.99)
            } else {
                base.g
            };
        }
        if let Some(a) = &self.albedo {
            p.albedo = a.eval_at(tc).clamp(Rgb::ZERO, Rgb::ONE);
        }
        p
    }
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

/// uv step of the bump map's finite differences where a hit has no footprint (pbrt-v4's
/// fallback without ray differentials).
pub const BUMP_DELTA: f32 = 0.0005;

/// The surface derivatives a normal or bump map needs at a hit: ∂p/∂u, ∂p/∂v of the shading
/// geometry and the shading normal's ∂n/∂u, ∂n/∂v (zero on flat triangles).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadingDerivatives {
    /// ∂p/∂u.
    pub dpdu: Vec3,
    /// ∂p/∂v.
    pub dpdv: Vec3,
    /// ∂n/∂u.
    pub dndu: Vec3,
    /// ∂n/∂v.
    pub dndv: Vec3,
}

impl NormalPerturbation {
    /// The perturbed shading normal at texture coordinates `tc` (its footprint sets the bump
    /// map's differencing step, as pbrt-v4's du = ½(|∂u/∂x| + |∂u/∂y|)), for shading normal
    /// `ns`, geometric normal `ng` (the result is on its side) and the derivatives `d`.
    pub fn shading_normal(
        &self,
        tc: &TexCoord,
        ns: Vec3,
        ng: Vec3,
        d: &ShadingDerivatives,
    ) -> Vec3 {
        let (uv, dpdu, dpdv) = (tc.uv, d.dpdu, d.dpdv);
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
            NormalPerturbation::Bump(disp) => {
                // pbrt-v4's BumpMap: steps from the footprint, else 0.0005.
                let step = |a: f32, b: f32| {
                    let s = 0.5 * (a.abs() + b.abs());
                    if s > 0.0 && s.is_finite() {
                        s
                    } else {
                        BUMP_DELTA
                    }
                };
                let du = step(tc.duvdx.x, tc.duvdy.x);
                let dv = step(tc.duvdx.y, tc.duvdy.y);
                let at = |uv: Vec2| {
                    disp.eval_at(&TexCoord {
                        uv,
                        duvdx: tc.duvdx,
                        duvdy: tc.duvdy,
                    })
                };
                let h = at(uv);
                let hu = at(uv + Vec2::new(du, 0.0));
                let hv = at(uv + Vec2::new(0.0, dv));
                // The displaced surface p + h·n differentiated: forward differences of h
                // along ns, plus h·∂n/∂u, h·∂n/∂v (the normal turning under the displacement).
                let pu = dpdu + ns * ((hu - h) / du) + d.dndu * h;
                let pv = dpdv + ns * ((hv - h) / dv) + d.dndv * h;
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
    /// A coated material's layer parameters.
    pub layer: Option<LayerParams>,
}
