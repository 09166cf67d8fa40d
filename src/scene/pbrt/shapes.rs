//! `Shape` directive: `trianglemesh`, `plymesh`, `bilinearmesh` (as triangles), `sphere`, `disk`,
//! `cylinder`.
//! Meshes are validated and taken to world space here: positions by the CTM, normals by its
//! inverse transpose (renormalised); `flip_normals` = ReverseOrientation xor handedness swap.

use super::params::ParamSet;
use super::ply::read_ply;
use super::textures::{TextureTable, Warn, resolve};
use super::tokenizer::{Loc, err_at};
use crate::geometry::curve::{CurveSegment, CurveType, bspline_to_bezier};
use crate::geometry::{Alpha, Transform};
use crate::scene::TriangleMesh;
use crate::scene::mesh_repair::repair_mesh;
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::PI;
use std::path::Path;

/// The geometry of one shape, in world space.
#[derive(Clone, Debug)]
pub enum ShapeGeom {
    /// A triangle mesh (world space, validated).
    Mesh(TriangleMesh),
    /// A full sphere.
    Sphere {
        /// Object-to-world.
        to_world: Transform,
        /// Radius in object space.
        radius: f32,
    },
    /// A full disk at z = height, normal +z.
    Disk {
        /// Object-to-world.
        to_world: Transform,
        /// Height in object space.
        height: f32,
        /// Radius in object space.
        radius: f32,
    },
    /// pbrt-v4's `bilinearmesh`: true bilinear patches (world space), and the same patches as
    /// two triangles each for where penumbra needs triangles (emitters).
    Bilinear {
        /// Per patch: corners p00, p10, p01, p11, their uvs, and whether the normal
        /// ∂p/∂u × ∂p/∂v is flipped.
        patches: Vec<([Vec3; 4], [Vec2; 4], bool)>,
        /// The triangle stand-in (`None` if every triangle was degenerate).
        mesh: Option<TriangleMesh>,
    },
    /// pbrt-v4's `curve`: cubic Bézier segments in the object space of `to_world`.
    Curves {
        /// Object-to-world.
        to_world: Transform,
        /// The segments.
        segments: Vec<CurveSegment>,
    },
    /// pbrt-v4's partial sphere (object space: z in [zmin, zmax], φ in [0, phimax]).
    PartialSphere {
        /// Object-to-world.
        to_world: Transform,
        /// Radius in object space.
        radius: f32,
        /// zmin, zmax (clamped to ±radius) and phimax in radians.
        cut: [f32; 3],
    },
    /// pbrt-v4's annulus / partial disk at z = height.
    PartialDisk {
        /// Object-to-world.
        to_world: Transform,
        /// Height in object space.
        height: f32,
        /// Outer radius, inner radius and phimax in radians.
        cut: [f32; 3],
    },
    /// pbrt-v4's cylinder (object space: axis z, z in [zmin, zmax], φ in [0, phimax]).
    Cylinder {
        /// Object-to-world.
        to_world: Transform,
        /// Radius in object space.
        radius: f32,
        /// Lower end.
        zmin: f32,
        /// Upper end.
        zmax: f32,
        /// Sweep in radians.
        phimax: f32,
    },
}

fn area_scale(t: &Transform) -> f32 {
    // Uniform-scale estimate: |det|^(2/3) (exact for similarity transforms).
    t.m.determinant().abs().powf(2.0 / 3.0)
}

