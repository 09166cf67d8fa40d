//! One ray through the 8-wide nodes on AVX2: closest hit (children visited near to far) and
//! any hit (leaves tested on sight), the loops of [`super::ray`] with eight box tests per node
//! in one `__m256` per plane. The leaves are the same 4-triangle packets, tested by the same
//! code, so the hits are those of the 4-wide traversal.
//!
//! The slab test is the 4-wide one lane for lane (same operations, same order, `maxps` /
//! `minps` semantics), so every child box gets the same verdict and entry distance as the
//! binary node it was collapsed from gets there. Every function takes the [`Avx2`] token: the
//! intrinsics run only where AVX2 was detected, and they are inlined into the function
//! [`crate::isa::Cpu::dispatch`] compiles for AVX2.

use super::{Bary, LEAF, Node8, STACK8, WideBvh};
use crate::geometry::bvh::{NEAR_SLACK, ROUNDING_SLACK, safe_inverse};
use crate::geometry::tri4::RayShear4;
use crate::isa::Avx2;
use glam::Vec3;
use std::arch::x86_64::{
    __m256, _CMP_LE_OQ, _mm256_cmp_ps, _mm256_load_ps, _mm256_max_ps, _mm256_min_ps,
    _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_setzero_ps, _mm256_store_ps,
    _mm256_sub_ps,
};
use std::mem::MaybeUninit;

/// Per-ray constants of the 8-wide slab test.
struct RayBox8 {
    o: [__m256; 3],
    inv: [__m256; 3],
    /// Per axis, the float offset in [`Node8::b`] of the plane row through which the ray
    /// enters (lower plane if the direction is positive) ...
    near: [usize; 3],
    /// ... and of the other one.
    far: [usize; 3],
    /// [`NEAR_SLACK`], [`ROUNDING_SLACK`] splatted.
    slack: [__m256; 2],
}

/// What a leaf holds for the closest-hit query.
enum Leaf8 {
    /// No hit below the best so far.
    Miss,
    /// A new best hit (leaf-order id, barycentrics).
    Hit((usize, Bary)),
    /// A triangle hit at exactly the best distance so far.
    Tie,
}

/// Eight f32 lanes in memory, aligned for `_mm256_store_ps`.
#[repr(C, align(32))]
struct Lanes8([f32; 8]);

impl RayBox8 {
    #[inline(always)]
    fn new(_: Avx2, o: Vec3, d: Vec3) -> Self {
        let inv = safe_inverse(d);
        let side = [
            (inv.x < 0.0) as usize,
            (inv.y < 0.0) as usize,
            (inv.z < 0.0) as usize,
        ];
        let row = |side: usize, axis: usize| (side * 3 + axis) * 8;
        // SAFETY: the token proves this CPU runs AVX2 (so AVX).
        unsafe {
            Self {
                o: [
                    _mm256_set1_ps(o.x),
                    _mm256_set1_ps(o.y),
                    _mm256_set1_ps(o.z),
                ],
                inv: [
                    _mm256_set1_ps(inv.x),
                    _mm256_set1_ps(inv.y),
                    _mm256_set1_ps(inv.z),
                ],
                near: [row(side[0], 0), row(side[1], 1), row(side[2], 2)],
                far: [
                    row(side[0] ^ 1, 0),
                    row(side[1] ^ 1, 1),
                    row(side[2] ^ 1, 2),
                ],
                slack: [_mm256_set1_ps(NEAR_SLACK), _mm256_set1_ps(ROUNDING_SLACK)],
            }
        }
    }
}

impl Node8 {
    /// Entry distances of the eight child boxes and the mask of those entered before
    /// `t_max` ([`super::Node4`]'s test on eight lanes).
    #[inline(always)]
    fn hit(&self, _: Avx2, r: &RayBox8, t_max: f32) -> (__m256, u32) {
        let b = self.b.as_ptr() as *const f32;
        // SAFETY: the token proves AVX2. `b` points at 48 floats (`[[[f32; 8]; 3]; 2]`); the
        // offsets are (side·3 + axis)·8 < 48 with side < 2, axis < 3, so each load reads one
        // row of eight inside it, at a multiple of 32 bytes from the start of the 64-byte
        // aligned node (`_mm256_load_ps`'s alignment).
        unsafe {
            let t = |off: usize, axis: usize| {
                _mm256_mul_ps(
                    _mm256_sub_ps(_mm256_load_ps(b.add(off)), r.o[axis]),
                    r.inv[axis],
                )
            };
            let near = _mm256_max_ps(
                _mm256_max_ps(
                    _mm256_max_ps(t(r.near[0], 0), t(r.near[1], 1)),
                    t(r.near[2], 2),
                ),
                _mm256_setzero_ps(),
            );
            let near = _mm256_mul_ps(near, r.slack[0]);
            let far = _mm256_min_ps(
                _mm256_min_ps(t(r.far[0], 0), t(r.far[1], 1)),
                t(r.far[2], 2),
            );
            let far = _mm256_mul_ps(far, r.slack[1]);
            let enter =
                _mm256_cmp_ps::<_CMP_LE_OQ>(near, _mm256_min_ps(far, _mm256_set1_ps(t_max)));
            (near, _mm256_movemask_ps(enter) as u32)
        }
    }
}

