//! The directive interpreter: include stack, graphics state (CTM, material, area light,
//! orientation), named coordinate systems, materials, textures, object instances.

use super::lights::{AreaLightDesc, parse_area_light, parse_light};
use super::materials::{MaterialCtx, MaterialDesc, parse_material};
use super::params::ParamSet;
use super::shapes::{ShapeCtx, make_shape, shape_alpha};
use super::textures::{TextureTable, Warn};
use super::tokenizer::{Loc, Tok, Token, Tokenizer, err_at};
use super::upgrade;
use super::{PbrtScene, ShapeCall};
use crate::camera::{Camera, Lens, Projection, SphericalMapping};
use crate::geometry::Transform;
use crate::scene::{AreaEmission, FilmSpec, Filter};
use glam::{Mat4, UVec2, Vec2, Vec3, Vec4};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

const MAX_INCLUDE_DEPTH: usize = 64;

#[derive(Clone)]
struct GState {
    ctm: Transform,
    reverse: bool,
    material: usize,
    area: Option<AreaLightDesc>,
}

struct OpenFile {
    tok: Tokenizer,
    dir: PathBuf,
    canon: Option<PathBuf>,
}

struct ObjectDef {
    name: String,
    shapes: Vec<ShapeCall>,
}

/// Parses one scene (with its includes) into a [`PbrtScene`].
pub struct Parser {
    files: Vec<OpenFile>,
    gs: GState,
    gs_stack: Vec<(GState, Loc, &'static str)>,
    named_coords: HashMap<String, Transform>,
    /// Material descriptions; index 0 is the default diffuse.
    descs: Vec<MaterialDesc>,
    /// Builder index of each description, assigned when a shape first uses it.
    builder_index: Vec<Option<u32>>,
    named_materials: HashMap<String, usize>,
    textures: TextureTable,
    objects: HashMap<String, Vec<ShapeCall>>,
    cur_object: Option<ObjectDef>,
    world_seen: Option<Loc>,
    warned: HashSet<String>,
    camera: Option<Camera>,
    /// Film sensor parameters and where the Film directive is.
    sensor: (super::film::SensorParams, Option<Loc>),
    /// `exposuretime` given on the Film (else the camera's shutter interval).
    film_exposure: Option<f32>,
    /// The camera's `shutterclose − shutteropen`.
    camera_exposure: f32,
    out: PbrtScene,
}

fn film_default() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(1280, 720),
        // pbrt-v4's default filter.
        filter: Filter::Gaussian {
            radius: Vec2::splat(1.5),
            sigma: 0.5,
        },
        filename: None,
        spp: None,
        sensor: Default::default(),
    }
}

fn describe(t: &Option<Token>) -> String {
    match t {
        Some(t) => t.tok.describe(),
        None => "end of file".into(),
    }
}

impl Parser {
    /// A parser reading `src` (named `name`, relative files resolved against `dir`).
    pub fn new(name: &str, src: Vec<u8>, dir: PathBuf, canon: Option<PathBuf>) -> Self {
        Self {
            files: vec![OpenFile {
                tok: Tokenizer::new(name, src),
                dir,
                canon,
            }],
            gs: GState {
                ctm: Transform::IDENTITY,
                reverse: false,
                material: 0,
                area: None,
            },
            gs_stack: Vec::new(),
            named_coords: HashMap::new(),
            descs: vec![MaterialDesc::default_diffuse()],
            builder_index: vec![None],
            named_materials: HashMap::new(),
            textures: TextureTable::default(),
            objects: HashMap::new(),
            cur_object: None,
            world_seen: None,
            warned: HashSet::new(),
            camera: None,
            sensor: (Default::default(), None),
            film_exposure: None,
            camera_exposure: 1.0,
            out: PbrtScene {
                camera: Camera {
                    camera_to_world: Transform::IDENTITY,
                    fov_deg: 90.0,
                    screen_window: None,
                    projection: Projection::Perspective,
                    lens: Lens::PINHOLE,
                },
                film: film_default(),
                max_depth: None,
                integrator: None,
                materials: Vec::new(),
                shapes: Vec::new(),
                lights: Vec::new(),
                warnings: Vec::new(),
                images: Default::default(),
            },
        }
    }

    fn warn(&mut self, key: &str, loc: &Loc, msg: String) {
        if self.warned.insert(key.to_string()) {
            self.out
                .warnings
                .push(format!("{}: warning: {msg}", loc.file_line()));
        }
    }

    fn top(&mut self) -> &mut OpenFile {
        self.files
            .last_mut()
            .expect("file stack is never empty while parsing")
    }

    fn dir(&self) -> PathBuf {
        self.files.last().map(|f| f.dir.clone()).unwrap_or_default()
    }

    fn next_arg(&mut self) -> anyhow::Result<Option<Token>> {
        self.top().tok.next_token()
    }

    fn here(&mut self) -> Loc {
        self.top().tok.here()
    }

    fn expect_string(&mut self, what: &str) -> anyhow::Result<(String, Loc)> {
        let t = self.next_arg()?;
        match t {
            Some(Token {
                tok: Tok::Str(s),
                loc,
            }) => Ok((s, loc)),
            other => {
                let loc = other
                    .as_ref()
                    .map(|t| t.loc.clone())
                    .unwrap_or_else(|| self.here());
                Err(err_at(
                    &loc,
                    format!("expected {what}, found {}", describe(&other)),
                ))
            }
        }
    }