impl ShapeGeom {
    /// World-space surface area (for area-light `power`).
    pub fn area(&self) -> f32 {
        match self {
            ShapeGeom::Mesh(m) => m
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let p = |i: u32| m.positions[i as usize];
                    0.5 * (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).length()
                })
                .sum(),
            ShapeGeom::Sphere { to_world, radius } => {
                4.0 * PI * radius * radius * area_scale(to_world)
            }
            ShapeGeom::Disk {
                to_world, radius, ..
            } => PI * radius * radius * area_scale(to_world),
            ShapeGeom::Cylinder {
                to_world,
                radius,
                zmin,
                zmax,
                phimax,
            } => phimax * radius * (zmax - zmin).abs() * area_scale(to_world),
            // pbrt-v4's Sphere::Area and Disk::Area.
            ShapeGeom::PartialSphere {
                to_world,
                radius,
                cut: [zmin, zmax, phimax],
            } => phimax * radius * (zmax - zmin).abs() * area_scale(to_world),
            ShapeGeom::PartialDisk {
                to_world,
                cut: [radius, inner, phimax],
                ..
            } => phimax * 0.5 * (radius * radius - inner * inner) * area_scale(to_world),
            ShapeGeom::Bilinear { mesh, .. } => mesh
                .as_ref()
                .map_or(0.0, |m| ShapeGeom::Mesh(m.clone()).area()),
            // Curves carry no emission (warned); a rough estimate: polygon length × width.
            ShapeGeom::Curves { to_world, segments } => {
                segments
                    .iter()
                    .map(|c| {
                        let l: f32 = (0..3).map(|i| (c.cp[i + 1] - c.cp[i]).length()).sum();
                        l * 0.5 * (c.width[0] + c.width[1])
                    })
                    .sum::<f32>()
                    * area_scale(to_world)
            }
        }
    }

    /// The same geometry moved by `t` (object instancing).
    pub fn transformed(&self, t: &Transform) -> ShapeGeom {
        match self {
            ShapeGeom::Mesh(m) => {
                let nt = t.m_inv.transpose();
                ShapeGeom::Mesh(TriangleMesh {
                    positions: m.positions.iter().map(|&p| t.point(p)).collect(),
                    normals: m.normals.as_ref().map(|ns| {
                        ns.iter()
                            .map(|&n| nt.transform_vector3(n).normalize_or_zero())
                            .collect()
                    }),
                    uvs: m.uvs.clone(),
                    indices: m.indices.clone(),
                    flip_normals: m.flip_normals ^ t.swaps_handedness(),
                })
            }
            ShapeGeom::Sphere { to_world, radius } => ShapeGeom::Sphere {
                to_world: t.then_apply_to(to_world),
                radius: *radius,
            },
            ShapeGeom::Disk {
                to_world,
                height,
                radius,
            } => ShapeGeom::Disk {
                to_world: t.then_apply_to(to_world),
                height: *height,
                radius: *radius,
            },
            ShapeGeom::Curves { to_world, segments } => ShapeGeom::Curves {
                to_world: t.then_apply_to(to_world),
                segments: segments.clone(),
            },
            ShapeGeom::Bilinear { patches, mesh } => ShapeGeom::Bilinear {
                patches: patches
                    .iter()
                    .map(|(p, uv, f)| (p.map(|q| t.point(q)), *uv, *f ^ t.swaps_handedness()))
                    .collect(),
                mesh: mesh
                    .as_ref()
                    .map(|m| match ShapeGeom::Mesh(m.clone()).transformed(t) {
                        ShapeGeom::Mesh(m) => m,
                        _ => unreachable!(),
                    }),
            },
            ShapeGeom::PartialSphere {
                to_world,
                radius,
                cut,
            } => ShapeGeom::PartialSphere {
                to_world: t.then_apply_to(to_world),
                radius: *radius,
                cut: *cut,
            },
            ShapeGeom::PartialDisk {
                to_world,
                height,
                cut,
            } => ShapeGeom::PartialDisk {
                to_world: t.then_apply_to(to_world),
                height: *height,
                cut: *cut,
            },
            ShapeGeom::Cylinder {
                to_world,
                radius,
                zmin,
                zmax,
                phimax,
            } => ShapeGeom::Cylinder {
                to_world: t.then_apply_to(to_world),
                radius: *radius,
                zmin: *zmin,
                zmax: *zmax,
                phimax: *phimax,
            },
        }
    }
}

/// Where a shape is made: CTM, orientation, directory for relative file names, location.
pub struct ShapeCtx<'a> {
    /// Current transformation matrix (object → world).
    pub ctm: &'a Transform,
    /// ReverseOrientation in effect.
    pub reverse: bool,
    /// Directory of the file containing the directive.
    pub dir: &'a Path,
    /// Location of the `Shape` directive.
    pub loc: &'a Loc,
}

/// An object-space mesh before validation.
pub struct RawMesh {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Optional normals.
    pub normals: Option<Vec<Vec3>>,
    /// Optional uvs.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangle indices (unchecked).
    pub indices: Vec<u32>,
}

