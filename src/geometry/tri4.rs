//! Four triangles against one ray at once: the watertight test of [`super::triangle`] with each
//! step done on four lanes (glam's `Vec4`, SSE2 on x86-64, a scalar fallback elsewhere).
//!
//! Every lane performs the same f32 operations in the same order as [`RayShear::intersect`]
//! (the shear rows there have one unit and one zero entry, so their dot products round exactly
//! like `a[kx] + sx·a[kz]` here), hence t, the barycentrics and the self-hit rejection
//! ([`self_hit_bound`]) are bit-identical. Lanes whose
//! edge functions are exactly 0 in f32 are redone by the scalar test, whose f64 fallback keeps
//! neighbouring triangles in agreement on shared edges (watertightness).

use super::triangle::{RayShear, self_hit_bound, shear_axes};
use glam::{Vec3, Vec4};

/// Four triangles in SoA layout, one leaf packet of the wide BVH. Aligned to a cache line:
/// 169 bytes padded to 192, so that a packet spans exactly three lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct TriPacket {
    /// `v[vertex][axis]`: that coordinate of the four lanes (unused lanes hold NaN).
    pub v: [[Vec4; 3]; 3],
    /// Leaf-order primitive ids of the lanes (`u32::MAX` for unused lanes).
    pub ids: [u32; 4],
    /// Lanes that hold triangles (bit i = lane i).
    pub tri: u32,
    /// Lanes that hold other primitives (quadrics), which the caller tests.
    pub other: u32,
    /// True for the last packet of a leaf (leaves are runs of consecutive packets).
    pub last: bool,
}

impl TriPacket {
    /// A packet with no primitive in any lane.
    pub const EMPTY: TriPacket = TriPacket {
        v: [[Vec4::NAN; 3]; 3],
        ids: [u32::MAX; 4],
        tri: 0,
        other: 0,
        last: false,
    };

    /// Put triangle `p` (leaf-order id `id`) into `lane`.
    pub fn set_triangle(&mut self, lane: usize, id: u32, p: [Vec3; 3]) {
        for (j, v) in p.iter().enumerate() {
            for axis in 0..3 {
                self.v[j][axis][lane] = v[axis];
            }
        }
        self.ids[lane] = id;
        self.tri |= 1 << lane;
    }

    /// Put a non-triangle primitive (leaf-order id `id`) into `lane`.
    pub fn set_other(&mut self, lane: usize, id: u32) {
        self.ids[lane] = id;
        self.other |= 1 << lane;
    }

    /// Vertex `j` of the triangle in `lane`.
    #[inline]
    fn vertex(&self, lane: usize, j: usize) -> Vec3 {
        let v = &self.v[j];
        Vec3::new(
            v[0].to_array()[lane],
            v[1].to_array()[lane],
            v[2].to_array()[lane],
        )
    }
}

/// A triangle hit inside a packet: lane, t and barycentrics (b0, b1, b2).
pub type LaneHit = (usize, f32, [f32; 3]);

/// Per-ray constants of the 4-wide test (the shear of [`RayShear`] as axis permutation plus
/// three factors, each splatted to four lanes).
#[derive(Clone, Copy, Debug)]
pub struct RayShear4 {
    k: [usize; 3],
    o: [Vec4; 3],
    s: [Vec4; 3],
    /// |d| along the sheared x and y axes, splatted (for `self_hit_bound`).
    ad: [Vec4; 2],
    /// The ray, for the scalar redo of exact-zero lanes (rare, so its shear is built lazily).
    ray: (Vec3, Vec3),
}

/// The vector part of a packet test.
struct Lanes {
    /// Lanes accepted by the f32 test.
    hit: u32,
    /// Triangle lanes with an exactly-zero edge function: to be redone by the scalar test.
    redo: u32,
    t: Vec4,
    e: [Vec4; 3],
    inv: Vec4,
}