    /// `n` numbers, bare or in one pair of brackets.
    fn expect_nums(&mut self, n: usize, directive: &str) -> anyhow::Result<Vec<f32>> {
        let bracketed = matches!(self.top().tok.peek()?, Some(Token { tok: Tok::Open, .. }));
        if bracketed {
            self.next_arg()?;
        }
        let mut v = Vec::with_capacity(n);
        while v.len() < n {
            let t = self.next_arg()?;
            match t {
                Some(Token {
                    tok: Tok::Num(x), ..
                }) => v.push(x as f32),
                other => {
                    let loc = other
                        .as_ref()
                        .map(|t| t.loc.clone())
                        .unwrap_or_else(|| self.here());
                    return Err(err_at(
                        &loc,
                        format!(
                            "{directive}: expected {n} numbers, found {} after {}",
                            describe(&other),
                            v.len()
                        ),
                    ));
                }
            }
        }
        if bracketed {
            let t = self.next_arg()?;
            if !matches!(
                t,
                Some(Token {
                    tok: Tok::Close,
                    ..
                })
            ) {
                let loc = t
                    .as_ref()
                    .map(|t| t.loc.clone())
                    .unwrap_or_else(|| self.here());
                return Err(err_at(
                    &loc,
                    format!(
                        "{directive}: expected ']' after {n} numbers, found {}",
                        describe(&t)
                    ),
                ));
            }
        }
        Ok(v)
    }

    /// Run a pbrt-v3 rewrite (`upgrade`) and report its warnings.
    fn upgrade<R>(&mut self, f: impl FnOnce(&mut Warn) -> R) -> R {
        let mut pending = Vec::new();
        let r = f(&mut |k: &str, l: &Loc, m: String| pending.push((k.to_string(), l.clone(), m)));
        for (k, l, m) in pending {
            self.warn(&k, &l, m);
        }
        r
    }

    fn params(&mut self) -> anyhow::Result<ParamSet> {
        let dir = self.dir();
        let mut ps = ParamSet::parse(&mut self.top().tok)?;
        ps.resolve_spectrum_files(&dir)?;
        Ok(ps)
    }

    fn report_unused(&mut self, ps: &ParamSet, what: &str) {
        let unused: Vec<(String, Loc)> = ps
            .unused()
            .map(|p| (format!("{} {}", p.ty.name(), p.name), p.loc.clone()))
            .collect();
        for (name, loc) in unused {
            self.warn(
                &format!("unused:{what}:{name}"),
                &loc,
                format!("{what}: parameter \"{name}\" is not supported; ignored"),
            );
        }
    }

    fn require_world(&self, directive: &str, loc: &Loc, inside: bool) -> anyhow::Result<()> {
        match (inside, &self.world_seen) {
            (true, None) => Err(err_at(loc, format!("{directive} before WorldBegin"))),
            (false, Some(w)) => Err(err_at(
                loc,
                format!("{directive} after WorldBegin (at {w}); expected it in the options block"),
            )),
            _ => Ok(()),
        }
    }

    fn concat(&mut self, m: Mat4, loc: &Loc, what: &str) -> anyhow::Result<()> {
        let t = Transform::new(m)
            .ok_or_else(|| err_at(loc, format!("{what}: singular or non-finite transform")))?;
        self.gs.ctm = self.gs.ctm.then_apply_to(&t);
        Ok(())
    }

    /// Run the whole file (and includes) and finish the scene.
    pub fn run(mut self) -> anyhow::Result<PbrtScene> {
        while let Some(top) = self.files.last_mut() {
            match top.tok.next_token()? {
                None => {
                    self.files.pop();
                }
                Some(Token {
                    tok: Tok::Word(w),
                    loc,
                }) => self.directive(&w, loc)?,
                Some(t) => {
                    return Err(err_at(
                        &t.loc,
                        format!("expected a directive, found {}", t.tok.describe()),
                    ));
                }
            }
        }
        self.finish()
    }

    fn finish(mut self) -> anyhow::Result<PbrtScene> {
        if let Some(obj) = &self.cur_object {
            return Err(anyhow::anyhow!(
                "end of input inside ObjectBegin \"{}\" (expected ObjectEnd)",
                obj.name
            ));
        }
        if self.world_seen.is_none() {
            return Err(anyhow::anyhow!(
                "end of input before WorldBegin: the scene has no world block"
            ));
        }
        if let Some((_, loc, kind)) = self.gs_stack.last().cloned() {
            self.warn(
                "unclosed",
                &loc,
                format!("{kind} without matching End at end of file"),
            );
        }
        if let (mut params, Some(loc)) = self.sensor.clone() {
            params.exposure_time = self.film_exposure.unwrap_or(self.camera_exposure);
            let r = self.upgrade(|w| super::film::sensor_response(&params, &loc, w))?;
            self.out.film.sensor = r;
        }
        self.out.images = std::mem::take(&mut self.textures.images);
        if let Some(cam) = self.camera.take() {
            self.out.camera = cam;
        }
        Ok(self.out)
    }

