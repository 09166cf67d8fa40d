//! Wavefront OBJ/MTL loader (via `tobj`).
//!
//! Every object/group becomes one world-space [`TriangleMesh`]; polygons are triangulated by
//! [`super::polygon`] (in linear time for convex ones: a 300,000-vertex face loads, BVH
//! included, in under 2 s). MTL mapping, in [`obj_material`]: `Kd` (and `map_Kd`) → diffuse
//! reflectance, non-zero `Ks` with `Ns` → modified Phong, `Ke` → one-sided area emission
//! (every triangle its own light), `d` and `map_d` → an alpha cut-out ([`obj_alpha`]). With [`LoadOptions::obj_ka_emission`], `Ka` is emitted
//! radiance as well (the Embree/tinyobjloader Cornell-box convention). OBJ has no camera: it
//! comes from the view flags or an automatic framing (see [`super::view`]). Every error and
//! every warning names `file:line` ([`super::obj_text`] finds the lines `tobj` does not give).

use super::load::{LoadOptions, Loaded, warn_if_unlit};
use super::obj_text::{self, MtlText};
use super::polygon::{Split, triangulate};
use super::view::{auto_frame, default_film, place_auto_camera};
use super::{AreaEmission, SceneBuilder, TriangleMesh, guard};
use crate::Rgb;
use crate::geometry::Alpha;
use crate::material::texture::ImageRgb;
use crate::material::{FloatTexture, Material, Texture};
use anyhow::{Context, anyhow, bail};
use glam::{Vec2, Vec3};
use std::cell::RefCell;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Reflectance of faces that name no material (or an unknown one).
const DEFAULT_KD: f32 = 0.5;

/// How `tobj` reads: one index per vertex, polygons kept (we triangulate), no points or lines.
const TOBJ: tobj::LoadOptions = tobj::LoadOptions {
    single_index: true,
    triangulate: false,
    ignore_points: true,
    ignore_lines: true,
};

/// An MTL library `tobj` asked for: its path, its text if it could be read, its error.
type Library = (PathBuf, Option<MtlText>, Option<tobj::LoadError>);

/// What `tobj` made of a text: its result, or a crash.
type Parsed = Result<tobj::LoadResult, guard::Crashed>;

fn parse(bytes: &[u8], load_mtl: impl Fn(&Path) -> tobj::MTLLoadResult) -> Parsed {
    guard::catch(|| tobj::load_obj_buf(&mut Cursor::new(bytes), &TOBJ, load_mtl))
}

/// The same failure: the same `tobj` error, or a crash again.
fn same_failure(a: &Parsed, b: &Parsed) -> bool {
    match (a, b) {
        (Err(_), Err(_)) => true,
        (Ok(Err(x)), Ok(Err(y))) => x == y,
        _ => false,
    }
}

/// The error for a file `tobj` refused (or crashed on), at the line where it stopped.
fn located_error(
    file: &str,
    bytes: &[u8],
    ranges: &[(usize, usize)],
    full: &Parsed,
) -> anyhow::Error {
    let no_mtl = |_: &Path| Ok((Vec::new(), Default::default()));
    let line = obj_text::first_failing_line(bytes, ranges, |prefix| {
        same_failure(&parse(prefix, no_mtl), full)
    })
    // A failure that needs the whole file (none seen yet) is reported at its last line.
    .unwrap_or(ranges.len().max(1));
    let text = obj_text::excerpt(bytes, ranges, line);
    let what = match full {
        Err(_) => "the OBJ parser crashed on this line".to_string(),
        Ok(Err(e)) => {
            let count = |key| obj_text::count_before(bytes, ranges, line, key);
            match e {
                tobj::LoadError::FaceVertexOutOfBounds => format!(
                    "face vertex index out of bounds ({} vertices 'v' defined before this line)",
                    count("v")
                ),
                tobj::LoadError::FaceTexCoordOutOfBounds => format!(
                    "face texture coordinate index out of bounds ({} 'vt' defined before this line)",
                    count("vt")
                ),
                tobj::LoadError::FaceNormalOutOfBounds => format!(
                    "face normal index out of bounds ({} 'vn' defined before this line)",
                    count("vn")
                ),
                tobj::LoadError::ReadError => "not valid UTF-8 text".to_string(),
                other => other.to_string(),
            }
        }
        Ok(Ok(_)) => "unexpected parse failure".to_string(),
    };
    if text.is_empty() {
        anyhow!("{file}:{line}: {what}")
    } else {
        anyhow!("{file}:{line}: {what}: `{text}`")
    }
}

