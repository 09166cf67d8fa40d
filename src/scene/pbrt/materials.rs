//! pbrt materials → an internal [`MaterialDesc`], converted to [`Material`] by [`to_material`].
//! The description keeps what the file said; the conversion says what penumbra approximates.

use super::params::{ParamSet, SpecVal};
use super::spectra::{SpectrumUse, named_glass_ior, sampled_at, to_rgb};
use super::textures::{ImageCache, TextureDesc, TextureTable, Warn};
use super::tokenizer::{Loc, err_at};
use crate::Rgb;
use crate::bsdf::{named_metal, roughness_to_alpha};
use crate::material::{Material, Texture};
use glam::Vec2;

/// A metal's eta or k: RGB, or one of pbrt's named spectra (`metal-Cu-eta`, …).
#[derive(Clone, Debug, PartialEq)]
pub enum MetalSpectrum {
    /// Explicit RGB.
    Rgb(Rgb),
    /// pbrt named spectrum (resolved by `bsdf::named_metal`).
    Named(String),
}

/// A material as the scene file describes it.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialDesc {
    /// `diffuse`.
    Diffuse {
        /// Albedo.
        reflectance: TextureDesc,
    },
    /// `diffusetransmission`.
    DiffuseTransmission {
        /// Reflectance (pbrt default 0.25).
        reflectance: TextureDesc,
        /// Transmittance (pbrt default 0.25).
        transmittance: TextureDesc,
        /// Factor on both (pbrt default 1).
        scale: f32,
    },
    /// `conductor`.
    Conductor {
        /// Real part of the IOR.
        eta: MetalSpectrum,
        /// Absorption.
        k: MetalSpectrum,
        /// Artist-friendly reflectance instead of eta/k.
        reflectance: Option<TextureDesc>,
        /// (uroughness, vroughness) as given.
        roughness: Vec2,
        /// pbrt's `remaproughness`.
        remap: bool,
    },
    /// `coateddiffuse`.
    CoatedDiffuse {
        /// Base albedo.
        reflectance: TextureDesc,
        /// (u, v) roughness of the coat as given.
        roughness: Vec2,
        /// Coat IOR.
        eta: f32,
        /// pbrt's `remaproughness`.
        remap: bool,
    },
    /// `dielectric` / `thindielectric`.
    Dielectric {
        /// IOR.
        eta: f32,
        /// (u, v) roughness as given.
        roughness: Vec2,
        /// pbrt's `remaproughness`.
        remap: bool,
        /// `thindielectric` (approximated by a dielectric).
        thin: bool,
    },
    /// `interface` / `none`: the shape is a medium boundary and is not rendered.
    Interface,
}

impl MaterialDesc {
    /// pbrt's default material: diffuse 0.5.
    pub fn default_diffuse() -> Self {
        Self::Diffuse {
            reflectance: TextureDesc::Constant(Rgb::splat(0.5)),
        }
    }
}

fn roughness(
    params: &ParamSet,
    tex: &TextureTable,
    default: f32,
    warn: &mut Warn,
) -> anyhow::Result<Vec2> {
    let r = tex.float_param(params, "roughness", default, warn)?;
    let u = if params.has("uroughness") {
        tex.float_param(params, "uroughness", r, warn)?
    } else {
        r
    };
    let v = if params.has("vroughness") {
        tex.float_param(params, "vroughness", r, warn)?
    } else {
        r
    };
    Ok(Vec2::new(u, v).max(Vec2::ZERO))
}

fn metal(params: &ParamSet, name: &str, default: &str) -> anyhow::Result<MetalSpectrum> {
    Ok(match params.spectrum(name)? {
        None => MetalSpectrum::Named(default.into()),
        Some(SpecVal::Named(n)) => MetalSpectrum::Named(n),
        Some(v) => MetalSpectrum::Rgb(to_rgb(&v, SpectrumUse::Unbounded).unwrap_or(Rgb::ONE)),
    })
}