/// Validate an object-space mesh and take it to world space. Errors: indices out of range or
/// not triples, attribute count mismatch. What a renderer can repair ([`repair_mesh`]: bad
/// normals, zero-area or non-finite triangles) is repaired with one warning for the shape; a
/// mesh that is empty, or left empty, is dropped with that warning (`Ok(None)`).
pub fn finish_mesh(
    raw: RawMesh,
    ctx: &ShapeCtx,
    what: &str,
    warn: &mut Warn,
) -> anyhow::Result<Option<TriangleMesh>> {
    let loc = ctx.loc;
    let n = raw.positions.len();
    if !raw.indices.len().is_multiple_of(3) {
        return Err(err_at(
            loc,
            format!(
                "expected a multiple of 3 indices, found {}",
                raw.indices.len()
            ),
        ));
    }
    if let Some((k, &i)) = raw
        .indices
        .iter()
        .enumerate()
        .find(|&(_, &i)| i as usize >= n)
    {
        return Err(err_at(
            loc,
            format!("index {i} (entry {k}) out of range: mesh has {n} vertices"),
        ));
    }
    if let Some(ns) = &raw.normals
        && ns.len() != n
    {
        return Err(err_at(
            loc,
            format!("expected {n} normals, found {}", ns.len()),
        ));
    }
    if let Some(uv) = &raw.uvs
        && uv.len() != n
    {
        return Err(err_at(loc, format!("expected {n} uvs, found {}", uv.len())));
    }
    // The identity (the common case after WorldBegin) is skipped entirely: no rounding, so a
    // scene loaded from file matches the same data given to the builder bit for bit (the
    // builder normalises normals itself).
    let identity = ctx.ctm.m == Mat4::IDENTITY;
    let m: Mat4 = ctx.ctm.m;
    let positions: Vec<Vec3> = if identity {
        raw.positions
    } else {
        raw.positions
            .iter()
            .map(|&p| m.transform_point3(p))
            .collect()
    };
    let nt = ctx.ctm.m_inv.transpose();
    let normals = raw.normals.map(|ns| {
        if identity {
            return ns;
        }
        ns.into_iter()
            .map(|v| nt.transform_vector3(v).normalize_or_zero())
            .collect()
    });
    let mut mesh = TriangleMesh {
        positions,
        normals,
        uvs: raw.uvs,
        indices: raw.indices,
        flip_normals: ctx.reverse ^ ctx.ctm.swaps_handedness(),
    };
    let repair = repair_mesh(&mut mesh);
    if !repair.is_clean() {
        warn(
            &format!("mesh-repair@{}", loc.file_line()),
            loc,
            format!("{what}: {}", repair.describe()),
        );
    }
    Ok((repair.kept() > 0).then_some(mesh))
}

fn indices_param(
    params: &ParamSet,
    name: &str,
    nverts: usize,
    per: usize,
    loc: &Loc,
) -> anyhow::Result<Vec<u32>> {
    match params.ints(name)? {
        Some((v, ploc)) => {
            let mut out = Vec::with_capacity(v.len());
            for (k, &i) in v.iter().enumerate() {
                if i < 0 || i >= nverts as i64 {
                    return Err(err_at(
                        &ploc,
                        format!("index {i} (entry {k}) out of range: mesh has {nverts} vertices"),
                    ));
                }
                out.push(i as u32);
            }
            Ok(out)
        }
        None if nverts == per => Ok((0..per as u32).collect()),
        None => Err(err_at(
            loc,
            format!(
                "expected \"integer {name}\" (required unless there are exactly {per} vertices)"
            ),
        )),
    }
}

/// Positions, optional normals, optional uvs of a mesh directive.
type MeshAttrs = (Vec<Vec3>, Option<Vec<Vec3>>, Option<Vec<Vec2>>);

fn mesh_attrs(params: &ParamSet, loc: &Loc) -> anyhow::Result<MeshAttrs> {
    let p = params
        .point3s("P")?
        .ok_or_else(|| err_at(loc, "expected \"point3 P\", found none"))?;
    let n = params.normals("N")?;
    let uv = match params.point2s("uv")? {
        Some(uv) => Some(uv),
        None => params.point2s("st")?,
    };
    for ignored in ["S", "faceIndices", "emission"] {
        let _ = params.find(ignored);
    }
    Ok((p, n, uv))
}