    fn include(&mut self, loc: &Loc) -> anyhow::Result<()> {
        let (file, floc) = self.expect_string("a file name")?;
        let path = super::textures::resolve(&self.top().dir, &file);
        let src = std::fs::read(&path).map_err(|e| {
            err_at(
                &floc,
                format!("cannot read included file {}: {e}", path.display()),
            )
        })?;
        let canon = std::fs::canonicalize(&path).ok();
        if canon.is_some() && self.files.iter().any(|f| f.canon == canon) {
            return Err(err_at(
                loc,
                format!("Include cycle: {} includes itself", path.display()),
            ));
        }
        if self.files.len() >= MAX_INCLUDE_DEPTH {
            return Err(err_at(loc, "Include nesting deeper than 64"));
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        self.files.push(OpenFile {
            tok: Tokenizer::new(path.display().to_string(), src),
            dir,
            canon,
        });
        Ok(())
    }

    fn material_index(&mut self, desc: usize) -> Option<u32> {
        if self.descs[desc] == MaterialDesc::Interface {
            return None;
        }
        if let Some(i) = self.builder_index[desc] {
            return Some(i);
        }
        let i = self.out.materials.len() as u32;
        self.out.materials.push(self.descs[desc].clone());
        self.builder_index[desc] = Some(i);
        Some(i)
    }

    fn parse_material_desc(
        &mut self,
        ty: &str,
        ps: &ParamSet,
        loc: &Loc,
    ) -> anyhow::Result<MaterialDesc> {
        let named: HashMap<String, MaterialDesc> = self
            .named_materials
            .iter()
            .map(|(k, &i)| (k.clone(), self.descs[i].clone()))
            .collect();
        let lookup = |n: &str| named.get(n).cloned();
        let dir = self.dir();
        // A normal map is loaded (cached with the textures' images) before the material
        // refers to it.
        if let Some(f) = ps.string("normalmap")?
            && !f.is_empty()
        {
            let path = super::textures::resolve(&dir, &f);
            let floc = ps.loc_of("normalmap").unwrap_or(loc.clone());
            if let Some(why) = crate::image::io::not_a_file(&path) {
                return Err(err_at(
                    &floc,
                    format!("normalmap: {why}: {}", path.display()),
                ));
            }
            // pbrt-v4 reads the three channels as a direction: a grey image is an error
            // there too, not a normal map of (g, g, g).
            let color = crate::image::io::has_color_channels(&path)
                .map_err(|e| err_at(&floc, format!("normalmap: {e:#}")))?;
            if !color {
                return Err(err_at(
                    &floc,
                    format!(
                        "normalmap: {} has one (grey) channel; a normal map needs R, G and B",
                        path.display()
                    ),
                ));
            }
            super::textures::load_image(&mut self.textures.images, &path, &floc)?;
        }
        let ctx = MaterialCtx {
            textures: &self.textures,
            named: &lookup,
            dir: &dir,
        };
        let mut pending = Vec::new();
        let d = parse_material(ty, ps, &ctx, loc, &mut |k: &str, l: &Loc, m: String| {
            pending.push((k.to_string(), l.clone(), m))
        })?;
        for (k, l, m) in pending {
            self.warn(&k, &l, m);
        }
        Ok(d)
    }

    fn directive(&mut self, name: &str, loc: Loc) -> anyhow::Result<()> {
        match name {
            "Include" | "Import" => self.include(&loc)?,
            "Option" => {
                let ps = self.params()?;
                let names: Vec<String> = ps.params.iter().map(|p| p.name.clone()).collect();
                self.warn(
                    "Option",
                    &loc,
                    format!("Option {} ignored", names.join(", ")),
                );
            }
            "ColorSpace" => {
                let (cs, _) = self.expect_string("a color space name")?;
                if cs != "srgb" {
                    self.warn(
                        "ColorSpace",
                        &loc,
                        format!("ColorSpace \"{cs}\" ignored (sRGB assumed)"),
                    );
                }
            }
            "Identity" => self.gs.ctm = Transform::IDENTITY,
            "Translate" => {
                let v = self.expect_nums(3, name)?;
                self.concat(
                    Mat4::from_translation(Vec3::new(v[0], v[1], v[2])),
                    &loc,
                    name,
                )?;
            }
            "Scale" => {
                let v = self.expect_nums(3, name)?;
                self.concat(Mat4::from_scale(Vec3::new(v[0], v[1], v[2])), &loc, name)?;
            }
            "Rotate" => {
                let v = self.expect_nums(4, name)?;
                let axis = Vec3::new(v[1], v[2], v[3]);
                if axis.length_squared() == 0.0 {
                    return Err(err_at(
                        &loc,
                        "Rotate: expected a non-zero axis, found (0, 0, 0)",
                    ));
                }
                self.concat(
                    Mat4::from_axis_angle(axis.normalize(), v[0].to_radians()),
                    &loc,
                    name,
                )?;
            }
            "LookAt" => {
                let v = self.expect_nums(9, name)?;
                let m = look_at(
                    Vec3::new(v[0], v[1], v[2]),
                    Vec3::new(v[3], v[4], v[5]),
                    Vec3::new(v[6], v[7], v[8]),
                )
                .ok_or_else(|| {
                    err_at(
                        &loc,
                        "LookAt: eye equals target, or up is parallel to the view direction",
                    )
                })?;
                self.concat(m, &loc, name)?;
            }
            "Transform" | "ConcatTransform" => {
                let v = self.expect_nums(16, name)?;
                let mut a = [0f32; 16];
                a.copy_from_slice(&v);
                // pbrt lists the matrix column by column (translation in entries 12–14).
                let m = Mat4::from_cols_array(&a);
                if name == "Transform" {
                    self.gs.ctm = Transform::IDENTITY;
                }
                self.concat(m, &loc, name)?;
            }
            "CoordinateSystem" => {
                let (n, _) = self.expect_string("a coordinate system name")?;
                self.named_coords.insert(n, self.gs.ctm);
            }
            "CoordSysTransform" => {
                let (n, nloc) = self.expect_string("a coordinate system name")?;
                self.gs.ctm = *self
                    .named_coords
                    .get(&n)
                    .ok_or_else(|| err_at(&nloc, format!("unknown coordinate system \"{n}\"")))?;
            }
            "TransformTimes" => {
                self.expect_nums(2, name)?;
                self.warn(
                    "motion",
                    &loc,
                    "motion blur (TransformTimes) ignored".into(),
                );
            }
            "ActiveTransform" => {
                let t = self.next_arg()?;
                match &t {
                    Some(Token {
                        tok: Tok::Word(w), ..
                    }) if w == "All" => {}
                    Some(Token {
                        tok: Tok::Word(w), ..
                    }) if w == "StartTime" || w == "EndTime" => self.warn(
                        "motion",
                        &loc,
                        "motion blur (ActiveTransform) ignored".into(),
                    ),
                    other => {
                        return Err(err_at(
                            &loc,
                            format!(
                                "ActiveTransform: expected All, StartTime or EndTime, found {}",
                                describe(other)
                            ),
                        ));
                    }
                }
            }
            "ReverseOrientation" => self.gs.reverse = !self.gs.reverse,
            "Camera" => {
                self.require_world(name, &loc, false)?;
                let (ty, tloc) = self.expect_string("a camera type")?;
                let ps = self.params()?;
                let projection = match ty.as_str() {
                    "perspective" => Projection::Perspective,
                    "orthographic" => Projection::Orthographic,
                    "spherical" => match ps.string("mapping")?.as_deref() {
                        None | Some("equalarea") => {
                            Projection::Spherical(SphericalMapping::EqualArea)
                        }
                        Some("equirectangular") => {
                            Projection::Spherical(SphericalMapping::Equirectangular)
                        }
                        Some(m) => {
                            return Err(err_at(
                                &ps.loc_of("mapping").unwrap_or(loc.clone()),
                                format!(
                                    "spherical camera: unknown mapping \"{m}\" (expected \"equalarea\" or \"equirectangular\")"
                                ),
                            ));
                        }
                    },
                    "realistic" => {
                        self.warn(
                            "camera-type",
                            &loc,
                            "camera \"realistic\" (lens system) approximated by a thin-lens perspective camera of the same 'lensradius'/'focaldistance' (fov 90)".into(),
                        );
                        for p in ["lensfile", "aperturediameter", "focusdistance", "aperture"] {
                            let _ = ps.find(p);
                        }
                        Projection::Perspective
                    }
                    other => {
                        return Err(err_at(
                            &tloc,
                            format!(
                                "unknown camera \"{other}\" (expected perspective, orthographic, spherical or realistic)"
                            ),
                        ));
                    }
                };
                let fov = ps.float("fov", 90.0)?;
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(err_at(
                        &loc,
                        format!("Camera: fov must be in (0, 180), found {fov}"),
                    ));
                }
                let sw = match ps.floats("screenwindow")? {
                    None => None,
                    Some(v) if v.len() == 4 => Some([v[0], v[1], v[2], v[3]]),
                    Some(v) => {
                        return Err(err_at(
                            &ps.loc_of("screenwindow").unwrap_or(loc.clone()),
                            format!(
                                "expected 4 values for float 'screenwindow', found {}",
                                v.len()
                            ),
                        ));
                    }
                };
                let lens = Lens {
                    radius: ps.float("lensradius", 0.0)?,
                    focal_distance: ps.float("focaldistance", 1e6)?,
                };
                if !(lens.radius >= 0.0 && lens.radius.is_finite()) {
                    return Err(err_at(
                        &loc,
                        format!("Camera: lensradius must be ≥ 0, found {}", lens.radius),
                    ));
                }
                if lens.radius > 0.0
                    && !(lens.focal_distance > 0.0 && lens.focal_distance.is_finite())
                {
                    return Err(err_at(
                        &loc,
                        format!(
                            "Camera: focaldistance must be positive, found {}",
                            lens.focal_distance
                        ),
                    ));
                }
                if matches!(projection, Projection::Spherical(_)) && lens.radius > 0.0 {
                    self.warn(
                        "spherical-lens",
                        &loc,
                        "spherical camera: 'lensradius' ignored (pbrt-v4 ignores it too)".into(),
                    );
                }
                // pbrt-v4: 'frameaspectratio' replaces the image's aspect ratio in the default
                // screen window.
                let sw = match (sw, ps.opt_float("frameaspectratio")?) {
                    (None, Some(frame)) if frame > 0.0 && frame.is_finite() => {
                        Some(if frame > 1.0 {
                            [-frame, frame, -1.0, 1.0]
                        } else {
                            [-1.0, 1.0, -1.0 / frame, 1.0 / frame]
                        })
                    }
                    (None, Some(frame)) => {
                        return Err(err_at(
                            &loc,
                            format!("Camera: frameaspectratio must be positive, found {frame}"),
                        ));
                    }
                    (sw, _) => sw,
                };
                let (open, close) = (
                    ps.float("shutteropen", 0.0)?,
                    ps.float("shutterclose", 1.0)?,
                );
                self.camera_exposure = close - open;
                self.report_unused(&ps, "Camera");
                // The CTM here is camera-from-world.
                let world_from_camera = self.gs.ctm.inverse();
                self.named_coords.insert("camera".into(), world_from_camera);
                self.camera = Some(Camera {
                    camera_to_world: world_from_camera,
                    fov_deg: fov,
                    screen_window: sw,
                    projection,
                    lens,
                });
            }
            "Film" => {
                self.require_world(name, &loc, false)?;
                let (ty, _) = self.expect_string("a film type")?;
                let mut ps = self.params()?;
                let ty = self.upgrade(|w| upgrade::film(&ty, &mut ps, &loc, w));
                if ty != "rgb" {
                    self.warn(
                        "film-type",
                        &loc,
                        format!("Film \"{ty}\" treated as \"rgb\""),
                    );
                }
                let x = ps.int("xresolution", 1280)?;
                let y = ps.int("yresolution", 720)?;
                if !(1..=65536).contains(&x) || !(1..=65536).contains(&y) {
                    return Err(err_at(
                        &loc,
                        format!("Film: expected resolution in 1..=65536, found {x}×{y}"),
                    ));
                }
                self.out.film.resolution = UVec2::new(x as u32, y as u32);
                self.out.film.filename = ps.string("filename")?;
                for p in ["cropwindow", "pixelbounds"] {
                    if ps.has(p) {
                        let _ = ps.find(p);
                        self.warn(p, &loc, format!("Film '{p}' ignored"));
                    }
                }
                self.sensor = (
                    super::film::SensorParams {
                        iso: ps.float("iso", 100.0)?,
                        white_balance: ps.float("whitebalance", 0.0)?,
                        sensor: ps.string("sensor")?.unwrap_or_else(|| "cie1931".into()),
                        exposure_time: 1.0,
                    },
                    Some(loc.clone()),
                );
                self.film_exposure = ps.opt_float("exposuretime")?;
                for p in ["savefp16", "diagonal", "maxcomponentvalue"] {
                    let _ = ps.find(p);
                }
                self.report_unused(&ps, "Film");
            }
            "Sampler" => {
                self.require_world(name, &loc, false)?;
                let _ = self.expect_string("a sampler type")?;
                let ps = self.params()?;
                let n = ps.int("pixelsamples", 16)?;
                if n < 1 {
                    return Err(err_at(
                        &loc,
                        format!("Sampler: pixelsamples must be ≥ 1, found {n}"),
                    ));
                }
                self.out.film.spp = Some(n.min(u32::MAX as i64) as u32);
                for p in [
                    "seed",
                    "randomization",
                    "jitter",
                    "xsamples",
                    "ysamples",
                    "dimensions",
                ] {
                    let _ = ps.find(p);
                }
                self.report_unused(&ps, "Sampler");
            }
            "PixelFilter" => {
                self.require_world(name, &loc, false)?;
                let (ty, tloc) = self.expect_string("a filter type")?;
                let mut ps = self.params()?;
                upgrade::filter(&ty, &mut ps);
                let default_r = match ty.as_str() {
                    "box" => 0.5,
                    "gaussian" => 1.5,
                    "mitchell" | "triangle" => 2.0,
                    _ => 4.0,
                };
                let r = Vec2::new(
                    ps.float("xradius", default_r)?,
                    ps.float("yradius", default_r)?,
                );
                if !(r.x > 0.0 && r.y > 0.0 && r.is_finite()) {
                    return Err(err_at(&loc, "PixelFilter: radius must be positive"));
                }
                let positive = |v: f32, what: &str| {
                    if v > 0.0 && v.is_finite() {
                        Ok(v)
                    } else {
                        Err(err_at(
                            &loc,
                            format!(
                                "PixelFilter \"{ty}\": expected a positive '{what}', found {v}"
                            ),
                        ))
                    }
                };
                let filter = match ty.as_str() {
                    "box" => Filter::Box { radius: r },
                    "triangle" => Filter::Triangle { radius: r },
                    "gaussian" => Filter::Gaussian {
                        radius: r,
                        sigma: positive(ps.float("sigma", 0.5)?, "sigma")?,
                    },
                    "mitchell" => Filter::Mitchell {
                        radius: r,
                        b: ps.float("B", 1.0 / 3.0)?,
                        c: ps.float("C", 1.0 / 3.0)?,
                    },
                    "sinc" => Filter::Sinc {
                        radius: r,
                        tau: positive(ps.float("tau", 3.0)?, "tau")?,
                    },
                    other => {
                        return Err(err_at(
                            &tloc,
                            format!(
                                "unknown PixelFilter \"{other}\" (expected box, gaussian, mitchell, sinc or triangle)"
                            ),
                        ));
                    }
                };
                // A filter whose integral is not positive cannot normalise a pixel.
                crate::integrator::film::FilterSampler::new(&filter)
                    .map_err(|e| err_at(&loc, e))?;
                self.out.film.filter = filter;
                self.report_unused(&ps, "PixelFilter");
            }
            "Integrator" => {
                self.require_world(name, &loc, false)?;
                let (ty, _) = self.expect_string("an integrator type")?;
                let ps = self.params()?;
                let d = ps.int("maxdepth", 5)?;
                let max_depth = d.clamp(0, u32::MAX as i64) as u32;
                self.out.max_depth = Some(max_depth);
                // pbrt-v4's light samplers are penumbra's selectors of the same names.
                let light_selection = match ps.string("lightsampler")?.as_deref() {
                    Some("uniform") => Some(crate::light_selection::SelectorKind::Uniform),
                    Some("power") => Some(crate::light_selection::SelectorKind::Power),
                    Some("bvh") => Some(crate::light_selection::SelectorKind::Bvh),
                    Some("exhaustive") => Some(crate::light_selection::SelectorKind::Exhaustive),
                    Some(other) => {
                        self.warn("lightsampler", &loc, format!("lightsampler \"{other}\" unknown: light selection by the --light-selection default"));
                        None
                    }
                    None => None,
                };
                if ps.bool("regularize", false)? {
                    self.warn("regularize", &loc, "\"regularize\" not implemented: near-specular BSDFs are rendered as they are".into());
                }
                for p in ps.params.iter() {
                    let _ = ps.find(&p.name);
                }
                if ty != "path" {
                    self.warn("Integrator", &loc, format!("Integrator \"{ty}\" rendered by penumbra's path tracer (maxdepth {max_depth})"));
                }
                self.out.integrator = Some(crate::scene::IntegratorSpec {
                    kind: crate::integrator::IntegratorKind::Path,
                    max_depth,
                    light_selection,
                });
            }
            "Accelerator" => {
                self.require_world(name, &loc, false)?;
                let _ = self.expect_string("an accelerator type")?;
                let _ = self.params()?;
            }
            "MakeNamedMedium" => {
                let _ = self.expect_string("a medium name")?;
                let _ = self.params()?;
                self.warn("medium", &loc, "participating media ignored".into());
            }
            "MediumInterface" => {
                let _ = self.expect_string("a medium name")?;
                if matches!(
                    self.top().tok.peek()?,
                    Some(Token {
                        tok: Tok::Str(_),
                        ..
                    })
                ) {
                    let _ = self.next_arg()?;
                }
                self.warn("medium", &loc, "participating media ignored".into());
            }
            "WorldBegin" => {
                if let Some(w) = &self.world_seen {
                    return Err(err_at(&loc, format!("WorldBegin again (first at {w})")));
                }
                self.world_seen = Some(loc.clone());
                self.gs.ctm = Transform::IDENTITY;
                self.named_coords
                    .insert("world".into(), Transform::IDENTITY);
            }
            "WorldEnd" => {
                self.require_world(name, &loc, true)?;
            }
            "AttributeBegin" | "TransformBegin" => {
                let kind = if name == "AttributeBegin" {
                    "AttributeBegin"
                } else {
                    "TransformBegin"
                };
                self.gs_stack.push((self.gs.clone(), loc, kind));
            }
            "AttributeEnd" | "TransformEnd" => {
                let want = if name == "AttributeEnd" {
                    "AttributeBegin"
                } else {
                    "TransformBegin"
                };
                match self.gs_stack.pop() {
                    None => {
                        return Err(err_at(&loc, format!("{name} without matching {want}")));
                    }
                    Some((g, bloc, kind)) => {
                        if kind != want {
                            return Err(err_at(
                                &loc,
                                format!("{name} closes {kind} opened at {bloc}"),
                            ));
                        }
                        if kind == "TransformBegin" {
                            self.gs.ctm = g.ctm;
                        } else {
                            self.gs = g;
                        }
                    }
                }
            }
            "Attribute" => {
                let _ = self.expect_string("an attribute target")?;
                let _ = self.params()?;
                self.warn(
                    "Attribute",
                    &loc,
                    "Attribute (default parameters) ignored".into(),
                );
            }
            "ObjectBegin" => {
                self.require_world(name, &loc, true)?;
                let (n, _) = self.expect_string("an object name")?;
                if let Some(o) = &self.cur_object {
                    return Err(err_at(
                        &loc,
                        format!("ObjectBegin \"{n}\" inside ObjectBegin \"{}\"", o.name),
                    ));
                }
                self.gs_stack.push((self.gs.clone(), loc, "AttributeBegin"));
                self.cur_object = Some(ObjectDef {
                    name: n,
                    shapes: Vec::new(),
                });
            }
            "ObjectEnd" => {
                let Some(obj) = self.cur_object.take() else {
                    return Err(err_at(&loc, "ObjectEnd without matching ObjectBegin"));
                };
                match self.gs_stack.pop() {
                    Some((g, _, "AttributeBegin")) => self.gs = g,
                    _ => {
                        return Err(err_at(
                            &loc,
                            "ObjectEnd: unbalanced AttributeBegin/End inside the object",
                        ));
                    }
                }
                self.objects.insert(obj.name, obj.shapes);
            }
            "ObjectInstance" => {
                self.require_world(name, &loc, true)?;
                let (n, nloc) = self.expect_string("an object name")?;
                if self.cur_object.is_some() {
                    return Err(err_at(&loc, "ObjectInstance inside ObjectBegin"));
                }
                let shapes = self
                    .objects
                    .get(&n)
                    .ok_or_else(|| err_at(&nloc, format!("unknown object \"{n}\"")))?;
                let t = self.gs.ctm;
                let moved: Vec<ShapeCall> = shapes
                    .iter()
                    .map(|s| ShapeCall {
                        geom: s.geom.transformed(&t),
                        alpha: s.alpha.clone(),
                        material: s.material,
                        emission: s.emission,
                        reverse_orientation: s.reverse_orientation,
                        loc: loc.clone(),
                    })
                    .collect();
                self.out.shapes.extend(moved);
            }
            "LightSource" => {
                self.require_world(name, &loc, true)?;
                let (ty, _) = self.expect_string("a light type")?;
                let mut ps = self.params()?;
                let ty = self.upgrade(|w| upgrade::light(&ty, &mut ps, &loc, w));
                let dir = self.dir();
                let mut pending = Vec::new();
                let l = parse_light(
                    &ty,
                    &ps,
                    &self.gs.ctm,
                    &dir,
                    &mut self.textures.images,
                    &loc,
                    &mut |k: &str, l: &Loc, m: String| pending.push((k.to_string(), l.clone(), m)),
                )?;
                for (k, l, m) in pending {
                    self.warn(&k, &l, m);
                }
                self.report_unused(&ps, &format!("LightSource \"{ty}\""));
                if let Some(l) = l {
                    self.out.lights.push(l);
                }
            }
            "AreaLightSource" => {
                self.require_world(name, &loc, true)?;
                let (ty, _) = self.expect_string("an area light type")?;
                let mut ps = self.params()?;
                let ty = self.upgrade(|w| upgrade::area_light(&ty, &mut ps, &loc, w));
                let mut pending = Vec::new();
                let a = parse_area_light(&ty, &ps, &loc, &mut |k: &str, l: &Loc, m: String| {
                    pending.push((k.to_string(), l.clone(), m))
                })?;
                for (k, l, m) in pending {
                    self.warn(&k, &l, m);
                }
                self.report_unused(&ps, "AreaLightSource");
                self.gs.area = a;
            }
            "Material" => {
                self.require_world(name, &loc, true)?;
                let (ty, _) = self.expect_string("a material type")?;
                let mut ps = self.params()?;
                let ty = self.upgrade(|w| upgrade::material(&ty, &mut ps, &loc, w));
                let d = self.parse_material_desc(&ty, &ps, &loc)?;
                self.report_unused(&ps, &format!("Material \"{ty}\""));
                self.descs.push(d);
                self.builder_index.push(None);
                self.gs.material = self.descs.len() - 1;
            }
            "MakeNamedMaterial" => {
                self.require_world(name, &loc, true)?;
                let (n, _) = self.expect_string("a material name")?;
                let mut ps = self.params()?;
                let ty = ps.string("type")?.ok_or_else(|| {
                    err_at(
                        &loc,
                        format!("MakeNamedMaterial \"{n}\": expected \"string type\", found none"),
                    )
                })?;
                let ty = self.upgrade(|w| upgrade::material(&ty, &mut ps, &loc, w));
                let d = self.parse_material_desc(&ty, &ps, &loc)?;
                self.report_unused(&ps, &format!("Material \"{ty}\""));
                if self.named_materials.contains_key(&n) {
                    self.warn(
                        &format!("redefine-material-{n}"),
                        &loc,
                        format!("named material \"{n}\" redefined"),
                    );
                }
                self.descs.push(d);
                self.builder_index.push(None);
                self.named_materials.insert(n, self.descs.len() - 1);
            }
            "NamedMaterial" => {
                self.require_world(name, &loc, true)?;
                let (n, nloc) = self.expect_string("a material name")?;
                self.gs.material = *self
                    .named_materials
                    .get(&n)
                    .ok_or_else(|| err_at(&nloc, format!("unknown named material \"{n}\"")))?;
            }
            "Texture" => {
                self.require_world(name, &loc, true)?;
                let (n, _) = self.expect_string("a texture name")?;
                let (ty, _) = self.expect_string("a texture type (\"spectrum\" or \"float\")")?;
                let (class, _) = self.expect_string("a texture class")?;
                let mut ps = self.params()?;
                upgrade::texture(&class, &mut ps);
                let dir = self.dir();
                let mut pending = Vec::new();
                self.textures.define(
                    &n,
                    &ty,
                    &class,
                    &ps,
                    &dir,
                    &loc,
                    &mut |k: &str, l: &Loc, m: String| pending.push((k.to_string(), l.clone(), m)),
                )?;
                for (k, l, m) in pending {
                    self.warn(&k, &l, m);
                }
                self.report_unused(&ps, &format!("Texture \"{class}\""));
            }
            "Shape" => {
                self.require_world(name, &loc, true)?;
                let (ty, _) = self.expect_string("a shape type")?;
                let mut ps = self.params()?;
                upgrade::shape(&ty, &mut ps);
                self.shape(&ty, &ps, &loc)?;
                self.report_unused(&ps, &format!("Shape \"{ty}\""));
            }
            other => {
                return Err(err_at(&loc, format!("unknown directive '{other}'")));
            }
        }
        Ok(())
    }

