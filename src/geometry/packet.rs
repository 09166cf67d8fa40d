//! Packet ray queries: [`PACKET`] rays traced together (coherent camera rays of one pixel,
//! shadow rays from nearby points toward one light). Each lane's result equals the scalar
//! query's ([`RayQuery::intersect`] / [`RayQuery::occluded`]) bit for bit.
//!
//! On the default backend ([`WideBvh`]) one traversal serves the whole packet: each node's four
//! child boxes are tested against every ray (lane loops over `[f32; PACKET]` that LLVM
//! vectorises; an AVX2 copy is picked at run time), with each ray's own arithmetic of
//! `Node4::hit` and its own best distance, so a ray's box verdicts are the scalar ones. A ray
//! tests a leaf's triangles only if it passed that leaf's box, with its own [`RayShear4`].
//!
//! Why the closest hit is the scalar one: a triangle (or quadric) test accepts a hit exactly
//! when it is valid and its t is below the current best (the t_max pre-filter never rejects
//! such a hit), and the box tests are conservative, so both traversals find the minimum t over
//! the valid hits. Only the primitive chosen among hits at exactly equal t depends on the
//! visiting order (the scalar keeps the first found). The packet traversal therefore also
//! watches for hits at exactly the best t from another primitive, and the (very rare) rays
//! with such a tie are redone by the scalar query.

// Lane loops `for i in 0..PACKET` over several arrays at once are what LLVM vectorises.
#![allow(clippy::needless_range_loop)]

use super::accel::Geometry;
use super::bvh::{NEAR_SLACK, ROUNDING_SLACK, safe_inverse};
use super::tri4::{RayShear4, TriPacket};
use super::triangle::{RayShear, shear_axes};
use super::wide::{Bary, LEAF, Node4, STACK, WideBvh};
use super::{Ray, RayQuery, SurfaceHit};
use std::mem::MaybeUninit;

/// Rays per packet query.
pub const PACKET: usize = 16;

/// One f32 per ray of a packet.
type Lanes = [f32; PACKET];

/// Closest-hit record of one ray: (leaf-order id, t, barycentrics).
type LaneHit = (usize, f32, Bary);

impl Geometry {
    /// Closest hit of each active ray (bit i of `active` ⇒ rays[i] is traced); out[i] = None for
    /// inactive lanes and misses. Equal, lane by lane, to `self.intersect(&rays[i])`.
    pub fn intersect_packet(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
    ) {
        let active = active & PACKET_MASK;
        *out = [None; PACKET];
        let Some(bvh) = self.wide().filter(|b| !b.is_single_leaf()) else {
            for i in bits(active) {
                out[i] = self.intersect(&rays[i]);
            }
            return;
        };
        let mut hits = [(0usize, 0.0f32, [0.0f32; 3]); PACKET];
        let (found, ties) = bvh.closest_packet(rays, active, &mut hits, |id, ray, t_max| {
            self.quadric_t_outlined(id, ray.o, ray.d, t_max)
        });
        for i in bits(found & !ties) {
            let (id, t, b) = hits[i];
            out[i] = Some(self.surface_hit(id, &rays[i], t, b));
        }
        for i in bits(ties) {
            out[i] = self.intersect(&rays[i]);
        }
    }

    /// Bit i set ⇔ ray i is active and `self.occluded(&rays[i])`.
    ///
    /// The scalar query per ray for now: the packet traversal
    /// ([`Self::occluded_packet_traversal`]) measured 517 vs 548 Ir per shadow ray on cornell
    /// but 2580 vs 779 on `dense` (the packet visits the union of the rays' subtrees).
    pub fn occluded_packet(&self, rays: &[Ray; PACKET], active: u32) -> u32 {
        let active = active & PACKET_MASK;
        bits(active).fold(0, |m, i| m | (self.occluded(&rays[i]) as u32) << i)
    }

    /// [`Self::occluded_packet`] by one traversal of the wide BVH for the whole packet (same
    /// results; faster only on small scenes so far, see there).
    pub fn occluded_packet_traversal(&self, rays: &[Ray; PACKET], active: u32) -> u32 {
        let active = active & PACKET_MASK;
        let Some(bvh) = self.wide() else {
            return bits(active).fold(0, |m, i| m | (self.occluded(&rays[i]) as u32) << i);
        };
        bvh.any_packet(rays, active, |id, ray| {
            self.quadric_t_outlined(id, ray.o, ray.d, ray.t_max) < ray.t_max
        })
    }
}