/// Build the shape of pbrt type `kind`; `Ok(None)` for unsupported kinds (warned).
pub fn make_shape(
    kind: &str,
    params: &ParamSet,
    ctx: &ShapeCtx,
    warn: &mut Warn,
) -> anyhow::Result<Option<ShapeGeom>> {
    let loc = ctx.loc;
    if params.has("displacement") {
        let _ = params.find("displacement");
        warn(
            "shape-displacement",
            loc,
            "shape parameter 'displacement' is ignored".into(),
        );
    }
    Ok(Some(match kind {
        "trianglemesh" => {
            let (p, n, uv) = mesh_attrs(params, loc)?;
            let indices = indices_param(params, "indices", p.len(), 3, loc)?;
            let raw = RawMesh {
                positions: p,
                normals: n,
                uvs: uv,
                indices,
            };
            match finish_mesh(raw, ctx, "trianglemesh", warn)? {
                Some(m) => ShapeGeom::Mesh(m),
                None => return Ok(None),
            }
        }
        "loopsubdiv" => match loop_subdiv_shape(params, ctx, warn)? {
            Some(m) => ShapeGeom::Mesh(m),
            None => return Ok(None),
        },
        "bilinearmesh" => {
            let (p, n, uv) = mesh_attrs(params, loc)?;
            let quads = indices_param(params, "indices", p.len(), 4, loc)?;
            if !quads.len().is_multiple_of(4) {
                return Err(err_at(
                    loc,
                    format!(
                        "bilinearmesh: expected a multiple of 4 indices, found {}",
                        quads.len()
                    ),
                ));
            }
            // Patch vertices are p00 p10 p01 p11. The true patches, in world space:
            let m = ctx.ctm.m;
            let nt = ctx.ctm.m_inv.transpose();
            let swap = ctx.reverse ^ ctx.ctm.swaps_handedness();
            let mut patches = Vec::with_capacity(quads.len() / 4);
            for q in quads.chunks_exact(4) {
                let c = [0, 1, 2, 3].map(|k| m.transform_point3(p[q[k] as usize]));
                if !c.iter().all(|v| v.is_finite()) {
                    return Err(err_at(loc, "bilinearmesh: non-finite vertex position"));
                }
                let uvc = match &uv {
                    Some(uv) => [0, 1, 2, 3].map(|k| uv[q[k] as usize]),
                    None => [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE],
                };
                // pbrt-v4: with normals, ∂p/∂u × ∂p/∂v faces the interpolated normal; without,
                // it flips for ReverseOrientation ⊕ a handedness swap. (The normals are then
                // not used for shading.)
                let ng = (c[1] - c[0] + c[3] - c[2]).cross(c[2] - c[0] + c[3] - c[1]);
                let flip = match &n {
                    Some(ns) => {
                        let sum: Vec3 = (0..4).map(|k| ns[q[k] as usize]).sum();
                        ng.dot(nt.transform_vector3(sum)) < 0.0
                    }
                    None => swap,
                };
                patches.push((c, uvc, flip));
            }
            if n.is_some() {
                warn(
                    "bilinearmesh-normals",
                    loc,
                    "bilinearmesh: 'N' orients the patches but is not interpolated for shading (geometric normals)".into(),
                );
            }
            // The triangle stand-in: split along p00–p11 keeping the orientation of
            // (p10 − p00) × (p01 − p00).
            let mut indices = Vec::with_capacity(quads.len() / 4 * 6);
            for q in quads.chunks_exact(4) {
                indices.extend_from_slice(&[q[0], q[1], q[3], q[0], q[3], q[2]]);
            }
            let raw = RawMesh {
                positions: p,
                normals: n,
                uvs: uv,
                indices,
            };
            let mesh = finish_mesh(raw, ctx, "bilinearmesh", warn)?;
            ShapeGeom::Bilinear { patches, mesh }
        }
        "plymesh" => {
            let file = params
                .string("filename")?
                .ok_or_else(|| err_at(loc, "plymesh: expected \"string filename\", found none"))?;
            let path = resolve(ctx.dir, &file);
            for ignored in ["edgelength", "displacement"] {
                let _ = params.find(ignored);
            }
            if let Some(why) = crate::image::io::not_a_file(&path) {
                return Err(err_at(
                    params.loc_of("filename").as_ref().unwrap_or(loc),
                    format!("plymesh: {why}: {}", path.display()),
                ));
            }
            let ply = read_ply(&path).map_err(|e| err_at(loc, format!("plymesh: {e}")))?;
            if ply.big_polygons > 0 {
                warn(
                    "ply-polygons",
                    loc,
                    format!(
                        "{} PLY polygons with more than 4 vertices triangulated (pbrt-v4 reads triangles and quads only)",
                        ply.big_polygons
                    ),
                );
            }
            let raw = RawMesh {
                positions: ply.positions,
                normals: ply.normals,
                uvs: ply.uvs,
                indices: ply.indices,
            };
            match finish_mesh(raw, ctx, &format!("plymesh \"{file}\""), warn)? {
                Some(m) => ShapeGeom::Mesh(m),
                None => return Ok(None),
            }
        }
        "sphere" => {
            let radius = params.float("radius", 1.0)?;
            if !(radius.is_finite() && radius > 0.0) {
                return Err(err_at(
                    loc,
                    format!("sphere: radius must be positive, found {radius}"),
                ));
            }
            // pbrt-v4's Sphere: z cuts clamped to the radius, phimax to [0, 360] degrees.
            let (z0, z1) = (
                params.float("zmin", -radius)?,
                params.float("zmax", radius)?,
            );
            let (zmin, zmax) = (
                z0.min(z1).clamp(-radius, radius),
                z0.max(z1).clamp(-radius, radius),
            );
            let phimax = params.float("phimax", 360.0)?.clamp(0.0, 360.0);
            if !(zmin < zmax && phimax > 0.0) {
                return Err(err_at(
                    loc,
                    format!(
                        "sphere: zmin < zmax and phimax > 0 needed, found z {zmin}..{zmax}, phimax {phimax}"
                    ),
                ));
            }
            if zmin > -radius || zmax < radius || phimax < 360.0 {
                ShapeGeom::PartialSphere {
                    to_world: *ctx.ctm,
                    radius,
                    cut: [zmin, zmax, phimax.to_radians()],
                }
            } else {
                ShapeGeom::Sphere {
                    to_world: *ctx.ctm,
                    radius,
                }
            }
        }
        "disk" => {
            let radius = params.float("radius", 1.0)?;
            if !(radius.is_finite() && radius > 0.0) {
                return Err(err_at(
                    loc,
                    format!("disk: radius must be positive, found {radius}"),
                ));
            }
            let inner = params.float("innerradius", 0.0)?;
            let phimax = params.float("phimax", 360.0)?.clamp(0.0, 360.0);
            if !((0.0..radius).contains(&inner) && phimax > 0.0) {
                return Err(err_at(
                    loc,
                    format!(
                        "disk: 0 ≤ innerradius < radius and phimax > 0 needed, found innerradius {inner}, phimax {phimax}"
                    ),
                ));
            }
            let height = params.float("height", 0.0)?;
            if inner > 0.0 || phimax < 360.0 {
                ShapeGeom::PartialDisk {
                    to_world: *ctx.ctm,
                    height,
                    cut: [radius, inner, phimax.to_radians()],
                }
            } else {
                ShapeGeom::Disk {
                    to_world: *ctx.ctm,
                    height,
                    radius,
                }
            }
        }
        "curve" => match curve_shape(params, ctx, warn)? {
            Some(segments) => ShapeGeom::Curves {
                to_world: *ctx.ctm,
                segments,
            },
            None => return Ok(None),
        },
        "cylinder" => {
            let radius = params.float("radius", 1.0)?;
            let zmin = params.float("zmin", -1.0)?;
            let zmax = params.float("zmax", 1.0)?;
            let phimax = params.float("phimax", 360.0)?;
            if !(radius.is_finite() && radius > 0.0) {
                return Err(err_at(
                    loc,
                    format!("cylinder: radius must be positive, found {radius}"),
                ));
            }
            if !(zmin.is_finite() && zmax.is_finite() && zmin != zmax) {
                return Err(err_at(
                    loc,
                    format!(
                        "cylinder: zmin and zmax must be finite and differ, found {zmin}, {zmax}"
                    ),
                ));
            }
            if !(phimax.is_finite() && phimax > 0.0) {
                return Err(err_at(
                    loc,
                    format!("cylinder: phimax must be positive, found {phimax}"),
                ));
            }
            ShapeGeom::Cylinder {
                to_world: *ctx.ctm,
                radius,
                zmin: zmin.min(zmax),
                zmax: zmin.max(zmax),
                phimax: phimax.min(360.0).to_radians(),
            }
        }
        other => {
            warn(
                &format!("shape-{other}"),
                loc,
                format!("shape \"{other}\" is not supported; skipped"),
            );
            for p in &params.params {
                let _ = params.find(&p.name);
            }
            return Ok(None);
        }
    }))
}

