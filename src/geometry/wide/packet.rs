//! Sixteen rays through the wide BVH at once (the packet queries of
//! [`Geometry`](crate::geometry::Geometry)): coherent camera rays of one pixel, shadow rays
//! from nearby points toward one light.
//!
//! One traversal serves the whole packet: each node's four child boxes are tested against
//! every ray, with each ray's own arithmetic of `Node4::hit` and its own best distance, so a
//! ray's box verdicts are the one-ray ones, and a leaf's triangles are tested against the rays
//! that passed its box, each lane doing [`RayShear4`](crate::geometry::tri4::RayShear4)'s f32
//! operations. The kernels are generic over the 16-lane vector type of `simd16` (AVX-512,
//! AVX2 or portable lane loops, picked at run time: [`Cpu::dispatch`]).
//!
//! Why the closest hit is the one-ray one: a triangle (or quadric) test accepts a hit exactly
//! when it is valid and its t is below the current best (the t_max pre-filter never rejects
//! such a hit), and the box tests are conservative, so both traversals find the minimum t over
//! the valid hits. Only the primitive chosen among hits at exactly equal t depends on the
//! visiting order (the one-ray query keeps the first found). The packet traversal therefore
//! also watches for hits at exactly the best t from another primitive, and the (very rare)
//! rays with such a tie are redone by the one-ray query.

use super::{Bary, LEAF, Node4, STACK, WideBvh};
use crate::geometry::Ray;
use crate::geometry::bvh::{NEAR_SLACK, ROUNDING_SLACK};
use crate::geometry::packet::{PACKET, PACKET_MASK, PacketRays, bits};
use crate::geometry::simd16::{Lanes, OnSimd, Simd, SimdKernel};
use crate::geometry::tri4::TriPacket;
use crate::geometry::triangle::{RayShear, self_hit_bound};
use crate::isa::Cpu;
use std::mem::MaybeUninit;

/// The closest-hit state of a packet's traversal, lanes over rays (in memory, so that the
/// rare scalar steps, exact-zero redos and quadrics, update single lanes).
pub(in crate::geometry) struct PacketHits {
    /// Best hit distance so far per ray (its t_max at first, −∞ in inactive lanes).
    pub(in crate::geometry) t: Lanes,
    /// `up(t)`: the bound of the tests, so that hits at exactly the best t are seen.
    tm: Lanes,
    /// Leaf-order id of each ray's best hit, as f32 bit patterns (compared as integers).
    pub(in crate::geometry) id: Lanes,
    /// The best hit's edge functions (after the traversal: its barycentrics).
    /// Scalar-redo and quadric hits store their barycentrics here with `inv` = 1, whose
    /// product is exact.
    pub(in crate::geometry) b: [Lanes; 3],
    /// The best hit's reciprocal determinant: barycentric k = b[k] · inv (the products of
    /// `RayShear4::closest`, formed once per ray at the end).
    inv: Lanes,
    /// Rays with a hit.
    pub(in crate::geometry) found: u32,
    /// Rays with another primitive hit at exactly their best t (redone by the scalar query).
    pub(in crate::geometry) ties: u32,
}

impl PacketHits {
    /// No hit yet.
    pub(in crate::geometry) const fn new() -> Self {
        PacketHits {
            t: [0.0; PACKET],
            tm: [0.0; PACKET],
            id: [0.0; PACKET],
            b: [[0.0; PACKET]; 3],
            inv: [0.0; PACKET],
            found: 0,
            ties: 0,
        }
    }

    /// Hit of ray `i` as (leaf-order id, t, barycentrics); valid for rays in `found`, after the
    /// traversal.
    #[inline(always)]
    pub(in crate::geometry) fn hit(&self, i: usize) -> (usize, f32, Bary) {
        let i = i & (PACKET - 1);
        (
            self.id[i].to_bits() as usize,
            self.t[i],
            [self.b[0][i], self.b[1][i], self.b[2][i]],
        )
    }
}

/// Per-ray constants of the slab test, lanes over rays.
struct PacketBox<S: Simd> {
    /// The backend's token.
    tk: S,
    o: [S::F; 3],
    inv: [S::F; 3],
    /// Rays that enter the box through the upper plane of that axis.
    neg: [S::M; 3],
    /// Entry side (0 = lower plane) per axis when all active rays agree, else `None`.
    uniform: Option<[usize; 3]>,
}