/// The lanes of a packet as a mask.
const PACKET_MASK: u32 = ((1u64 << PACKET) - 1) as u32;

/// Indices of the set bits of `m`, lowest first.
#[inline(always)]
fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        if m == 0 {
            return None;
        }
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        Some(i)
    })
}

/// SSE `maxps` on one lane (the second operand if either is NaN): `Vec4::max` of `Node4::hit`.
#[inline(always)]
fn mx(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// SSE `minps` on one lane (see [`mx`]).
#[inline(always)]
fn mn(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Per-ray constants of the slab test, lanes over rays.
struct PacketBox {
    o: [Lanes; 3],
    inv: [Lanes; 3],
    /// All ones where the ray enters the box through the upper plane of that axis.
    neg: [[u32; PACKET]; 3],
    /// Entry side (0 = lower plane) per axis when all active rays agree, else `None`.
    uniform: Option<[usize; 3]>,
}

impl PacketBox {
    #[inline(always)]
    fn new(rays: &[Ray; PACKET], active: u32) -> Self {
        let mut b = PacketBox {
            o: [[0.0; PACKET]; 3],
            inv: [[0.0; PACKET]; 3],
            neg: [[0; PACKET]; 3],
            uniform: None,
        };
        let (mut any_neg, mut all_neg) = ([false; 3], [true; 3]);
        for (i, r) in rays.iter().enumerate() {
            let inv = safe_inverse(r.d).to_array();
            let o = r.o.to_array();
            let on = active & (1 << i) != 0;
            for a in 0..3 {
                b.o[a][i] = o[a];
                b.inv[a][i] = inv[a];
                let neg = inv[a] < 0.0;
                b.neg[a][i] = if neg { !0 } else { 0 };
                any_neg[a] |= on & neg;
                all_neg[a] &= !on | neg;
            }
        }
        if (0..3).all(|a| !any_neg[a] || all_neg[a]) {
            b.uniform = Some([
                any_neg[0] as usize,
                any_neg[1] as usize,
                any_neg[2] as usize,
            ]);
        }
        b
    }
}

/// `if m { a } else { b }` lane-wise on bit patterns (a blend after vectorisation).
#[inline(always)]
fn pick(m: u32, a: f32, b: f32) -> f32 {
    f32::from_bits((a.to_bits() & m) | (b.to_bits() & !m))
}

/// The slab test of child `c` of `node` against every ray: each lane computes exactly what
/// `Node4::hit` computes for that ray and lane c. Writes the entry distances to `near` and
/// returns the mask of rays that enter the box before their `t_max`.
#[inline(always)]
fn child_hits<const MIXED: bool>(
    node: &Node4,
    c: usize,
    r: &PacketBox,
    side: [usize; 3],
    t_max: &Lanes,
    near: &mut Lanes,
) -> u32 {
    let plane = |s: usize, a: usize| node.b[s][a].to_array()[c];
    let lo = [plane(0, 0), plane(0, 1), plane(0, 2)];
    let hi = [plane(1, 0), plane(1, 1), plane(1, 2)];
    let planes = [lo, hi];
    let mut hit = [false; PACKET];
    for i in 0..PACKET {
        let t = |a: usize| {
            let (n, f) = if MIXED {
                let m = r.neg[a][i];
                (pick(m, hi[a], lo[a]), pick(m, lo[a], hi[a]))
            } else {
                (planes[side[a] & 1][a], planes[(side[a] ^ 1) & 1][a])
            };
            ((n - r.o[a][i]) * r.inv[a][i], (f - r.o[a][i]) * r.inv[a][i])
        };
        let (nx, fx) = t(0);
        let (ny, fy) = t(1);
        let (nz, fz) = t(2);
        let n = mx(mx(mx(nx, ny), nz), 0.0) * NEAR_SLACK;
        let f = mn(mn(fx, fy), fz) * ROUNDING_SLACK;
        near[i] = n;
        hit[i] = n <= mn(f, t_max[i]);
    }
    hit.iter()
        .enumerate()
        .fold(0, |m, (i, &h)| m | (h as u32) << i)
}

/// [`child_hits`] for the four children.
#[inline(always)]
fn node_hits(node: &Node4, r: &PacketBox, t_max: &Lanes, near: &mut [Lanes; 4]) -> [u32; 4] {
    let mut m = [0; 4];
    match r.uniform {
        Some(side) => {
            for c in 0..4 {
                m[c] = child_hits::<false>(node, c, r, side, t_max, &mut near[c]);
            }
        }
        None => {
            for c in 0..4 {
                m[c] = child_hits::<true>(node, c, r, [0; 3], t_max, &mut near[c]);
            }
        }
    }
    m
}

/// Per-ray constants of the watertight triangle test, lanes over rays, for a packet whose
/// active rays share the shear axes (the common case for coherent packets): the constants of
/// [`RayShear4`] for each ray.
struct PacketShear {
    k: [usize; 3],
    o: [Lanes; 3],
    s: [Lanes; 3],
}

impl PacketShear {
    /// `None` if the active rays do not all share the shear axes.
    #[inline(always)]
    fn new(rays: &[Ray; PACKET], active: u32) -> Option<Self> {
        let k = shear_axes(rays[active.trailing_zeros() as usize & (PACKET - 1)].d);
        let mut ps = PacketShear {
            k,
            o: [[0.0; PACKET]; 3],
            s: [[0.0; PACKET]; 3],
        };
        for i in bits(active) {
            let (o, d) = (rays[i].o.to_array(), rays[i].d.to_array());
            if shear_axes(rays[i].d) != k {
                return None;
            }
            // The quotients of `RayShear4::new` (its vector division is lane-wise IEEE).
            let dz = d[k[2]];
            for a in 0..3 {
                ps.o[a][i] = o[k[a]];
            }
            ps.s[0][i] = -d[k[0]] / dz;
            ps.s[1][i] = -d[k[1]] / dz;
            ps.s[2][i] = 1.0 / dz;
        }
        Some(ps)
    }
}

/// One triangle against every ray of the packet: each lane performs the f32 operations of
/// [`RayShear4`]'s lane test for that ray (same order, hence the same bits).
struct TriLanes {
    /// Rays accepted by the f32 test with t in (0, t_max).
    hit: u32,
    /// Rays with an exactly-zero edge function: to be redone by the scalar test.
    redo: u32,
    t: Lanes,
    b: [Lanes; 3],
}

/// One f32 per ray, with lane-wise operators written as plain loops: each statement becomes a
/// few vector instructions (the loop vectoriser does not take the whole triangle test at once).
#[derive(Clone, Copy)]
struct V(Lanes);

/// A lane-wise comparison result (all ones / zero per lane).
#[derive(Clone, Copy)]
struct M([u32; PACKET]);

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt) => {
        impl std::ops::$tr for V {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: V) -> V {
                let mut r = [0.0; PACKET];
                for i in 0..PACKET {
                    r[i] = self.0[i] $op o.0[i];
                }
                V(r)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl V {
    #[inline(always)]
    fn splat(x: f32) -> V {
        V([x; PACKET])
    }
    #[inline(always)]
    fn cmp(self, o: V, f: impl Fn(f32, f32) -> bool) -> M {
        let mut m = [0; PACKET];
        for i in 0..PACKET {
            m[i] = if f(self.0[i], o.0[i]) { !0 } else { 0 };
        }
        M(m)
    }
    /// Sign bits as a lane mask.
    #[inline(always)]
    fn sign(self) -> M {
        let mut m = [0; PACKET];
        for i in 0..PACKET {
            m[i] = ((self.0[i].to_bits() as i32) >> 31) as u32;
        }
        M(m)
    }
    /// `1.0` with the sign of each lane.
    #[inline(always)]
    fn sign_one(self) -> V {
        let mut r = [0.0; PACKET];
        for i in 0..PACKET {
            r[i] = f32::from_bits(1.0f32.to_bits() | (self.0[i].to_bits() & 0x8000_0000));
        }
        V(r)
    }
}

impl M {
    #[inline(always)]
    fn zip(self, o: M, f: impl Fn(u32, u32) -> u32) -> M {
        let mut m = [0; PACKET];
        for i in 0..PACKET {
            m[i] = f(self.0[i], o.0[i]);
        }
        M(m)
    }
    /// One bit per lane.
    #[inline(always)]
    fn bits(self) -> u32 {
        self.0
            .iter()
            .enumerate()
            .fold(0, |b, (i, &m)| b | (m >> 31) << i)
    }
}

#[inline(always)]
fn triangle_lanes(ps: &PacketShear, p: [[f32; 3]; 3], t_max: &Lanes) -> TriLanes {
    let [kx, ky, kz] = ps.k;
    let (o, s) = (ps.o.map(V), ps.s.map(V));
    // A function, not a closure: closures are not inlined reliably, and out of line they
    // would miss the caller's AVX2.
    #[inline(always)]
    fn shear(v: [f32; 3], k: [usize; 3], o: &[V; 3], s: &[V; 3]) -> (V, V, V) {
        let (ax, ay, az) = (
            V::splat(v[k[0]]) - o[0],
            V::splat(v[k[1]]) - o[1],
            V::splat(v[k[2]]) - o[2],
        );
        (ax + az * s[0], ay + az * s[1], az * s[2])
    }

    let (ax, ay, az) = shear(p[0], [kx, ky, kz], &o, &s);
    let (bx, by, bz) = shear(p[1], [kx, ky, kz], &o, &s);
    let (cx, cy, cz) = shear(p[2], [kx, ky, kz], &o, &s);
    let e0 = bx * cy - by * cx;
    let e1 = cx * ay - cy * ax;
    let e2 = ax * by - ay * bx;
    let zero = V::splat(0.0);
    let eq = |a: f32, b: f32| a == b;
    let redo = e0.cmp(zero, eq).zip(e1.cmp(zero, eq), |a, b| a | b);
    let redo = redo.zip(e2.cmp(zero, eq), |a, b| a | b);
    let n0 = e0.sign();
    let mixed = n0
        .zip(e1.sign(), |a, b| a ^ b)
        .zip(n0.zip(e2.sign(), |a, b| a ^ b), |a, b| a | b);
    let det = e0 + e1 + e2;
    let t_scaled = e0 * az + e1 * bz + e2 * cz;
    let t_max = V(*t_max);
    let tmd = t_max * det;
    let sgn = det.sign_one();
    let (ts, tm) = (t_scaled * sgn, tmd * sgn);
    let in_range = ts
        .cmp(zero, |a, b| a > b)
        .zip(ts.cmp(tm, |a, b| a <= b), |a, b| a & b);
    let inv = V::splat(1.0) / det;
    let t = t_scaled * inv;
    let ok = t
        .cmp(zero, |a, b| a > b)
        .zip(t.cmp(t_max, |a, b| a < b), |a, b| a & b);
    let hit = in_range
        .zip(ok, |a, b| a & b)
        .zip(mixed.zip(redo, |a, b| a | b), |a, b| a & !b);
    TriLanes {
        hit: hit.bits(),
        redo: redo.bits(),
        t: t.0,
        b: [(e0 * inv).0, (e1 * inv).0, (e2 * inv).0],
    }
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

/// [`up`] on every lane.
#[inline(always)]
fn up_lanes(b: &Lanes) -> Lanes {
    let mut u = *b;
    for x in u.iter_mut() {
        *x = up(*x);
    }
    u
}

/// Record a hit of ray `i` on primitive `id` at `t` (below `up(best[i])`): a closer one
/// replaces the best, one at exactly the best t from another primitive marks a tie.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn consider(
    best: &mut Lanes,
    tm: &mut Lanes,
    out: &mut [LaneHit; PACKET],
    found: &mut u32,
    ties: &mut u32,
    i: usize,
    id: usize,
    t: f32,
    b: Bary,
) {
    let bit = 1 << i;
    if t < best[i] {
        best[i] = t;
        tm[i] = up(t);
        out[i] = (id, t, b);
        *found |= bit;
        *ties &= !bit;
    } else if t == best[i] && *found & bit != 0 && out[i].0 != id {
        *ties |= bit;
    }
}

/// The [`RayShear4`] of ray `i`, built on first use (`built` marks the built ones).
#[inline(always)]
fn ray_shear<'a>(
    shears: &'a mut [MaybeUninit<RayShear4>; PACKET],
    built: &mut u32,
    rays: &[Ray; PACKET],
    i: usize,
) -> &'a RayShear4 {
    let i = i & (PACKET - 1);
    if *built & (1 << i) == 0 {
        shears[i].write(RayShear4::new(rays[i].o, rays[i].d));
        *built |= 1 << i;
    }
    // SAFETY: slot i was written, now or at an earlier call (its bit in `built` is set).
    unsafe { shears[i].assume_init_ref() }
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
fn still_open(near: &Lanes, best: &Lanes, mask: u32) -> u32 {
    let mut open = [false; PACKET];
    for i in 0..PACKET {
        // `<=`, not the scalar `<`: a box entered exactly at the best t may hold a tie.
        open[i] = near[i] <= best[i];
    }
    open.iter()
        .enumerate()
        .fold(0, |m, (i, &o)| m | (o as u32) << i)
        & mask
}

impl WideBvh {
    /// Closest hits of the rays `active`: writes `out[i]` for each ray i in the returned hit
    /// mask; the second mask flags rays with another primitive hit at exactly their best t
    /// (the caller redoes those with the scalar query). `other(id, ray, t_max)` is the hit
    /// distance of a non-triangle primitive if below `t_max`, else +∞.
    pub(super) fn closest_packet(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        out: &mut [LaneHit; PACKET],
        other: impl FnMut(usize, &Ray, f32) -> f32,
    ) -> (u32, u32) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.closest_packet_avx2(rays, active, out, other) };
        }
        self.closest_packet_impl(rays, active, out, other)
    }

    /// [`Self::closest_packet_impl`] compiled for AVX2 (8 rays per vector instead of 4).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn closest_packet_avx2(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        out: &mut [LaneHit; PACKET],
        other: impl FnMut(usize, &Ray, f32) -> f32,
    ) -> (u32, u32) {
        self.closest_packet_impl(rays, active, out, other)
    }

    #[inline(always)]
    fn closest_packet_impl(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        out: &mut [LaneHit; PACKET],
        mut other: impl FnMut(usize, &Ray, f32) -> f32,
    ) -> (u32, u32) {
        if self.nodes.is_empty() || active == 0 {
            return (0, 0);
        }
        let r = PacketBox::new(rays, active);
        let mut best: Lanes = [f32::NEG_INFINITY; PACKET];
        for i in bits(active) {
            best[i] = rays[i].t_max;
        }
        // Bounds of the tests: up(best), so that hits at exactly the best t are seen.
        let mut tm = up_lanes(&best);
        let pshear = PacketShear::new(rays, active);
        // Per-ray shears for packets whose rays differ in shear axes, built at first use.
        let mut shears = [const { MaybeUninit::<RayShear4>::uninit() }; PACKET];
        let mut built = 0u32;
        let (mut found, mut ties) = (0u32, 0u32);
        let mut stack = [const { MaybeUninit::<Pending>::uninit() }; STACK];
        let mut sp = 0usize;
        let (mut cur, mut mask) = (0u32, active);
        let mut near = [[0.0f32; PACKET]; 4];
        loop {
            if cur & LEAF == 0 {
                // SAFETY: interior references are node indices written by the build, and the
                // root exists (`nodes` is not empty).
                let node = unsafe { self.nodes.get_unchecked(cur as usize) };
                let mut m = node_hits(node, &r, &best, &mut near);
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
                    if let Some(ps) = &pshear {
                        for lane in bits(pk.tri) {
                            let p = tri_vertices(pk, lane);
                            let id = pk.ids[lane & 3] as usize;
                            let h = triangle_lanes(ps, p, &tm);
                            for i in bits(h.hit & mask) {
                                let i = i & (PACKET - 1);
                                let b = [h.b[0][i], h.b[1][i], h.b[2][i]];
                                consider(
                                    &mut best, &mut tm, out, &mut found, &mut ties, i, id, h.t[i],
                                    b,
                                );
                            }
                            for i in bits(h.redo & mask) {
                                let i = i & (PACKET - 1);
                                if let Some((t, b0, b1, b2)) = redo_triangle(&rays[i], p, tm[i]) {
                                    consider(
                                        &mut best,
                                        &mut tm,
                                        out,
                                        &mut found,
                                        &mut ties,
                                        i,
                                        id,
                                        t,
                                        [b0, b1, b2],
                                    );
                                }
                            }
                        }
                    } else if pk.tri != 0 {
                        for i in bits(mask) {
                            let i = i & (PACKET - 1);
                            let shear = ray_shear(&mut shears, &mut built, rays, i);
                            if let Some((lane, t, b)) = shear.closest(pk, tm[i]) {
                                let id = pk.ids[lane & 3] as usize;
                                consider(
                                    &mut best, &mut tm, out, &mut found, &mut ties, i, id, t, b,
                                );
                            }
                        }
                    }
                    for lane in bits(pk.other) {
                        let id = pk.ids[lane & 3] as usize;
                        for i in bits(mask) {
                            let i = i & (PACKET - 1);
                            let t_max = tm[i];
                            let t = other(id, &rays[i], t_max);
                            if t < t_max {
                                consider(
                                    &mut best,
                                    &mut tm,
                                    out,
                                    &mut found,
                                    &mut ties,
                                    i,
                                    id,
                                    t,
                                    [1.0 / 3.0; 3],
                                );
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
                    return (found, ties);
                }
                sp -= 1;
                // SAFETY: every slot below the stack pointer was written by a push above.
                let e = unsafe { stack.get_unchecked(sp).assume_init_ref() };
                let m = still_open(&e.near, &best, e.mask);
                if m != 0 {
                    cur = e.child;
                    mask = m;
                    break;
                }
            }
        }
    }

    /// Mask of the rays `active` that something blocks in (0, t_max); `other(id, ray)` tells
    /// whether non-triangle primitive `id` blocks `ray`.
    pub(super) fn any_packet(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        other: impl FnMut(usize, &Ray) -> bool,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.any_packet_avx2(rays, active, other) };
        }
        self.any_packet_impl(rays, active, other)
    }

    /// [`Self::any_packet_impl`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn any_packet_avx2(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        other: impl FnMut(usize, &Ray) -> bool,
    ) -> u32 {
        self.any_packet_impl(rays, active, other)
    }

    #[inline(always)]
    fn any_packet_impl(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        mut other: impl FnMut(usize, &Ray) -> bool,
    ) -> u32 {
        if self.nodes.is_empty() || active == 0 {
            return 0;
        }
        let r = PacketBox::new(rays, active);
        let mut t_max: Lanes = [f32::NEG_INFINITY; PACKET];
        for i in bits(active) {
            t_max[i] = rays[i].t_max;
        }
        let pshear = PacketShear::new(rays, active);
        // Per-ray shears for packets whose rays differ in shear axes, built at first use.
        let mut shears = [const { MaybeUninit::<RayShear4>::uninit() }; PACKET];
        let mut built = 0u32;
        let mut blocked = 0u32;
        // Only interior nodes are pushed (leaves are tested on sight), with their ray mask.
        let mut stack = [const { MaybeUninit::<(u32, u32)>::uninit() }; STACK];
        let mut sp = 0usize;
        let (mut cur, mut mask) = (0u32, active);
        let mut near = [[0.0f32; PACKET]; 4];
        loop {
            // SAFETY: as in `closest_packet`, node references are valid indices.
            let node = unsafe { self.nodes.get_unchecked(cur as usize) };
            let m = node_hits(node, &r, &t_max, &mut near);
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
                    if let Some(ps) = &pshear {
                        for lane in bits(pk.tri) {
                            let p = tri_vertices(pk, lane);
                            let h = triangle_lanes(ps, p, &t_max);
                            blocked |= h.hit & m;
                            for i in bits(h.redo & m & !blocked) {
                                let i = i & (PACKET - 1);
                                let hit = redo_triangle(&rays[i], p, t_max[i]).is_some();
                                blocked |= (hit as u32) << i;
                            }
                        }
                    } else if pk.tri != 0 {
                        for i in bits(m & !blocked) {
                            let i = i & (PACKET - 1);
                            let shear = ray_shear(&mut shears, &mut built, rays, i);
                            blocked |= (shear.any(pk, t_max[i]) as u32) << i;
                        }
                    }
                    for lane in bits(pk.other) {
                        for i in bits(m & !blocked) {
                            let hit = other(pk.ids[lane & 3] as usize, &rays[i]);
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