impl WideBvh {
    /// [`Self::closest_hinted`] through the 8-wide nodes: the same hit (the same packets are
    /// tested by the same code, near to far). Falls back to the 4-wide traversal for a
    /// single-leaf tree (its fast path) or when there are no 8-wide nodes.
    #[inline(always)]
    pub fn closest8(
        &self,
        avx2: Avx2,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut other: impl FnMut(usize, f32) -> f32,
        found: impl Fn(usize),
    ) -> Option<(usize, f32, Bary)> {
        if self.single_leaf.is_some() || self.nodes8.is_empty() {
            return self.closest_hinted(o, d, t_max, other, found);
        }
        let r = RayBox8::new(avx2, o, d);
        // Built at the first leaf, as in the 4-wide query.
        let mut shear: Option<RayShear4> = None;
        let mut best = t_max;
        let mut hit: Option<(usize, Bary)> = None;
        // Not cleared per ray: only entries below `sp` are ever read, and those were written.
        let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK8];
        let mut sp = 0usize;
        let mut cur = 0u32;
        let mut near = Lanes8([0.0; 8]);
        loop {
            if cur & LEAF == 0 {
                // SAFETY: interior references are indices of nodes pushed by `collapse8`, and
                // the root 0 exists (`nodes8` is not empty).
                let node = unsafe { self.nodes8.get_unchecked(cur as usize) };
                let (t_near, mask) = node.hit(avx2, &r, best);
                if mask != 0 {
                    if mask & (mask - 1) == 0 {
                        cur = node.child[mask.trailing_zeros() as usize & 7];
                        continue;
                    }
                    // SAFETY: the token proves AVX; `near` is 32-byte aligned (`Lanes8`).
                    unsafe { _mm256_store_ps(near.0.as_mut_ptr(), t_near) };
                    let near = &near.0;
                    let rest = mask & (mask - 1);
                    if rest & (rest - 1) == 0 {
                        // Two children: the nearer is visited, the other pushed (of equal
                        // distances the lower lane first), by a select.
                        let (i, j) = (
                            mask.trailing_zeros() as usize & 7,
                            rest.trailing_zeros() as usize & 7,
                        );
                        let (go, other) = if near[i] <= near[j] { (i, j) } else { (j, i) };
                        let item = (node.child[other], near[other]);
                        if self.large {
                            self.prefetch8(item.0);
                        }
                        // SAFETY: sp < STACK8, as for the pushes below.
                        unsafe { stack.get_unchecked_mut(sp) }.write(item);
                        sp += 1;
                        cur = node.child[go];
                        continue;
                    }
                    // Three or more: insertion-sorted onto the stack, far below near (of
                    // equal distances the lower lane ends up higher); the top one is visited.
                    let base = sp;
                    let mut bits = mask;
                    while bits != 0 {
                        let i = bits.trailing_zeros() as usize & 7;
                        bits &= bits - 1;
                        let item = (node.child[i], near[i]);
                        if self.large {
                            self.prefetch8(item.0);
                        }
                        let mut j = sp;
                        // SAFETY: slots base..sp were written in this loop, and sp < STACK8:
                        // at 8-wide depth d at most 7·(d − 1) entries are pending below
                        // `base` (seven per ancestor), and d ≤ MAX_TREE_DEPTH (each 8-wide
                        // level consumes a binary one), so indices stay below 7·d < STACK8.
                        unsafe {
                            while j > base && stack.get_unchecked(j - 1).assume_init().1 <= item.1 {
                                *stack.get_unchecked_mut(j) = *stack.get_unchecked(j - 1);
                                j -= 1;
                            }
                            stack.get_unchecked_mut(j).write(item);
                        }
                        sp += 1;
                    }
                    sp -= 1;
                    // SAFETY: slot sp was written just above.
                    cur = unsafe { stack.get_unchecked(sp).assume_init().0 };
                    continue;
                }
            } else {
                let shear = shear.get_or_insert_with(|| RayShear4::new(o, d));
                match self.leaf_closest8(cur, shear, &mut best, &mut other, &found) {
                    Leaf8::Miss => {}
                    Leaf8::Hit(h) => hit = Some(h),
                    // Which of two triangles at the same t is returned depends on the
                    // visiting order: the 4-wide query's answer, so that every image stays
                    // what it was (rare: 3 in 10⁶ camera rays on the cornell box's edges).
                    Leaf8::Tie => return self.closest_hinted(o, d, t_max, other, found),
                }
            }
            // Pop the nearest pending subtree that can still hold a closer hit.
            loop {
                if sp == 0 {
                    return hit.map(|(id, b)| (id, best, b));
                }
                sp -= 1;
                // SAFETY: every slot below the stack pointer was written by a push above.
                let (c, t) = unsafe { stack.get_unchecked(sp).assume_init() };
                if t < best {
                    cur = c;
                    break;
                }
            }
        }
    }

    /// [`Self::leaf_closest`] that also reports a triangle hit exactly at `*best` (a tie with
    /// the best hit so far), found by testing up to the next float above it.
    #[inline(always)]
    fn leaf_closest8(
        &self,
        child: u32,
        shear: &RayShear4,
        best: &mut f32,
        other: &mut impl FnMut(usize, f32) -> f32,
        found: &impl Fn(usize),
    ) -> Leaf8 {
        let mut hit = Leaf8::Miss;
        let mut pi = (child & !LEAF) as usize;
        loop {
            // SAFETY: a leaf reference is the first packet of a non-empty run inside
            // `packets` whose final packet has `last` set (see `WideBvh::leaf`).
            let pk = unsafe { self.packets.get_unchecked(pi) };
            if pk.tri != 0
                && let Some((lane, t, b)) = shear.closest(pk, best.next_up())
            {
                if t == *best {
                    return Leaf8::Tie;
                }
                *best = t;
                let id = pk.ids[lane & 3] as usize;
                found(id);
                hit = Leaf8::Hit((id, b));
            }
            let mut others = pk.other;
            while others != 0 {
                let id = pk.ids[others.trailing_zeros() as usize] as usize;
                others &= others - 1;
                let t = other(id, *best);
                if t < *best {
                    *best = t;
                    hit = Leaf8::Hit((id, [1.0 / 3.0; 3]));
                }
            }
            if pk.last {
                return hit;
            }
            pi += 1;
        }
    }

    /// [`Self::any`] through the 8-wide nodes (the 4-wide traversal when there are none).
    #[inline(always)]
    pub fn any8(
        &self,
        avx2: Avx2,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut other: impl FnMut(usize) -> bool,
    ) -> bool {
        if self.nodes8.is_empty() {
            return self.any(o, d, t_max, other);
        }
        let r = RayBox8::new(avx2, o, d);
        let shear = RayShear4::new(o, d);
        // Only interior nodes are pushed (leaves are tested on sight).
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK8];
        let mut sp = 0usize;
        let mut cur = 0u32;
        loop {
            // SAFETY: as in `closest8`, node references are valid indices.
            let node = unsafe { self.nodes8.get_unchecked(cur as usize) };
            let (_, mask) = node.hit(avx2, &r, t_max);
            // Leaves first: a leaf hit ends the query.
            let mut inner = 0u32;
            let mut bits = mask;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize & 7;
                bits &= bits - 1;
                let c = node.child[i];
                if c & LEAF == 0 {
                    inner |= 1 << i;
                } else if self.leaf_any(c, &shear, t_max, &mut other) {
                    return true;
                }
            }
            if inner != 0 {
                let first = inner.trailing_zeros() as usize & 7;
                inner &= inner - 1;
                while inner != 0 {
                    // SAFETY: at most seven pushes per level of a tree at most
                    // MAX_TREE_DEPTH deep, so sp < STACK8.
                    unsafe { stack.get_unchecked_mut(sp) }
                        .write(node.child[inner.trailing_zeros() as usize & 7]);
                    sp += 1;
                    inner &= inner - 1;
                }
                cur = node.child[first];
                continue;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every slot below the stack pointer was written by a push above.
            cur = unsafe { stack.get_unchecked(sp).assume_init() };
        }
    }

    /// Start loading child reference `child` (8-wide node or leaf packet) into the cache.
    #[inline(always)]
    fn prefetch8(&self, child: u32) {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // A node is four cache lines, a packet three (both line-aligned).
        let (p, lines) = if child & LEAF == 0 {
            let p = self.nodes8.as_ptr().wrapping_add(child as usize);
            (p as *const i8, 4)
        } else {
            let p = self.packets.as_ptr().wrapping_add((child & !LEAF) as usize);
            (p as *const i8, 3)
        };
        // SAFETY: a prefetch is a hint that never faults, whatever the address.
        unsafe {
            _mm_prefetch(p, _MM_HINT_T0);
            _mm_prefetch(p.wrapping_add(64), _MM_HINT_T0);
            _mm_prefetch(p.wrapping_add(128), _MM_HINT_T0);
            if lines == 4 {
                _mm_prefetch(p.wrapping_add(192), _MM_HINT_T0);
            }
        }
    }
}
