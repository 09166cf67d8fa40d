//! `Texture` directive: `imagemap`, `constant`, `scale`, `checkerboard` (spectrum) and
//! `imagemap`, `constant`, `scale` (float), with pbrt-v4's `encoding`, `scale` and `invert`.

use super::params::{ParamSet, ParamType};
use super::spectra::{SpectrumUse, to_rgb};
use super::tokenizer::{Loc, err_at};
use crate::Rgb;
use crate::material::texture::{ImageRgb, MipFilter, UvMap, Wrap};
use glam::Vec2;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Images loaded while parsing (each file once), keyed by resolved path.
pub type ImageCache = HashMap<PathBuf, Arc<ImageRgb>>;

/// Load `path` (cached); errors point at `loc`.
pub fn load_image(cache: &mut ImageCache, path: &Path, loc: &Loc) -> anyhow::Result<Arc<ImageRgb>> {
    if let Some(img) = cache.get(path) {
        return Ok(img.clone());
    }
    let img = crate::image::io::read_image(path).map_err(|e| err_at(loc, format!("{e:#}")))?;
    let rgb = Arc::new(ImageRgb {
        width: img.width,
        height: img.height,
        pixels: img.pixels,
    });
    cache.insert(path.to_path_buf(), rgb.clone());
    Ok(rgb)
}

/// How an 8-bit image's code values become texture values (pbrt-v4's `encoding`; float
/// formats — EXR, PFM, HDR — are linear whatever it says).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    /// The sRGB transfer curve (pbrt-v4's default for PNG).
    SRgb,
    /// Code value / 255 (pbrt-v4's default for other 8-bit formats).
    Linear,
    /// (code value / 255)^γ.
    Gamma(f32),
}

impl Encoding {
    /// pbrt-v4's `"string encoding"` of an image texture, defaulting by file type.
    pub fn parse(params: &ParamSet, path: &Path, loc: &Loc) -> anyhow::Result<Self> {
        let png = crate::image::io::extension(path) == "png";
        let Some(e) = params.string("encoding")? else {
            return Ok(if png { Self::SRgb } else { Self::Linear });
        };
        let eloc = params.loc_of("encoding").unwrap_or(loc.clone());
        if e == "sRGB" {
            return Ok(Self::SRgb);
        }
        if e == "linear" {
            return Ok(Self::Linear);
        }
        if let Some(g) = e.strip_prefix("gamma ")
            && let Ok(g) = g.trim().parse::<f32>()
            && g > 0.0
            && g.is_finite()
        {
            return Ok(Self::Gamma(g));
        }
        Err(err_at(
            &eloc,
            format!(
                "unknown encoding \"{e}\" (expected \"sRGB\", \"linear\" or \"gamma <positive γ>\")"
            ),
        ))
    }

    /// Re-encode an image that the reader decoded as sRGB (8-bit formats) or read as linear
    /// (float formats) so its values follow this encoding.
    pub fn apply(self, path: &Path, img: &Arc<ImageRgb>) -> Arc<ImageRgb> {
        let ext = crate::image::io::extension(path);
        if self == Self::SRgb || matches!(ext.as_str(), "exr" | "pfm" | "hdr") {
            return img.clone();
        }
        let code = |v: f32| crate::image::io::linear_to_srgb(v.clamp(0.0, 1.0));
        let f = |v: f32| match self {
            Self::Gamma(g) => code(v).powf(g),
            _ => code(v),
        };
        let mut out = (**img).clone();
        for p in &mut out.pixels {
            *p = Rgb::new(f(p.x), f(p.y), f(p.z));
        }
        Arc::new(out)
    }
}

/// How an image texture is read (pbrt-v4's `wrap` and `filter`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sampling {
    /// `"string wrap"`.
    pub wrap: Wrap,
    /// `"string filter"` (`ewa` read as trilinear, warned).
    pub filter: MipFilter,
}