fn ior(params: &ParamSet, loc: &Loc) -> anyhow::Result<f32> {
    use super::params::ParamType;
    let eta = match params.type_of("eta") {
        None | Some(ParamType::Float | ParamType::Integer) => params.float("eta", 1.5)?,
        Some(_) => match params.spectrum("eta")? {
            Some(SpecVal::Named(n)) => named_glass_ior(&n)
                .ok_or_else(|| err_at(loc, format!("'eta': unknown named spectrum \"{n}\"")))?,
            Some(SpecVal::Sampled(p)) => sampled_at(&p, 550.0) as f32,
            Some(SpecVal::Rgb(c)) => c.y,
            Some(SpecVal::Blackbody(_)) | None => 1.5,
        },
    };
    if !(eta.is_finite() && eta > 0.0) {
        return Err(err_at(loc, format!("'eta' must be positive, found {eta}")));
    }
    Ok(eta)
}

/// Everything `Material`/`MakeNamedMaterial` needs to resolve references.
pub struct MaterialCtx<'a> {
    /// Named textures.
    pub textures: &'a TextureTable,
    /// Looks up a named material's description (for `mix`).
    pub named: &'a dyn Fn(&str) -> Option<MaterialDesc>,
}

/// Parse a material of pbrt type `ty`.
pub fn parse_material(
    ty: &str,
    params: &ParamSet,
    ctx: &MaterialCtx,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<MaterialDesc> {
    let tex = ctx.textures;
    for ignored in ["displacement", "normalmap"] {
        if params.has(ignored) {
            let _ = params.find(ignored);
            warn(ignored, loc, format!("material '{ignored}' is ignored"));
        }
    }
    Ok(match ty {
        "diffuse" => MaterialDesc::Diffuse {
            reflectance: tex
                .spectrum_param(params, "reflectance", Some(Rgb::splat(0.5)))?
                .unwrap_or(TextureDesc::Constant(Rgb::splat(0.5))),
        },
        "diffusetransmission" => {
            let quarter = || TextureDesc::Constant(Rgb::splat(0.25));
            let scale = params.float("scale", 1.0)?;
            if !(scale.is_finite() && scale >= 0.0) {
                return Err(err_at(loc, format!("'scale' must be ≥ 0, found {scale}")));
            }
            MaterialDesc::DiffuseTransmission {
                reflectance: tex
                    .spectrum_param(params, "reflectance", Some(Rgb::splat(0.25)))?
                    .unwrap_or_else(quarter),
                transmittance: tex
                    .spectrum_param(params, "transmittance", Some(Rgb::splat(0.25)))?
                    .unwrap_or_else(quarter),
                scale,
            }
        }
        "conductor" => MaterialDesc::Conductor {
            eta: metal(params, "eta", "metal-Cu-eta")?,
            k: metal(params, "k", "metal-Cu-k")?,
            reflectance: tex.spectrum_param(params, "reflectance", None)?,
            roughness: roughness(params, tex, 0.0, warn)?,
            remap: params.bool("remaproughness", true)?,
        },
        "coateddiffuse" => {
            for ignored in ["thickness", "albedo", "g", "maxdepth", "nsamples"] {
                let _ = params.find(ignored);
            }
            MaterialDesc::CoatedDiffuse {
                reflectance: tex
                    .spectrum_param(params, "reflectance", Some(Rgb::splat(0.5)))?
                    .unwrap_or(TextureDesc::Constant(Rgb::splat(0.5))),
                roughness: roughness(params, tex, 0.0, warn)?,
                eta: ior(params, loc)?,
                remap: params.bool("remaproughness", true)?,
            }
        }
        "dielectric" | "thindielectric" => {
            let thin = ty == "thindielectric";
            if thin {
                warn(
                    "thindielectric",
                    loc,
                    "material \"thindielectric\" approximated by a dielectric interface".into(),
                );
            }
            MaterialDesc::Dielectric {
                eta: ior(params, loc)?,
                roughness: roughness(params, tex, 0.0, warn)?,
                remap: params.bool("remaproughness", true)?,
                thin,
            }
        }
        "mix" => {
            let names = params.strings("materials")?.ok_or_else(|| {
                err_at(
                    loc,
                    "mix: expected \"string materials\" [ a b ], found none",
                )
            })?;
            if names.len() != 2 {
                return Err(err_at(
                    loc,
                    format!("mix: expected 2 material names, found {}", names.len()),
                ));
            }
            let amount = tex.float_param(params, "amount", 0.5, warn)?;
            // pbrt picks materials[1] with probability `amount`: keep the likelier one.
            let pick = if amount > 0.5 { &names[1] } else { &names[0] };
            warn(
                "mix",
                loc,
                format!("material \"mix\" approximated by its dominant component \"{pick}\""),
            );
            (ctx.named)(pick)
                .ok_or_else(|| err_at(loc, format!("mix: unknown material \"{pick}\"")))?
        }
        "interface" | "none" | "" => MaterialDesc::Interface,
        other => {
            warn(
                &format!("material-{other}"),
                loc,
                format!("material \"{other}\" is not supported; using diffuse 0.5"),
            );
            MaterialDesc::default_diffuse()
        }
    })
}

fn texture(t: &TextureDesc, images: &ImageCache) -> anyhow::Result<Texture> {
    Ok(match t {
        TextureDesc::Constant(c) => Texture::Constant(*c),
        TextureDesc::Checkerboard { a, b, freq } => Texture::Checkerboard {
            a: *a,
            b: *b,
            freq: *freq,
        },
        TextureDesc::Image {
            path,
            scale,
            invert,
        } => {
            let img = images
                .get(path)
                .cloned()
                .ok_or_else(|| anyhow::anyhow!("{}: image not loaded", path.display()))?;
            let image = if *invert {
                let mut inv = (*img).clone();
                for p in &mut inv.pixels {
                    *p = (Rgb::ONE - *p).max(Rgb::ZERO);
                }
                std::sync::Arc::new(inv)
            } else {
                img
            };
            Texture::Image {
                image,
                scale: *scale,
            }
        }
    })
}

fn push_once(warnings: &mut Vec<String>, msg: String) {
    if !warnings.contains(&msg) {
        warnings.push(msg);
    }
}

/// Convert a description into a renderer material; what cannot be represented falls back to
/// diffuse grey 0.5 with a warning.
pub fn to_material(
    desc: &MaterialDesc,
    images: &ImageCache,
    warnings: &mut Vec<String>,
) -> anyhow::Result<Material> {
    let alpha = |r: Vec2, remap: bool| {
        if remap {
            Vec2::new(roughness_to_alpha(r.x), roughness_to_alpha(r.y))
        } else {
            r
        }
    };
    Ok(match desc {
        MaterialDesc::Diffuse { reflectance } => Material::Diffuse {
            reflectance: texture(reflectance, images)?,
        },
        MaterialDesc::DiffuseTransmission {
            reflectance,
            transmittance,
            scale,
        } => Material::DiffuseTransmission {
            reflectance: texture(reflectance, images)?,
            transmittance: texture(transmittance, images)?,
            scale: *scale,
        },
        MaterialDesc::Conductor {
            eta,
            k,
            reflectance,
            roughness,
            remap,
        } => {
            let mut metal = |m: &MetalSpectrum, pick_k: bool| -> Rgb {
                match m {
                    MetalSpectrum::Rgb(c) => *c,
                    MetalSpectrum::Named(name) => match named_metal(name) {
                        Some((e, kk)) => {
                            if pick_k {
                                kk
                            } else {
                                e
                            }
                        }
                        None => {
                            push_once(
                                warnings,
                                format!("warning: unknown named spectrum \"{name}\"; using copper"),
                            );
                            let (e, kk) = named_metal("metal-Cu-eta").unwrap_or_default();
                            if pick_k { kk } else { e }
                        }
                    },
                }
            };
            let (eta, k) = (metal(eta, false), metal(k, true));
            let reflectance = match reflectance {
                Some(t) => Some(texture(t, images)?),
                None => None,
            };
            Material::Conductor {
                eta,
                k,
                alpha: alpha(*roughness, *remap),
                reflectance,
            }
        }
        MaterialDesc::CoatedDiffuse {
            reflectance,
            roughness,
            eta,
            remap,
        } => Material::CoatedDiffuse {
            reflectance: texture(reflectance, images)?,
            alpha: alpha(*roughness, *remap),
            eta: *eta,
        },
        MaterialDesc::Dielectric {
            eta,
            roughness,
            remap,
            thin,
        } => {
            if *thin {
                push_once(
                    warnings,
                    "warning: thindielectric approximated by a dielectric".to_string(),
                );
            }
            Material::Dielectric {
                eta: *eta,
                alpha: alpha(*roughness, *remap),
            }
        }
        MaterialDesc::Interface => {
            // Shapes with an interface material are skipped by the parser; never reached.
            Material::Diffuse {
                reflectance: Texture::Constant(Rgb::ZERO),
            }
        }
    })
}
