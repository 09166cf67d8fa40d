//! pbrt materials → an internal [`MaterialDesc`], converted to [`Material`] by [`to_material`].
//! The description keeps what the file said; the conversion says what penumbra approximates.

use super::named_spectra;
use super::params::{ParamSet, SpecVal};
use super::spectra::{
    SpectrumUse, conductor_rgb, dielectric_rgb, named_glass_ior, named_glass_rgb, sampled_at,
    spectrum_to_rgb, to_rgb,
};
use super::textures::{FloatTexDesc, ImageCache, TextureDesc, TextureTable, Warn};
use super::tokenizer::{Loc, err_at};
use crate::Rgb;
use crate::bsdf::{LayerParams, roughness_to_alpha};
use crate::material::{
    FloatTexture, LayerTextures, Material, NormalPerturbation, RoughnessTextures, Texture,
    VaryingMaterial,
};
use glam::Vec2;

/// A metal's eta or k: RGB, or a spectrum (named `metal-*`, inline or from a `.spd` file).
#[derive(Clone, Debug, PartialEq)]
pub enum MetalSpectrum {
    /// Explicit RGB.
    Rgb(Rgb),
    /// (λ nm, value) pairs, reduced to RGB with the other half by `spectra::conductor_rgb`.
    Spectral(Vec<(f32, f32)>),
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
        /// `thickness`, `albedo`, `g`, `maxdepth`, `nsamples`.
        layer: LayerParams,
    },
    /// `coatedconductor`.
    CoatedConductor {
        /// `interface.eta`.
        coat_eta: f32,
        /// `interface.(u|v)roughness` as given.
        coat_roughness: Vec2,
        /// `conductor.eta`.
        eta: MetalSpectrum,
        /// `conductor.k`.
        k: MetalSpectrum,
        /// `reflectance` instead of eta/k.
        reflectance: Option<TextureDesc>,
        /// `conductor.(u|v)roughness` as given.
        roughness: Vec2,
        /// pbrt's `remaproughness` (both layers).
        remap: bool,
        /// `thickness`, `albedo`, `g`, `maxdepth`, `nsamples`.
        layer: LayerParams,
    },
    /// `dielectric` / `thindielectric`.
    Dielectric {
        /// IOR (at 550 nm when it varies with wavelength).
        eta: f32,
        /// One IOR per RGB channel when it varies with wavelength
        /// (`spectra::dielectric_rgb`); `None` for a constant IOR.
        dispersion: Option<Rgb>,
        /// (u, v) roughness as given.
        roughness: Vec2,
        /// pbrt's `remaproughness`.
        remap: bool,
        /// `thindielectric` (approximated by a dielectric).
        thin: bool,
    },
    /// `interface` / `none`: the shape is a medium boundary and is not rendered.
    Interface,
    /// A material whose roughness is a varying float texture (`base` keeps the constant
    /// parts and `remaproughness`).
    Varying {
        /// The material.
        base: Box<MaterialDesc>,
        /// (u, v) roughness of the (only, or conductor) layer, when textured.
        roughness: Option<[FloatTexDesc; 2]>,
        /// (u, v) roughness of a coated conductor's interface, when textured.
        coat_roughness: Option<[FloatTexDesc; 2]>,
        /// Normal or bump map.
        normal: Option<NormalDesc>,
        /// Textured layer parameters of a coated material.
        layer: Option<LayerTexDesc>,
    },
}

/// A coated material's layer parameters given as varying textures (pbrt-v4's `thickness`,
/// `g`, `albedo` are textures); each replaces the constant one at every hit.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct LayerTexDesc {
    /// `thickness`.
    pub thickness: Option<FloatTexDesc>,
    /// `g`.
    pub g: Option<FloatTexDesc>,
    /// `albedo`.
    pub albedo: Option<TextureDesc>,
}

/// A material's normal map (resolved path, loaded while parsing) or bump displacement.
#[derive(Clone, Debug, PartialEq)]
pub enum NormalDesc {
    /// `"string normalmap"`.
    Map(std::path::PathBuf),
    /// `"texture displacement"` (varying; a constant displacement changes nothing).
    Bump(FloatTexDesc),
}