impl<S: Simd> PacketBox<S> {
    /// From the rays' lanes `l` ([`Simd::rays`]).
    #[inline(always)]
    fn new(tk: S, l: &[S::F; 7], active: u32) -> Self {
        // Loops, not closures: a closure left out of line would lack the caller's target
        // features, and so would every intrinsic in it.
        let (mut inv, mut neg) = ([l[3]; 3], [S::lt(l[3], l[3]); 3]);
        let mut negs = [0u32; 3];
        for a in 0..3 {
            // `safe_inverse` per lane: tiny components become ±1e-30 with their sign bit.
            let d = l[3 + a];
            let tiny = S::lt(S::abs(d), tk.splat(1e-30));
            let small = S::select(S::sign(d), tk.splat(-1e-30), tk.splat(1e-30));
            inv[a] = S::div(tk.splat(1.0), S::select(tiny, small, d));
            neg[a] = S::lt(inv[a], tk.splat(0.0));
            negs[a] = S::bits(neg[a]) & active;
        }
        let uniform = (negs.iter().all(|&n| n == 0 || n == active)).then_some([
            (negs[0] != 0) as usize,
            (negs[1] != 0) as usize,
            (negs[2] != 0) as usize,
        ]);
        PacketBox {
            tk,
            o: [l[0], l[1], l[2]],
            inv,
            neg,
            uniform,
        }
    }
}

/// The slab test of child `c` of `node` against every ray: each lane computes exactly what
/// `Node4::hit` computes for that ray and lane c. Writes the entry distances to `near` and
/// returns the mask of rays that enter the box before their `t_max`.
#[inline(always)]
fn child_hits<S: Simd, const MIXED: bool>(
    node: &Node4,
    c: usize,
    r: &PacketBox<S>,
    side: [usize; 3],
    t_max: S::F,
    near: &mut Lanes,
) -> u32 {
    let tk = r.tk;
    let plane = |s: usize, a: usize| node.b[s & 1][a].to_array()[c & 3];
    let mut n = [tk.splat(0.0); 3];
    let mut f = [tk.splat(0.0); 3];
    for a in 0..3 {
        let (np, fp) = if MIXED {
            let (lo, hi) = (tk.splat(plane(0, a)), tk.splat(plane(1, a)));
            (S::select(r.neg[a], hi, lo), S::select(r.neg[a], lo, hi))
        } else {
            (tk.splat(plane(side[a], a)), tk.splat(plane(side[a] ^ 1, a)))
        };
        n[a] = (np - r.o[a]) * r.inv[a];
        f[a] = (fp - r.o[a]) * r.inv[a];
    }
    let nr = S::max(S::max(S::max(n[0], n[1]), n[2]), tk.splat(0.0)) * tk.splat(NEAR_SLACK);
    let fr = S::min(S::min(f[0], f[1]), f[2]) * tk.splat(ROUNDING_SLACK);
    S::store(nr, near);
    S::bits(S::le(nr, S::min(fr, t_max)))
}

/// [`child_hits`] for the four children.
#[inline(always)]
fn node_hits<S: Simd>(
    node: &Node4,
    r: &PacketBox<S>,
    t_max: &Lanes,
    near: &mut [Lanes; 4],
) -> [u32; 4] {
    let tk = r.tk;
    let t_max = tk.load(t_max);
    let mut m = [0; 4];
    match r.uniform {
        Some(side) => {
            for c in 0..4 {
                m[c] = child_hits::<S, false>(node, c, r, side, t_max, &mut near[c]);
            }
        }
        None => {
            for c in 0..4 {
                m[c] = child_hits::<S, true>(node, c, r, [0; 3], t_max, &mut near[c]);
            }
        }
    }
    m
}

/// Per-ray constants of the watertight triangle test, lanes over rays: the constants of
/// [`RayShear4`](super::tri4::RayShear4) for each ray, with each lane's own shear axes (`shear_axes` of its direction).
struct PacketShear<S: Simd> {
    /// The backend's token.
    tk: S,
    /// The shear axes when all active rays share them (the common case for coherent packets),
    /// else `None`: then each lane picks its vertex coordinates by `pick`.
    k: Option<[usize; 3]>,
    /// Per sheared coordinate j: the lanes whose axis k[j] is 0, and those whose axis is 1.
    pick: [[S::M; 2]; 3],
    o: [S::F; 3],
    s: [S::F; 3],
    /// |d| along the sheared x and y axes (for `self_hit_bound`).
    ad: [S::F; 2],
}