/// Load an OBJ file (and the MTL libraries it names) into a scene.
pub fn load_obj(path: &Path, opts: &LoadOptions) -> anyhow::Result<Loaded> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).with_context(|| format!("{file}: cannot read"))?;
    // Line offsets only when a message needs a line (16 bytes a line is a lot for big files).
    let ranges_cell = std::cell::OnceCell::new();
    let ranges = || ranges_cell.get_or_init(|| obj_text::lines(&bytes));
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();

    // MTL libraries in the order `tobj` asks for them, with the text it was given.
    let libraries: RefCell<Vec<Library>> = RefCell::new(Vec::new());
    let load_mtl = |name: &Path| -> tobj::MTLLoadResult {
        let p = dir.join(name);
        let Ok(raw) = std::fs::read(&p) else {
            libraries
                .borrow_mut()
                .push((p, None, Some(tobj::LoadError::OpenFileFailed)));
            return Err(tobj::LoadError::OpenFileFailed);
        };
        let text = obj_text::read_mtl(&p.display().to_string(), &raw);
        let r = guard::catch(|| tobj::load_mtl_buf(&mut Cursor::new(&text.bytes)))
            .unwrap_or(Err(tobj::LoadError::GenericFailure));
        libraries
            .borrow_mut()
            .push((p, Some(text), r.as_ref().err().copied()));
        r
    };
    let parsed = parse(&bytes, load_mtl);
    let (models, materials) = match parsed {
        Ok(Ok(r)) => r,
        ref failed => return Err(located_error(&file, &bytes, ranges(), failed)),
    };
    let libraries = libraries.into_inner();
    let mut warnings = Vec::new();
    let mtllib_lines = || -> Vec<usize> {
        let ranges = ranges();
        (1..=ranges.len())
            .filter(|&n| {
                let (a, b) = ranges[n - 1];
                std::str::from_utf8(&bytes[a..b])
                    .ok()
                    .and_then(|l| l.split_whitespace().next())
                    == Some("mtllib")
            })
            .collect()
    };
    let mut key_lines: HashMap<(String, String), String> = HashMap::new();
    for (k, (p, text, err)) in libraries.iter().enumerate() {
        let at = || {
            mtllib_lines()
                .get(k)
                .map_or(file.clone(), |n| format!("{file}:{n}"))
        };
        if let Some(t) = text {
            warnings.extend(t.warnings.iter().cloned());
            for ((m, key), n) in &t.lines {
                key_lines
                    .entry((m.clone(), key.clone()))
                    .or_insert_with(|| format!("{}:{n}", t.file));
            }
        }
        match (text, err) {
            (_, None) => {}
            (None, Some(_)) => warnings.push(format!(
                "{}: material library {} not found; its materials are grey diffuse",
                at(),
                p.display()
            )),
            (Some(t), Some(e)) => {
                let ranges = obj_text::lines(&t.bytes);
                let line = obj_text::first_failing_line(&t.bytes, &ranges, obj_text::mtl_fails)
                    .unwrap_or(ranges.len().max(1));
                warnings.push(format!(
                    "{}:{line}: material library not loaded ({e}: `{}`); its materials are grey diffuse",
                    t.file,
                    obj_text::excerpt(&t.bytes, &ranges, line)
                ));
            }
        }
    }
    let materials = materials.unwrap_or_default();
    let at_key = |m: &str, key: &str| {
        key_lines
            .get(&(m.to_string(), key.to_string()))
            .cloned()
            .unwrap_or_else(|| file.clone())
    };

    let mut textures = TextureCache::new(dir.clone());
    let mut b = SceneBuilder::new();
    // One scene material and emission per MTL entry, plus the default at the end.
    let mut mat_ids = Vec::with_capacity(materials.len() + 1);
    for m in &materials {
        let (mat, emission) = obj_material(m, opts, &mut textures, &at_key, &mut warnings);
        let alpha = obj_alpha(m, &mut textures, &at_key, &mut warnings);
        mat_ids.push((b.add_material(mat), emission, alpha));
    }
    let default_id = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(DEFAULT_KD)),
    });

    // Where each mesh starts, found only if something needs saying about one.
    let names: Vec<String> = materials.iter().map(|m| m.name.clone()).collect();
    let mut first_lines: Option<Vec<Option<usize>>> = None;
    let mut at_mesh = |i: usize| -> String {
        let lines = first_lines.get_or_insert_with(|| {
            let l = obj_text::mesh_first_lines(&bytes, ranges(), &names);
            if l.len() == models.len() {
                l
            } else {
                Vec::new()
            }
        });
        match lines.get(i).copied().flatten() {
            Some(n) => format!("{file}:{n}"),
            None => file.clone(),
        }
    };

    let mut any_face = None;
    for (i, model) in models.iter().enumerate() {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        any_face.get_or_insert(i);
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|c| Vec3::from_slice(c))
            .collect();
        let nv = positions.len();
        let (indices, fans) = triangles_of(m, &positions);
        if fans > 0 {
            warnings.push(format!(
                "{}: object '{}': {fans} polygons are not simple (self-intersecting or without area); fan-triangulated",
                at_mesh(i),
                model.name
            ));
        }
        // With single_index, normals/uvs are per vertex when present (else empty).
        let normals = (m.normals.len() == 3 * nv && nv > 0)
            .then(|| m.normals.chunks_exact(3).map(Vec3::from_slice).collect());
        let uvs = (m.texcoords.len() == 2 * nv && nv > 0)
            .then(|| m.texcoords.chunks_exact(2).map(Vec2::from_slice).collect());
        let (material, emission, alpha) = match m.material_id {
            Some(k) if k < mat_ids.len() => mat_ids[k].clone(),
            Some(k) => {
                warnings.push(format!(
                    "{}: object '{}' uses material #{k}, which was not loaded; using grey diffuse",
                    at_mesh(i),
                    model.name
                ));
                (default_id, None, None)
            }
            None => (default_id, None, None),
        };
        let mesh = TriangleMesh {
            positions,
            normals,
            uvs,
            indices,
            flip_normals: false,
        };
        let repair = b
            .add_mesh_cut_out(mesh, material, emission, alpha)
            .map_err(|e| anyhow!("{}: object '{}': {e}", at_mesh(i), model.name))?;
        if !repair.is_clean() {
            warnings.push(format!(
                "{}: object '{}': {}",
                at_mesh(i),
                model.name,
                repair.describe()
            ));
        }
    }
    match any_face {
        None => bail!(
            "{file}:{}: no faces ('f' lines with three or more vertices) in the file",
            ranges().len().max(1)
        ),
        Some(i) if b.primitive_count() == 0 => bail!(
            "{}: no triangle is left: every one has zero area or a non-finite vertex",
            at_mesh(i)
        ),
        Some(_) => {}
    }
    // Placeholder until the scene exists to be probed.
    let camera = auto_frame(Vec3::ZERO, Vec3::ONE, 40.0)?;
    let mut scene = b
        .build(camera, default_film())
        .with_context(|| format!("{file}: building the scene"))?;
    let note =
        place_auto_camera(&mut scene, &opts.view).with_context(|| format!("{file}: camera"))?;
    let hint = if !opts.obj_ka_emission
        && materials
            .iter()
            .any(|m| m.ambient.is_some_and(|a| a.iter().any(|&c| c > 0.0)))
    {
        " (some materials have an ambient colour Ka: --obj-ka-emission makes it emitted light)"
    } else {
        ""
    };
    warn_if_unlit(&scene, &file, hint, &mut warnings);
    Ok(Loaded {
        scene,
        warnings,
        notes: vec![format!("{file}: {note}")],
    })
}