/// Most triangles `loopsubdiv` may make (4^levels per control triangle): 2^24 (about 1.5 GB
/// of mesh); more levels are reduced to fit, with a warning.
const LOOP_MAX_TRIANGLES: usize = 1 << 24;

/// pbrt-v4's `loopsubdiv`: `levels` (default 3) of Loop subdivision of `P`/`indices`, at the
/// limit surface with its normals (uvs are dropped, as pbrt-v4 does). Triangles that repeat a
/// vertex are dropped; a mesh the rules cannot subdivide (not a consistently oriented
/// manifold) is rendered as its control mesh; both with a warning.
fn loop_subdiv_shape(
    params: &ParamSet,
    ctx: &ShapeCtx,
    warn: &mut Warn,
) -> anyhow::Result<Option<TriangleMesh>> {
    let loc = ctx.loc;
    let p = params
        .point3s("P")?
        .ok_or_else(|| err_at(loc, "loopsubdiv: expected \"point3 P\", found none"))?;
    let mut indices = indices_param(params, "indices", p.len(), 3, loc)?;
    if !indices.len().is_multiple_of(3) {
        return Err(err_at(
            loc,
            format!(
                "loopsubdiv: expected a multiple of 3 indices, found {}",
                indices.len()
            ),
        ));
    }
    let levels = params.int("levels", 3)?;
    if levels < 0 {
        return Err(err_at(
            loc,
            format!("loopsubdiv: 'levels' must be ≥ 0, found {levels}"),
        ));
    }
    for ignored in ["uv", "st", "N"] {
        let _ = params.find(ignored);
    }
    let before = indices.len();
    let tris: Vec<u32> = indices
        .chunks_exact(3)
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .flatten()
        .copied()
        .collect();
    if tris.len() != before {
        warn(
            &format!("loopsubdiv-degenerate@{}", loc.file_line()),
            loc,
            format!(
                "loopsubdiv: {} triangles that repeat a vertex dropped",
                (before - tris.len()) / 3
            ),
        );
    }
    indices = tris;
    let mut levels = levels.min(16) as u32;
    while levels > 0 && (indices.len() / 3) << (2 * levels) > LOOP_MAX_TRIANGLES {
        levels -= 1;
    }
    if levels < params.int("levels", 3)?.min(16) as u32 {
        warn(
            &format!("loopsubdiv-levels@{}", loc.file_line()),
            loc,
            format!(
                "loopsubdiv: 'levels' reduced to {levels} (at most {LOOP_MAX_TRIANGLES} triangles)"
            ),
        );
    }
    let raw = match crate::scene::loop_subdiv::loop_subdivide(&p, &indices, levels) {
        Ok(m) => RawMesh {
            positions: m.positions,
            normals: Some(m.normals),
            uvs: None,
            indices: m.indices,
        },
        Err(why) => {
            warn(
                &format!("loopsubdiv-manifold@{}", loc.file_line()),
                loc,
                format!("loopsubdiv: {why}; rendered as the unsubdivided control mesh"),
            );
            RawMesh {
                positions: p,
                normals: None,
                uvs: None,
                indices,
            }
        }
    };
    finish_mesh(raw, ctx, "loopsubdiv", warn)
}

