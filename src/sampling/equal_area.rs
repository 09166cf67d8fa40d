//! Clarberg's equal-area octahedral mapping between the unit square and the unit sphere, as
//! pbrt-v4 uses it for environment maps and the spherical camera (pbrt-v4 §3.8.3).
//!
//! The square [0,1]² is centred and folded like an octahedron: the inner diamond
//! |u'| + |v'| ≤ 1 (u' = 2u − 1, v' = 2v − 1) is the upper hemisphere z ≥ 0 with the pole at
//! the centre, the four corner triangles the lower one with the pole at the corners. Every
//! region of the square covers a solid angle 4π times its area, so a piecewise-constant
//! density p(u, v) over the square is the density p/(4π) per steradian.

use glam::{Vec2, Vec3};

/// The direction of square point `p ∈ [0,1]²` (unit length).
pub fn equal_area_square_to_sphere(p: Vec2) -> Vec3 {
    let u = 2.0 * p.x - 1.0;
    let v = 2.0 * p.y - 1.0;
    let (up, vp) = (u.abs(), v.abs());
    // Signed distance from the diagonal |u| + |v| = 1: positive inside the upper diamond.
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    // φ within the quadrant, from the position along the diamond's edge.
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * std::f32::consts::FRAC_PI_4;
    let z = (1.0 - r * r).copysign(signed);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(cos_phi.copysign(u) * s, sin_phi.copysign(v) * s, z)
}

/// The square point of direction `d` (need not be unit length; zero maps to the centre):
/// the inverse of [`equal_area_square_to_sphere`].
pub fn equal_area_sphere_to_square(d: Vec3) -> Vec2 {
    let d = d.normalize_or_zero();
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let t = if a == 0.0 { 0.0 } else { b / a };
    // φ/(π/2) within the quadrant, measured from the nearer axis.
    let mut phi = t.atan() * std::f32::consts::FRAC_2_PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    let u = u.copysign(d.x);
    let v = v.copysign(d.y);
    Vec2::new(0.5 * (u + 1.0), 0.5 * (v + 1.0))
}

/// Fold a point just outside [0,1]² back in the way the octahedral map continues across its
/// edges (an edge meets its mirror image: crossing u = 0 at v lands at u = 0 at 1 − v).
pub fn wrap_equal_area_square(mut p: Vec2) -> Vec2 {
    if p.x < 0.0 {
        p.x = -p.x;
        p.y = 1.0 - p.y;
    } else if p.x > 1.0 {
        p.x = 2.0 - p.x;
        p.y = 1.0 - p.y;
    }
    if p.y < 0.0 {
        p.x = 1.0 - p.x;
        p.y = -p.y;
    } else if p.y > 1.0 {
        p.x = 1.0 - p.x;
        p.y = 2.0 - p.y;
    }
    p
}