/// Lane-wise `a[k]`, where `m` = [lanes with k = 0, lanes with k = 1] (disjoint).
#[inline(always)]
fn pick3<S: Simd>(m: [S::M; 2], a: [S::F; 3]) -> S::F {
    S::select(m[0], a[0], S::select(m[1], a[1], a[2]))
}

impl<S: Simd> PacketShear<S> {
    /// From the rays' lanes `l` ([`Simd::rays`]).
    #[inline(always)]
    fn new(tk: S, l: &[S::F; 7], active: u32) -> Self {
        // `shear_axes` per lane: kz is the dominant axis (ties to the later one), and
        // (kx, ky) = (kz + 1, kz + 2) mod 3, swapped when d[kz] < 0.
        let d = [l[3], l[4], l[5]];
        let a = [S::abs(l[3]), S::abs(l[4]), S::abs(l[5])];
        let x_gt_y = S::lt(a[1], a[0]);
        let x_max = S::and(x_gt_y, S::lt(a[2], a[0]));
        let y_max = S::andnot(S::lt(a[2], a[1]), x_gt_y);
        let z_max = S::andnot(tk.mask(PACKET_MASK), S::or(x_max, y_max));
        let neg = S::lt(pick3::<S>([x_max, y_max], d), tk.splat(0.0));
        let pos = S::andnot(tk.mask(PACKET_MASK), neg);
        let either = |p: S::M, n: S::M| S::or(S::and(pos, p), S::and(neg, n));
        let pick = [
            [either(z_max, y_max), either(x_max, z_max)],
            [either(y_max, z_max), either(z_max, x_max)],
            [x_max, y_max],
        ];
        let uniform = |m: S::M| {
            let b = S::bits(m) & active;
            b == 0 || b == active
        };
        let k = (uniform(x_max) && uniform(y_max) && uniform(neg)).then(|| {
            let first = |m: S::M| S::bits(m) & active != 0;
            let kz = if first(x_max) {
                0
            } else if first(y_max) {
                1
            } else {
                2
            };
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if first(neg) {
                [ky, kx, kz]
            } else {
                [kx, ky, kz]
            }
        });
        // The quotients of `RayShear4::new`: −(a / b) = (−a) / b exactly, and the product
        // with −1 is an exact negation.
        let o = [l[0], l[1], l[2]];
        let (dx, dy, dz) = (
            pick3::<S>(pick[0], d),
            pick3::<S>(pick[1], d),
            pick3::<S>(pick[2], d),
        );
        let minus = tk.splat(-1.0);
        PacketShear {
            tk,
            k,
            pick,
            o: [
                pick3::<S>(pick[0], o),
                pick3::<S>(pick[1], o),
                pick3::<S>(pick[2], o),
            ],
            s: [
                S::div(dx, dz) * minus,
                S::div(dy, dz) * minus,
                S::div(tk.splat(1.0), dz),
            ],
            ad: [S::abs(dx), S::abs(dy)],
        }
    }
}

/// One triangle against every ray of the packet: each lane performs the f32 operations of
/// [`RayShear4`](super::tri4::RayShear4)'s lane test for that ray (same order, hence the same
/// bits, self-hit rejection included).
struct TriLanes<S: Simd> {
    /// The backend's token.
    tk: S,
    /// Rays accepted by the f32 test with t in (0, t_max).
    hit: u32,
    /// Rays with an exactly-zero edge function: to be redone by the scalar test.
    redo: u32,
    /// Hit distances (valid in `hit`).
    t: S::F,
    /// Edge functions and the reciprocal determinant: barycentric k = e[k] · inv.
    e: [S::F; 3],
    inv: S::F,
}

