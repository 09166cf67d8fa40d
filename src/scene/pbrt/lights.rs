//! `LightSource` and `AreaLightSource` → internal descriptions, converted by [`to_light`].
//!
//! Units follow pbrt-v4: a light's spectrum is taken as unit-luminance (RGB as given,
//! blackbody/sampled spectra normalised to luminance 1), times `scale`; `power` (point, spot,
//! area) and `illuminance` (distant, uniform infinite) then rescale it so the emitted power or
//! the irradiance at normal incidence equals the given value.

use super::params::{ParamSet, SpecVal};
use super::spectra::{SpectrumUse, to_rgb};
use super::textures::{ImageCache, Warn, load_image, resolve};
use super::tokenizer::{Loc, err_at};
use crate::Rgb;
use crate::geometry::Transform;
use crate::lights::Light;
use crate::lights::envmap::EnvLayout;
use glam::Vec3;
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

/// A non-area light as the scene file describes it (world space).
#[derive(Clone, Debug, PartialEq)]
pub enum LightDesc {
    /// `point`: intensity I (W/sr-equivalent) at `p`.
    Point {
        /// Position.
        p: Vec3,
        /// Radiant intensity.
        intensity: Rgb,
    },
    /// `spot`.
    Spot {
        /// Position.
        p: Vec3,
        /// Unit axis direction.
        dir: Vec3,
        /// Intensity on the axis.
        intensity: Rgb,
        /// cos(coneangle − conedelta).
        cos_falloff_start: f32,
        /// cos(coneangle).
        cos_total_width: f32,
    },
    /// `distant`: radiance arriving from direction `w_toward_light`.
    Distant {
        /// Unit direction from the scene toward the light.
        w_toward_light: Vec3,
        /// Scaled radiance (irradiance at normal incidence).
        l: Rgb,
    },
    /// `infinite` with a constant `L`.
    UniformInfinite {
        /// Radiance.
        l: Rgb,
    },
    /// `infinite` with an image `filename`.
    EnvMap {
        /// Image path (checked to exist).
        path: PathBuf,
        /// Multiplier (`scale`, times the `illuminance` normalisation).
        scale: f32,
        /// Equal-area octahedral (square images, pbrt-v4) or lat-long (any other shape).
        layout: EnvLayout,
        /// The CTM at the light.
        light_to_world: Transform,
    },
}

/// `AreaLightSource "diffuse"` state attached to subsequent shapes.
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLightDesc {
    /// Radiance × scale.
    pub l: Rgb,
    /// Emits on both sides.
    pub two_sided: bool,
    /// If set, rescale so the shape's total emitted power equals this.
    pub power: Option<f32>,
}

impl AreaLightDesc {
    /// Radiance for a shape of world-space `area` (applies `power`).
    pub fn radiance_for_area(&self, area: f32) -> Rgb {
        match self.power {
            Some(phi) if area > 0.0 => {
                let sides = if self.two_sided { 2.0 } else { 1.0 };
                self.l * (phi / (PI * area * sides))
            }
            _ => self.l,
        }
    }
}

fn spectrum(params: &ParamSet, name: &str) -> anyhow::Result<Rgb> {
    let v = params.spectrum(name)?;
    // Emission cannot be negative; pbrt-v4 refuses such an RGB too, rather than rendering black.
    if let (Some(SpecVal::Rgb(c)), Some(at)) = (&v, params.loc_of(name))
        && c.min_element() < 0.0
    {
        return Err(err_at(
            &at,
            format!(
                "RGB parameter \"{name}\" [{} {} {}] has a negative component: emitted radiance cannot be negative",
                c.x, c.y, c.z
            ),
        ));
    }
    Ok(v.and_then(|v| to_rgb(&v, SpectrumUse::Illuminant))
        .unwrap_or(Rgb::ONE))
}

fn positive_opt(params: &ParamSet, name: &str) -> anyhow::Result<Option<f32>> {
    Ok(params.opt_float(name)?.filter(|&v| v > 0.0))
}