/// pbrt-v4's `curve` parameters as cubic Bézier segments: `P` (`basis` `bezier`: 3k + 1
/// points for degree 3, 2k + 1 for degree 2; `bspline`: k + 3 for degree 3), `type` (`flat`,
/// `ribbon` with `N` at the k + 1 segment ends, `cylinder`), `width` or `width0`/`width1`
/// (linear along the whole curve). `splitdepth` only splits pbrt's BVH leaves: ignored.
fn curve_shape(
    params: &ParamSet,
    ctx: &ShapeCtx,
    warn: &mut Warn,
) -> anyhow::Result<Option<Vec<CurveSegment>>> {
    let loc = ctx.loc;
    let p = params
        .point3s("P")?
        .ok_or_else(|| err_at(loc, "curve: expected \"point3 P\", found none"))?;
    let basis = params.string("basis")?.unwrap_or_else(|| "bezier".into());
    let degree = params.int("degree", 3)?;
    let kind = match params.string("type")?.as_deref().unwrap_or("flat") {
        "flat" => CurveType::Flat,
        "ribbon" => CurveType::Ribbon,
        "cylinder" => CurveType::Cylinder,
        other => {
            return Err(err_at(
                loc,
                format!("curve: unknown type \"{other}\" (expected flat, ribbon or cylinder)"),
            ));
        }
    };
    let w = params.float("width", 1.0)?;
    let (w0, w1) = (params.float("width0", w)?, params.float("width1", w)?);
    let _ = params.int("splitdepth", 3)?;
    let cubic: Vec<[Vec3; 4]> = match (basis.as_str(), degree) {
        ("bezier", 3) if p.len() >= 4 && (p.len() - 1) % 3 == 0 => (0..(p.len() - 1) / 3)
            .map(|k| [p[3 * k], p[3 * k + 1], p[3 * k + 2], p[3 * k + 3]])
            .collect(),
        ("bezier", 2) if p.len() >= 3 && (p.len() - 1) % 2 == 0 => (0..(p.len() - 1) / 2)
            .map(|k| {
                let (a, b, c) = (p[2 * k], p[2 * k + 1], p[2 * k + 2]);
                [a, a + (b - a) * (2.0 / 3.0), c + (b - c) * (2.0 / 3.0), c]
            })
            .collect(),
        ("bspline", 3) if p.len() >= 4 => (0..p.len() - 3)
            .map(|k| bspline_to_bezier([p[k], p[k + 1], p[k + 2], p[k + 3]]))
            .collect(),
        (b, d) => {
            warn(
                "curve-basis",
                loc,
                format!(
                    "curve: basis \"{b}\" of degree {d} with {} points is not supported; skipped",
                    p.len()
                ),
            );
            return Ok(None);
        }
    };
    let nseg = cubic.len();
    let normals = params.normals("N")?;
    if kind == CurveType::Ribbon && normals.as_ref().is_none_or(|n| n.len() != nseg + 1) {
        return Err(err_at(
            loc,
            format!(
                "curve: a ribbon needs {} normals \"N\" (one per segment end), found {}",
                nseg + 1,
                normals.as_ref().map_or(0, |n| n.len())
            ),
        ));
    }
    Ok(Some(
        cubic
            .into_iter()
            .enumerate()
            .map(|(k, cp)| {
                let f = |i: usize| i as f32 / nseg as f32;
                let n = normals.as_ref().map_or([Vec3::Z; 2], |n| {
                    [n[k].normalize_or_zero(), n[k + 1].normalize_or_zero()]
                });
                CurveSegment {
                    cp,
                    width: [w0 + (w1 - w0) * f(k), w0 + (w1 - w0) * f(k + 1)],
                    n,
                    kind,
                }
            })
            .collect(),
    ))
}