impl MaterialDesc {
    /// pbrt's default material: diffuse 0.5.
    pub fn default_diffuse() -> Self {
        Self::Diffuse {
            reflectance: TextureDesc::Constant(Rgb::splat(0.5)),
        }
    }
}

/// `roughness`/`uroughness`/`vroughness`: the constant part and, when either axis is a
/// varying texture, both axes as textures.
type Roughness = (Vec2, Option<[FloatTexDesc; 2]>);

fn roughness(
    params: &ParamSet,
    tex: &TextureTable,
    default: f32,
    warn: &mut Warn,
) -> anyhow::Result<Roughness> {
    prefixed_roughness(params, tex, "", default, warn)
}

/// `{prefix}roughness`, overridden per axis by `{prefix}uroughness` / `{prefix}vroughness`.
fn prefixed_roughness(
    params: &ParamSet,
    tex: &TextureTable,
    prefix: &str,
    default: f32,
    warn: &mut Warn,
) -> anyhow::Result<Roughness> {
    let (rn, un, vn) = (
        format!("{prefix}roughness"),
        format!("{prefix}uroughness"),
        format!("{prefix}vroughness"),
    );
    let r = tex.float_texture_param(params, &rn, default, warn)?;
    let axis = |name: &str, warn: &mut Warn| -> anyhow::Result<FloatTexDesc> {
        if params.has(name) {
            tex.float_texture_param(params, name, default, warn)
        } else {
            Ok(r.clone())
        }
    };
    let (u, v) = (axis(&un, warn)?, axis(&vn, warn)?);
    Ok(match (u.constant(), v.constant()) {
        (Some(a), Some(b)) => (Vec2::new(a, b).max(Vec2::ZERO), None),
        // The constant part is unused where the texture applies; the texture's mean is not
        // needed, 0 keeps `base` a valid material.
        _ => (Vec2::ZERO, Some([u, v])),
    })
}

/// Wrap `base` when a roughness is textured or the normal is perturbed.
fn varying(
    base: MaterialDesc,
    roughness: Option<[FloatTexDesc; 2]>,
    coat_roughness: Option<[FloatTexDesc; 2]>,
    normal: Option<NormalDesc>,
) -> MaterialDesc {
    varying_layer(base, roughness, coat_roughness, normal, None)
}

fn varying_layer(
    base: MaterialDesc,
    roughness: Option<[FloatTexDesc; 2]>,
    coat_roughness: Option<[FloatTexDesc; 2]>,
    normal: Option<NormalDesc>,
    layer: Option<LayerTexDesc>,
) -> MaterialDesc {
    if roughness.is_none() && coat_roughness.is_none() && normal.is_none() && layer.is_none() {
        return base;
    }
    // A material that is already varying (a `mix` component) keeps its own maps.
    if let MaterialDesc::Varying {
        base,
        roughness: r0,
        coat_roughness: c0,
        normal: n0,
        layer: l0,
    } = base
    {
        return MaterialDesc::Varying {
            base,
            roughness: roughness.or(r0),
            coat_roughness: coat_roughness.or(c0),
            normal: normal.or(n0),
            layer: layer.or(l0),
        };
    }
    MaterialDesc::Varying {
        base: Box::new(base),
        roughness,
        coat_roughness,
        normal,
        layer,
    }
}

