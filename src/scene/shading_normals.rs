//! Normal and bump maps at closest hits (every path vertex): the shading normal of a hit whose
//! material has one is replaced before the shading frame is built (pbrt-v4's `NormalMap` / `BumpMap`), from the
//! hit triangle's ∂p/∂u, ∂p/∂v, or a quadric's, curve's or bilinear patch's own (pbrt-v4's
//! parametric derivatives, [`crate::geometry::Quadric::derivatives`]).

use super::Scene;
use crate::geometry::{HitColumns, PrimKind, SurfaceHit};
use crate::material::{ShadingDerivatives, TexCoord};
use glam::{Vec2, Vec3};

/// pbrt-v4's triangle ∂n/∂u, ∂n/∂v from the vertex normals `n` and uvs (zero for degenerate
/// uvs, where pbrt picks an arbitrary frame of the normals' spread instead).
pub fn triangle_dndu(n: [Vec3; 3], uv: [Vec2; 3]) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dn1, dn2) = (n[0] - n[2], n[1] - n[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if !(det.abs() > 1e-32) {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let inv = 1.0 / det;
    (
        (dn1 * duv12.y - dn2 * duv02.y) * inv,
        (dn2 * duv02.x - dn1 * duv12.x) * inv,
    )
}

/// ∂p/∂u and ∂p/∂v of triangle `p` with texture coordinates `uv` (pbrt-v4's triangle
/// derivatives, made perpendicular to the shading normal `ns` when the mesh has vertex
/// normals); `None` when the uvs are degenerate.
fn triangle_derivatives(
    p: [Vec3; 3],
    uv: [Vec2; 3],
    ns: Vec3,
    smooth: bool,
) -> Option<(Vec3, Vec3)> {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if !(det.abs() > 1e-12) {
        return None;
    }
    let inv = 1.0 / det;
    let dpdu = (dp02 * duv12.y - dp12 * duv02.y) * inv;
    let dpdv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
    if !smooth {
        return Some((dpdu, dpdv));
    }
    // pbrt-v4's shading frame of a mesh with normals: ts = ns × ∂p/∂u, ss = ts × ns.
    let ts = ns.cross(dpdu);
    if ts.length_squared() == 0.0 {
        return None;
    }
    Some((ts.cross(ns), ts))
}

/// Replace the shading normals of the active lanes' hits (and their packet columns) whose
/// material has a normal or bump map. Only `active` lanes: the others hold an earlier vertex's
/// hit, already perturbed, which a second pass would tilt again.
pub fn perturb_hits(
    scene: &Scene,
    active: u32,
    hits: &mut [Option<SurfaceHit>],
    cols: &mut HitColumns,
) {
    for k in crate::geometry::packet::bits(active) {
        let Some(hit) = &mut hits[k] else { continue };
        let Some(material) = scene.materials.get(hit.material as usize) else {
            continue;
        };
        let Some(pert) = material.normal_perturbation() else {
            continue;
        };
        let Some(prim) = scene.geometry.primitive(hit.prim) else {
            continue;
        };
        let d = match prim.kind {
            PrimKind::Triangle { mesh, v } => {
                let m = &scene.geometry.meshes[mesh as usize];
                let uv = match &m.uvs {
                    Some(uv) => v.map(|i| uv[i as usize]),
                    // pbrt-v4's default parameterisation.
                    None => [Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::ONE],
                };
                let Some((dpdu, dpdv)) =
                    triangle_derivatives(prim.p, uv, hit.ns, m.normals.is_some())
                else {
                    continue;
                };
                let (dndu, dndv) = match &m.normals {
                    Some(n) => triangle_dndu(v.map(|i| n[i as usize]), uv),
                    None => (Vec3::ZERO, Vec3::ZERO),
                };
                ShadingDerivatives {
                    dpdu,
                    dpdv,
                    dndu,
                    dndv,
                }
            }
            PrimKind::Quadric(q) => {
                let Some([dpdu, dpdv, dndu, dndv]) =
                    scene.geometry.quadrics[q as usize].derivatives(hit.p, hit.uv, hit.ng)
                else {
                    continue;
                };
                ShadingDerivatives {
                    dpdu,
                    dpdv,
                    dndu,
                    dndv,
                }
            }
        };
        let tc = material
            .footprint()
            .map_or(TexCoord::point(hit.uv), |f| f.tex_coord(hit));
        let ns = pert.shading_normal(&tc, hit.ns, hit.ng, &d);
        hit.ns = ns;
        for a in 0..3 {
            cols.ns[a][k] = ns[a];
        }
    }
}