/// The triangles of a `tobj` mesh and how many of its polygons were not simple.
fn triangles_of(m: &tobj::Mesh, positions: &[Vec3]) -> (Vec<u32>, usize) {
    if m.face_arities.is_empty() {
        return (m.indices.clone(), 0);
    }
    let mut out = Vec::with_capacity(m.indices.len() * 3 / 2);
    let (mut at, mut fans) = (0usize, 0);
    for &n in &m.face_arities {
        let n = n as usize;
        let Some(poly) = m.indices.get(at..at + n) else {
            break;
        };
        at += n;
        if triangulate(poly, positions, &mut out) == Split::Fan {
            fans += 1;
        }
    }
    (out, fans)
}

/// Map one MTL entry to a material and its emission (the one place the mapping lives).
///
/// `Kd`/`map_Kd` → diffuse; non-zero `Ks` → modified Phong with exponent `Ns`, scaled down so
/// kd + ks ≤ 1 per channel (energy conservation) with a warning; `Ke` (+ `Ka` with
/// `--obj-ka-emission`) → one-sided emitted radiance on the winding-normal side. A colour that
/// is not finite (NaN, or beyond f32 like 1e39) is not used and a negative component is taken
/// as 0, each with a warning at `at(material, statement)` (`file:line`).
pub fn obj_material(
    m: &tobj::Material,
    opts: &LoadOptions,
    textures: &mut TextureCache,
    at: &dyn Fn(&str, &str) -> String,
    warnings: &mut Vec<String>,
) -> (Material, Option<AreaEmission>) {
    let mut colour = |c: Option<[f32; 3]>, key: &str, fallback: &str| -> Option<Rgb> {
        let c = Rgb::from_array(c?);
        let name = &m.name;
        if !c.is_finite() {
            warnings.push(format!(
                "{}: material '{name}': {key} {} {} {} is not finite; {fallback}",
                at(name, key),
                c.x,
                c.y,
                c.z
            ));
            return None;
        }
        if c.min_element() < 0.0 {
            warnings.push(format!(
                "{}: material '{name}': {key} {} {} {} has a negative component, taken as 0",
                at(name, key),
                c.x,
                c.y,
                c.z
            ));
        }
        Some(c.max(Rgb::ZERO))
    };
    let mut kd = colour(m.diffuse, "Kd", "using the default 0.5").unwrap_or(Rgb::splat(DEFAULT_KD));
    let mut ks = colour(m.specular, "Ks", "ignored").unwrap_or(Rgb::ZERO);
    let ke = colour(m.emissive, "Ke", "the material does not emit").unwrap_or(Rgb::ZERO);
    let ka = if opts.obj_ka_emission {
        colour(m.ambient, "Ka", "the material does not emit").unwrap_or(Rgb::ZERO)
    } else {
        Rgb::ZERO
    };
    let sum = (kd + ks).max_element();
    if ks.max_element() > 0.0 && sum > 1.0 {
        warnings.push(format!(
            "{}: material '{}': Kd + Ks = {sum:.3} > 1, both scaled by {:.3} to conserve energy",
            at(&m.name, "Ks"),
            m.name,
            1.0 / sum
        ));
        kd /= sum;
        ks /= sum;
    }
    let kd_tex = match &m.diffuse_texture {
        Some(name) => match textures.get(name) {
            Ok(img) => Texture::Image {
                image: img,
                scale: Rgb::ONE,
            },
            Err(e) => {
                warnings.push(format!(
                    "{}: material '{}': map_Kd {name}: {e:#}; using constant Kd",
                    at(&m.name, "Kd"),
                    m.name
                ));
                Texture::Constant(kd)
            }
        },
        None => Texture::Constant(kd),
    };
    let ns = m
        .shininess
        .filter(|n| n.is_finite() && *n >= 0.0)
        .unwrap_or(1.0);
    let material = if ks.max_element() > 0.0 {
        Material::Phong {
            kd: kd_tex,
            ks,
            n: ns,
        }
    } else {
        Material::Diffuse {
            reflectance: kd_tex,
        }
    };
    let le = ke + ka;
    let emission = (le.max_element() > 0.0).then_some(AreaEmission {
        l: le,
        two_sided: false,
    });
    (material, emission)
}