    fn shape(&mut self, ty: &str, ps: &ParamSet, loc: &Loc) -> anyhow::Result<()> {
        let dir = self.dir();
        let ctx = ShapeCtx {
            ctm: &self.gs.ctm,
            reverse: self.gs.reverse,
            dir: &dir,
            loc,
        };
        let mut pending = Vec::new();
        let mut warn = |k: &str, l: &Loc, m: String| pending.push((k.to_string(), l.clone(), m));
        let geom = make_shape(ty, ps, &ctx, &mut warn)?;
        let alpha = shape_alpha(ps, &self.textures, loc, &mut warn)?;
        for (k, l, m) in pending {
            self.warn(&k, &l, m);
        }
        let Some(geom) = geom else { return Ok(()) };
        let Some(material) = self.material_index(self.gs.material) else {
            self.warn(
                "interface",
                loc,
                "shapes with material \"interface\" are medium boundaries and are not rendered"
                    .into(),
            );
            return Ok(());
        };
        let emission = self.gs.area.as_ref().map(|a| AreaEmission {
            l: a.radiance_for_area(geom.area()),
            two_sided: a.two_sided,
        });
        if emission.is_some() && matches!(geom, super::shapes::ShapeGeom::Cylinder { .. }) {
            self.warn(
                "cylinder-light",
                loc,
                format!(
                    "emissive cylinder tessellated into {} triangle lights per side (penumbra samples no analytic cylinder light)",
                    crate::scene::builder::CYLINDER_LIGHT_SEGMENTS * 2
                ),
            );
        }
        if emission.as_ref().is_some_and(|e| !e.two_sided)
            && self.gs.ctm.swaps_handedness()
            && matches!(
                geom,
                super::shapes::ShapeGeom::Sphere { .. }
                    | super::shapes::ShapeGeom::Disk { .. }
                    | super::shapes::ShapeGeom::PartialSphere { .. }
                    | super::shapes::ShapeGeom::PartialDisk { .. }
                    | super::shapes::ShapeGeom::Cylinder { .. }
            )
        {
            // pbrt-v4's quadric intersections flip the normal for the handedness swap but its
            // shape samples do not, so its own hits and light samples disagree on the side.
            self.warn(
                "mirrored-quadric-light",
                loc,
                format!(
                    "one-sided \"{ty}\" light under a mirroring transform emits to the side of pbrt-v4's intersection normal (ReverseOrientation XOR handedness swap) for hits and light samples alike; pbrt-v4's own light samples emit to the other side"
                ),
            );
        }
        if emission.is_some()
            && matches!(
                geom,
                super::shapes::ShapeGeom::PartialSphere { .. }
                    | super::shapes::ShapeGeom::PartialDisk { .. }
            )
        {
            let (nu, nv) = crate::scene::builder::PARTIAL_LIGHT_GRID;
            self.warn(
                "partial-quadric-light",
                loc,
                format!(
                    "emissive partial \"{ty}\" tessellated into {nu}×{nv}×2 triangle lights (penumbra samples no analytic partial sphere or annulus)"
                ),
            );
        }
        if emission.is_some()
            && alpha.is_some()
            && matches!(
                geom,
                super::shapes::ShapeGeom::Sphere { .. } | super::shapes::ShapeGeom::Disk { .. }
            )
        {
            let (nu, nv) = crate::scene::builder::PARTIAL_LIGHT_GRID;
            self.warn(
                "masked-quadric-light",
                loc,
                format!(
                    "emissive \"{ty}\" with an alpha cut-out tessellated into {nu}×{nv}×2 triangle lights (penumbra masks the light samples of triangle lights only)"
                ),
            );
        }
        if emission.is_some() && matches!(geom, super::shapes::ShapeGeom::Curves { .. }) {
            self.warn(
                "curve-light",
                loc,
                "area lights on curves are not supported: the curve is not emissive".into(),
            );
        }
        if emission.is_some() && self.cur_object.is_some() {
            self.warn(
                "instance-light",
                loc,
                "area lights inside object instances are kept (pbrt-v4 ignores them)".into(),
            );
        }
        let call = ShapeCall {
            geom,
            alpha,
            material,
            emission,
            reverse_orientation: self.gs.reverse,
            loc: loc.clone(),
        };
        match &mut self.cur_object {
            Some(obj) => obj.shapes.push(call),
            None => self.out.shapes.push(call),
        }
        Ok(())
    }
}

/// pbrt's LookAt: the camera-from-world matrix of an eye at `pos` looking at `look`.
pub fn look_at(pos: Vec3, look: Vec3, up: Vec3) -> Option<Mat4> {
    let dir = (look - pos).normalize_or_zero();
    if dir == Vec3::ZERO {
        return None;
    }
    let right = up.normalize_or_zero().cross(dir);
    if right.length_squared() < 1e-12 {
        return None;
    }
    let right = right.normalize();
    let new_up = dir.cross(right);
    let world_from_camera = Mat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        Vec4::new(pos.x, pos.y, pos.z, 1.0),
    );
    let m = world_from_camera.inverse();
    m.is_finite().then_some(m)
}