/// pbrt-v4's `"string normalmap"` / `"texture displacement"` of a material.
fn normal_desc(
    params: &ParamSet,
    ctx: &MaterialCtx,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<Option<NormalDesc>> {
    let map = match params.string("normalmap")? {
        Some(f) if !f.is_empty() => Some(NormalDesc::Map(super::textures::resolve(ctx.dir, &f))),
        _ => None,
    };
    let bump = if params.has("displacement") {
        match ctx
            .textures
            .float_texture_param(params, "displacement", 0.0, warn)?
        {
            FloatTexDesc::Constant(_) => None,
            t => Some(NormalDesc::Bump(t)),
        }
    } else {
        None
    };
    if map.is_some() && bump.is_some() {
        warn(
            "normalmap-and-bump",
            loc,
            "material has both 'normalmap' and 'displacement': the normal map is used".into(),
        );
    }
    Ok(map.or(bump))
}

/// pbrt-v4's layered-material parameters (`thickness`, `albedo`, `g`, `maxdepth`,
/// `nsamples`), checked.
fn layer_params(
    params: &ParamSet,
    tex: &TextureTable,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<(LayerParams, Option<LayerTexDesc>)> {
    let mut varying = LayerTexDesc::default();
    let mut float = |name: &str, default: f32, warn: &mut Warn| -> anyhow::Result<f32> {
        let t = tex.float_texture_param(params, name, default, warn)?;
        Ok(match t.constant() {
            Some(v) => v,
            None => {
                if name == "thickness" {
                    varying.thickness = Some(t);
                } else {
                    varying.g = Some(t);
                }
                default
            }
        })
    };
    let thickness = float("thickness", 0.01, warn)?;
    let g = float("g", 0.0, warn)?;
    let albedo = match tex.spectrum_param(params, "albedo", Some(Rgb::ZERO))? {
        Some(TextureDesc::Constant(c)) => c,
        Some(t) => {
            varying.albedo = Some(t);
            Rgb::ZERO
        }
        None => Rgb::ZERO,
    };
    let max_depth = params.int("maxdepth", 10)?;
    let n_samples = params.int("nsamples", 1)?;
    if !(thickness.is_finite() && thickness >= 0.0) {
        return Err(err_at(
            loc,
            format!("'thickness' must be ≥ 0, found {thickness}"),
        ));
    }
    if !(g.is_finite() && g > -1.0 && g < 1.0) {
        return Err(err_at(loc, format!("'g' must be in (−1, 1), found {g}")));
    }
    if !(1..=1000).contains(&max_depth) || !(1..=1000).contains(&n_samples) {
        return Err(err_at(
            loc,
            format!(
                "'maxdepth' and 'nsamples' must be in 1..=1000, found {max_depth}, {n_samples}"
            ),
        ));
    }
    let textured = varying != LayerTexDesc::default();
    Ok((
        LayerParams {
            thickness,
            albedo,
            g,
            max_depth: max_depth as u32,
            n_samples: n_samples as u32,
        },
        textured.then_some(varying),
    ))
}

fn metal(params: &ParamSet, name: &str, default: &str) -> anyhow::Result<MetalSpectrum> {
    let table = |n: &str| named_spectra::spectrum(n).map(MetalSpectrum::Spectral);
    Ok(match params.spectrum(name)? {
        None => table(default).unwrap_or(MetalSpectrum::Rgb(Rgb::ONE)),
        Some(SpecVal::Sampled(p)) => MetalSpectrum::Spectral(p),
        Some(SpecVal::Named(n)) => table(&n).unwrap_or_else(|| {
            MetalSpectrum::Rgb(
                to_rgb(&SpecVal::Named(n), SpectrumUse::Unbounded).unwrap_or(Rgb::ONE),
            )
        }),
        Some(v) => MetalSpectrum::Rgb(to_rgb(&v, SpectrumUse::Unbounded).unwrap_or(Rgb::ONE)),
    })
}

/// An index of refraction as the file gives it: the index at 550 nm and, when it varies with
/// wavelength (a `glass-*` name, sampled pairs or a `.spd` file, or a non-grey RGB, which
/// pbrt-v4 upsamples to a varying spectrum), one index per RGB channel.
fn ior_spectrum(params: &ParamSet, name: &str, loc: &Loc) -> anyhow::Result<(f32, Option<Rgb>)> {
    use super::params::ParamType;
    let (eta, rgb) = match params.type_of(name) {
        None | Some(ParamType::Float | ParamType::Integer) => (params.float(name, 1.5)?, None),
        Some(_) => match params.spectrum(name)? {
            Some(SpecVal::Named(n)) => {
                let v = named_glass_ior(&n).ok_or_else(|| {
                    err_at(
                        loc,
                        format!("'{name}': \"{n}\" is not an index of refraction"),
                    )
                })?;
                (v, named_glass_rgb(&n))
            }
            Some(SpecVal::Sampled(p)) => (
                sampled_at(&p, 550.0) as f32,
                Some(dielectric_rgb(|l| sampled_at(&p, l))),
            ),
            Some(SpecVal::Rgb(c)) => (c.y, Some(c)),
            Some(SpecVal::Blackbody(_)) | None => (1.5, None),
        },
    };
    let positive = |v: f32| v.is_finite() && v > 0.0;
    if !positive(eta) {
        return Err(err_at(
            loc,
            format!("'{name}' must be positive, found {eta}"),
        ));
    }
    if let Some(c) = rgb
        && !c.to_array().into_iter().all(positive)
    {
        return Err(err_at(
            loc,
            format!("'{name}' must be positive in every channel, found {c}"),
        ));
    }
    // An index that does not vary is no dispersion (and renders as before).
    Ok((eta, rgb.filter(|c| c.x != c.y || c.y != c.z)))
}

/// The index of a coat (`coateddiffuse`, `coatedconductor`): layered BSDFs take one index, so
/// a spectral one is its value at 550 nm, with a warning.
fn ior(params: &ParamSet, name: &str, loc: &Loc, warn: &mut Warn) -> anyhow::Result<f32> {
    let (eta, dispersion) = ior_spectrum(params, name, loc)?;
    if dispersion.is_some() {
        warn(
            "dispersion",
            loc,
            format!(
                "spectral '{name}' of a coat: dispersion approximated by the index at 550 nm (only \"dielectric\" disperses)"
            ),
        );
    }
    Ok(eta)
}

/// Everything `Material`/`MakeNamedMaterial` needs to resolve references.
pub struct MaterialCtx<'a> {
    /// Named textures.
    pub textures: &'a TextureTable,
    /// Looks up a named material's description (for `mix`).
    pub named: &'a dyn Fn(&str) -> Option<MaterialDesc>,
    /// Directory of the file being parsed (normal maps are relative to it).
    pub dir: &'a std::path::Path,
}

/// Parse a material of pbrt type `ty`.
pub fn parse_material(
    ty: &str,
    params: &ParamSet,
    ctx: &MaterialCtx,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<MaterialDesc> {
    let normal = normal_desc(params, ctx, loc, warn)?;
    let desc = material_body(ty, params, ctx, loc, warn)?;
    Ok(match desc {
        MaterialDesc::Interface => MaterialDesc::Interface,
        d => varying(d, None, None, normal),
    })
}

fn material_body(
    ty: &str,
    params: &ParamSet,
    ctx: &MaterialCtx,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<MaterialDesc> {
    let tex = ctx.textures;
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
        "conductor" => {
            let (r, rt) = roughness(params, tex, 0.0, warn)?;
            let base = MaterialDesc::Conductor {
                eta: metal(params, "eta", "metal-Cu-eta")?,
                k: metal(params, "k", "metal-Cu-k")?,
                reflectance: tex.spectrum_param(params, "reflectance", None)?,
                roughness: r,
                remap: params.bool("remaproughness", true)?,
            };
            varying(base, rt, None, None)
        }
        "coateddiffuse" => {
            let (r, rt) = roughness(params, tex, 0.0, warn)?;
            let (layer, lt) = layer_params(params, tex, loc, warn)?;
            let base = MaterialDesc::CoatedDiffuse {
                reflectance: tex
                    .spectrum_param(params, "reflectance", Some(Rgb::splat(0.5)))?
                    .unwrap_or(TextureDesc::Constant(Rgb::splat(0.5))),
                roughness: r,
                eta: ior(params, "eta", loc, warn)?,
                remap: params.bool("remaproughness", true)?,
                layer,
            };
            varying_layer(base, rt, None, None, lt)
        }
        "coatedconductor" => {
            let (cr, crt) = prefixed_roughness(params, tex, "interface.", 0.0, warn)?;
            let (r, rt) = prefixed_roughness(params, tex, "conductor.", 0.0, warn)?;
            let (layer, lt) = layer_params(params, tex, loc, warn)?;
            let base = MaterialDesc::CoatedConductor {
                coat_eta: ior(params, "interface.eta", loc, warn)?,
                coat_roughness: cr,
                eta: metal(params, "conductor.eta", "metal-Cu-eta")?,
                k: metal(params, "conductor.k", "metal-Cu-k")?,
                reflectance: tex.spectrum_param(params, "reflectance", None)?,
                roughness: r,
                remap: params.bool("remaproughness", true)?,
                layer,
            };
            varying_layer(base, rt, crt, None, lt)
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
            let (r, rt) = roughness(params, tex, 0.0, warn)?;
            let (eta, dispersion) = ior_spectrum(params, "eta", loc)?;
            let base = MaterialDesc::Dielectric {
                eta,
                dispersion,
                roughness: r,
                remap: params.bool("remaproughness", true)?,
                thin,
            };
            varying(base, rt, None, None)
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

fn image(
    path: &std::path::Path,
    encoding: super::textures::Encoding,
    images: &ImageCache,
) -> anyhow::Result<std::sync::Arc<crate::material::texture::ImageRgb>> {
    let img = images
        .get(path)
        .ok_or_else(|| anyhow::anyhow!("{}: image not loaded", path.display()))?;
    Ok(encoding.apply(path, img))
}

fn mip(
    img: std::sync::Arc<crate::material::texture::ImageRgb>,
    sampling: super::textures::Sampling,
) -> std::sync::Arc<crate::material::texture::MipMap> {
    std::sync::Arc::new(crate::material::texture::MipMap::new(
        img,
        sampling.wrap,
        sampling.filter,
    ))
}

/// A float texture description as a renderer texture (images MIP-mapped, as pbrt-v4's).
pub fn float_texture(t: &FloatTexDesc, images: &ImageCache) -> anyhow::Result<FloatTexture> {
    Ok(match t {
        FloatTexDesc::Constant(v) => FloatTexture::Constant(*v),
        FloatTexDesc::Image {
            path,
            scale,
            invert,
            encoding,
            sampling,
        } => FloatTexture::Mip {
            map: mip(image(path, *encoding, images)?, *sampling),
            scale: *scale,
            invert: *invert,
        },
        FloatTexDesc::Product(a, b) => FloatTexture::Product(
            Box::new(float_texture(a, images)?),
            Box::new(float_texture(b, images)?),
        ),
        FloatTexDesc::Mapped(m, t) => FloatTexture::Mapped(*m, Box::new(float_texture(t, images)?)),
        FloatTexDesc::Checkerboard { a, b, freq } => FloatTexture::Checkerboard {
            a: *a,
            b: *b,
            freq: *freq,
        },
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
            encoding,
            sampling,
        } => {
            let img = image(path, *encoding, images)?;
            if *invert {
                // pbrt-v4: max(0, 1 − scale·value), baked into a copy of the image. pbrt
                // inverts after filtering; 1 − s·x is affine, so the two agree wherever the
                // clamp at 0 does not act.
                let mut inv = (*img).clone();
                for p in &mut inv.pixels {
                    *p = (Rgb::ONE - *p * *scale).max(Rgb::ZERO);
                }
                Texture::Mip {
                    map: mip(std::sync::Arc::new(inv), *sampling),
                    scale: Rgb::ONE,
                }
            } else {
                Texture::Mip {
                    map: mip(img, *sampling),
                    scale: *scale,
                }
            }
        }
        TextureDesc::Product(a, b) => {
            Texture::Product(Box::new(texture(a, images)?), Box::new(texture(b, images)?))
        }
        TextureDesc::Float(f) => Texture::Float(float_texture(f, images)?),
        TextureDesc::Mapped(m, t) => Texture::Mapped(*m, Box::new(texture(t, images)?)),
    })
}

/// RGB (η, k) of a conductor: both spectral → matched to the spectral Fresnel reflectance
/// (`spectra::conductor_rgb`); otherwise each half on its own.
pub fn conductor_pair(eta: &MetalSpectrum, k: &MetalSpectrum) -> (Rgb, Rgb) {
    let one = |m: &MetalSpectrum| match m {
        MetalSpectrum::Rgb(c) => *c,
        MetalSpectrum::Spectral(p) => spectrum_to_rgb(|l| sampled_at(p, l)).max(Rgb::ZERO),
    };
    match (eta, k) {
        (MetalSpectrum::Spectral(e), MetalSpectrum::Spectral(kk)) => conductor_rgb(e, kk),
        _ => (one(eta), one(k)),
    }
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
            let (eta, k) = conductor_pair(eta, k);
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
            layer,
        } => Material::CoatedDiffuse {
            reflectance: texture(reflectance, images)?,
            alpha: alpha(*roughness, *remap),
            eta: *eta,
            layer: Some(*layer),
        },
        MaterialDesc::CoatedConductor {
            coat_eta,
            coat_roughness,
            eta,
            k,
            reflectance,
            roughness,
            remap,
            layer,
        } => {
            let (eta, k) = conductor_pair(eta, k);
            let reflectance = match reflectance {
                Some(t) => Some(texture(t, images)?),
                None => None,
            };
            Material::CoatedConductor {
                coat_eta: *coat_eta,
                coat_alpha: alpha(*coat_roughness, *remap),
                eta,
                k,
                alpha: alpha(*roughness, *remap),
                reflectance,
                layer: *layer,
            }
        }
        MaterialDesc::Dielectric {
            eta,
            dispersion,
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
            match dispersion {
                Some(eta) => Material::DispersiveDielectric {
                    eta: *eta,
                    alpha: alpha(*roughness, *remap),
                },
                None => Material::Dielectric {
                    eta: *eta,
                    alpha: alpha(*roughness, *remap),
                },
            }
        }
        MaterialDesc::Varying {
            base,
            roughness,
            coat_roughness,
            normal,
            layer,
        } => {
            let remap = match **base {
                MaterialDesc::Conductor { remap, .. }
                | MaterialDesc::CoatedDiffuse { remap, .. }
                | MaterialDesc::CoatedConductor { remap, .. }
                | MaterialDesc::Dielectric { remap, .. } => remap,
                _ => true,
            };
            let textures = |t: &Option<[FloatTexDesc; 2]>| -> anyhow::Result<_> {
                Ok(match t {
                    Some([u, v]) => Some(RoughnessTextures {
                        uv: [float_texture(u, images)?, float_texture(v, images)?],
                        remap,
                    }),
                    None => None,
                })
            };
            let normal = match normal {
                // pbrt-v4 reads normal maps with the linear encoding.
                Some(NormalDesc::Map(path)) => Some(NormalPerturbation::NormalMap {
                    image: image(path, super::textures::Encoding::Linear, images)?,
                    scale: 1.0,
                    uv_handed: false,
                }),
                Some(NormalDesc::Bump(t)) => {
                    Some(NormalPerturbation::Bump(float_texture(t, images)?))
                }
                None => None,
            };
            Material::Varying(Box::new(VaryingMaterial {
                base: to_material(base, images, warnings)?,
                roughness: textures(roughness)?,
                coat_roughness: textures(coat_roughness)?,
                normal,
                layer: match layer {
                    Some(l) => Some(LayerTextures {
                        thickness: l
                            .thickness
                            .as_ref()
                            .map(|t| float_texture(t, images))
                            .transpose()?,
                        g: l.g.as_ref().map(|t| float_texture(t, images)).transpose()?,
                        albedo: l.albedo.as_ref().map(|t| texture(t, images)).transpose()?,
                    }),
                    None => None,
                },
            }))
        }
        MaterialDesc::Interface => {
            // Shapes with an interface material are skipped by the parser; never reached.
            Material::Diffuse {
                reflectance: Texture::Constant(Rgb::ZERO),
            }
        }
    })
}