impl RayShear4 {
    /// Precompute the shear for ray (o, d); `d` must be non-zero.
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let k = shear_axes(d);
        // Arrays, not `Vec3` indexing: glam's runtime `Index` is a `match` per access.
        let (oa, da) = (o.to_array(), d.to_array());
        let dz = da[k[2]];
        // One vector division instead of three scalar ones: IEEE quotients are the same, and
        // −(a / b) = (−a) / b exactly under round-to-nearest.
        let q = Vec4::new(-da[k[0]], -da[k[1]], 1.0, 1.0) / Vec4::splat(dz);
        Self {
            k,
            o: [
                Vec4::splat(oa[k[0]]),
                Vec4::splat(oa[k[1]]),
                Vec4::splat(oa[k[2]]),
            ],
            s: [Vec4::splat(q.x), Vec4::splat(q.y), Vec4::splat(q.z)],
            ad: [Vec4::splat(da[k[0]].abs()), Vec4::splat(da[k[1]].abs())],
            ray: (o, d),
        }
    }

    #[inline(always)]
    fn lanes(&self, pk: &TriPacket, t_max: f32) -> Lanes {
        let [kx, ky, kz] = self.k;
        // Ray-space vertex j: (x, y, z) with the same roundings as RayShear's dot products.
        let sheared = |j: usize| {
            let v = &pk.v[j];
            let (ax, ay, az) = (v[kx] - self.o[0], v[ky] - self.o[1], v[kz] - self.o[2]);
            (ax + az * self.s[0], ay + az * self.s[1], az * self.s[2])
        };
        let (ax, ay, az) = sheared(0);
        let (bx, by, bz) = sheared(1);
        let (cx, cy, cz) = sheared(2);
        let e0 = bx * cy - by * cx;
        let e1 = cx * ay - cy * ax;
        let e2 = ax * by - ay * bx;
        let zero = Vec4::ZERO;
        let redo = (e0.cmpeq(zero) | e1.cmpeq(zero) | e2.cmpeq(zero)).bitmask() & pk.tri;
        // Lanes whose edge functions differ in sign. Zero lanes are redone and NaN lanes fail
        // `in_range`, so for the remaining lanes comparing sign bits is the scalar test's
        // `(e < 0 for some) && (e > 0 for some)`.
        let n0 = e0.is_negative_bitmask();
        let mixed = (n0 ^ e1.is_negative_bitmask()) | (n0 ^ e2.is_negative_bitmask());
        let zero_lanes = Lanes {
            hit: 0,
            redo,
            t: zero,
            e: [e0, e1, e2],
            inv: zero,
        };
        if !mixed & pk.tri & !redo == 0 {
            // The ray's line passes by every triangle: skip the distances.
            return zero_lanes;
        }
        let det = e0 + e1 + e2;
        let t_scaled = e0 * az + e1 * bz + e2 * cz;
        let tmd = Vec4::splat(t_max) * det;
        // The scalar test's two sign cases in one: multiplying by ±1 is exact and turns
        // `det < 0 && t_scaled < 0 && t_scaled >= tmd` into the `det > 0` case. A zero det
        // fails (t_scaled·s > 0 and ≤ ±0 or NaN), as does NaN.
        let sgn = Vec4::ONE.copysign(det);
        let (ts, tm) = (t_scaled * sgn, tmd * sgn);
        let in_range = ts.cmpgt(zero) & ts.cmple(tm);
        let candidates = in_range.bitmask() & !mixed & pk.tri & !redo;
        if candidates == 0 {
            // The common miss: skip the division.
            return zero_lanes;
        }
        // Hits not provably in front of the origin (the scalar test's `self_hit_bound`).
        let max3 = |a: Vec4, b: Vec4, c: Vec4| a.abs().max(b.abs()).max(c.abs());
        let (mx, my, mz) = (max3(ax, bx, cx), max3(ay, by, cy), max3(az, bz, cz));
        let bound = self_hit_bound(mx, my, mz, self.ad[0], self.ad[1], Vec4::splat);
        let clear = ts.cmpgt(bound);
        let inv = Vec4::ONE / det;
        let t = t_scaled * inv;
        let ok = t.cmpgt(zero) & t.cmplt(Vec4::splat(t_max)) & clear;
        Lanes {
            hit: ok.bitmask() & candidates,
            redo,
            t,
            e: [e0, e1, e2],
            inv,
        }
    }

    /// Closest triangle hit in `pk` with t in (0, t_max); ties go to the lowest lane.
    #[inline(always)]
    pub fn closest(&self, pk: &TriPacket, t_max: f32) -> Option<LaneHit> {
        let h = self.lanes(pk, t_max);
        if h.hit | h.redo == 0 {
            return None;
        }
        // Arrays, not `Vec4` indexing by a runtime lane (glam's `Index` is a `match`).
        let t = h.t.to_array();
        let mut best_t = t_max;
        // The best lane, with its barycentrics only if the scalar redo produced them: those
        // of a vector lane are formed once below, not at every improvement.
        let mut best: Option<(usize, Option<[f32; 3]>)> = None;
        // Lanes in increasing order, so that equal t keeps the lowest lane.
        let mut lanes = h.hit | h.redo;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize & 3;
            lanes &= lanes - 1;
            if h.hit & (1 << lane) != 0 {
                if t[lane] < best_t {
                    best_t = t[lane];
                    best = Some((lane, None));
                }
            } else if let Some((tl, b0, b1, b2)) = redo_lane(self.ray, pk, lane, best_t) {
                best_t = tl;
                best = Some((lane, Some([b0, b1, b2])));
            }
        }
        let (lane, b) = best?;
        let b = b.unwrap_or_else(|| {
            let inv = h.inv.to_array()[lane];
            let e = [h.e[0].to_array(), h.e[1].to_array(), h.e[2].to_array()];
            [e[0][lane] * inv, e[1][lane] * inv, e[2][lane] * inv]
        });
        Some((lane, best_t, b))
    }

    /// True if any triangle of `pk` is hit with t in (0, t_max).
    #[inline(always)]
    pub fn any(&self, pk: &TriPacket, t_max: f32) -> bool {
        let h = self.lanes(pk, t_max);
        if h.hit != 0 {
            return true;
        }
        if h.redo == 0 {
            // The common miss: no scalar shear to build.
            return false;
        }
        // Inline here (unlike in `closest`): out of line measured 5 Ir per any-hit ray more.
        let mut redo = h.redo;
        let scalar = RayShear::new(self.ray.0, self.ray.1);
        while redo != 0 {
            let lane = redo.trailing_zeros() as usize & 3;
            redo &= redo - 1;
            let (p0, p1, p2) = (pk.vertex(lane, 0), pk.vertex(lane, 1), pk.vertex(lane, 2));
            if scalar.intersect(p0, p1, p2, t_max).is_some() {
                return true;
            }
        }
        false
    }
}

