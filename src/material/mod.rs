//! Materials: what a surface is made of, turned into a [`Bsdf`] at each hit (textures resolved).
//! The pbrt/OBJ/glTF loaders map onto exactly these variants.

pub mod float_texture;
pub mod footprint;
pub mod texture;
pub mod varying;

pub use float_texture::FloatTexture;
pub use footprint::Footprint;
pub use texture::{TexCoord, Texture};
pub use varying::{
    AlphaOverride, LayerTextures, NormalPerturbation, RoughnessTextures, ShadingDerivatives,
    VaryingMaterial,
};

use crate::Rgb;
use crate::bsdf::coated_conductor::{coated_conductor, layered_diffuse};
use crate::bsdf::fresnel::k_from_reflectance;
use crate::bsdf::ggx::is_smooth;
use crate::bsdf::{
    Bsdf, CoatedDiffuse, Conductor, Dielectric, DiffuseTransmission, DispersiveDielectric, Lambert,
    LayerParams, Mirror, Phong,
};
use crate::geometry::SurfaceHit;
use glam::Vec2;
use std::sync::Arc;

/// A surface material description.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian diffuse with a reflectance texture.
    Diffuse {
        /// Albedo.
        reflectance: Texture,
    },
    /// Modified Phong (kd + ks ≤ 1 enforced by scaling at BSDF construction).
    Phong {
        /// Diffuse reflectance.
        kd: Texture,
        /// Specular reflectance.
        ks: Rgb,
        /// Phong exponent.
        n: f32,
    },
    /// GGX conductor.
    Conductor {
        /// Real part of the complex index (per channel).
        eta: Rgb,
        /// Extinction coefficient (per channel).
        k: Rgb,
        /// GGX widths (already remapped from roughness by the loader).
        alpha: Vec2,
        /// pbrt's "reflectance" mode: normal-incidence reflectance overriding eta/k.
        reflectance: Option<Texture>,
    },
    /// Dielectric coat over a diffuse base (pbrt coateddiffuse / Mitsuba roughplastic).
    CoatedDiffuse {
        /// Base albedo.
        reflectance: Texture,
        /// Coat GGX widths.
        alpha: Vec2,
        /// Coat index of refraction.
        eta: f32,
        /// pbrt-v4's layered evaluation (slab thickness, albedo, g, walk budget); `None` is
        /// the closed-form thin-coat model of [`CoatedDiffuse`].
        layer: Option<LayerParams>,
    },
    /// pbrt-v4 `coatedconductor`: a dielectric coat over a GGX conductor (layered BSDF).
    CoatedConductor {
        /// Coat index of refraction.
        coat_eta: f32,
        /// Coat GGX widths.
        coat_alpha: Vec2,
        /// Conductor η in air (per channel).
        eta: Rgb,
        /// Conductor k in air (per channel).
        k: Rgb,
        /// Conductor GGX widths.
        alpha: Vec2,
        /// pbrt's "reflectance" mode: normal-incidence reflectance overriding η/k.
        reflectance: Option<Texture>,
        /// Slab and walk parameters.
        layer: LayerParams,
    },
    /// Glass-like dielectric (smooth or GGX rough).
    Dielectric {
        /// Index of refraction (inside / outside).
        eta: f32,
        /// GGX widths (already remapped from roughness by the loader).
        alpha: Vec2,
    },
    /// Glass whose index varies with wavelength: one index per RGB channel (see
    /// [`DispersiveDielectric`]); a constant index is [`Material::Dielectric`].
    DispersiveDielectric {
        /// Index of refraction (inside / outside) per channel.
        eta: Rgb,
        /// GGX widths (already remapped from roughness by the loader).
        alpha: Vec2,
    },
    /// Perfect mirror (reflectance 1).
    Mirror,
    /// Lambertian reflection on the viewer's side and Lambertian transmission to the other
    /// (pbrt-v4 `diffusetransmission`): both scaled by `scale`, then clamped to [0, 1].
    DiffuseTransmission {
        /// Reflectance.
        reflectance: Texture,
        /// Transmittance.
        transmittance: Texture,
        /// Factor on both.
        scale: f32,
    },
    /// A material whose roughness varies over the surface (float textures).
    Varying(Box<VaryingMaterial>),
    /// A material whose textures filter over each hit's pixel footprint (MIP-mapped images,
    /// checkerboards); set by the scene builder, which knows the camera and the triangles.
    Filtered {
        /// The material.
        base: Box<Material>,
        /// The footprint model of the scene's camera and triangles.
        footprint: Arc<Footprint>,
    },
}

/// The Lambertian BSDF of a `diffuse` material (reflectance clamped to [0, 1]): the hot path
/// of [`Material::bsdf`], shared with its general arm.
#[inline(always)]
fn diffuse(reflectance: &Texture, hit: &SurfaceHit) -> Lambert {
    Lambert::new(reflectance.eval(hit.uv).clamp(Rgb::ZERO, Rgb::ONE))
}

