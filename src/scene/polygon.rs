//! Triangulation of the polygon faces of OBJ and PLY files: O(n) for the convex polygons files
//! almost always hold, ear clipping (`earcut`, z-order hashed for large polygons) for the
//! others.
//!
//! Triangles are what the BVH is built from, so their shape matters as much as their count: a
//! fan from one vertex of an n-gon gives n − 2 slivers whose boxes all overlap near that vertex,
//! and the BVH build degrades to quadratic time on them (a 40,000-vertex polygon took 32 s to
//! load, a 300,000-vertex one did not finish in 5 minutes). A polygon is therefore first split
//! by halving its chain of vertices recursively: the triangles form a balanced tree whose small
//! ones line the boundary and whose boxes barely overlap. That split is kept when it tiles the
//! polygon (always for convex ones), which one pass over its triangles' signed areas decides.

use glam::{DVec2, DVec3, Vec3};

/// How a polygon with more than four vertices was triangulated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Three or four vertices: the triangle itself, or the quad split along (0, 2) as pbrt does.
    Small,
    /// Convex in its plane (up to rounding): balanced split of the vertex chain.
    Balanced,
    /// Concave but simple: ear clipping (`earcut`).
    Ears,
    /// Not a simple polygon in any plane (self-intersecting, or no area): fan from vertex 0,
    /// whose zero-area triangles mesh repair then drops.
    Fan,
}

/// Append the triangles of polygon `poly` (indices into `positions`, in order) to `out`, with
/// the polygon's winding. Fewer than three vertices add nothing.
pub fn triangulate(poly: &[u32], positions: &[Vec3], out: &mut Vec<u32>) -> Split {
    let n = poly.len();
    match n {
        0..=2 => return Split::Small,
        3 => {
            out.extend_from_slice(poly);
            return Split::Small;
        }
        4 => {
            out.extend_from_slice(&[poly[0], poly[1], poly[2], poly[0], poly[2], poly[3]]);
            return Split::Small;
        }
        _ => {}
    }
    let p = |k: usize| -> DVec3 {
        positions
            .get(poly[k] as usize)
            .map_or(DVec3::ZERO, |v| v.as_dvec3())
    };
    let normal = newell_normal(n, &p);
    let Some(flat) = project(n, &p, normal) else {
        fan(poly, out);
        return Split::Fan;
    };
    out.reserve(3 * (n - 2));
    let start = out.len();
    balanced(poly, out);
    if balanced_is_exact(&flat, &mut out[start..]) {
        return Split::Balanced;
    }
    out.truncate(start);
    let mut tris: Vec<u32> = Vec::with_capacity(3 * (n - 2));
    let xy: Vec<[f64; 2]> = flat.iter().map(|v| [v.x, v.y]).collect();
    earcut::Earcut::new().earcut_slice(&xy, &[] as &[u32], &mut tris);
    if tris.len() != 3 * (n - 2) {
        fan(poly, out);
        return Split::Fan;
    }
    // Ear clipping leaves slivers; Delaunay edge flips (boundary kept) fatten them.
    earcut::refine(&mut tris, &xy);
    for t in tris.chunks_exact(3) {
        let (a, b, c) = (t[0] as usize, t[1] as usize, t[2] as usize);
        // Keep the polygon's winding whatever orientation earcut emits.
        let w = (flat[b] - flat[a]).perp_dot(flat[c] - flat[a]);
        if w >= 0.0 {
            out.extend_from_slice(&[poly[a], poly[b], poly[c]]);
        } else {
            out.extend_from_slice(&[poly[a], poly[c], poly[b]]);
        }
    }
    Split::Ears
}

/// Whether the balanced split `tris` (of the polygon with projected vertices `flat`) covers
/// the polygon. The signed areas of any split of the closed chain add up to its winding
/// number, so if no triangle is clockwise they tile the polygon exactly. Rounding in the
/// input (a finely sampled curve written with 7 decimals has many slightly reflex vertices)
/// makes a few tiny triangles clockwise; up to a total of 1e-6 of the polygon's area they are
/// accepted, turned to the polygon's winding (they double a sliver no pixel can see).
fn balanced_is_exact(flat: &[DVec2], tris: &mut [u32]) -> bool {
    let mut total = 0.0;
    let mut negative = 0.0;
    let mut k = 0;
    for_each_balanced(flat.len(), |i, m, j| {
        let a = 0.5 * (flat[m] - flat[i]).perp_dot(flat[j] - flat[i]);
        total += a;
        if a < 0.0 {
            negative -= a;
            tris.swap(3 * k + 1, 3 * k + 2);
        }
        k += 1;
    });
    total > 0.0 && negative <= 1e-6 * total
}

/// Newell's normal: robust for non-planar and partly collinear polygons; its length is twice
/// the projected area.
fn newell_normal(n: usize, p: &impl Fn(usize) -> DVec3) -> DVec3 {
    let c = p(0);
    let mut sum = DVec3::ZERO;
    for k in 0..n {
        let (a, b) = (p(k) - c, p((k + 1) % n) - c);
        sum += a.cross(b);
    }
    sum
}

/// The polygon in the plane of `normal`, oriented counter-clockwise; `None` if it has no area
/// or a non-finite vertex.
fn project(n: usize, p: &impl Fn(usize) -> DVec3, normal: DVec3) -> Option<Vec<DVec2>> {
    if !(normal.is_finite() && normal.length_squared() > 0.0) {
        return None;
    }
    let a = normal.abs();
    // Drop the dominant axis; order the two kept ones so that (u, v, normal) is right-handed.
    let (u, v, s) = if a.z >= a.x && a.z >= a.y {
        (0, 1, normal.z)
    } else if a.x >= a.y {
        (1, 2, normal.x)
    } else {
        (2, 0, normal.y)
    };
    let sign = if s >= 0.0 { 1.0 } else { -1.0 };
    Some(
        (0..n)
            .map(|k| {
                let q = p(k);
                DVec2::new(q[u], sign * q[v])
            })
            .collect(),
    )
}

/// The balanced split of an n-chain, as positions in the chain: (i, m, j) with m halving
/// i..j, then each half, depth first.
fn for_each_balanced(n: usize, mut f: impl FnMut(usize, usize, usize)) {
    let mut stack = vec![(0usize, n - 1)];
    while let Some((i, j)) = stack.pop() {
        if j - i < 2 {
            continue;
        }
        let m = i + (j - i) / 2;
        f(i, m, j);
        stack.push((m, j));
        stack.push((i, m));
    }
}

fn balanced(poly: &[u32], out: &mut Vec<u32>) {
    for_each_balanced(poly.len(), |i, m, j| {
        out.extend_from_slice(&[poly[i], poly[m], poly[j]]);
    });
}

fn fan(poly: &[u32], out: &mut Vec<u32>) {
    for k in 1..poly.len() - 1 {
        out.extend_from_slice(&[poly[0], poly[k], poly[k + 1]]);
    }
}