/// A float texture as the scene describes it.
#[derive(Clone, Debug, PartialEq)]
pub enum FloatTexDesc {
    /// The same value everywhere.
    Constant(f32),
    /// An image's first channel times `scale`, optionally inverted (max(0, 1 − v)).
    Image {
        /// Resolved path (loaded while parsing).
        path: PathBuf,
        /// Multiplier (before the inversion).
        scale: f32,
        /// pbrt's `invert`.
        invert: bool,
        /// pbrt's `encoding`.
        encoding: Encoding,
        /// pbrt's `wrap` and `filter`.
        sampling: Sampling,
    },
    /// Product (pbrt's float `scale` texture with a varying factor).
    Product(Box<FloatTexDesc>, Box<FloatTexDesc>),
    /// Looked up through a uv mapping.
    Mapped(UvMap, Box<FloatTexDesc>),
    /// pbrt-v4's float 2D checkerboard: `a` where ⌊u·fu⌋ + ⌊v·fv⌋ is even.
    Checkerboard {
        /// tex1
        a: f32,
        /// tex2
        b: f32,
        /// (uscale, vscale)
        freq: Vec2,
    },
}

impl FloatTexDesc {
    /// The value if it is the same everywhere.
    pub fn constant(&self) -> Option<f32> {
        match self {
            Self::Constant(v) => Some(*v),
            Self::Product(a, b) => Some(a.constant()? * b.constant()?),
            Self::Image { .. } => None,
            Self::Mapped(_, t) => t.constant(),
            Self::Checkerboard { a, b, .. } => (a == b).then_some(*a),
        }
    }

    /// The product of two float textures, folded when both are constant.
    pub fn times(self, other: Self) -> Self {
        match (self.constant(), other.constant()) {
            (Some(a), Some(b)) => Self::Constant(a * b),
            _ => Self::Product(Box::new(self), Box::new(other)),
        }
    }
}

/// A spectrum texture as the scene describes it (images are loaded at conversion).
#[derive(Clone, Debug, PartialEq)]
pub enum TextureDesc {
    /// The same colour everywhere.
    Constant(Rgb),
    /// An image file times `scale` (optionally inverted: max(0, 1 − scale·value)).
    Image {
        /// Resolved path (checked to exist while parsing).
        path: PathBuf,
        /// Multiplier.
        scale: Rgb,
        /// pbrt's `invert`.
        invert: bool,
        /// pbrt's `encoding`.
        encoding: Encoding,
        /// pbrt's `wrap` and `filter`.
        sampling: Sampling,
    },
    /// The product of two textures.
    Product(Box<TextureDesc>, Box<TextureDesc>),
    /// A float texture as a grey colour.
    Float(FloatTexDesc),
    /// pbrt's 2D checkerboard: `a` where ⌊u·fu⌋ + ⌊v·fv⌋ is even.
    Checkerboard {
        /// tex1
        a: Rgb,
        /// tex2
        b: Rgb,
        /// (uscale, vscale)
        freq: Vec2,
    },
    /// Looked up through a uv mapping.
    Mapped(UvMap, Box<TextureDesc>),
}

impl TextureDesc {
    fn scaled(self, s: Rgb) -> Self {
        match self {
            Self::Constant(c) => Self::Constant(c * s),
            // pbrt-v4 inverts after scaling: an inverted map's outer scale cannot fold in.
            Self::Image {
                path,
                scale,
                invert: false,
                encoding,
                sampling,
            } => Self::Image {
                path,
                scale: scale * s,
                invert: false,
                encoding,
                sampling,
            },
            t if s == Rgb::ONE => t,
            t @ (Self::Image { .. } | Self::Float(_)) => {
                Self::Product(Box::new(t), Box::new(Self::Constant(s)))
            }
            Self::Product(a, b) => Self::Product(Box::new(a.scaled(s)), b),
            Self::Checkerboard { a, b, freq } => Self::Checkerboard {
                a: a * s,
                b: b * s,
                freq,
            },
            Self::Mapped(m, t) => Self::Mapped(m, Box::new(t.scaled(s))),
        }
    }
}

/// Named textures defined so far (pbrt-v4: global, not scoped by attributes).
#[derive(Default)]
pub struct TextureTable {
    /// Spectrum textures.
    pub spectrum: HashMap<String, TextureDesc>,
    /// Float textures: `None` for a class penumbra does not implement (warned at definition;
    /// a parameter naming it takes its default).
    pub float: HashMap<String, Option<FloatTexDesc>>,
    /// Every image loaded so far (textures and environment maps).
    pub images: ImageCache,
}

