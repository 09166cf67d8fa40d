//! Mesh repair shared by every mesh source (pbrt, PLY, OBJ, glTF, built-ins): what a renderer
//! can fix in a triangle mesh is fixed here and counted, and the caller, who knows the file and
//! line, reports it in one warning per mesh. As pbrt-v4 and Tungsten do, a bad shading normal
//! falls back to the geometric normal and a triangle that encloses no area (or has a vertex at
//! infinity or NaN) is dropped; nothing else about a clean mesh changes, bit for bit.

use super::TriangleMesh;
use glam::{Vec2, Vec3};

/// What [`repair_mesh`] changed in one mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshRepair {
    /// Triangles before repair.
    pub triangles: usize,
    /// Triangles dropped because their area is zero (or not a number).
    pub zero_area: usize,
    /// Triangles dropped because a vertex position is NaN or infinite.
    pub non_finite: usize,
    /// Vertices in the mesh.
    pub vertices: usize,
    /// Vertex normals that were NaN, infinite or zero-length and now follow the surface.
    pub bad_normals: usize,
    /// Every normal was bad: the mesh is shaded with its geometric normal alone.
    pub normals_dropped: bool,
    /// Non-finite texture coordinates set to (0, 0).
    pub bad_uvs: usize,
}

impl MeshRepair {
    /// Triangles left after repair.
    pub fn kept(&self) -> usize {
        self.triangles - self.zero_area - self.non_finite
    }

    /// Nothing was repaired.
    pub fn is_clean(&self) -> bool {
        *self
            == MeshRepair {
                triangles: self.triangles,
                vertices: self.vertices,
                ..Default::default()
            }
            && self.triangles > 0
    }

    /// One sentence for the warning: what was wrong, how much, and what was done.
    pub fn describe(&self) -> String {
        if self.triangles == 0 {
            return "the mesh has no triangles; dropped".to_string();
        }
        let t = self.triangles;
        let mut parts = Vec::new();
        if self.zero_area > 0 {
            parts.push(format!(
                "{} of {t} triangles have zero area and are dropped",
                self.zero_area
            ));
        }
        if self.non_finite > 0 {
            parts.push(format!(
                "{} of {t} triangles use a non-finite vertex position and are dropped",
                self.non_finite
            ));
        }
        if self.bad_normals > 0 {
            let what = if self.normals_dropped {
                "the mesh is shaded with its geometric normal"
            } else {
                "those vertices use the geometric normal of their triangles"
            };
            parts.push(format!(
                "{} of {} vertex normals are NaN, infinite or zero; {what}",
                self.bad_normals, self.vertices
            ));
        }
        if self.bad_uvs > 0 {
            parts.push(format!(
                "{} non-finite texture coordinates set to (0, 0)",
                self.bad_uvs
            ));
        }
        if self.kept() == 0 {
            parts.push("no triangle is left; the mesh is dropped".to_string());
        }
        parts.join("; ")
    }
}

/// The normal `n` as it will be shaded, or `None` if it cannot be (NaN, infinite, zero, or so
/// large its length overflows).
fn usable(n: Vec3) -> Option<Vec3> {
    let u = n.normalize_or_zero();
    (u != Vec3::ZERO).then_some(u)
}

/// Repair `mesh` in place and say what changed. The indices must already be in range and the
/// attribute arrays as long as `positions` (the builder checks both; this never panics on a
/// mesh that passed those checks).
///
/// A bad vertex normal becomes the area-weighted sum of the winding normals of the kept
/// triangles around the vertex, turned to the side of the good normals of those triangles (so
/// a mesh whose winding disagrees with its normals stays consistent), or to the side
/// `flip_normals` names when there are none. If no normal is usable the mesh loses its normals.
pub fn repair_mesh(mesh: &mut TriangleMesh) -> MeshRepair {
    let nv = mesh.positions.len();
    let mut r = MeshRepair {
        triangles: mesh.indices.len() / 3,
        vertices: nv,
        ..Default::default()
    };
    let pos = &mesh.positions;
    let finite: Vec<bool> = pos.iter().map(|p| p.is_finite()).collect();
    let mut w = 0;
    for t in 0..r.triangles {
        let v = [
            mesh.indices[3 * t] as usize,
            mesh.indices[3 * t + 1] as usize,
            mesh.indices[3 * t + 2] as usize,
        ];
        if !v.iter().all(|&i| finite.get(i).copied().unwrap_or(false)) {
            r.non_finite += 1;
            continue;
        }
        // The same test the builder and the intersector use for "encloses an area".
        let cross = (pos[v[1]] - pos[v[0]]).cross(pos[v[2]] - pos[v[0]]);
        if !(cross.length_squared() > 0.0) {
            r.zero_area += 1;
            continue;
        }
        mesh.indices.copy_within(3 * t..3 * t + 3, 3 * w);
        w += 1;
    }
    mesh.indices.truncate(3 * w);

    if let Some(ns) = &mut mesh.normals {
        let good: Vec<Option<Vec3>> = ns.iter().map(|&n| usable(n)).collect();
        r.bad_normals = good.iter().filter(|g| g.is_none()).count();
        if r.bad_normals == nv && nv > 0 {
            r.normals_dropped = true;
        } else if r.bad_normals > 0 {
            // Per bad vertex: Σ winding normals (area weighted) and Σ good neighbour normals.
            let mut sum = vec![Vec3::ZERO; nv];
            let mut side = vec![Vec3::ZERO; nv];
            for tri in mesh.indices.chunks_exact(3) {
                let v = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
                if v.iter().all(|&i| good[i].is_some()) {
                    continue;
                }
                let cross = (pos[v[1]] - pos[v[0]]).cross(pos[v[2]] - pos[v[0]]);
                let around: Vec3 = v.iter().filter_map(|&i| good[i]).sum();
                for &i in &v {
                    if good[i].is_none() {
                        sum[i] += cross;
                        side[i] += around;
                    }
                }
            }
            for i in 0..nv {
                if good[i].is_some() {
                    continue;
                }
                let mut n = sum[i].normalize_or_zero();
                let flip = if side[i] != Vec3::ZERO {
                    n.dot(side[i]) < 0.0
                } else {
                    mesh.flip_normals
                };
                if flip {
                    n = -n;
                }
                // Unreferenced vertices keep a zero normal: no hit ever interpolates it.
                ns[i] = n;
            }
        }
    }
    if r.normals_dropped {
        mesh.normals = None;
    }
    if let Some(uvs) = &mut mesh.uvs {
        for uv in uvs.iter_mut().filter(|uv| !uv.is_finite()) {
            *uv = Vec2::ZERO;
            r.bad_uvs += 1;
        }
    }
    r
}