/// The shape's `"float alpha"` / `"texture alpha"` cut-out (pbrt-v4: none when the coverage is
/// 1). Coverage is clamped to [0, 1] by the alpha test; a varying float texture (image,
/// checkerboard, scale, mapped) is evaluated at each candidate hit's uv (a quadric's, a
/// curve's or a patch's own uv as for meshes).
pub fn shape_alpha(
    params: &ParamSet,
    textures: &TextureTable,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<Option<Alpha>> {
    if !params.has("alpha") {
        return Ok(None);
    }
    let t = textures.float_texture_param(params, "alpha", 1.0, warn)?;
    if let Some(a) = t.constant() {
        if !a.is_finite() {
            return Err(err_at(
                params.loc_of("alpha").as_ref().unwrap_or(loc),
                format!("'alpha' must be a finite number, found {a}"),
            ));
        }
        if a >= 1.0 {
            return Ok(None);
        }
    }
    Ok(Some(match t.constant() {
        Some(a) => Alpha::Constant(a.max(0.0)),
        None => {
            let tex = super::materials::float_texture(&t, &textures.images).map_err(|e| {
                err_at(
                    params.loc_of("alpha").as_ref().unwrap_or(loc),
                    format!("{e:#}"),
                )
            })?;
            Alpha::Texture(std::sync::Arc::new(tex))
        }
    }))
}