/// Sink for "approximated/ignored" warnings: (dedupe key, message).
pub type Warn<'a> = dyn FnMut(&str, &Loc, String) + 'a;

impl TextureTable {
    /// A spectrum param that may be a texture reference or a constant spectrum.
    pub fn spectrum_param(
        &self,
        params: &ParamSet,
        name: &str,
        default: Option<Rgb>,
    ) -> anyhow::Result<Option<TextureDesc>> {
        if params.type_of(name) == Some(ParamType::Texture) {
            let tex = params.texture(name)?.unwrap_or_default();
            let loc = params.loc_of(name).expect("present");
            return match self.spectrum.get(&tex) {
                Some(t) => Ok(Some(t.clone())),
                None if self.float.contains_key(&tex) => Err(err_at(
                    &loc,
                    format!("'{name}': expected a spectrum texture, found float texture \"{tex}\""),
                )),
                None => Err(err_at(&loc, format!("'{name}': unknown texture \"{tex}\""))),
            };
        }
        match params.spectrum(name)? {
            Some(v) => Ok(Some(TextureDesc::Constant(
                to_rgb(&v, SpectrumUse::Albedo).unwrap_or(Rgb::splat(0.5)),
            ))),
            None => Ok(default.map(TextureDesc::Constant)),
        }
    }

    /// A float param that may be a texture reference, where penumbra needs one value: varying
    /// textures warn and use `default`.
    pub fn float_param(
        &self,
        params: &ParamSet,
        name: &str,
        default: f32,
        warn: &mut Warn,
    ) -> anyhow::Result<f32> {
        let t = self.float_texture_param(params, name, default, warn)?;
        match t.constant() {
            Some(v) => Ok(v),
            None => {
                let loc = params.loc_of(name).expect("a varying texture was named");
                warn(
                    &format!("float-texture-{name}"),
                    &loc,
                    format!(
                        "varying float texture for '{name}' is not supported there; using {default}"
                    ),
                );
                Ok(default)
            }
        }
    }

    /// A float param that may be a texture reference (constant or varying).
    pub fn float_texture_param(
        &self,
        params: &ParamSet,
        name: &str,
        default: f32,
        warn: &mut Warn,
    ) -> anyhow::Result<FloatTexDesc> {
        if params.type_of(name) == Some(ParamType::Texture) {
            let tex = params.texture(name)?.unwrap_or_default();
            let loc = params.loc_of(name).expect("present");
            return match self.float.get(&tex) {
                Some(Some(t)) => Ok(t.clone()),
                Some(None) => {
                    warn(
                        "float-texture-class",
                        &loc,
                        format!(
                            "float texture \"{tex}\" for '{name}' is of an unsupported class; using {default}"
                        ),
                    );
                    Ok(FloatTexDesc::Constant(default))
                }
                None if self.spectrum.contains_key(&tex) => Err(err_at(
                    &loc,
                    format!("'{name}': expected a float texture, found spectrum texture \"{tex}\""),
                )),
                None => Err(err_at(
                    &loc,
                    format!("'{name}': unknown float texture \"{tex}\""),
                )),
            };
        }
        Ok(FloatTexDesc::Constant(params.float(name, default)?))
    }

