//! pbrt-v4 scene loader (our own tokenizer and parser).
//!
//! `tokenizer` → `params` (typed parameter lists) → `parser` (directives, graphics state,
//! includes, instancing) which records shapes, materials and lights as descriptions
//! ([`PbrtScene`]); [`PbrtScene::into_builder`] then converts them (`materials::to_material`,
//! `lights::to_light`) and feeds the [`SceneBuilder`]. Malformed input is an error
//! `file:line:column: expected X, found Y`; unsupported features are one warning per kind
//! (`file:line: warning: …`) and the load continues.

pub mod cie_data;
pub mod film;
pub mod lights;
pub mod materials;
pub mod named_spectra;
pub mod params;
pub mod parser;
pub mod ply;
pub mod shapes;
pub mod spectra;
pub mod textures;
pub mod tokenizer;
pub mod upgrade;

use crate::camera::Camera;
use crate::scene::{AreaEmission, FilmSpec, Scene, SceneBuilder};
use anyhow::Context;
use lights::LightDesc;
use materials::MaterialDesc;
use shapes::ShapeGeom;
use std::path::Path;
use tokenizer::{Loc, err_at};

/// One recorded `SceneBuilder` call for a shape.
#[derive(Clone, Debug)]
pub struct ShapeCall {
    /// World-space geometry.
    pub geom: ShapeGeom,
    /// The shape's alpha cut-out.
    pub alpha: Option<crate::geometry::Alpha>,
    /// Builder material index (into [`PbrtScene::materials`]).
    pub material: u32,
    /// Area emission, if an `AreaLightSource` was active.
    pub emission: Option<AreaEmission>,
    /// ReverseOrientation in effect (spheres and disks; meshes fold it into `flip_normals`).
    pub reverse_orientation: bool,
    /// Where the `Shape` (or `ObjectInstance`) directive is.
    pub loc: Loc,
}

/// A parsed scene: everything the builder will be given, inspectable without building.
#[derive(Clone, Debug)]
pub struct PbrtScene {
    /// Camera (defaults: identity, fov 90).
    pub camera: Camera,
    /// Film settings (default 1280×720, box filter).
    pub film: FilmSpec,
    /// `Integrator "maxdepth"` if given.
    pub max_depth: Option<u32>,
    /// The `Integrator` directive as penumbra renders it, if the file has one.
    pub integrator: Option<crate::scene::IntegratorSpec>,
    /// Materials in builder order (only those used by a shape).
    pub materials: Vec<MaterialDesc>,
    /// Shapes in file order.
    pub shapes: Vec<ShapeCall>,
    /// Non-area lights.
    pub lights: Vec<LightDesc>,
    /// Warnings, `file:line: warning: …`, one per kind.
    pub warnings: Vec<String>,
    /// Images loaded while parsing (textures, environment maps), by resolved path.
    pub images: textures::ImageCache,
}

/// Parse a pbrt-v4 file (and its includes) into descriptions.
pub fn parse_pbrt(path: &Path) -> anyhow::Result<PbrtScene> {
    let src = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let canon = std::fs::canonicalize(path).ok();
    parser::Parser::new(&path.display().to_string(), src, dir, canon)
        .run()
        .map_err(|e| annotate_eof(e, path))
}

/// Parse pbrt-v4 text; `name` labels locations, relative files resolve against `dir`.
pub fn parse_pbrt_str(name: &str, src: &str, dir: &Path) -> anyhow::Result<PbrtScene> {
    parser::Parser::new(name, src.as_bytes().to_vec(), dir.to_path_buf(), None)
        .run()
        .map_err(|e| annotate_eof(e, Path::new(name)))
}

/// End-of-input errors have no token to point at: name the file and its last line.
fn annotate_eof(e: anyhow::Error, path: &Path) -> anyhow::Error {
    let msg = e.to_string();
    if msg.starts_with("end of input") {
        let lines = std::fs::read_to_string(path)
            .map(|s| s.lines().count().max(1))
            .unwrap_or(1);
        anyhow::anyhow!("{}:{}:1: {msg}", path.display(), lines)
    } else {
        e
    }
}