/// The cut-out of MTL material `m`: coverage = `d` (dissolve, 1 if absent) × the `map_d`
/// mask, under the stochastic alpha test (a `d` of 0.3 stops 0.3 of the light). The mask is
/// the image's alpha channel where it has one (a colour texture with transparency), else its
/// first channel as stored (a grey mask). `None`: opaque. (`Tr`, which exporters disagree on,
/// is not read.)
pub fn obj_alpha(
    m: &tobj::Material,
    textures: &mut TextureCache,
    at: &dyn Fn(&str, &str) -> String,
    warnings: &mut Vec<String>,
) -> Option<Alpha> {
    let d = match m.dissolve {
        Some(d) if d.is_finite() => d.clamp(0.0, 1.0),
        Some(d) => {
            warnings.push(format!(
                "{}: material '{}': d {d} is not finite; opaque",
                at(&m.name, "d"),
                m.name
            ));
            1.0
        }
        None => 1.0,
    };
    if d == 0.0 {
        warnings.push(format!(
            "{}: material '{}': d 0 makes it fully transparent (invisible)",
            at(&m.name, "d"),
            m.name
        ));
    }
    let mask = m
        .dissolve_texture
        .as_ref()
        .and_then(|name| match textures.get_mask(name) {
            Ok(img) => Some(img),
            Err(e) => {
                warnings.push(format!(
                    "{}: material '{}': map_d {name}: {e:#}; no mask",
                    at(&m.name, "map_d"),
                    m.name
                ));
                None
            }
        });
    match mask {
        Some(image) => Some(Alpha::Texture(Arc::new(FloatTexture::Image {
            image,
            scale: d,
            invert: false,
        }))),
        None => (d < 1.0).then_some(Alpha::Constant(d)),
    }
}

