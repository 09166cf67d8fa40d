//! Watertight ray–triangle intersection (Woop, Benthin & Wald 2013, as in pbrt-v4): rays
//! through a shared edge or vertex of a mesh hit at least one of its triangles (no cracks),
//! because the edge functions of neighbours are computed from the same vertices in the same
//! ray-sheared space.
//!
//! A hit whose t is not provably positive is rejected ([`self_hit_bound`]): a ray spawned on
//! a surface starts on it or, offset by the hit's error bound, on the side it leaves to, so
//! its true distance to that surface (and to coplanar neighbours) is ≤ 0 and only rounding
//! can make the computed t positive. The spawn offset alone cannot prevent that: on a plane
//! y = 0 the error bound and hence the offset are exactly zero, and elsewhere the rounding
//! of this test grows with the vertices' distance from the origin of the ray, not with the
//! hit point's coordinates that the offset is made of.

use super::float::gamma;
use glam::{DVec2, Vec3, Vec3A};
use std::ops::{Add, Mul};

/// Conservative bound on the rounding error of the test's scaled distance
/// `t_scaled = e0·z0 + e1·z1 + e2·z2` (= t·det), from the largest magnitudes `mx`, `my`, `mz`
/// of the three vertices' ray-space coordinates and the ray direction's components `adx`,
/// `ady` (absolute values) along the sheared axes: a hit with |t_scaled| ≤ this cannot be
/// told from t ≤ 0 and is rejected. `k` splats a constant. One definition for the one-ray,
/// 4-wide and 16-lane tests, so all three round it identically.
///
/// The error analysis of pbrt-v4's triangle test (*Physically Based Rendering*, 4th ed.,
/// "Managing Rounding Error"), recast for this arithmetic:
/// * sheared x = fl(X + fl(Z·sx)) with X, Z the translated coordinates: its error is at most
///   γ₂·|x| + γ₅·|sx·Z|, and |sx·Z| = |dx|·|z|(1 + γ₃) because z = Z/dz. Hence
///   δx ≤ γ₆·(mx + |dx|·mz), and likewise δy. (Written with |dx|·mz rather than pbrt's mz,
///   the bound holds for unnormalised directions too: shadow rays span origin to light.)
/// * z = fl(fl(Z)·sz): δz ≤ γ₂·|z| (the rounding of sz scales every z alike, which moves t
///   but not its sign).
/// * each edge function e = fl(fl(a·b) − fl(c·d)) has |e| ≤ 2·mx·my·(1 + γ₂) and error
///   δe ≤ 2·(γ₂·mx·my + δx·my + δy·mx);
/// * the sum of three products e·z: ≤ 3·(δe·mz + |e|·δz + γ₃·|e|·mz).
///
/// Collected: mz·(A·mx·my + B·mz·(|dx|·my + |dy|·mx)) with A = 3·(2γ₂ + 4γ₆ + 4γ₃(1 + γ₂))
/// and B = 6γ₆. Replacing max|e| by its bound 2·mx·my (pbrt computes it) saves the lanes
/// four operations for a bound at most ~1.5× larger. The bound's own rounding (six
/// operations, ~6ε relative) is far inside the slack of the γ's.
#[inline(always)]
pub fn self_hit_bound<T>(mx: T, my: T, mz: T, adx: T, ady: T, k: impl Fn(f32) -> T) -> T
where
    T: Copy + Add<Output = T> + Mul<Output = T>,
{
    const A: f32 = 3.0 * (2.0 * gamma(2) + 4.0 * gamma(6) + 4.0 * gamma(3) * (1.0 + gamma(2)));
    const B: f32 = 6.0 * gamma(6);
    mz * (k(A) * (mx * my) + k(B) * (mz * (adx * my + ady * mx)))
}

/// Per-ray constants of the shear that maps the ray to +z through the origin, stored as the
/// rows of the shear matrix so that each vertex is transformed by three dot products instead of
/// runtime-indexed component shuffles (the same numbers, fewer instructions).
#[derive(Clone, Copy, Debug)]
pub struct RayShear {
    o: Vec3,
    rx: Vec3,
    ry: Vec3,
    rz: Vec3,
    /// |d| along the sheared x and y axes (for [`self_hit_bound`]).
    adx: f32,
    ady: f32,
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
            adx: d[kx].abs(),
            ady: d[ky].abs(),
        }
    }

    /// Intersect triangle (p0, p1, p2); returns (t, b0, b1, b2) with t in (0, t_max) and t
    /// provably positive (beyond [`self_hit_bound`]).
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
        let max3 = |a: f32, b: f32, c: f32| a.abs().max(b.abs()).max(c.abs());
        let (mx, my, mz) = (max3(ax, bx, cx), max3(ay, by, cy), max3(az, bz, cz));
        // `!(>)` rather than `<=`: the vector tests keep lanes whose |t_scaled| exceeds the
        // bound, so a NaN bound must reject here too.
        if !(t_scaled.abs() > self_hit_bound(mx, my, mz, self.adx, self.ady, |c| c)) {
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
    // A `static` table, built once (a literal array would be built again for every ray).
    static KZ: [usize; 4] = [2, 1, 0, 0];
    let kz = KZ[(x_max as usize) << 1 | y_max as usize];
    // `d[kz] < 0` from one vector compare: mis-area 2717 → 2713 Ir/sample (558ef04).
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

/// The factor of [`barycentric_error`]: pbrt-v4's γ7 bounds the error of the barycentric
/// point, and γ2 more clears the rounding of the spawn offset's sum p + ng·d (at most half an
/// ulp of each coordinate, about γ1 of the summands' magnitudes), so that
/// `SurfaceHit::spawn_origin` needs no per-coordinate step away from p (pbrt's
/// `OffsetRayOrigin` takes one; here that cost the light-sample lane kernel 3% of its Ir).
pub const POINT_ERROR_GAMMA: f32 = gamma(9);

/// Conservative absolute error of the barycentric point b0·p0 + b1·p1 + b2·p2, per axis, with
/// room for the rounding of a spawned ray's origin ([`POINT_ERROR_GAMMA`] times the
/// magnitudes of the summands).
#[inline]
pub fn barycentric_error(b: [f32; 3], p: [Vec3; 3]) -> Vec3 {
    ((p[0] * b[0]).abs() + (p[1] * b[1]).abs() + (p[2] * b[2]).abs()) * POINT_ERROR_GAMMA
}