/// Ray-space vertex `j` of triangle `lane` of `pk` (a function, not a closure, so it keeps the
/// caller's target features). The coordinates are broadcast straight from the packet, not
/// through a copy (dc42e56: 1-thread 256² 64 spp light-area 0.307 → 0.287 s).
#[inline(always)]
fn shear<S: Simd>(
    pk: &TriPacket,
    lane: usize,
    j: usize,
    ps: &PacketShear<S>,
) -> (S::F, S::F, S::F) {
    let tk = ps.tk;
    let v = |a: usize| tk.splat(AsRef::<[f32; 4]>::as_ref(&pk.v[j][a])[lane & 3]);
    let c = match ps.k {
        Some(k) => [v(k[0]), v(k[1]), v(k[2])],
        None => {
            let v = [v(0), v(1), v(2)];
            [
                pick3::<S>(ps.pick[0], v),
                pick3::<S>(ps.pick[1], v),
                pick3::<S>(ps.pick[2], v),
            ]
        }
    };
    let (ax, ay, az) = (c[0] - ps.o[0], c[1] - ps.o[1], c[2] - ps.o[2]);
    (ax + az * ps.s[0], ay + az * ps.s[1], az * ps.s[2])
}

/// The triangle test of [`TriLanes`] for rays `mask` (the division only if some ray is a
/// candidate).
#[inline(always)]
fn triangle_lanes<S: Simd>(
    ps: &PacketShear<S>,
    pk: &TriPacket,
    lane: usize,
    t_max: &Lanes,
    mask: u32,
) -> TriLanes<S> {
    let tk = ps.tk;
    let (ax, ay, az) = shear(pk, lane, 0, ps);
    let (bx, by, bz) = shear(pk, lane, 1, ps);
    let (cx, cy, cz) = shear(pk, lane, 2, ps);
    let e0 = bx * cy - by * cx;
    let e1 = cx * ay - cy * ax;
    let e2 = ax * by - ay * bx;
    let zero = tk.splat(0.0);
    let redo = S::or(S::or(S::eq(e0, zero), S::eq(e1, zero)), S::eq(e2, zero));
    let n0 = S::sign(e0);
    let mixed = S::or(S::xor(n0, S::sign(e1)), S::xor(n0, S::sign(e2)));
    let det = e0 + e1 + e2;
    let t_scaled = e0 * az + e1 * bz + e2 * cz;
    let t_max = tk.load(t_max);
    let tmd = t_max * det;
    let sgn = S::sign_one(det);
    let (ts, tm) = (t_scaled * sgn, tmd * sgn);
    let in_range = S::and(S::lt(zero, ts), S::le(ts, tm));
    let cand = S::andnot(in_range, S::or(mixed, redo));
    let redo = S::bits(redo);
    if S::bits(cand) & mask == 0 {
        // The common miss: skip the division.
        return TriLanes {
            tk,
            hit: 0,
            redo,
            t: zero,
            e: [e0, e1, e2],
            inv: zero,
        };
    }
    // Hits not provably in front of the origin (the scalar test's `self_hit_bound`), only
    // for packets with a candidate: the common miss above does not pay for the bound.
    let (mx, my, mz) = (
        max_abs3::<S>(ax, bx, cx),
        max_abs3::<S>(ay, by, cy),
        max_abs3::<S>(az, bz, cz),
    );
    let bound = self_hit_bound(mx, my, mz, ps.ad[0], ps.ad[1], |x| tk.splat(x));
    let inv = S::div(tk.splat(1.0), det);
    let t = t_scaled * inv;
    let ok = S::and(S::and(S::lt(zero, t), S::lt(t, t_max)), S::lt(bound, ts));
    TriLanes {
        tk,
        hit: S::bits(S::and(ok, cand)),
        redo,
        t,
        e: [e0, e1, e2],
        inv,
    }
}

/// Lane-wise max(|a|, |b|, |c|) (a function, not a closure, for the caller's target features).
#[inline(always)]
fn max_abs3<S: Simd>(a: S::F, b: S::F, c: S::F) -> S::F {
    S::max(S::max(S::abs(a), S::abs(b)), S::abs(c))
}

/// Vertices of triangle `lane` of `pk` as `[vertex][axis]`.
#[inline(always)]
fn tri_vertices(pk: &TriPacket, lane: usize) -> [[f32; 3]; 3] {
    let v = |j: usize, a: usize| pk.v[j][a].to_array()[lane & 3];
    [
        [v(0, 0), v(0, 1), v(0, 2)],
        [v(1, 0), v(1, 1), v(1, 2)],
        [v(2, 0), v(2, 1), v(2, 2)],
    ]
}