/// Image textures by file name, decoded once and shared between materials.
pub struct TextureCache {
    dir: PathBuf,
    images: HashMap<String, Result<Arc<ImageRgb>, String>>,
    masks: HashMap<String, Result<Arc<ImageRgb>, String>>,
}

impl TextureCache {
    /// A cache resolving relative names against `dir` (the OBJ's directory).
    pub fn new(dir: PathBuf) -> Self {
        Self {
            dir,
            images: HashMap::new(),
            masks: HashMap::new(),
        }
    }

    /// The path of the map named `name` (MTL options such as `-bm 1` before the name are
    /// skipped: the file name is the last token).
    fn path(&self, name: &str) -> PathBuf {
        let fname = name
            .split_whitespace()
            .last()
            .unwrap_or(name)
            .replace('\\', "/");
        self.dir.join(fname)
    }

    /// The `map_d` mask called `name`: its alpha channel if it has one, else its first channel,
    /// as stored (no sRGB decoding), in every channel.
    pub fn get_mask(&mut self, name: &str) -> anyhow::Result<Arc<ImageRgb>> {
        let p = self.path(name);
        self.masks
            .entry(name.to_string())
            .or_insert_with(|| {
                let img = image::open(&p).map_err(|e| format!("{}: {e}", p.display()))?;
                let has_alpha = img.color().has_alpha();
                let rgba = img.to_rgba32f();
                let pixels = rgba
                    .pixels()
                    .map(|px| Rgb::splat(if has_alpha { px[3] } else { px[0] }))
                    .collect();
                Ok(Arc::new(ImageRgb {
                    width: rgba.width(),
                    height: rgba.height(),
                    pixels,
                }))
            })
            .clone()
            .map_err(|e| anyhow!(e))
    }

    /// The image called `name` (MTL options such as `-bm 1` before the name are skipped).
    pub fn get(&mut self, name: &str) -> anyhow::Result<Arc<ImageRgb>> {
        let p = self.path(name);
        self.images
            .entry(name.to_string())
            .or_insert_with(|| {
                crate::image::io::read_image(&p)
                    .map(|img| {
                        Arc::new(ImageRgb {
                            width: img.width,
                            height: img.height,
                            pixels: img.pixels,
                        })
                    })
                    .map_err(|e| format!("{e:#}"))
            })
            .clone()
            .map_err(|e| anyhow!(e))
    }
}
