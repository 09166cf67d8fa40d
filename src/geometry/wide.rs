//! A 4-wide BVH: a binary BVH ([`Tree2`]: obvhs's PLOC tree or penumbra's binned-SAH one) collapsed so that each node holds up to
//! four children whose boxes are tested together (SoA, one `Vec4` per box plane), and leaves are
//! runs of [`TriPacket`]s whose four triangles are tested together ([`RayShear4`]).
//!
//! The box test is the conservative slab test of the BVH2 (same slack, so rounding never culls a
//! box the exact ray touches). Per ray, the near and far plane of each axis are picked once from
//! the direction's sign instead of a min/max per box; this also makes the inverted boxes
//! (lo = +∞, hi = −∞) of unused child slots miss every ray.

use super::accel::{PrimKind, Primitive};
use super::bvh::{NEAR_SLACK, ROUNDING_SLACK, safe_inverse};
use super::tree2::Tree2;
use super::tri4::{RayShear4, TriPacket};
use glam::{Vec3, Vec4};
use std::mem::MaybeUninit;
use std::ops::Range;

/// Child-reference flag: the low bits are the first packet of a leaf, not a node index.
pub(super) const LEAF: u32 = 1 << 31;
/// Deepest binary tree that is collapsed (deeper ones are rejected by [`WideBvh::build`]).
pub const MAX_TREE_DEPTH: usize = 96;
/// Traversal stack depth: each wide level consumes at least one binary level, and a node
/// pushes at most three children.
pub(super) const STACK: usize = 3 * MAX_TREE_DEPTH + 1;

/// Subtrees with at most this many primitives become a single leaf.
const LEAF_PRIMS: usize = 4;

/// Triangle barycentrics (b0, b1, b2) of a hit (unused for other primitives).
pub type Bary = [f32; 3];

/// One node: `b[0][axis]` / `b[1][axis]` hold the lower / upper box plane of the four children.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Node4 {
    /// Box planes: `b[side][axis]` lane c = that plane of child c.
    pub(super) b: [[Vec4; 3]; 2],
    /// Node index, or `LEAF | first packet` (unused slots have inverted boxes and are never
    /// followed).
    pub(super) child: [u32; 4],
}

impl Node4 {
    const EMPTY: Node4 = Node4 {
        b: [[Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3]],
        child: [LEAF; 4],
    };

