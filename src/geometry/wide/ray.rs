//! One ray through the wide BVH: closest hit (children visited near to far, the farther ones
//! insertion-sorted onto the stack) and any hit (leaves tested on sight, first hit ends it).
//!
//! The box test is the conservative slab test of the BVH2 (same slack, so rounding never culls a
//! box the exact ray touches). Per ray, the near and far plane of each axis are picked once from
//! the direction's sign instead of a min/max per box; this also makes the inverted boxes
//! (lo = +∞, hi = −∞) of unused child slots miss every ray.

use super::{Bary, LEAF, Node4, STACK, SingleLeaf, WideBvh};
use crate::geometry::bvh::{NEAR_SLACK, ROUNDING_SLACK, safe_inverse};
use crate::geometry::tri4::RayShear4;
use glam::{Vec3, Vec4};
use std::mem::MaybeUninit;

impl Node4 {
    /// Entry distances of the four child boxes and the mask of those entered before `t_max`.
    #[inline(always)]
    fn hit(&self, r: &RayBox, t_max: f32) -> (Vec4, u32) {
        // `side & 1`: the plane index is 0 or 1 by construction, so no check per node.
        let t = |side: usize, axis: usize| (self.b[side & 1][axis] - r.o[axis]) * r.inv[axis];
        let near = t(r.near[0], 0)
            .max(t(r.near[1], 1))
            .max(t(r.near[2], 2))
            .max(Vec4::ZERO)
            * NEAR_SLACK;
        let far = t(r.far[0], 0).min(t(r.far[1], 1)).min(t(r.far[2], 2)) * ROUNDING_SLACK;
        (near, near.cmple(far.min(Vec4::splat(t_max))).bitmask())
    }
}

/// Per-ray constants of the 4-wide slab test.
struct RayBox {
    o: [Vec4; 3],
    inv: [Vec4; 3],
    /// Side (0 = lower, 1 = upper box plane) through which the ray enters, per axis.
    near: [usize; 3],
    /// The other side per axis (stored once per ray rather than `near ^ 1` per node).
    far: [usize; 3],
}

impl RayBox {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3) -> Self {
        let inv = safe_inverse(d);
        let near = [
            (inv.x < 0.0) as usize,
            (inv.y < 0.0) as usize,
            (inv.z < 0.0) as usize,
        ];
        Self {
            o: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            inv: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            near,
            far: [near[0] ^ 1, near[1] ^ 1, near[2] ^ 1],
        }
    }
}

/// `Vec4::max` on one lane (SSE `maxps` semantics, NaN and zero sign included), so that the
/// single-box test reduces the axes exactly like [`Node4::hit`] does per lane.
#[inline(always)]
fn lane_max(a: f32, b: f32) -> f32 {
    Vec4::splat(a).max(Vec4::splat(b)).x
}

/// `Vec4::min` on one lane (see [`lane_max`]).
#[inline(always)]
fn lane_min(a: f32, b: f32) -> f32 {
    Vec4::splat(a).min(Vec4::splat(b)).x
}

impl SingleLeaf {
    /// The slab test of [`Node4::hit`] for this one box: the same operations on the same
    /// values as its lane 0, hence the same verdict, without the splatted per-ray setup.
    #[inline(always)]
    fn hit(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        let inv = safe_inverse(d);
        let t = |lo: f32, hi: f32, o: f32, inv: f32| {
            let (n, f) = if inv < 0.0 { (hi, lo) } else { (lo, hi) };
            ((n - o) * inv, (f - o) * inv)
        };
        let (nx, fx) = t(self.lo.x, self.hi.x, o.x, inv.x);
        let (ny, fy) = t(self.lo.y, self.hi.y, o.y, inv.y);
        let (nz, fz) = t(self.lo.z, self.hi.z, o.z, inv.z);
        let near = lane_max(lane_max(lane_max(nx, ny), nz), 0.0) * NEAR_SLACK;
        let far = lane_min(fx, fy);
        let far = lane_min(far, fz) * ROUNDING_SLACK;
        near <= lane_min(far, t_max)
    }
}

impl WideBvh {
    /// True if the tree is a single leaf whose box the ray (o, d) misses in (0, t_max), so
    /// that [`Self::closest`] would return `None`: a cheap pre-test for callers whose own
    /// per-query work (setting up a traversal) is worth skipping.
    #[inline(always)]
    pub fn single_leaf_missed(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        match &self.single_leaf {
            Some(leaf) => !leaf.hit(o, d, t_max),
            None => false,
        }
    }

