//! Ray–triangle intersection (Möller–Trumbore) and the hit record of a mesh triangle.

use super::float::gamma;
use glam::Vec3;

/// Intersect the ray (o, d) with triangle (p0, p0+e1, p0+e2); returns (t, b1, b2) with
/// t in (0, t_max). Edges are inclusive so that rays through a shared edge of a closed mesh hit
/// one of its two triangles (no cracks).
#[inline(always)]
pub fn intersect_triangle(
    o: Vec3,
    d: Vec3,
    t_max: f32,
    p0: Vec3,
    e1: Vec3,
    e2: Vec3,
) -> Option<(f32, f32, f32)> {
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - p0;
    let b1 = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qv = tv.cross(e1);
    let b2 = d.dot(qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    if t > 0.0 && t < t_max { Some((t, b1, b2)) } else { None }
}

/// Conservative absolute error of the barycentric point b0·p0 + b1·p1 + b2·p2 (pbrt-v4's
/// bound, γ(7) times the magnitudes of the summands), per axis.
#[inline]
pub fn barycentric_error(b: [f32; 3], p: [Vec3; 3]) -> Vec3 {
    ((p[0] * b[0]).abs() + (p[1] * b[1]).abs() + (p[2] * b[2]).abs()) * gamma(7)
}
