//! Loop subdivision (pbrt-v4's `loopsubdiv` shape): each level splits every triangle into four,
//! moving old ("even") vertices by Loop's one-ring rule (β = 3/16 for valence 3, else 3/(8n);
//! boundary vertices (1 − 2·1/8)·v + 1/8·(two boundary neighbours)) and placing new ("odd")
//! edge vertices at 3/8·(ends) + 1/8·(opposite vertices), or the midpoint on a boundary. The
//! result is pushed to the limit surface (interior mask γ = 1/(n + 3/(8β)); boundary
//! 2/3·v + 1/6·(neighbours), the cubic B-spline's limit that the boundary rules converge to —
//! pbrt-v4 weights 3/5, 1/5 there, which is not a fixed point of its own rules and moves
//! boundary limits with the level) and given the limit surface's normals from the book's
//! tangent masks. Old vertices keep their indices at every level, so a control vertex's
//! limit position is `positions[i]` of the output.

use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;

/// A triangle mesh with per-vertex normals.
#[derive(Clone, Debug)]
pub struct LoopMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals (empty before [`limit`]).
    pub normals: Vec<Vec3>,
    /// Counter-clockwise triangles.
    pub indices: Vec<u32>,
}

/// One vertex's neighbours in counter-clockwise order (seen from the side the triangles'
/// winding faces) and whether the fan is open (a boundary vertex: the ring's first and last
/// vertices are its boundary neighbours).
struct Ring {
    verts: Vec<u32>,
    boundary: bool,
}

/// Every vertex's ring (`None` for vertices no triangle uses). Errors when the mesh is not an
/// edge-manifold with consistently oriented triangles (the rules need a single fan per vertex).
fn rings(n: usize, indices: &[u32]) -> Result<Vec<Option<Ring>>, String> {
    // For each vertex v: the (x, y) of each triangle (v, x, y) around it.
    let mut fans: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    let mut directed: HashMap<(u32, u32), ()> = HashMap::with_capacity(indices.len());
    for t in indices.chunks_exact(3) {
        for k in 0..3 {
            let (v, x, y) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            fans[v as usize].push((x, y));
            if directed.insert((v, x), ()).is_some() {
                return Err(format!(
                    "edge {v}–{x} is used twice in the same direction (a non-manifold edge or inconsistently oriented triangles)"
                ));
            }
        }
    }
    let mut out = Vec::with_capacity(n);
    for (v, fan) in fans.iter().enumerate() {
        if fan.is_empty() {
            out.push(None);
            continue;
        }
        // An open fan starts at the x that no triangle ends at.
        let start = fan
            .iter()
            .find(|(x, _)| !fan.iter().any(|(_, y)| y == x))
            .map(|&(x, _)| x);
        let boundary = start.is_some();
        let first = start.unwrap_or(fan[0].0);
        let mut verts = vec![first];
        let mut cur = first;
        for _ in 0..fan.len() {
            match fan.iter().find(|(x, _)| *x == cur) {
                Some(&(_, y)) => {
                    if !boundary && y == first {
                        break;
                    }
                    verts.push(y);
                    cur = y;
                }
                None => break,
            }
        }
        let walked = if boundary {
            verts.len() - 1
        } else {
            verts.len()
        };
        if walked != fan.len() {
            return Err(format!(
                "vertex {v} joins {} triangles that do not form one fan (a non-manifold vertex)",
                fan.len()
            ));
        }
        out.push(Some(Ring { verts, boundary }));
    }
    Ok(out)
}

/// Loop's β for an interior vertex of valence `n`.
fn beta(n: usize) -> f64 {
    if n == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * n as f64)
    }
}

fn d(p: Vec3) -> DVec3 {
    p.as_dvec3()
}