/// The scalar test of a triangle with an exactly-zero f32 edge function for `ray` (rare, so
/// out of line): (t, b0, b1, b2) with t in (0, t_max).
#[cold]
#[inline(never)]
fn redo_triangle(ray: &Ray, p: [[f32; 3]; 3], t_max: f32) -> Option<(f32, f32, f32, f32)> {
    let v = p.map(glam::Vec3::from_array);
    RayShear::new(ray.o, ray.d).intersect(v[0], v[1], v[2], t_max)
}

/// `next_up` for the best distances of the closest-hit traversal (non-negative or +∞; other
/// values, which admit no hit either way, are kept): a test with this bound accepts t = best.
#[inline(always)]
fn up(b: f32) -> f32 {
    // Branch-free (it runs on every lane): +1 ulp exactly for 0 ≤ b < ∞.
    f32::from_bits(b.to_bits() + (0.0..f32::INFINITY).contains(&b) as u32)
}

/// Record a hit of ray `i` on primitive `id` at `t` (below `up(best[i])`) with barycentrics
/// `b`: a closer one replaces the best, one at exactly the best t from another primitive
/// marks a tie (the scalar steps; [`consider_lanes`] is the vector one).
#[inline(always)]
fn consider(st: &mut PacketHits, i: usize, id: usize, t: f32, b: Bary) {
    let i = i & (PACKET - 1);
    let bit = 1 << i;
    if t < st.t[i] {
        st.t[i] = t;
        st.tm[i] = up(t);
        st.id[i] = f32::from_bits(id as u32);
        for (row, bk) in st.b.iter_mut().zip(b) {
            row[i] = bk;
        }
        st.inv[i] = 1.0;
        st.found |= bit;
        st.ties &= !bit;
    } else if t == st.t[i] && st.found & bit != 0 && st.id[i].to_bits() != id as u32 {
        st.ties |= bit;
    }
}

/// [`consider`] for the rays `hit` of triangle `id`'s test `h`, on all lanes at once: the
/// same comparisons per lane, and the barycentric products deferred to the end (the same
/// operands, hence the same bits).
#[inline(always)]
fn consider_lanes<S: Simd>(st: &mut PacketHits, id: u32, h: &TriLanes<S>, hit: u32) {
    let tk = h.tk;
    let best = tk.load(&st.t);
    let ids = tk.load(&st.id);
    let idv = tk.splat(f32::from_bits(id));
    let hm = tk.mask(hit);
    let closer = S::and(S::lt(h.t, best), hm);
    let same = S::and(S::and(S::eq(h.t, best), hm), tk.mask(st.found));
    let tie = S::andnot(same, S::eq_bits(ids, idv));
    S::store(S::select(closer, h.t, best), &mut st.t);
    // Hits have 0 < t < ∞, where `up` adds one to the bit pattern.
    let tm = S::select(closer, h.t, tk.load(&st.tm));
    S::store(S::inc_bits(closer, tm), &mut st.tm);
    S::store(S::select(closer, idv, ids), &mut st.id);
    for k in 0..3 {
        S::store(S::select(closer, h.e[k], tk.load(&st.b[k])), &mut st.b[k]);
    }
    S::store(S::select(closer, h.inv, tk.load(&st.inv)), &mut st.inv);
    let closer = S::bits(closer);
    st.found |= closer;
    st.ties = (st.ties & !closer) | S::bits(tie);
}

/// A pending subtree of the closest-hit traversal: each ray's entry distance, so that a pop
/// drops the rays whose best hit has since come closer (the scalar traversal's pop test).
#[derive(Clone, Copy)]
struct Pending {
    near: Lanes,
    child: u32,
    mask: u32,
}

/// Rays `mask` whose entry distance is not beyond their best hit.
#[inline(always)]
fn still_open<S: Simd>(tk: S, near: &Lanes, best: &Lanes, mask: u32) -> u32 {
    // `<=`, not the scalar `<`: a box entered exactly at the best t may hold a tie.
    S::bits(S::le(tk.load(near), tk.load(best))) & mask
}