    /// Closest hit of the ray (o, d) in (0, t_max): (leaf-order id, t, barycentrics).
    /// Triangles are tested here; `other(id, t_best)` returns the hit distance of a
    /// non-triangle primitive if below `t_best`, else +∞.
    #[cfg(test)]
    pub fn closest(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        other: impl FnMut(usize, f32) -> f32,
    ) -> Option<(usize, f32, Bary)> {
        self.closest_hinted(o, d, t_max, other, |_| {})
    }

    /// [`Self::closest`], calling `found(id)` at each new best triangle hit, so that the caller
    /// can start loading what its hit record needs while the traversal goes on.
    #[inline(always)]
    pub fn closest_hinted(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut other: impl FnMut(usize, f32) -> f32,
        found: impl Fn(usize),
    ) -> Option<(usize, f32, Bary)> {
        if let Some(leaf) = &self.single_leaf {
            // The traversal would test the root's one box and then this leaf with
            // best = t_max: the same here, minus its per-ray setup (most rays miss).
            if !leaf.hit(o, d, t_max) {
                return None;
            }
            let mut best = t_max;
            let shear = RayShear4::new(o, d);
            let hit = self.leaf_closest(leaf.child, &shear, &mut best, &mut other, &found);
            return hit.map(|(id, b)| (id, best, b));
        }
        if self.nodes.is_empty() {
            return None;
        }
        let r = RayBox::new(o, d);
        // Built at the first leaf: a ray that misses every leaf box (most rays against the
        // small emitter-only geometry) never pays for the shear setup.
        let mut shear: Option<RayShear4> = None;
        let mut best = t_max;
        let mut hit: Option<(usize, Bary)> = None;
        // Not cleared per ray: only entries below `sp` are ever read, and those were written.
        let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = 0u32;
        loop {
            if cur & LEAF == 0 {
                // SAFETY: interior references are indices of nodes pushed by `collapse`, and
                // the root 0 exists (`nodes` is not empty).
                let node = unsafe { self.nodes.get_unchecked(cur as usize) };
                let (near, mask) = node.hit(&r, best);
                if mask != 0 {
                    if mask & (mask - 1) == 0 {
                        cur = node.child[mask.trailing_zeros() as usize & 3];
                        continue;
                    }
                    let near = near.to_array();
                    let rest = mask & (mask - 1);
                    if rest & (rest - 1) == 0 {
                        // Two children (the commonest case): the nearer is visited, the other
                        // pushed; of equal distances the lower lane first, the order of the
                        // insertion sort below. Selects, not the sort's data-dependent loop
                        // branches (cornell path 64², 16 spp, callgrind --branch-sim: 5.50 →
                        // 5.34 mispredicted branches and 1063 → 1048 Ir per query).
                        let (i, j) = (
                            mask.trailing_zeros() as usize & 3,
                            rest.trailing_zeros() as usize & 3,
                        );
                        let lower_first = near[i] <= near[j];
                        let (go, other) = if lower_first { (i, j) } else { (j, i) };
                        let item = (node.child[other], near[other]);
                        if self.large {
                            self.prefetch(item.0);
                        }
                        // SAFETY: sp < STACK, as for the pushes below.
                        unsafe { stack.get_unchecked_mut(sp) }.write(item);
                        sp += 1;
                        cur = node.child[go];
                        continue;
                    }
                    // Three or four children: insertion-sorted straight onto the stack, far
                    // below near (of equal distances the lower lane ends up higher), and the
                    // top one is visited. No separate array to sort and copy.
                    let base = sp;
                    let mut bits = mask;
                    while bits != 0 {
                        let i = bits.trailing_zeros() as usize & 3;
                        bits &= bits - 1;
                        let item = (node.child[i], near[i]);
                        if self.large {
                            self.prefetch(item.0);
                        }
                        let mut j = sp;
                        // SAFETY: slots base..sp were written in this loop, and sp < STACK:
                        // at wide depth d at most 3·(d − 1) entries are pending below `base`
                        // (three per ancestor), so indices stay below 3·d ≤ STACK − 1. Hit
                        // children have non-NaN entry distances, so `<=` is the exact
                        // complement of the `>` of a stable ascending sort.
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
                if let Some(h) = self.leaf_closest(cur, shear, &mut best, &mut other, &found) {
                    hit = Some(h);
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

    /// Start loading child reference `child` (node or leaf packet) into the cache: a subtree
    /// pushed for later is then ready when popped, its latency hidden behind the nearer one.
    #[inline(always)]
    fn prefetch(&self, child: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            // A node is two cache lines, a packet three (both line-aligned).
            let (p, lines) = if child & LEAF == 0 {
                (
                    self.nodes.as_ptr().wrapping_add(child as usize) as *const i8,
                    64,
                )
            } else {
                let p = self.packets.as_ptr().wrapping_add((child & !LEAF) as usize);
                (p as *const i8, 128)
            };
            // SAFETY: a prefetch is a hint that never faults, whatever the address.
            unsafe {
                _mm_prefetch(p, _MM_HINT_T0);
                _mm_prefetch(p.wrapping_add(64), _MM_HINT_T0);
                _mm_prefetch(p.wrapping_add(lines), _MM_HINT_T0);
            }
        }
    }

    /// The closest hit below `*best` among the primitives of leaf `child` (a `LEAF`
    /// reference): lowers `*best` to its t and returns (leaf-order id, barycentrics).
    #[inline(always)]
    pub(super) fn leaf_closest(
        &self,
        child: u32,
        shear: &RayShear4,
        best: &mut f32,
        other: &mut impl FnMut(usize, f32) -> f32,
        found: &impl Fn(usize),
    ) -> Option<(usize, Bary)> {
        let mut hit = None;
        let mut pi = (child & !LEAF) as usize;
        loop {
            // SAFETY: a leaf reference is the first packet of a non-empty run inside
            // `packets` (see `leaf`) whose final packet has `last` set, so pi never leaves
            // `packets`.
            let pk = unsafe { self.packets.get_unchecked(pi) };
            if pk.tri != 0
                && let Some((lane, t, b)) = shear.closest(pk, *best)
            {
                *best = t;
                let id = pk.ids[lane & 3] as usize;
                found(id);
                hit = Some((id, b));
            }
            let mut others = pk.other;
            while others != 0 {
                let id = pk.ids[others.trailing_zeros() as usize] as usize;
                others &= others - 1;
                let t = other(id, *best);
                if t < *best {
                    *best = t;
                    hit = Some((id, [1.0 / 3.0; 3]));
                }
            }
            if pk.last {
                return hit;
            }
            pi += 1;
        }
    }

    /// True if leaf `child` (a `LEAF` reference) holds a triangle, or a primitive for which
    /// `other(id)` is true, that blocks the ray in (0, t_max).
    #[inline(always)]
    pub(super) fn leaf_any(
        &self,
        child: u32,
        shear: &RayShear4,
        t_max: f32,
        other: &mut impl FnMut(usize) -> bool,
    ) -> bool {
        let mut pi = (child & !LEAF) as usize;
        loop {
            // SAFETY: as in `closest`, a leaf's packet run lies inside `packets`.
            let pk = unsafe { self.packets.get_unchecked(pi) };
            if pk.tri != 0 && shear.any(pk, t_max) {
                return true;
            }
            let mut others = pk.other;
            while others != 0 {
                let id = pk.ids[others.trailing_zeros() as usize] as usize;
                others &= others - 1;
                if other(id) {
                    return true;
                }
            }
            if pk.last {
                return false;
            }
            pi += 1;
        }
    }

    /// True if a triangle, or a primitive for which `other(id, t_max)` is true, blocks the ray
    /// (o, d) in (0, t_max); stops at the first hit.
    #[inline]
    pub fn any(&self, o: Vec3, d: Vec3, t_max: f32, other: impl FnMut(usize) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        self.any_from(0, o, d, t_max, other)
    }

    /// [`Self::any`] within the subtree of node `root` (a valid node index).
    #[inline]
    pub(super) fn any_from(
        &self,
        root: u32,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut other: impl FnMut(usize) -> bool,
    ) -> bool {
        let r = RayBox::new(o, d);
        let shear = RayShear4::new(o, d);
        // Not cleared per ray: only entries below `sp` are ever read, and those were written.
        // Only interior nodes are pushed (leaves are tested on sight).
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
        let mut sp = 0usize;
        let mut cur = root;
        loop {
            // SAFETY: as in `closest`, node references are valid indices.
            let node = unsafe { self.nodes.get_unchecked(cur as usize) };
            let (_, mask) = node.hit(&r, t_max);
            // Leaves first: a leaf hit ends the query, while a subtree may be descended
            // without result (large occluders such as walls sit in leaves near the root).
            let mut inner = 0u32;
            let mut bits = mask;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize & 3;
                bits &= bits - 1;
                let c = node.child[i];
                if c & LEAF == 0 {
                    inner |= 1 << i;
                } else if self.leaf_any(c, &shear, t_max, &mut other) {
                    return true;
                }
            }
            if inner != 0 {
                let first = inner.trailing_zeros() as usize & 3;
                inner &= inner - 1;
                while inner != 0 {
                    // SAFETY: at most three pushes per level of a tree at most
                    // MAX_TREE_DEPTH deep, so sp < STACK.
                    unsafe { stack.get_unchecked_mut(sp) }
                        .write(node.child[inner.trailing_zeros() as usize & 3]);
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
}