/// Parse `AreaLightSource "type" params`.
pub fn parse_area_light(
    ty: &str,
    params: &ParamSet,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<Option<AreaLightDesc>> {
    if ty != "diffuse" {
        warn(
            "arealight-type",
            loc,
            format!("area light type \"{ty}\" is not supported; shapes will not emit"),
        );
        return Ok(None);
    }
    if params.has("filename") {
        let _ = params.find("filename");
        warn(
            "arealight-image",
            loc,
            "image area lights approximated by their L".into(),
        );
    }
    let l = spectrum(params, "L")? * params.float("scale", 1.0)?;
    Ok(Some(AreaLightDesc {
        l,
        two_sided: params.bool("twosided", false)?,
        power: positive_opt(params, "power")?,
    }))
}

/// Parse `LightSource "type" params` under the CTM `ctm`.
pub fn parse_light(
    ty: &str,
    params: &ParamSet,
    ctm: &Transform,
    dir: &Path,
    images: &mut ImageCache,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<Option<LightDesc>> {
    let scale = params.float("scale", 1.0)?;
    let desc = match ty {
        "point" => {
            let mut i = spectrum(params, "I")? * scale;
            if let Some(phi) = positive_opt(params, "power")? {
                i *= phi / (4.0 * PI);
            }
            LightDesc::Point {
                p: ctm.point(params.vec3("from", Vec3::ZERO)?),
                intensity: i,
            }
        }
        "spot" => {
            let from = params.vec3("from", Vec3::ZERO)?;
            let to = params.vec3("to", Vec3::Z)?;
            let dir = ctm.vector(to - from).normalize_or_zero();
            if dir == Vec3::ZERO || !dir.is_finite() {
                return Err(err_at(loc, "spot light: 'from' and 'to' coincide"));
            }
            let cone = params.float("coneangle", 30.0)?;
            let delta = params.float("conedelta", 5.0)?;
            let cos_total = cone.to_radians().cos();
            let cos_start = (cone - delta).to_radians().cos();
            let mut i = spectrum(params, "I")? * scale;
            if let Some(phi) = positive_opt(params, "power")? {
                let k = 2.0 * PI * ((1.0 - cos_start) + (cos_start - cos_total) / 2.0);
                if k > 0.0 {
                    i *= phi / k;
                }
            }
            LightDesc::Spot {
                p: ctm.point(from),
                dir,
                intensity: i,
                cos_falloff_start: cos_start,
                cos_total_width: cos_total,
            }
        }
        "distant" => {
            let from = params.vec3("from", Vec3::ZERO)?;
            let to = params.vec3("to", Vec3::Z)?;
            let w = ctm.vector(from - to).normalize_or_zero();
            if w == Vec3::ZERO || !w.is_finite() {
                return Err(err_at(loc, "distant light: 'from' and 'to' coincide"));
            }
            let mut l = spectrum(params, "L")? * scale;
            if let Some(e) = positive_opt(params, "illuminance")? {
                l *= e;
            }
            LightDesc::Distant {
                w_toward_light: w,
                l,
            }
        }
        "infinite" => {
            if params.has("portal") {
                let _ = params.find("portal");
                warn("portal", loc, "infinite light 'portal' ignored".into());
            }
            match params.string("filename")? {
                Some(file) => {
                    if params.has("L") {
                        return Err(err_at(
                            loc,
                            "infinite light: expected either \"L\" or \"filename\", found both",
                        ));
                    }
                    let path = resolve(dir, &file);
                    if let Some(why) = crate::image::io::not_a_file(&path) {
                        return Err(err_at(
                            params.loc_of("filename").as_ref().unwrap_or(loc),
                            format!("infinite light: {why}: {}", path.display()),
                        ));
                    }
                    let floc = params.loc_of("filename").unwrap_or(loc.clone());
                    let img = load_image(images, &path, &floc)?;
                    let negative = img.pixels.iter().filter(|p| p.min_element() < 0.0).count();
                    if img.pixels.iter().all(|p| !(p.max_element() > 0.0)) {
                        warn(
                            &format!("envmap-black@{}", floc.file_line()),
                            &floc,
                            format!(
                                "environment map {} has no pixel with positive radiance: the light is black",
                                path.display()
                            ),
                        );
                    } else if negative > 0 {
                        warn(
                            &format!("envmap-negative@{}", floc.file_line()),
                            &floc,
                            format!(
                                "environment map {}: {negative} of {} pixels have negative values, taken as 0",
                                path.display(),
                                img.pixels.len()
                            ),
                        );
                    }
                    let layout = if img.width == img.height {
                        EnvLayout::EqualArea
                    } else {
                        warn(
                            "envmap-latlong",
                            loc,
                            format!(
                                "environment map {} is {}x{}, not square: pbrt-v4 requires square equal-area maps and would refuse it; read as latitude-longitude (row 0 = +z)",
                                path.display(),
                                img.width,
                                img.height
                            ),
                        );
                        EnvLayout::LatLong
                    };
                    let mut scale = scale;
                    if let Some(e) = positive_opt(params, "illuminance")? {
                        let k = map_illuminance(&img, layout);
                        if !(k > 0.0) {
                            return Err(err_at(
                                params.loc_of("illuminance").as_ref().unwrap_or(loc),
                                format!(
                                    "infinite light: 'illuminance' {e} asked of a map that sends no light to the upper hemisphere: {}",
                                    path.display()
                                ),
                            ));
                        }
                        scale *= e / k;
                    }
                    LightDesc::EnvMap {
                        path,
                        scale,
                        layout,
                        light_to_world: *ctm,
                    }
                }
                None => {
                    let mut l = spectrum(params, "L")? * scale;
                    if let Some(e) = positive_opt(params, "illuminance")? {
                        l *= e / PI;
                    }
                    LightDesc::UniformInfinite { l }
                }
            }
        }
        "goniometric" | "projection" => {
            warn(
                &format!("light-{ty}"),
                loc,
                format!("light \"{ty}\" is refused (not supported by penumbra); skipped"),
            );
            for p in &params.params {
                let _ = params.find(&p.name);
            }
            return Ok(None);
        }
        other => {
            return Err(err_at(
                loc,
                format!("unknown light type \"{other}\" (expected point, spot, distant, infinite)"),
            ));
        }
    };
    Ok(Some(desc))
}

/// Convert a description into a renderer light (`images` holds what the parser loaded).
pub fn to_light(desc: &LightDesc, images: &ImageCache) -> anyhow::Result<Light> {
    use crate::lights::{DistantLight, EnvMapLight, PointLight, SpotLight, UniformInfiniteLight};
    Ok(match desc {
        LightDesc::Point { p, intensity } => Light::Point(PointLight::new(*p, *intensity)),
        LightDesc::Spot {
            p,
            dir,
            intensity,
            cos_falloff_start,
            cos_total_width,
        } => Light::Spot(SpotLight::new(
            *p,
            *dir,
            *intensity,
            *cos_falloff_start,
            *cos_total_width,
        )),
        LightDesc::Distant { w_toward_light, l } => {
            Light::Distant(DistantLight::new(*w_toward_light, *l))
        }
        LightDesc::UniformInfinite { l } => Light::UniformInfinite(UniformInfiniteLight::new(*l)),
        LightDesc::EnvMap {
            path,
            scale,
            layout,
            light_to_world,
        } => {
            let img = images
                .get(path)
                .cloned()
                .ok_or_else(|| anyhow::anyhow!("{}: image not loaded", path.display()))?;
            let make = match layout {
                EnvLayout::EqualArea => EnvMapLight::equal_area,
                EnvLayout::LatLong => EnvMapLight::new,
            };
            Light::EnvMap(Box::new(
                make(img, Rgb::splat(*scale), *light_to_world)
                    .map_err(|e| anyhow::anyhow!("{}: {e:#}", path.display()))?,
            ))
        }
    })
}

/// Illuminance at an upward-facing (light-space +z) patch from the map at scale 1:
/// ∫ L(ω)·cos θ dω over z > 0, the luminance of each texel times its cosine and solid angle.
/// (pbrt-v4's file format defines 'illuminance' so; its code sums with 2π/n² per texel where
/// each equal-area texel covers 4π/n², which makes its maps twice as bright as asked.)
pub fn map_illuminance(img: &crate::material::texture::ImageRgb, layout: EnvLayout) -> f32 {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut e = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let uv = glam::Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let (d, d_omega) = match layout {
                EnvLayout::EqualArea => (
                    crate::sampling::equal_area_square_to_sphere(uv),
                    4.0 * std::f64::consts::PI / (w * h) as f64,
                ),
                EnvLayout::LatLong => {
                    let (st, ct) = (uv.y * PI).sin_cos();
                    let (sp, cp) = (uv.x * 2.0 * PI).sin_cos();
                    (
                        Vec3::new(st * cp, st * sp, ct),
                        2.0 * std::f64::consts::PI.powi(2) * st as f64 / (w * h) as f64,
                    )
                }
            };
            if d.z > 0.0 {
                let l = crate::luminance(img.pixels[y * w + x].max(Rgb::ZERO)) as f64;
                e += l * d.z as f64 * d_omega;
            }
        }
    }
    e as f32
}