impl PbrtScene {
    /// Convert descriptions and feed a [`SceneBuilder`]. Builder errors get the shape's
    /// location.
    pub fn into_builder(self) -> anyhow::Result<(SceneBuilder, Camera, FilmSpec, Vec<String>)> {
        let mut warnings = self.warnings;
        let mut b = SceneBuilder::new();
        let mut warned_at = std::collections::HashSet::new();
        for m in &self.materials {
            b.add_material(materials::to_material(m, &self.images, &mut warnings)?);
        }
        for s in self.shapes {
            let r = match s.geom {
                // Meshes were repaired when read; an instance's transform can still overflow.
                ShapeGeom::Mesh(mesh) => {
                    b.add_mesh_cut_out(mesh, s.material, s.emission, s.alpha)
                        .map(|rep| {
                            // One warning per ObjectInstance line, however many shapes.
                            if !rep.is_clean() && warned_at.insert(s.loc.file_line()) {
                                warnings.push(format!(
                                    "{}: warning: instanced mesh: {}",
                                    s.loc.file_line(),
                                    rep.describe()
                                ));
                            }
                        })
                }
                ShapeGeom::Sphere { to_world, radius } => b.add_sphere(
                    to_world,
                    radius,
                    s.material,
                    s.emission,
                    s.reverse_orientation,
                    s.alpha,
                ),
                ShapeGeom::Disk {
                    to_world,
                    height,
                    radius,
                } => b.add_disk(
                    to_world,
                    height,
                    radius,
                    s.material,
                    s.emission,
                    s.reverse_orientation,
                    s.alpha,
                ),
                ShapeGeom::PartialSphere {
                    to_world,
                    radius,
                    cut,
                } => b.add_partial_sphere(
                    to_world,
                    radius,
                    cut,
                    s.material,
                    s.emission,
                    s.reverse_orientation,
                    s.alpha,
                ),
                ShapeGeom::PartialDisk {
                    to_world,
                    height,
                    cut,
                } => b.add_partial_disk(
                    to_world,
                    height,
                    cut,
                    s.material,
                    s.emission,
                    s.reverse_orientation,
                    s.alpha,
                ),
                ShapeGeom::Curves { to_world, segments } => {
                    segments.into_iter().try_for_each(|c| {
                        b.add_curve(
                            to_world,
                            c,
                            s.material,
                            s.reverse_orientation,
                            s.alpha.clone(),
                        )
                    })
                }
                ShapeGeom::Bilinear { patches, mesh } => {
                    if s.emission.is_some() {
                        // Lights are triangles: exact for parallelograms.
                        let bent = patches.iter().any(|(c, _, _)| {
                            let size = (c[3] - c[0]).length().max((c[1] - c[2]).length());
                            (c[3] - c[2] - c[1] + c[0]).length() > 1e-5 * size
                        });
                        if bent && warned_at.insert(format!("bilinear@{}", s.loc.file_line())) {
                            warnings.push(format!(
                                "{}: warning: emissive bilinearmesh with non-parallelogram patches approximated by two triangles each",
                                s.loc.file_line()
                            ));
                        }
                        match mesh {
                            Some(m) => b
                                .add_mesh_cut_out(m, s.material, s.emission, s.alpha)
                                .map(|_| ()),
                            None => Ok(()),
                        }
                    } else {
                        patches.into_iter().try_for_each(|(p, uv, flip)| {
                            b.add_bilinear_patch(p, uv, s.material, flip, s.alpha.clone())
                        })
                    }
                }
                ShapeGeom::Cylinder {
                    to_world,
                    radius,
                    zmin,
                    zmax,
                    phimax,
                } => b.add_cylinder(
                    to_world,
                    [radius, zmin, zmax, phimax],
                    s.material,
                    s.emission,
                    s.reverse_orientation,
                    s.alpha,
                ),
            };
            r.map_err(|e| err_at(&s.loc, e))?;
        }
        for l in &self.lights {
            b.add_light(lights::to_light(l, &self.images)?);
        }
        Ok((b, self.camera, self.film, warnings))
    }
}

/// Parse a pbrt-v4 file into a filled builder (tests inspect `builder.materials/lights`).
pub fn parse_pbrt_to_builder(
    path: &Path,
) -> anyhow::Result<(SceneBuilder, Camera, FilmSpec, Vec<String>)> {
    parse_pbrt(path)?.into_builder()
}

/// Load a pbrt-v4 scene: the entry point the CLI calls.
pub fn load_pbrt(path: &Path) -> anyhow::Result<(Scene, Vec<String>)> {
    let parsed = parse_pbrt(path)?;
    let integrator = parsed.integrator.clone();
    let (b, camera, film, warnings) = parsed.into_builder()?;
    let mut scene = b.build(camera, film)?;
    scene.integrator = integrator;
    Ok((scene, warnings))
}
