//! Wavefront OBJ/MTL loader (via `tobj`).
//!
//! Every object/group becomes one world-space [`TriangleMesh`] (polygons are fan-triangulated
//! by `tobj`). MTL mapping, in [`obj_material`]: `Kd` (and `map_Kd`) → diffuse reflectance,
//! non-zero `Ks` with `Ns` → modified Phong, `Ke` → one-sided area emission (every triangle its
//! own light). With [`LoadOptions::obj_ka_emission`], `Ka` is emitted radiance as well (the
//! Embree/tinyobjloader Cornell-box convention). OBJ has no camera: it comes from the view
//! flags or an automatic framing (see [`super::view`]).

use super::load::{LoadOptions, Loaded};
use super::view::{bounds_of, default_film, flag_or_auto_camera};
use super::{AreaEmission, SceneBuilder, TriangleMesh};
use crate::Rgb;
use crate::material::texture::ImageRgb;
use crate::material::{Material, Texture};
use anyhow::{Context, anyhow, bail};
use glam::{Vec2, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Reflectance of faces that name no material (or an unknown one).
const DEFAULT_KD: f32 = 0.5;

/// Load an OBJ file (and the MTL libraries it names) into a scene.
pub fn load_obj(path: &Path, opts: &LoadOptions) -> anyhow::Result<Loaded> {
    let file = path.display().to_string();
    // tobj is a third-party parser fed with user files: a panic inside it must become an
    // error naming the file, not take the renderer down.
    let parsed = std::panic::catch_unwind(|| {
        tobj::load_obj(
            path,
            &tobj::LoadOptions {
                triangulate: true,
                single_index: true,
                ..Default::default()
            },
        )
    })
    .map_err(|_| anyhow!("{file}: the OBJ parser crashed on this file"))?;
    let (models, materials) = parsed.map_err(|e| anyhow!("{file}: cannot load OBJ: {e}"))?;
    let mut warnings = Vec::new();
    let materials = match materials {
        Ok(m) => m,
        Err(e) => {
            warnings.push(format!(
                "{file}: material library not loaded ({e}); every face uses a grey diffuse"
            ));
            Vec::new()
        }
    };
    if models.is_empty() {
        bail!("{file}: no faces found (is the file empty or truncated?)");
    }

    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut textures = TextureCache::new(dir);
    let mut b = SceneBuilder::new();
    // One scene material and emission per MTL entry, plus the default at the end.
    let mut mat_ids = Vec::with_capacity(materials.len() + 1);
    for m in &materials {
        let (mat, emission) = obj_material(m, opts, &mut textures, &file, &mut warnings);
        mat_ids.push((b.add_material(mat), emission));
    }
    let default_id = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(DEFAULT_KD)),
    });

    let mut lo_hi: Option<(Vec3, Vec3)> = None;
    for model in &models {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|c| Vec3::from_slice(c))
            .collect();
        let nv = positions.len();
        // With single_index, normals/uvs are per vertex when present (else empty).
        let normals = (m.normals.len() == 3 * nv && nv > 0)
            .then(|| m.normals.chunks_exact(3).map(Vec3::from_slice).collect());
        let uvs = (m.texcoords.len() == 2 * nv && nv > 0)
            .then(|| m.texcoords.chunks_exact(2).map(Vec2::from_slice).collect());
        let (material, emission) = match m.material_id {
            Some(i) if i < mat_ids.len() => mat_ids[i],
            Some(i) => {
                warnings.push(format!(
                    "{file}: object '{}' uses material #{i}, which was not loaded; using grey diffuse",
                    model.name
                ));
                (default_id, None)
            }
            None => (default_id, None),
        };
        if let Some((lo, hi)) = bounds_of(&positions) {
            lo_hi = Some(match lo_hi {
                None => (lo, hi),
                Some((a, b)) => (a.min(lo), b.max(hi)),
            });
        }
        let mesh = TriangleMesh {
            positions,
            normals,
            uvs,
            indices: m.indices.clone(),
            flip_normals: false,
        };
        b.add_mesh(mesh, material, emission)
            .with_context(|| format!("{file}: object '{}'", model.name))?;
    }
    let Some((lo, hi)) = lo_hi else {
        bail!("{file}: no faces found (is the file empty or truncated?)");
    };
    if b.degenerate_triangles > 0 {
        warnings.push(format!(
            "{file}: skipped {} zero-area triangles",
            b.degenerate_triangles
        ));
    }
    if b.primitive_count() == 0 {
        bail!("{file}: every triangle has zero area");
    }
    let camera =
        flag_or_auto_camera(&opts.view, lo, hi).with_context(|| format!("{file}: camera"))?;
    let scene = b
        .build(camera, default_film())
        .with_context(|| format!("{file}: building the scene"))?;
    Ok(Loaded { scene, warnings })
}

/// Map one MTL entry to a material and its emission (the one place the mapping lives).
///
/// `Kd`/`map_Kd` → diffuse; non-zero `Ks` → modified Phong with exponent `Ns`, scaled down so
/// kd + ks ≤ 1 per channel (energy conservation) with a warning; `Ke` (+ `Ka` with
/// `--obj-ka-emission`) → one-sided emitted radiance on the winding-normal side.
pub fn obj_material(
    m: &tobj::Material,
    opts: &LoadOptions,
    textures: &mut TextureCache,
    file: &str,
    warnings: &mut Vec<String>,
) -> (Material, Option<AreaEmission>) {
    let rgb = |c: Option<[f32; 3]>| c.map(Rgb::from_array).filter(|c| c.is_finite());
    let mut kd = rgb(m.diffuse)
        .unwrap_or(Rgb::splat(DEFAULT_KD))
        .max(Rgb::ZERO);
    let mut ks = rgb(m.specular).unwrap_or(Rgb::ZERO).max(Rgb::ZERO);
    let sum = (kd + ks).max_element();
    if ks.max_element() > 0.0 && sum > 1.0 {
        warnings.push(format!(
            "{file}: material '{}': Kd + Ks = {sum:.3} > 1, both scaled by {:.3} to conserve energy",
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
                    "{file}: material '{}': map_Kd {name}: {e:#}; using constant Kd",
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
    let mut le = rgb(m.emissive).unwrap_or(Rgb::ZERO);
    if opts.obj_ka_emission {
        le += rgb(m.ambient).unwrap_or(Rgb::ZERO);
    }
    let le = le.max(Rgb::ZERO);
    let emission = (le.max_element() > 0.0).then_some(AreaEmission {
        l: le,
        two_sided: false,
    });
    (material, emission)
}

/// Image textures by file name, decoded once and shared between materials.
pub struct TextureCache {
    dir: PathBuf,
    images: HashMap<String, Result<Arc<ImageRgb>, String>>,
}

impl TextureCache {
    /// A cache resolving relative names against `dir` (the OBJ's directory).
    pub fn new(dir: PathBuf) -> Self {
        Self {
            dir,
            images: HashMap::new(),
        }
    }

    /// The image called `name` (MTL options such as `-bm 1` before the name are skipped).
    pub fn get(&mut self, name: &str) -> anyhow::Result<Arc<ImageRgb>> {
        let dir = &self.dir;
        self.images
            .entry(name.to_string())
            .or_insert_with(|| {
                // The file name is the last token: MTL map options precede it.
                let fname = name
                    .split_whitespace()
                    .last()
                    .unwrap_or(name)
                    .replace('\\', "/");
                let p = dir.join(fname);
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