fn diffuse_at(reflectance: &Texture, tc: &TexCoord) -> Lambert {
    Lambert::new(reflectance.eval_at(tc).clamp(Rgb::ZERO, Rgb::ONE))
}

impl Material {
    /// The BSDF at a hit. `front` is true when the ray arrives on the side of `hit.ng`
    /// (transmissive materials need it to orient their index of refraction).
    #[inline]
    pub fn bsdf(&self, hit: &SurfaceHit, front: bool) -> Bsdf {
        // Diffuse (most surfaces) here, the rest out of line: mis-area 3769 → 3750 Ir/sample.
        match self.lambert(hit) {
            Some(b) => Bsdf::Lambert(b),
            None => self.bsdf_general(hit, front),
        }
    }

    /// The Lambertian BSDF of a diffuse material at `hit` (`None` for other materials):
    /// for callers that store it straight into a lane rather than through a [`Bsdf`].
    // Always inlined: left to LLVM it was outlined from li_wave by an unrelated change
    // (+0.5% Ir, cornell 64² 4 spp, callgrind).
    #[inline(always)]
    pub fn lambert(&self, hit: &SurfaceHit) -> Option<Lambert> {
        match self {
            Material::Diffuse { reflectance } => Some(diffuse(reflectance, hit)),
            // Only the normal varies (the hit already carries it): still Lambertian, so the
            // lane kernels shade it as they shade the plain material.
            Material::Varying(v) if v.roughness.is_none() && v.coat_roughness.is_none() => {
                v.base.lambert(hit)
            }
            Material::Filtered { base, footprint } if base.is_lambertian() => {
                base.lambert_at(&footprint.tex_coord(hit))
            }
            _ => None,
        }
    }

    /// True if [`Material::lambert`] gives this material's BSDF.
    fn is_lambertian(&self) -> bool {
        match self {
            Material::Diffuse { .. } => true,
            Material::Varying(v) => {
                v.roughness.is_none() && v.coat_roughness.is_none() && v.base.is_lambertian()
            }
            Material::Filtered { base, .. } => base.is_lambertian(),
            _ => false,
        }
    }

    /// [`Material::lambert`] with textures read over the footprint `tc`.
    fn lambert_at(&self, tc: &TexCoord) -> Option<Lambert> {
        match self {
            Material::Diffuse { reflectance } => Some(diffuse_at(reflectance, tc)),
            Material::Varying(v) if v.roughness.is_none() && v.coat_roughness.is_none() => {
                v.base.lambert_at(tc)
            }
            Material::Filtered { base, .. } => base.lambert_at(tc),
            _ => None,
        }
    }

    /// [`Material::bsdf`] for every material (the out-of-line path).
    #[inline(never)]
    fn bsdf_general(&self, hit: &SurfaceHit, front: bool) -> Bsdf {
        self.bsdf_with(
            hit,
            &TexCoord::point(hit.uv),
            front,
            AlphaOverride::default(),
        )
    }

    /// The BSDF at a hit, textures read over `tc`, with GGX widths `ov` replacing the
    /// material's constant ones.
    fn bsdf_with(&self, hit: &SurfaceHit, tc: &TexCoord, front: bool, ov: AlphaOverride) -> Bsdf {
        match self {
            Material::Filtered { base, footprint } => {
                base.bsdf_with(hit, &footprint.tex_coord(hit), front, ov)
            }
            Material::Varying(v) => {
                let base_layer = match &v.base {
                    Material::CoatedDiffuse { layer, .. } => *layer,
                    Material::CoatedConductor { layer, .. } => Some(*layer),
                    _ => None,
                };
                let ov = AlphaOverride {
                    alpha: v.roughness.as_ref().map(|r| r.alpha_at(tc)),
                    coat_alpha: v.coat_roughness.as_ref().map(|r| r.alpha_at(tc)),
                    layer: match (&v.layer, base_layer) {
                        (Some(l), Some(b)) => Some(l.apply(b, tc)),
                        _ => None,
                    },
                };
                v.base.bsdf_with(hit, tc, front, ov)
            }
            Material::Diffuse { reflectance } => Bsdf::Lambert(diffuse_at(reflectance, tc)),
            Material::Phong { kd, ks, n } => Bsdf::Phong(Phong::clamped(kd.eval_at(tc), *ks, *n)),
            Material::Conductor {
                eta,
                k,
                alpha,
                reflectance,
            } => {
                let (eta, k) = match reflectance {
                    Some(r) => (Rgb::ONE, k_from_reflectance(r.eval_at(tc))),
                    None => (*eta, *k),
                };
                Bsdf::Conductor(Conductor::new(eta, k, ov.alpha.unwrap_or(*alpha)))
            }
            Material::CoatedDiffuse {
                reflectance,
                alpha,
                eta,
                layer,
            } => {
                let alpha = ov.alpha.unwrap_or(*alpha);
                match ov.layer.or(*layer) {
                    None => Bsdf::CoatedDiffuse(CoatedDiffuse::new(
                        reflectance.eval_at(tc),
                        alpha,
                        *eta,
                    )),
                    Some(p) => Bsdf::Layered(Box::new(layered_diffuse(
                        reflectance.eval_at(tc),
                        *eta,
                        alpha,
                        p,
                    ))),
                }
            }
            Material::CoatedConductor {
                coat_eta,
                coat_alpha,
                eta,
                k,
                alpha,
                reflectance,
                layer,
            } => {
                let (eta, k) = match reflectance {
                    Some(r) => (Rgb::ONE, k_from_reflectance(r.eval_at(tc))),
                    None => (*eta, *k),
                };
                Bsdf::Layered(Box::new(coated_conductor(
                    *coat_eta,
                    ov.coat_alpha.unwrap_or(*coat_alpha),
                    eta,
                    k,
                    ov.alpha.unwrap_or(*alpha),
                    ov.layer.unwrap_or(*layer),
                )))
            }
            Material::Dielectric { eta, alpha } => Bsdf::Dielectric(Dielectric {
                eta: *eta,
                alpha: ov.alpha.unwrap_or(*alpha),
                entering: front,
            }),
            Material::DispersiveDielectric { eta, alpha } => {
                Bsdf::DispersiveDielectric(DispersiveDielectric {
                    eta: *eta,
                    alpha: ov.alpha.unwrap_or(*alpha),
                    entering: front,
                })
            }
            Material::Mirror => Bsdf::Mirror(Mirror { r: Rgb::ONE }),
            Material::DiffuseTransmission {
                reflectance,
                transmittance,
                scale,
            } => Bsdf::DiffuseTransmission(DiffuseTransmission::new(
                reflectance.eval_at(tc) * *scale,
                transmittance.eval_at(tc) * *scale,
            )),
        }
    }

