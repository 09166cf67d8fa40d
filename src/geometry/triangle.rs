//! Watertight ray–triangle intersection (Woop, Benthin & Wald 2013, as in pbrt-v4): rays
//! through a shared edge or vertex of a mesh hit at least one of its triangles (no cracks),
//! because the edge functions of neighbours are computed from the same vertices in the same
//! ray-sheared space.

use super::float::gamma;
use glam::{DVec2, Vec3, Vec3A};

/// Per-ray constants of the shear that maps the ray to +z through the origin, stored as the
/// rows of the shear matrix so that each vertex is transformed by three dot products instead of
/// runtime-indexed component shuffles (the same numbers, fewer instructions).
#[derive(Clone, Copy, Debug)]
pub struct RayShear {
    o: Vec3,
    rx: Vec3,
    ry: Vec3,
    rz: Vec3,
}

impl RayShear {
    /// Precompute the shear for ray (o, d); `d` must be non-zero.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let [kx, ky, kz] = shear_axes(d);
        let dz = d[kz];
        let unit = |k: usize| Vec3::AXES[k];
        Self {
            o,
            rx: unit(kx) - unit(kz) * (d[kx] / dz),
            ry: unit(ky) - unit(kz) * (d[ky] / dz),
            rz: unit(kz) * (1.0 / dz),
        }
    }

    /// Intersect triangle (p0, p1, p2); returns (t, b0, b1, b2) with t in (0, t_max).
    #[inline(always)]
    pub fn intersect(
        &self,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
        t_max: f32,
    ) -> Option<(f32, f32, f32, f32)> {
        let a = p0 - self.o;
        let b = p1 - self.o;
        let c = p2 - self.o;
        let (ax, ay) = (self.rx.dot(a), self.ry.dot(a));
        let (bx, by) = (self.rx.dot(b), self.ry.dot(b));
        let (cx, cy) = (self.rx.dot(c), self.ry.dot(c));
        let mut e0 = bx * cy - by * cx;
        let mut e1 = cx * ay - cy * ax;
        let mut e2 = ax * by - ay * bx;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            // Exactly on an edge in f32: decide in f64 so neighbours agree.
            let (a2, b2, c2) = (
                DVec2::new(ax as f64, ay as f64),
                DVec2::new(bx as f64, by as f64),
                DVec2::new(cx as f64, cy as f64),
            );
            e0 = (b2.x * c2.y - b2.y * c2.x) as f32;
            e1 = (c2.x * a2.y - c2.y * a2.x) as f32;
            e2 = (a2.x * b2.y - a2.y * b2.x) as f32;
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 {
            return None;
        }
        let (az, bz, cz) = (self.rz.dot(a), self.rz.dot(b), self.rz.dot(c));
        let t_scaled = e0 * az + e1 * bz + e2 * cz;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv = 1.0 / det;
        let t = t_scaled * inv;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, e0 * inv, e1 * inv, e2 * inv))
    }
}

/// The axes (kx, ky, kz) of the ray-space permutation: kz is the dominant axis of `d`, and kx,
/// ky are swapped when d[kz] < 0 to keep the handedness (so edge-function signs are consistent).
/// Shared by [`RayShear`] and the 4-wide test so that both transform vertices identically.
#[inline]
pub fn shear_axes(d: Vec3) -> [usize; 3] {
    // Branch-free: the dominant axis of a random direction is unpredictable. kz is 0 if
    // |x| > |y| and |x| > |z|, else 1 if |y| > |z|, else 2 (ties go to the later axis).
    let a = d.abs();
    let x_gt_y = a.x > a.y;
    let x_max = x_gt_y & (a.x > a.z);
    let y_max = !x_gt_y & (a.y > a.z);
    // A `static` table is one load; a literal array is built on the stack at every call.
    static KZ: [usize; 4] = [2, 1, 0, 0];
    let kz = KZ[(x_max as usize) << 1 | y_max as usize];
    // `d[kz] < 0` from one vector compare (an indexed array would go through the stack).
    let neg = (Vec3A::from(d).cmplt(Vec3A::ZERO).bitmask() as usize >> kz) & 1;
    // (kx, ky) = (kz + 1, kz + 2) mod 3, swapped when d[kz] < 0.
    const AXES: [[usize; 3]; 8] = [
        [1, 2, 0],
        [2, 0, 1],
        [0, 1, 2],
        [0, 1, 2],
        [2, 1, 0],
        [0, 2, 1],
        [1, 0, 2],
        [1, 0, 2],
    ];
    AXES[(kz | neg << 2) & 7]
}

/// Intersect the ray (o, d) with triangle (p0, p1, p2); returns (t, b0, b1, b2).
#[inline]
pub fn intersect_triangle(
    o: Vec3,
    d: Vec3,
    t_max: f32,
    p: [Vec3; 3],
) -> Option<(f32, f32, f32, f32)> {
    RayShear::new(o, d).intersect(p[0], p[1], p[2], t_max)
}

/// Conservative absolute error of the barycentric point b0·p0 + b1·p1 + b2·p2 (pbrt-v4's
/// bound, γ(7) times the magnitudes of the summands), per axis.
#[inline]
pub fn barycentric_error(b: [f32; 3], p: [Vec3; 3]) -> Vec3 {
    ((p[0] * b[0]).abs() + (p[1] * b[1]).abs() + (p[2] * b[2]).abs()) * gamma(7)
}