    /// Load an `imagemap` texture's file (cached): its path and encoding.
    fn image_file(
        &mut self,
        params: &ParamSet,
        dir: &Path,
        loc: &Loc,
        warn: &mut Warn,
    ) -> anyhow::Result<(PathBuf, Encoding, Sampling)> {
        let file = params.string("filename")?.ok_or_else(|| {
            err_at(
                loc,
                "imagemap texture: expected \"string filename\", found none",
            )
        })?;
        let path = resolve(dir, &file);
        if let Some(why) = crate::image::io::not_a_file(&path) {
            return Err(err_at(
                params.loc_of("filename").as_ref().unwrap_or(loc),
                format!("imagemap texture: {why}: {}", path.display()),
            ));
        }
        let floc = params.loc_of("filename").unwrap_or(loc.clone());
        load_image(&mut self.images, &path, &floc)?;
        let mut sampling = Sampling::default();
        if let Some(w) = params.string("wrap")? {
            sampling.wrap = Wrap::parse(&w).ok_or_else(|| {
                err_at(
                    params.loc_of("wrap").as_ref().unwrap_or(loc),
                    format!(
                        "unknown wrap mode \"{w}\" (expected \"repeat\", \"black\", \"clamp\" or \"octahedralsphere\")"
                    ),
                )
            })?;
        }
        if let Some(f) = params.string("filter")? {
            let floc = params.loc_of("filter").unwrap_or(loc.clone());
            sampling.filter = match f.as_str() {
                "point" => MipFilter::Point,
                "bilinear" => MipFilter::Bilinear,
                "trilinear" => MipFilter::Trilinear,
                "ewa" | "EWA" => {
                    warn(
                        "texture-filter-ewa",
                        &floc,
                        "image texture filter \"ewa\" approximated by \"trilinear\" (isotropic footprint)".into(),
                    );
                    MipFilter::Trilinear
                }
                other => {
                    return Err(err_at(
                        &floc,
                        format!(
                            "unknown texture filter \"{other}\" (expected \"point\", \"bilinear\", \"trilinear\" or \"ewa\")"
                        ),
                    ));
                }
            };
        }
        Ok((
            path,
            Encoding::parse(params, &resolve(dir, &file), loc)?,
            sampling,
        ))
    }

    /// Parse a `Texture "name" "spectrum"|"float" "class" params` directive and store it.
    // The three positional strings of the directive are passed as they appear in the file.
    #[allow(clippy::too_many_arguments)]
    pub fn define(
        &mut self,
        name: &str,
        ty: &str,
        class: &str,
        params: &ParamSet,
        dir: &Path,
        loc: &Loc,
        warn: &mut Warn,
    ) -> anyhow::Result<()> {
        if let Some(m) = params.string("mapping")?
            && m != "uv"
        {
            warn(
                "texture-mapping",
                loc,
                format!("texture mapping \"{m}\" approximated by uv"),
            );
        }
        for ignored in ["maxanisotropy", "dimension"] {
            let _ = params.find(ignored);
        }
        // pbrt-v4's uv mapping of the classes that have one (checkerboard's scale is its
        // square frequency below; its offset is mapped here).
        let mapped = matches!(class, "imagemap" | "checkerboard");
        let map = if mapped {
            let scale = Vec2::new(params.float("uscale", 1.0)?, params.float("vscale", 1.0)?);
            let delta = Vec2::new(params.float("udelta", 0.0)?, params.float("vdelta", 0.0)?);
            if class == "checkerboard" {
                // floor(s·u + d) = floor(s·(u + d/s)): the offset goes before the squares'
                // frequency (a zero frequency makes one square whatever the offset).
                let d = |d: f32, s: f32| if s == 0.0 { 0.0 } else { d / s };
                UvMap {
                    scale: Vec2::ONE,
                    delta: Vec2::new(d(delta.x, scale.x), d(delta.y, scale.y)),
                }
            } else {
                UvMap { scale, delta }
            }
        } else {
            UvMap::IDENTITY
        };
        match ty {
            "spectrum" | "color" => {
                let d = self.spectrum_texture(class, params, dir, loc, warn)?;
                let d = if map == UvMap::IDENTITY {
                    d
                } else {
                    TextureDesc::Mapped(map, Box::new(d))
                };
                self.spectrum.insert(name.to_string(), d);
            }
            "float" => {
                let v = match class {
                    "constant" => Some(FloatTexDesc::Constant(params.float("value", 1.0)?)),
                    "scale" => {
                        let t = self.float_texture_param(params, "tex", 1.0, warn)?;
                        let s = self.float_texture_param(params, "scale", 1.0, warn)?;
                        Some(t.times(s))
                    }
                    "imagemap" => {
                        let (path, encoding, sampling) = self.image_file(params, dir, loc, warn)?;
                        Some(FloatTexDesc::Image {
                            path,
                            scale: params.float("scale", 1.0)?,
                            invert: params.bool("invert", false)?,
                            encoding,
                            sampling,
                        })
                    }
                    "checkerboard" => {
                        if params.int("dimension", 2)? != 2 {
                            warn(
                                "checkerboard-3d",
                                loc,
                                "3D checkerboard approximated by 2D".into(),
                            );
                        }
                        let konst = |n: &str, d: f32, warn: &mut Warn| -> anyhow::Result<f32> {
                            let t = self.float_texture_param(params, n, d, warn)?;
                            Ok(t.constant().unwrap_or_else(|| {
                                warn(
                                    "nested-texture",
                                    loc,
                                    format!(
                                        "non-constant texture for '{n}' is not supported; using {d}"
                                    ),
                                );
                                d
                            }))
                        };
                        Some(FloatTexDesc::Checkerboard {
                            a: konst("tex1", 1.0, warn)?,
                            b: konst("tex2", 0.0, warn)?,
                            freq: Vec2::new(
                                params.float("uscale", 1.0)?,
                                params.float("vscale", 1.0)?,
                            ),
                        })
                    }
                    _ => {
                        warn(
                            "float-texture",
                            loc,
                            format!("float texture class \"{class}\" is not supported"),
                        );
                        None
                    }
                };
                let v = match v {
                    Some(t) if map != UvMap::IDENTITY => {
                        Some(FloatTexDesc::Mapped(map, Box::new(t)))
                    }
                    v => v,
                };
                self.float.insert(name.to_string(), v);
            }
            other => {
                return Err(err_at(
                    loc,
                    format!("expected texture type \"spectrum\" or \"float\", found \"{other}\""),
                ));
            }
        }
        Ok(())
    }