impl WideBvh {
    /// The rays `active` that enter the box of the root's first child before their t_max, on
    /// `cpu`; for a single-leaf tree, bit i is `!self.single_leaf_missed(ray i)` (the same
    /// operations on the same values: `SingleLeaf::hit` is lane 0 of `Node4::hit`).
    pub(in crate::geometry) fn root_box_packet<R: PacketRays + ?Sized>(
        &self,
        cpu: Cpu,
        rays: &R,
        active: u32,
    ) -> u32 {
        /// [`WideBvh::root_box_impl`]'s arguments.
        struct RootBox<'a, R: ?Sized>(&'a WideBvh, &'a R, u32);
        impl<R: PacketRays + ?Sized> SimdKernel for RootBox<'_, R> {
            type Output = u32;
            #[inline(always)]
            fn run<S: Simd>(self, tk: S) -> u32 {
                self.0.root_box_impl(tk, self.1, self.2)
            }
        }
        cpu.dispatch(OnSimd(RootBox(self, rays, active)))
    }

    #[inline(always)]
    fn root_box_impl<S: Simd, R: PacketRays + ?Sized>(&self, tk: S, rays: &R, active: u32) -> u32 {
        let Some(root) = self.nodes.first() else {
            return 0;
        };
        let l = rays.lanes(tk);
        let r = PacketBox::new(tk, &l, active);
        let mut near = [0.0f32; PACKET];
        let m = match r.uniform {
            Some(side) => child_hits::<S, false>(root, 0, &r, side, l[6], &mut near),
            None => child_hits::<S, true>(root, 0, &r, [0; 3], l[6], &mut near),
        };
        m & active
    }
}