/// The texel (x, y) of an `n × n` octahedral image that holds texel coordinates `(x, y)`,
/// which may lie one image width outside: pbrt-v4's `WrapMode::OctahedralSphere`.
pub fn wrap_octahedral_texel(mut x: i64, mut y: i64, n: i64) -> (usize, usize) {
    if x < 0 {
        x = -x - 1;
        y = n - 1 - y;
    } else if x >= n {
        x = 2 * n - 1 - x;
        y = n - 1 - y;
    }
    if y < 0 {
        x = n - 1 - x;
        y = -y - 1;
    } else if y >= n {
        x = n - 1 - x;
        y = 2 * n - 1 - y;
    }
    (x.clamp(0, n - 1) as usize, y.clamp(0, n - 1) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::hash::{next_f32, pcg_from_keys};

    #[test]
    fn poles_axes_and_corners() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        assert!(close(
            equal_area_square_to_sphere(Vec2::splat(0.5)),
            Vec3::Z
        ));
        for c in [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE] {
            assert!(close(equal_area_square_to_sphere(c), -Vec3::Z));
        }
        // Edge midpoints of the square are on the equator's axes.
        assert!(close(
            equal_area_square_to_sphere(Vec2::new(1.0, 0.5)),
            Vec3::X
        ));
        assert!(close(
            equal_area_square_to_sphere(Vec2::new(0.5, 1.0)),
            Vec3::Y
        ));
        assert!(close(
            equal_area_square_to_sphere(Vec2::new(0.0, 0.5)),
            -Vec3::X
        ));
        assert!(close(
            equal_area_square_to_sphere(Vec2::new(0.5, 0.0)),
            -Vec3::Y
        ));
    }

    #[test]
    fn round_trip_both_ways_for_random_points() {
        let mut rng = pcg_from_keys(&[7, 11]);
        for _ in 0..100_000 {
            let p = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
            let d = equal_area_square_to_sphere(p);
            assert!((d.length() - 1.0).abs() < 1e-5, "{p} -> {d}");
            let q = equal_area_sphere_to_square(d);
            assert!((p - q).abs().max_element() < 2e-5, "{p} -> {d} -> {q}");
            let e = equal_area_square_to_sphere(q);
            assert!((d - e).length() < 2e-5);
        }
    }

    #[test]
    fn equal_area_cells_cover_equal_solid_angles() {
        // Each of 8×8 cells covers 4π/64 sr: Monte Carlo over uniform directions.
        let mut rng = pcg_from_keys(&[3]);
        let n = 400_000;
        let mut counts = [0u32; 64];
        for _ in 0..n {
            let d =
                crate::sampling::uniform_sphere(Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
            let q = equal_area_sphere_to_square(d);
            let (i, j) = (((q.x * 8.0) as usize).min(7), ((q.y * 8.0) as usize).min(7));
            counts[j * 8 + i] += 1;
        }
        let mean = n as f64 / 64.0;
        for c in counts {
            // 5σ of a binomial count.
            assert!(
                ((c as f64) - mean).abs() < 5.0 * mean.sqrt(),
                "{c} vs {mean}"
            );
        }
    }

    #[test]
    fn wraps_continue_the_sphere_across_edges() {
        // A point just outside an edge lands on the far side of that edge on the sphere: its
        // direction and that of the mirror point just inside straddle the edge's direction
        // (clamping would put it on the edge, mirroring in place on top of the inside point).
        // (Away from the edges' midpoints, where the fold's two sides meet at an equator
        // axis and both points land on the same side.)
        let mut rng = pcg_from_keys(&[5]);
        for _ in 0..10_000 {
            let t = 0.05 + 0.3 * next_f32(&mut rng);
            let t = if next_f32(&mut rng) < 0.5 { t } else { 1.0 - t };
            let e = 1e-3 * (0.1 + next_f32(&mut rng));
            for (outside, inside, edge) in [
                (Vec2::new(-e, t), Vec2::new(e, t), Vec2::new(0.0, t)),
                (
                    Vec2::new(1.0 + e, t),
                    Vec2::new(1.0 - e, t),
                    Vec2::new(1.0, t),
                ),
                (Vec2::new(t, -e), Vec2::new(t, e), Vec2::new(t, 0.0)),
                (
                    Vec2::new(t, 1.0 + e),
                    Vec2::new(t, 1.0 - e),
                    Vec2::new(t, 1.0),
                ),
            ] {
                let a = equal_area_square_to_sphere(wrap_equal_area_square(outside));
                let b = equal_area_square_to_sphere(inside);
                let c = equal_area_square_to_sphere(edge);
                let (ac, bc, ab) = ((a - c).length(), (b - c).length(), (a - b).length());
                assert!(ac < 1e-2 && bc < 1e-2, "{outside}: {a} {b} {c}");
                assert!(ab > 1.2 * ac.max(bc), "{outside}: not across the edge");
            }
        }
        assert_eq!(wrap_octahedral_texel(-1, 2, 8), (0, 5));
        assert_eq!(wrap_octahedral_texel(8, 2, 8), (7, 5));
        assert_eq!(wrap_octahedral_texel(3, -1, 8), (4, 0));
        assert_eq!(wrap_octahedral_texel(3, 8, 8), (4, 7));
        assert_eq!(wrap_octahedral_texel(3, 4, 8), (3, 4));
    }
}