/// The scalar test of triangle `lane` of `pk` against `ray` (an exact-zero edge function in
/// f32). Cold and out of line: it almost never runs, and no ray should pay for its per-ray
/// setup; it takes the ray by value, not the `RayShear4` (ed2cc26, d907286).
#[cold]
#[inline(never)]
fn redo_lane(
    ray: (Vec3, Vec3),
    pk: &TriPacket,
    lane: usize,
    t_max: f32,
) -> Option<(f32, f32, f32, f32)> {
    let (p0, p1, p2) = (pk.vertex(lane, 0), pk.vertex(lane, 1), pk.vertex(lane, 2));
    RayShear::new(ray.0, ray.1).intersect(p0, p1, p2, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle::intersect_triangle;
    use crate::sampling::hash::{next_f32, pcg_from_keys};
    use rand_pcg::Pcg32;

    #[test]
    fn lanes_match_the_scalar_test_bit_for_bit() {
        let mut s = pcg_from_keys(&[7]);
        let rnd3 = |s: &mut Pcg32| Vec3::new(next_f32(s), next_f32(s), next_f32(s)) * 2.0 - 1.0;
        let (mut hits, mut checked, mut spawned) = (0, 0, 0);
        for _ in 0..20_000 {
            let mut pk = TriPacket::EMPTY;
            let mut tris = Vec::new();
            for lane in 0..3 {
                let p = [rnd3(&mut s), rnd3(&mut s), rnd3(&mut s)];
                pk.set_triangle(lane, lane as u32, p);
                tris.push(p);
            }
            // Lane 3 shares an edge with lane 0 so that exact-zero edge functions occur.
            let p = [tris[0][1], tris[0][0], rnd3(&mut s)];
            pk.set_triangle(3, 3, p);
            tris.push(p);
            let mut o = rnd3(&mut s) * 2.0;
            let pick = next_f32(&mut s);
            let d = if pick < 0.2 {
                // Rays through a shared vertex.
                tris[0][0] - o
            } else {
                rnd3(&mut s)
            };
            let from_lane0 = pick > 0.8;
            if from_lane0 {
                // Rays leaving a point of lane 0's triangle: its own hit, at t ≈ 0 in
                // rounding, must be rejected by both tests alike (`self_hit_bound`).
                let (a, b) = (next_f32(&mut s), next_f32(&mut s));
                let (a, b) = if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                };
                let t = tris[0];
                o = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
            }
            let t_max = if next_f32(&mut s) < 0.5 {
                f32::INFINITY
            } else {
                3.0
            };
            let r4 = RayShear4::new(o, d);
            let want = tris
                .iter()
                .enumerate()
                .filter_map(|(i, p)| intersect_triangle(o, d, t_max, *p).map(|h| (i, h)))
                .fold(
                    None::<(usize, (f32, f32, f32, f32))>,
                    |best, (i, h)| match best {
                        Some((_, b)) if b.0 <= h.0 => best,
                        _ => Some((i, h)),
                    },
                );
            let got = r4.closest(&pk, t_max);
            checked += 1;
            if from_lane0 {
                spawned += 1;
                let scalar_self = intersect_triangle(o, d, t_max, tris[0]);
                assert!(
                    scalar_self.is_none_or(|h| h.0 > 1e-3),
                    "self-hit {scalar_self:?} from {o} along {d}"
                );
            }
            match (want, got) {
                (None, None) => {}
                (Some((i, (t, b0, b1, b2))), Some((lane, tg, bg))) => {
                    hits += 1;
                    assert_eq!((i, t, [b0, b1, b2]), (lane, tg, bg));
                }
                _ => panic!("scalar {want:?} vs packet {got:?}"),
            }
            assert_eq!(r4.any(&pk, t_max), want.is_some());
        }
        assert!(hits > checked / 20, "{hits} hits of {checked}");
        assert!(
            spawned > checked / 10,
            "{spawned} rays from lane 0 of {checked}"
        );
    }
}
