//! What a scene's geometry is made of: [`Primitive`]s (triangles with their vertices inline,
//! or references to quadrics), the per-mesh data their hit records interpolate
//! ([`MeshShading`]), and the per-primitive quantities the BVH build needs (bounds, normals).

use super::alpha::Alpha;
use super::quadric::Quadric;
use glam::{Vec2, Vec3};

/// Per-vertex data of a mesh that hit records interpolate.
#[derive(Clone, Debug, Default)]
pub struct MeshShading {
    /// Optional per-vertex shading normals.
    pub normals: Option<Vec<Vec3>>,
    /// Optional per-vertex texture coordinates.
    pub uvs: Option<Vec<Vec2>>,
    /// Flip the geometric normal (only when there are no vertex normals).
    pub flip: bool,
    /// Alpha cut-out: hits where it does not keep them are ignored by every query.
    pub alpha: Option<Alpha>,
}

/// What a primitive is.
#[derive(Clone, Copy, Debug)]
pub enum PrimKind {
    /// Triangle `tri` (its vertex indices are `indices[3·tri..]`) of mesh `mesh`.
    Triangle {
        /// Mesh index into `Geometry::meshes`.
        mesh: u32,
        /// Vertex indices into the mesh's arrays.
        v: [u32; 3],
    },
    /// Index into `Geometry::quadrics`.
    Quadric(u32),
}

/// A primitive: triangle vertices inline for the hot intersection loop, plus its ids. Vertices
/// (not edges) are stored so that neighbours see bit-identical shared vertices (watertight).
#[derive(Clone, Copy, Debug)]
pub struct Primitive {
    /// Triangle vertices (unused for quadrics).
    pub p: [Vec3; 3],
    /// Shape.
    pub kind: PrimKind,
    /// Material index.
    pub material: u32,
    /// Area light index or `NO_LIGHT`.
    pub light: u32,
}

/// Unit geometric normal of triangle `p` (winding order), zero if degenerate.
pub(super) fn triangle_normal(p: [Vec3; 3]) -> Vec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
}

/// World bounding box of `p` (padded so that flat boxes are never culled by rounding).
pub(super) fn prim_bounds(p: &Primitive, quadrics: &[Quadric]) -> (Vec3, Vec3) {
    match p.kind {
        PrimKind::Triangle { .. } => {
            let [a, b, c] = p.p;
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            // Axis-aligned triangles have flat boxes, which slab tests may reject for rays that
            // do hit them: pad by a relative epsilon.
            let pad = (hi - lo).max_element() * 1e-6 + lo.abs().max(hi.abs()).max_element() * 1e-7;
            (lo - pad, hi + pad)
        }
        PrimKind::Quadric(q) => quadrics[q as usize].bounds(),
    }
}