impl WideBvh {
    /// Closest hits of the rays `active` on `cpu` into `out` (a fresh [`PacketHits`]):
    /// `out.hit(i)` for each ray i in `out.found`; `out.ties` flags rays with another
    /// primitive hit at exactly their best t (the caller redoes those with the scalar query).
    /// `other(id, ray, t_max)` is the hit distance of a primitive the traversal does not test
    /// itself (a quadric, a cut-out triangle) if below `t_max`, else +∞.
    pub(in crate::geometry) fn closest_packet<R: PacketRays + ?Sized>(
        &self,
        cpu: Cpu,
        rays: &R,
        active: u32,
        out: &mut PacketHits,
        other: impl FnMut(usize, &Ray, f32) -> f32,
    ) {
        /// [`WideBvh::closest_packet_impl`]'s arguments.
        struct Closest<'a, R: ?Sized, F>(&'a WideBvh, &'a R, u32, &'a mut PacketHits, F);
        impl<R: PacketRays + ?Sized, F: FnMut(usize, &Ray, f32) -> f32> SimdKernel for Closest<'_, R, F> {
            type Output = ();
            #[inline(always)]
            fn run<S: Simd>(self, tk: S) {
                let Closest(bvh, rays, active, out, other) = self;
                bvh.closest_packet_impl(tk, rays, active, out, other)
            }
        }
        cpu.dispatch(OnSimd(Closest(self, rays, active, out, other)))
    }

    /// Mask of the rays `active` that something blocks in (0, t_max), on `cpu`;
    /// `other(id, ray)` tells whether a primitive the traversal does not test itself blocks
    /// `ray`.
    pub(in crate::geometry) fn any_packet<R: PacketRays + ?Sized>(
        &self,
        cpu: Cpu,
        rays: &R,
        active: u32,
        sparse: u32,
        other: impl FnMut(usize, &Ray) -> bool,
    ) -> u32 {
        /// [`WideBvh::any_packet_impl`]'s arguments.
        struct Any<'a, R: ?Sized, F>(&'a WideBvh, &'a R, u32, u32, F);
        impl<R: PacketRays + ?Sized, F: FnMut(usize, &Ray) -> bool> SimdKernel for Any<'_, R, F> {
            type Output = u32;
            #[inline(always)]
            fn run<S: Simd>(self, tk: S) -> u32 {
                let Any(bvh, rays, active, sparse, other) = self;
                bvh.any_packet_impl(tk, rays, active, sparse, other)
            }
        }
        cpu.dispatch(OnSimd(Any(self, rays, active, sparse, other)))
    }

    #[inline(always)]
    fn closest_packet_impl<S: Simd, R: PacketRays + ?Sized>(
        &self,
        tk: S,
        rays: &R,
        active: u32,
        st: &mut PacketHits,
        mut other: impl FnMut(usize, &Ray, f32) -> f32,
    ) {
        if self.nodes.is_empty() || active == 0 {
            return;
        }
        let l = rays.lanes(tk);
        let r = PacketBox::new(tk, &l, active);
        let best = S::select(tk.mask(active), l[6], tk.splat(f32::NEG_INFINITY));
        S::store(best, &mut st.t);
        // Bounds of the tests: up(best), so that hits at exactly the best t are seen.
        let zero = tk.splat(0.0);
        let finite = S::and(S::le(zero, best), S::lt(best, tk.splat(f32::INFINITY)));
        S::store(S::inc_bits(finite, best), &mut st.tm);
        let ps = PacketShear::new(tk, &l, active);
        let mut stack = [const { MaybeUninit::<Pending>::uninit() }; STACK];
        let mut sp = 0usize;
        let (mut cur, mut mask) = (0u32, active);
        let mut near = [[0.0f32; PACKET]; 4];
        loop {
            if cur & LEAF == 0 {
                // SAFETY: interior references are node indices written by the build, and the
                // root exists (`nodes` is not empty).
                let node = unsafe { self.nodes.get_unchecked(cur as usize) };
                let mut m = node_hits::<S>(node, &r, &st.t, &mut near);
                let mut order = [0usize; 4];
                let mut key = [0.0f32; 4];
                let mut n = 0;
                for c in 0..4 {
                    m[c] &= mask;
                    if m[c] != 0 {
                        // Front to back by the first ray's entry distance (insertion sort).
                        let k = near[c][m[c].trailing_zeros() as usize & (PACKET - 1)];
                        let mut j = n;
                        while j > 0 && key[j - 1] > k {
                            key[j] = key[j - 1];
                            order[j] = order[j - 1];
                            j -= 1;
                        }
                        key[j] = k;
                        order[j] = c;
                        n += 1;
                    }
                }
                if n > 0 {
                    // Push the farther children far to near, visit the nearest.
                    for &c in order[1..n].iter().rev() {
                        // SAFETY: at most three pushes per wide level of a tree at most
                        // MAX_TREE_DEPTH deep, so sp < STACK (as in `WideBvh::closest`).
                        unsafe { stack.get_unchecked_mut(sp) }.write(Pending {
                            near: near[c],
                            child: node.child[c],
                            mask: m[c],
                        });
                        sp += 1;
                    }
                    cur = node.child[order[0]];
                    mask = m[order[0]];
                    continue;
                }
            } else {
                let mut pi = (cur & !LEAF) as usize;
                loop {
                    // SAFETY: a leaf reference is the first packet of a non-empty run inside
                    // `packets` whose final packet has `last` set (see `WideBvh::leaf`).
                    let pk = unsafe { self.packets.get_unchecked(pi) };
                    // Accept t = best too, to notice ties (see the module docs).
                    for lane in bits(pk.tri) {
                        let id = pk.ids[lane & 3];
                        let h = triangle_lanes(&ps, pk, lane, &st.tm, mask);
                        let hits = h.hit & mask;
                        if hits != 0 {
                            consider_lanes(st, id, &h, hits);
                        }
                        for i in bits(h.redo & mask) {
                            let i = i & (PACKET - 1);
                            let p = tri_vertices(pk, lane);
                            if let Some((t, b0, b1, b2)) = redo_triangle(&rays.ray(i), p, st.tm[i])
                            {
                                consider(st, i, id as usize, t, [b0, b1, b2]);
                            }
                        }
                    }
                    for lane in bits(pk.other) {
                        let id = pk.ids[lane & 3] as usize;
                        for i in bits(mask) {
                            let i = i & (PACKET - 1);
                            let t_max = st.tm[i];
                            let t = other(id, &rays.ray(i), t_max);
                            if t < t_max {
                                consider(st, i, id, t, [1.0 / 3.0; 3]);
                            }
                        }
                    }
                    if pk.last {
                        break;
                    }
                    pi += 1;
                }
            }
            // Pop the nearest pending subtree that some ray may still find a hit in.
            loop {
                if sp == 0 {
                    // The barycentrics of the best hits (see `PacketHits::b`).
                    let inv = tk.load(&st.inv);
                    for k in 0..3 {
                        S::store(tk.load(&st.b[k]) * inv, &mut st.b[k]);
                    }
                    return;
                }
                sp -= 1;
                // SAFETY: every slot below the stack pointer was written by a push above.
                let e = unsafe { stack.get_unchecked(sp).assume_init_ref() };
                let m = still_open(tk, &e.near, &st.t, e.mask);
                if m != 0 {
                    cur = e.child;
                    mask = m;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any_packet_impl<S: Simd, R: PacketRays + ?Sized>(
        &self,
        tk: S,
        rays: &R,
        active: u32,
        sparse: u32,
        mut other: impl FnMut(usize, &Ray) -> bool,
    ) -> u32 {
        if self.nodes.is_empty() || active == 0 {
            return 0;
        }
        let l = rays.lanes(tk);
        let r = PacketBox::new(tk, &l, active);
        let mut t_max: Lanes = [0.0; PACKET];
        let inactive = tk.splat(f32::NEG_INFINITY);
        S::store(S::select(tk.mask(active), l[6], inactive), &mut t_max);
        let ps = PacketShear::new(tk, &l, active);
        let mut blocked = 0u32;
        // Only interior nodes are pushed (leaves are tested on sight), with their ray mask.
        let mut stack = [const { MaybeUninit::<(u32, u32)>::uninit() }; STACK];
        let mut sp = 0usize;
        let (mut cur, mut mask) = (0u32, active);
        let mut near = [[0.0f32; PACKET]; 4];
        loop {
            if mask.count_ones() <= sparse {
                // Few rays left in this subtree: the packet would test every box for all 16
                // lanes, the scalar query only for these rays.
                for i in bits(mask & !blocked) {
                    let ray = &rays.ray(i & (PACKET - 1));
                    let hit = self.any_from(cur, ray.o, ray.d, ray.t_max, |id| other(id, ray));
                    blocked |= (hit as u32) << i;
                }
                if blocked == active {
                    return blocked;
                }
            } else {
                // SAFETY: as in `closest_packet`, node references are valid indices.
                let node = unsafe { self.nodes.get_unchecked(cur as usize) };
                let m = node_hits::<S>(node, &r, &t_max, &mut near);
                let mut inner = [(0u32, 0u32); 4];
                let mut n = 0;
                for c in 0..4 {
                    let m = m[c] & mask & !blocked;
                    if m == 0 {
                        continue;
                    }
                    let child = node.child[c];
                    if child & LEAF == 0 {
                        inner[n] = (child, m);
                        n += 1;
                        continue;
                    }
                    // Leaves first: a hit there drops rays from the packet.
                    let mut pi = (child & !LEAF) as usize;
                    loop {
                        // SAFETY: as in `closest_packet`, a leaf's packet run lies in `packets`.
                        let pk = unsafe { self.packets.get_unchecked(pi) };
                        for lane in bits(pk.tri) {
                            let h = triangle_lanes(&ps, pk, lane, &t_max, m & !blocked);
                            blocked |= h.hit & m;
                            for i in bits(h.redo & m & !blocked) {
                                let i = i & (PACKET - 1);
                                let p = tri_vertices(pk, lane);
                                let hit = redo_triangle(&rays.ray(i), p, t_max[i]).is_some();
                                blocked |= (hit as u32) << i;
                            }
                        }
                        for lane in bits(pk.other) {
                            for i in bits(m & !blocked) {
                                let hit = other(pk.ids[lane & 3] as usize, &rays.ray(i));
                                blocked |= (hit as u32) << i;
                            }
                        }
                        if pk.last || m & !blocked == 0 {
                            break;
                        }
                        pi += 1;
                    }
                    if blocked == active {
                        return blocked;
                    }
                }
                let mut next = None;
                for &(child, m) in inner[..n].iter().rev() {
                    let m = m & !blocked;
                    if m == 0 {
                        continue;
                    }
                    if let Some(e) = next.replace((child, m)) {
                        // SAFETY: at most three pushes per level (as in `WideBvh::any`).
                        unsafe { stack.get_unchecked_mut(sp) }.write(e);
                        sp += 1;
                    }
                }
                if let Some((c, m)) = next {
                    (cur, mask) = (c, m);
                    continue;
                }
            }
            loop {
                if sp == 0 {
                    return blocked;
                }
                sp -= 1;
                // SAFETY: every slot below the stack pointer was written by a push above.
                let (c, m) = unsafe { stack.get_unchecked(sp).assume_init() };
                let m = m & !blocked;
                if m != 0 {
                    (cur, mask) = (c, m);
                    break;
                }
            }
        }
    }
}