    fn const_spectrum(
        &self,
        params: &ParamSet,
        name: &str,
        default: Rgb,
        loc: &Loc,
        warn: &mut Warn,
    ) -> anyhow::Result<Rgb> {
        match self.spectrum_param(params, name, Some(default))? {
            Some(TextureDesc::Constant(c)) => Ok(c),
            _ => {
                warn(
                    "nested-texture",
                    loc,
                    format!("non-constant texture for '{name}' is not supported; using {default}"),
                );
                Ok(default)
            }
        }
    }

    fn spectrum_texture(
        &mut self,
        class: &str,
        params: &ParamSet,
        dir: &Path,
        loc: &Loc,
        warn: &mut Warn,
    ) -> anyhow::Result<TextureDesc> {
        Ok(match class {
            "constant" => {
                TextureDesc::Constant(self.const_spectrum(params, "value", Rgb::ONE, loc, warn)?)
            }
            "imagemap" => {
                let (path, encoding, sampling) = self.image_file(params, dir, loc, warn)?;
                let scale = params.float("scale", 1.0)?;
                TextureDesc::Image {
                    path,
                    scale: Rgb::splat(scale),
                    invert: params.bool("invert", false)?,
                    encoding,
                    sampling,
                }
            }
            "scale" => {
                let base = self
                    .spectrum_param(params, "tex", Some(Rgb::ONE))?
                    .unwrap_or(TextureDesc::Constant(Rgb::ONE));
                match self.float_texture_param(params, "scale", 1.0, warn)? {
                    FloatTexDesc::Constant(s) => base.scaled(Rgb::splat(s)),
                    by => TextureDesc::Product(Box::new(base), Box::new(TextureDesc::Float(by))),
                }
            }
            "checkerboard" => {
                if params.int("dimension", 2)? != 2 {
                    warn(
                        "checkerboard-3d",
                        loc,
                        "3D checkerboard approximated by 2D".into(),
                    );
                }
                TextureDesc::Checkerboard {
                    a: self.const_spectrum(params, "tex1", Rgb::ONE, loc, warn)?,
                    b: self.const_spectrum(params, "tex2", Rgb::ZERO, loc, warn)?,
                    freq: Vec2::new(params.float("uscale", 1.0)?, params.float("vscale", 1.0)?),
                }
            }
            other => {
                warn(
                    "texture-class",
                    loc,
                    format!("texture class \"{other}\" is not supported; using constant 0.5"),
                );
                TextureDesc::Constant(Rgb::splat(0.5))
            }
        })
    }
}

/// Resolve a file name relative to the including file's directory.
pub fn resolve(dir: &Path, file: &str) -> PathBuf {
    let p = Path::new(file);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        dir.join(p)
    }
}