    /// The material's normal or bump map, if it has one.
    #[inline]
    pub fn normal_perturbation(&self) -> Option<&NormalPerturbation> {
        match self {
            Material::Varying(v) => v.normal.as_ref(),
            Material::Filtered { base, .. } => base.normal_perturbation(),
            _ => None,
        }
    }

    /// True if every BSDF of this material is a delta lobe (light sampling cannot help).
    pub fn is_delta_only(&self) -> bool {
        match self {
            // A roughness texture may be zero in places and not in others.
            Material::Varying(v) => {
                v.roughness.is_none()
                    && v.coat_roughness.is_none()
                    && v.layer.is_none()
                    && v.base.is_delta_only()
            }
            Material::Filtered { base, .. } => base.is_delta_only(),
            Material::Mirror => true,
            Material::Conductor { alpha, .. }
            | Material::Dielectric { alpha, .. }
            | Material::DispersiveDielectric { alpha, .. } => is_smooth(*alpha),
            Material::CoatedConductor {
                coat_alpha,
                alpha,
                layer,
                ..
            } => is_smooth(*coat_alpha) && is_smooth(*alpha) && layer.albedo == Rgb::ZERO,
            Material::Diffuse { .. }
            | Material::Phong { .. }
            | Material::CoatedDiffuse { .. }
            | Material::DiffuseTransmission { .. } => false,
        }
    }
}

impl Material {
    /// True if some texture of the material filters over a footprint (MIP-mapped images,
    /// checkerboards): the scene builder then gives it the camera's footprint model.
    pub fn filters_textures(&self) -> bool {
        let r = |r: &Option<RoughnessTextures>| {
            r.as_ref()
                .is_some_and(|r| r.uv[0].filters() || r.uv[1].filters())
        };
        match self {
            Material::Diffuse { reflectance } => reflectance.filters(),
            Material::Phong { kd, .. } => kd.filters(),
            Material::Conductor { reflectance, .. }
            | Material::CoatedConductor { reflectance, .. } => {
                reflectance.as_ref().is_some_and(Texture::filters)
            }
            Material::CoatedDiffuse { reflectance, .. } => reflectance.filters(),
            Material::DiffuseTransmission {
                reflectance,
                transmittance,
                ..
            } => reflectance.filters() || transmittance.filters(),
            Material::Dielectric { .. }
            | Material::DispersiveDielectric { .. }
            | Material::Mirror => false,
            Material::Varying(v) => {
                v.base.filters_textures()
                    || r(&v.roughness)
                    || r(&v.coat_roughness)
                    || matches!(&v.normal, Some(NormalPerturbation::Bump(d)) if d.filters())
                    || v.layer.as_ref().is_some_and(|l| {
                        l.thickness.as_ref().is_some_and(FloatTexture::filters)
                            || l.g.as_ref().is_some_and(FloatTexture::filters)
                            || l.albedo.as_ref().is_some_and(Texture::filters)
                    })
            }
            Material::Filtered { .. } => false,
        }
    }

    /// The footprint model the scene builder gave this material, if any.
    pub fn footprint(&self) -> Option<&Footprint> {
        match self {
            Material::Filtered { footprint, .. } => Some(&**footprint),
            _ => None,
        }
    }

    /// The material without its footprint model (textures read at points).
    pub fn unfiltered(&self) -> &Material {
        match self {
            Material::Filtered { base, .. } => base,
            m => m,
        }
    }
}