/// One level of Loop subdivision (positions not yet at the limit).
pub fn subdivide_once(mesh: &LoopMesh) -> Result<LoopMesh, String> {
    let n = mesh.positions.len();
    let rings = rings(n, &mesh.indices)?;
    let p = &mesh.positions;
    let sum = |vs: &[u32]| vs.iter().map(|&i| d(p[i as usize])).sum::<DVec3>();
    // Even vertices: same indices.
    let mut positions: Vec<Vec3> = (0..n)
        .map(|v| match &rings[v] {
            None => p[v],
            Some(r) if r.boundary => {
                let (a, b) = (r.verts[0], *r.verts.last().expect("non-empty"));
                (0.75 * d(p[v]) + 0.125 * (d(p[a as usize]) + d(p[b as usize]))).as_vec3()
            }
            Some(r) => {
                let k = r.verts.len();
                let b = beta(k);
                ((1.0 - k as f64 * b) * d(p[v]) + b * sum(&r.verts)).as_vec3()
            }
        })
        .collect();
    // The vertex opposite each directed edge.
    let mut opposite: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.indices.len());
    for t in mesh.indices.chunks_exact(3) {
        for k in 0..3 {
            opposite.insert((t[k], t[(k + 1) % 3]), t[(k + 2) % 3]);
        }
    }
    // Odd vertices, one per undirected edge.
    let mut edge_vertex: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.indices.len());
    let mut odd = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&i) = edge_vertex.get(&key) {
            return i;
        }
        let (pa, pb) = (d(p[a as usize]), d(p[b as usize]));
        let q = match (opposite.get(&(a, b)), opposite.get(&(b, a))) {
            (Some(&c), Some(&e)) => {
                0.375 * (pa + pb) + 0.125 * (d(p[c as usize]) + d(p[e as usize]))
            }
            _ => 0.5 * (pa + pb),
        };
        let i = positions.len() as u32;
        positions.push(q.as_vec3());
        edge_vertex.insert(key, i);
        i
    };
    let mut indices = Vec::with_capacity(mesh.indices.len() * 4);
    for t in mesh.indices.chunks_exact(3) {
        let (a, b, c) = (t[0], t[1], t[2]);
        let ab = odd(a, b, &mut positions);
        let bc = odd(b, c, &mut positions);
        let ca = odd(c, a, &mut positions);
        indices.extend_from_slice(&[a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca]);
    }
    Ok(LoopMesh {
        positions,
        normals: Vec::new(),
        indices,
    })
}

/// Push every vertex to its limit position and give it the limit surface's normal (oriented
/// with the triangles' winding).
pub fn limit(mesh: &LoopMesh) -> Result<LoopMesh, String> {
    let n = mesh.positions.len();
    let rings = rings(n, &mesh.indices)?;
    let p = &mesh.positions;
    let at = |i: u32| d(p[i as usize]);
    // Winding normals (area-weighted) to orient, and to stand in where a mask degenerates.
    let mut face_n = vec![DVec3::ZERO; n];
    for t in mesh.indices.chunks_exact(3) {
        let f = (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
        for &v in t {
            face_n[v as usize] += f;
        }
    }
    let mut positions = Vec::with_capacity(n);
    let mut normals = Vec::with_capacity(n);
    for v in 0..n {
        let pv = d(p[v]);
        let Some(r) = &rings[v] else {
            positions.push(p[v]);
            normals.push(Vec3::Z);
            continue;
        };
        let ring: Vec<DVec3> = r.verts.iter().map(|&i| at(i)).collect();
        let k = ring.len();
        let (lim, s, t) = if r.boundary {
            let lim = (4.0 * pv + ring[0] + ring[k - 1]) / 6.0;
            let s = ring[k - 1] - ring[0];
            let t = match k {
                2 => ring[0] + ring[1] - 2.0 * pv,
                3 => ring[1] - pv,
                4 => -ring[0] + 2.0 * ring[1] + 2.0 * ring[2] - ring[3] - 2.0 * pv,
                _ => {
                    let th = PI / (k - 1) as f64;
                    let mut t = th.sin() * (ring[0] + ring[k - 1]);
                    for (i, q) in ring.iter().enumerate().take(k - 1).skip(1) {
                        t += (2.0 * th.cos() - 2.0) * (th * i as f64).sin() * *q;
                    }
                    -t
                }
            };
            (lim, s, t)
        } else {
            let g = 1.0 / (k as f64 + 3.0 / (8.0 * beta(k)));
            let lim = (1.0 - k as f64 * g) * pv + g * ring.iter().sum::<DVec3>();
            let (mut s, mut t) = (DVec3::ZERO, DVec3::ZERO);
            for (i, q) in ring.iter().enumerate() {
                let a = 2.0 * PI * i as f64 / k as f64;
                s += a.cos() * *q;
                t += a.sin() * *q;
            }
            (lim, s, t)
        };
        let mut nrm = s.cross(t);
        let len = nrm.length();
        if !(len > 1e-12 * face_n[v].length().max(1e-300)) || !len.is_finite() {
            nrm = face_n[v];
        }
        if nrm.dot(face_n[v]) < 0.0 {
            nrm = -nrm;
        }
        positions.push(lim.as_vec3());
        normals.push(nrm.normalize_or_zero().as_vec3());
    }
    Ok(LoopMesh {
        positions,
        normals,
        indices: mesh.indices.clone(),
    })
}

/// `levels` levels of Loop subdivision of a triangle mesh, at the limit surface with its
/// normals. Errors (nothing changed) when the mesh is not a consistently oriented
/// edge-manifold.
pub fn loop_subdivide(
    positions: &[Vec3],
    indices: &[u32],
    levels: u32,
) -> Result<LoopMesh, String> {
    let mut mesh = LoopMesh {
        positions: positions.to_vec(),
        normals: Vec::new(),
        indices: indices.to_vec(),
    };
    for _ in 0..levels {
        mesh = subdivide_once(&mesh)?;
    }
    limit(&mesh)
}