    /// Entry distances of the four child boxes and the mask of those entered before `t_max`.
    #[inline(always)]
    fn hit(&self, r: &RayBox, t_max: f32) -> (Vec4, u32) {
        // `& 1` lets the compiler drop the bounds checks of the runtime plane choice.
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
    /// The other side per axis (stored, not `near ^ 1` per node: one instruction less each).
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

/// The 4-wide BVH (see the module docs). Primitive ids are leaf-order indices of the BVH2.
#[derive(Clone, Debug, Default)]
pub struct WideBvh {
    pub(super) nodes: Vec<Node4>,
    pub(super) packets: Vec<TriPacket>,
    /// Set when the whole tree is one leaf (the emitter-only geometry of most scenes): its
    /// box (the root's lane 0) and leaf reference, for [`WideBvh::closest`]'s fast path.
    single_leaf: Option<SingleLeaf>,
}

/// The box and leaf reference of a tree that is a single leaf.
#[derive(Clone, Copy, Debug)]
struct SingleLeaf {
    lo: Vec3,
    hi: Vec3,
    child: u32,
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
    /// Collapse `tree` over `prims` (input order; `tree.order` maps leaf order to it). Returns
    /// `None` if the tree is deeper than [`MAX_TREE_DEPTH`] (the traversal stack's bound).
    pub fn build(tree: &Tree2, prims: &[Primitive]) -> Option<Self> {
        let mut w = Self::default();
        if !tree.nodes.is_empty() {
            if tree.depth() > MAX_TREE_DEPTH {
                return None;
            }
            w.collapse(tree, prims, 0);
        }
        // One node whose lanes 1..3 are unused (inverted boxes, which every ray misses) and
        // whose lane 0 is therefore a leaf.
        if let [root] = w.nodes.as_slice() {
            let unused = (1..4).all(|lane| {
                (0..3).all(|a| root.b[0][a][lane] == f32::INFINITY)
                    && (0..3).all(|a| root.b[1][a][lane] == f32::NEG_INFINITY)
            });
            if unused && root.child[0] & LEAF != 0 {
                let lane0 = |side: usize| {
                    Vec3::new(root.b[side][0].x, root.b[side][1].x, root.b[side][2].x)
                };
                w.single_leaf = Some(SingleLeaf {
                    lo: lane0(0),
                    hi: lane0(1),
                    child: root.child[0],
                });
            }
        }
        Some(w)
    }

    /// True if the whole tree is one leaf (most scenes' emitter-only geometry).
    pub fn is_single_leaf(&self) -> bool {
        self.single_leaf.is_some()
    }

    /// Number of nodes and of leaf packets (statistics).
    pub fn size(&self) -> (usize, usize) {
        (self.nodes.len(), self.packets.len())
    }

    /// Emit the wide node for binary node `n2`: its children, with the largest interior child
    /// repeatedly replaced by its two children (largest surface area first, as in the SAH) until
    /// there are four. Subtrees of at most [`LEAF_PRIMS`] primitives become one leaf: a packet
    /// tests four triangles for little more than the price of one.
    fn collapse(&mut self, tree: &Tree2, prims: &[Primitive], n2: usize) {
        let nodes = &tree.nodes;
        let is_leaf = |k: usize| nodes[k].range.len() <= LEAF_PRIMS || nodes[k].children.is_none();
        let mut kids: Vec<usize> = match nodes[n2].children {
            Some(c) if !is_leaf(n2) => c.to_vec(),
            _ => vec![n2],
        };
        while kids.len() < 4 {
            let widest = kids
                .iter()
                .enumerate()
                .filter(|&(_, &k)| !is_leaf(k))
                .max_by(|a, b| nodes[*a.1].half_area().total_cmp(&nodes[*b.1].half_area()));
            let Some((i, &k)) = widest else { break };
            let Some([a, b]) = nodes[k].children else {
                break;
            };
            kids[i] = a;
            kids.push(b);
        }
        let idx = self.nodes.len();
        self.nodes.push(Node4::EMPTY);
        for (lane, &k) in kids.iter().enumerate() {
            let child = if is_leaf(k) {
                LEAF | self.leaf(tree, prims, nodes[k].range.clone())
            } else {
                let child = self.nodes.len() as u32;
                self.collapse(tree, prims, k);
                child
            };
            let node = &mut self.nodes[idx];
            for a in 0..3 {
                node.b[0][a][lane] = nodes[k].lo[a];
                node.b[1][a][lane] = nodes[k].hi[a];
            }
            node.child[lane] = child;
        }
    }

    /// Pack the leaf-order primitives `range` into consecutive packets; returns the first.
    fn leaf(&mut self, tree: &Tree2, prims: &[Primitive], range: Range<usize>) -> u32 {
        let first = self.packets.len();
        let ids: Vec<usize> = range.collect();
        for chunk in ids.chunks(4) {
            let mut pk = TriPacket::EMPTY;
            for (lane, &id) in chunk.iter().enumerate() {
                let p = &prims[tree.order[id] as usize];
                match p.kind {
                    PrimKind::Triangle { .. } => pk.set_triangle(lane, id as u32, p.p),
                    PrimKind::Quadric(_) => pk.set_other(lane, id as u32),
                }
            }
            self.packets.push(pk);
        }
        if ids.is_empty() {
            // Every leaf owns at least one packet, so a leaf reference is always in bounds
            // (the traversal reads packets unchecked).
            self.packets.push(TriPacket::EMPTY);
        }
        if let Some(last) = self.packets.last_mut() {
            last.last = true;
        }
        first as u32
    }

    /// True if the tree is a single leaf whose box the ray (o, d) misses in (0, t_max), so
    /// that [`Self::closest`] would return `None`: a cheap pre-test for callers whose own
    /// per-query work (a large stack frame) is worth skipping.
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
    #[inline]
    pub fn closest(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut other: impl FnMut(usize, f32) -> f32,
    ) -> Option<(usize, f32, Bary)> {
        if let Some(leaf) = &self.single_leaf {
            // The traversal would test the root's one box and then this leaf with
            // best = t_max: the same here, minus its per-ray setup (most rays miss).
            if !leaf.hit(o, d, t_max) {
                return None;
            }
            let mut best = t_max;
            let hit = self.leaf_closest(leaf.child, &RayShear4::new(o, d), &mut best, &mut other);
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
                    // Two to four children: insertion-sorted straight onto the stack, far
                    // below near (of equal distances the lower lane ends up higher), and the
                    // top one is visited. No separate array to sort and copy.
                    let near = near.to_array();
                    let base = sp;
                    let mut bits = mask;
                    while bits != 0 {
                        let i = bits.trailing_zeros() as usize & 3;
                        bits &= bits - 1;
                        let item = (node.child[i], near[i]);
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
                if let Some(h) = self.leaf_closest(cur, shear, &mut best, &mut other) {
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

    /// The closest hit below `*best` among the primitives of leaf `child` (a `LEAF`
    /// reference): lowers `*best` to its t and returns (leaf-order id, barycentrics).
    #[inline(always)]
    fn leaf_closest(
        &self,
        child: u32,
        shear: &RayShear4,
        best: &mut f32,
        other: &mut impl FnMut(usize, f32) -> f32,
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
                hit = Some((pk.ids[lane & 3] as usize, b));
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
    fn leaf_any(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::bvh::Bvh;
    use crate::geometry::triangle::intersect_triangle;
    use crate::sampling::hash::{next_f32, pcg_from_keys};
    use rand_pcg::Pcg32;

    /// The bounding box of each triangle.
    fn boxes(prims: &[Primitive]) -> Vec<(Vec3, Vec3)> {
        prims
            .iter()
            .map(|p| {
                (
                    p.p[0].min(p.p[1]).min(p.p[2]),
                    p.p[0].max(p.p[1]).max(p.p[2]),
                )
            })
            .collect()
    }

    #[test]
    fn single_leaf_fast_path_matches_the_traversal() {
        let mut s = pcg_from_keys(&[5]);
        let rnd3 = |s: &mut Pcg32| Vec3::new(next_f32(s), next_f32(s), next_f32(s)) * 2.0 - 1.0;
        let mut fast_hits = 0;
        for n in 1..=4u32 {
            let prims: Vec<Primitive> = (0..n)
                .map(|i| Primitive {
                    p: [rnd3(&mut s), rnd3(&mut s), rnd3(&mut s)],
                    kind: PrimKind::Triangle { mesh: 0, v: [i; 3] },
                    material: 0,
                    light: u32::MAX,
                })
                .collect();
            let Some(fast) = WideBvh::build(&Tree2::ploc(&boxes(&prims)), &prims) else {
                panic!("{n} triangles gave a too deep tree");
            };
            assert!(fast.single_leaf.is_some(), "{n} triangles are not one leaf");
            let slow = WideBvh {
                single_leaf: None,
                ..fast.clone()
            };
            for _ in 0..5000 {
                let o = rnd3(&mut s) * 3.0;
                // Half the rays aim at a vertex, so hits and box-edge cases are common.
                let d = if next_f32(&mut s) < 0.5 {
                    prims[0].p[0] - o
                } else {
                    rnd3(&mut s)
                };
                let t_max = if next_f32(&mut s) < 0.5 {
                    f32::INFINITY
                } else {
                    2.0
                };
                let want = slow.closest(o, d, t_max, |_, _| f32::INFINITY);
                let got = fast.closest(o, d, t_max, |_, _| f32::INFINITY);
                assert_eq!(want, got);
                fast_hits += got.is_some() as u32;
            }
        }
        assert!(fast_hits > 1000, "{fast_hits} hits");
    }

    #[test]
    fn both_binary_trees_collapse_to_correct_wide_trees() {
        let mut s = pcg_from_keys(&[3]);
        let rnd3 = |s: &mut Pcg32| Vec3::new(next_f32(s), next_f32(s), next_f32(s)) * 10.0;
        let prims: Vec<Primitive> = (0..500u32)
            .map(|i| {
                let p0 = rnd3(&mut s);
                let (p1, p2) = (p0 + rnd3(&mut s) * 0.1, p0 + rnd3(&mut s) * 0.1);
                Primitive {
                    p: [p0, p1, p2],
                    kind: PrimKind::Triangle { mesh: 0, v: [i; 3] },
                    material: 0,
                    light: u32::MAX,
                }
            })
            .collect();
        let boxes = boxes(&prims);
        for tree in [Tree2::ploc(&boxes), Tree2::from_bvh(Bvh::build(&boxes))] {
            // Every primitive appears once in the leaf order; parents span their children.
            let mut seen = vec![0; prims.len()];
            tree.order.iter().for_each(|&i| seen[i as usize] += 1);
            assert!(seen.iter().all(|&c| c == 1));
            for n in &tree.nodes {
                if let Some([a, b]) = n.children {
                    assert_eq!(n.range, tree.nodes[a].range.start..tree.nodes[b].range.end);
                }
            }
            let Some(w) = WideBvh::build(&tree, &prims) else {
                panic!("500 triangles gave a tree deeper than {MAX_TREE_DEPTH}");
            };
            let mut hits = 0;
            for _ in 0..2000 {
                let (o, d) = (rnd3(&mut s), rnd3(&mut s) - Vec3::splat(5.0));
                let want = prims
                    .iter()
                    .filter_map(|p| intersect_triangle(o, d, f32::INFINITY, p.p))
                    .map(|h| h.0)
                    .min_by(f32::total_cmp);
                let got = w.closest(o, d, f32::INFINITY, |_, _| f32::INFINITY);
                assert_eq!(want, got.map(|h| h.1));
                if let Some((id, t, _)) = got {
                    hits += 1;
                    let p = prims[tree.order[id] as usize].p;
                    assert_eq!(
                        intersect_triangle(o, d, f32::INFINITY, p).map(|h| h.0),
                        Some(t)
                    );
                }
                assert_eq!(w.any(o, d, f32::INFINITY, |_| false), want.is_some());
            }
            assert!(hits > 100, "{hits} hits");
        }
    }
}
