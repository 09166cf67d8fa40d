//! `Texture` directive: `imagemap`, `constant`, `scale`, `checkerboard` (spectrum and float).

use super::params::{ParamSet, ParamType};
use super::spectra::{SpectrumUse, to_rgb};
use super::tokenizer::{Loc, err_at};
use crate::Rgb;
use crate::material::texture::ImageRgb;
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

/// A spectrum texture as the scene describes it (images are loaded at conversion).
#[derive(Clone, Debug, PartialEq)]
pub enum TextureDesc {
    /// The same colour everywhere.
    Constant(Rgb),
    /// An image file times `scale` (optionally inverted: 1 − value).
    Image {
        /// Resolved path (checked to exist while parsing).
        path: PathBuf,
        /// Multiplier.
        scale: Rgb,
        /// pbrt's `invert`.
        invert: bool,
    },
    /// pbrt's 2D checkerboard: `a` where ⌊u·fu⌋ + ⌊v·fv⌋ is even.
    Checkerboard {
        /// tex1
        a: Rgb,
        /// tex2
        b: Rgb,
        /// (uscale, vscale)
        freq: Vec2,
    },
}

impl TextureDesc {
    fn scaled(self, s: Rgb) -> Self {
        match self {
            Self::Constant(c) => Self::Constant(c * s),
            Self::Image {
                path,
                scale,
                invert,
            } => Self::Image {
                path,
                scale: scale * s,
                invert,
            },
            Self::Checkerboard { a, b, freq } => Self::Checkerboard {
                a: a * s,
                b: b * s,
                freq,
            },
        }
    }
}

/// Named textures defined so far (pbrt-v4: global, not scoped by attributes).
#[derive(Default)]
pub struct TextureTable {
    /// Spectrum textures.
    pub spectrum: HashMap<String, TextureDesc>,
    /// Float textures: `Some(v)` when constant, `None` when varying (unsupported for floats).
    pub float: HashMap<String, Option<f32>>,
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

    /// A float param that may be a texture reference; varying float textures warn and use
    /// `default`.
    pub fn float_param(
        &self,
        params: &ParamSet,
        name: &str,
        default: f32,
        warn: &mut Warn,
    ) -> anyhow::Result<f32> {
        if params.type_of(name) == Some(ParamType::Texture) {
            let tex = params.texture(name)?.unwrap_or_default();
            let loc = params.loc_of(name).expect("present");
            return match self.float.get(&tex) {
                Some(Some(v)) => Ok(*v),
                Some(None) => {
                    warn(
                        "float-texture",
                        &loc,
                        format!(
                            "varying float texture \"{tex}\" for '{name}' is not supported; using {default}"
                        ),
                    );
                    Ok(default)
                }
                None => Err(err_at(
                    &loc,
                    format!("'{name}': unknown float texture \"{tex}\""),
                )),
            };
        }
        params.float(name, default)
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
        for ignored in [
            "filter",
            "wrap",
            "encoding",
            "maxanisotropy",
            "udelta",
            "vdelta",
            "dimension",
        ] {
            let _ = params.find(ignored);
        }
        match ty {
            "spectrum" | "color" => {
                let d = self.spectrum_texture(class, params, dir, loc, warn)?;
                self.spectrum.insert(name.to_string(), d);
            }
            "float" => {
                let v = match class {
                    "constant" => Some(params.float("value", 1.0)?),
                    "scale" => {
                        let t = self.float_param(params, "tex", 1.0, warn)?;
                        let s = self.float_param(params, "scale", 1.0, warn)?;
                        Some(t * s)
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
                let scale = params.float("scale", 1.0)?;
                TextureDesc::Image {
                    path,
                    scale: Rgb::splat(scale),
                    invert: params.bool("invert", false)?,
                }
            }
            "scale" => {
                let base = self
                    .spectrum_param(params, "tex", Some(Rgb::ONE))?
                    .unwrap_or(TextureDesc::Constant(Rgb::ONE));
                let s = self.float_param(params, "scale", 1.0, warn)?;
                base.scaled(Rgb::splat(s))
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
