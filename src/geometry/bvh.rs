//! penumbra's own BVH: a binned-SAH binary BVH with 32-byte nodes, ordered closest-hit
//! traversal and an early-out any-hit traversal.
//!
//! Sibling nodes are stored next to each other (one 64-byte line per pair), so an interior node
//! needs only the index of its first child. Primitives are referenced by leaf order: the caller
//! reorders its primitive array by [`Bvh::indices`] so that a leaf is a contiguous range.
//!
//! Box tests are conservative: the far distance of each slab interval is widened by 2γ(3)
//! (pbrt-v4's bound) and the near distance shrunk by as much, so rounding never culls a box that the exact ray touches — this matters
//! for the zero-thickness boxes of axis-aligned walls.

use super::float::gamma;
use glam::{Vec3, Vec3A};

/// Bins per axis of the SAH sweep.
const BINS: usize = 16;
/// Leaves never hold more than this many primitives (unless they are all coincident).
const MAX_LEAF: u32 = 4;
/// Cost of one node traversal relative to one primitive test (SAH).
const TRAVERSAL_COST: f32 = 1.0;
/// Depth of the traversal stack; SAH trees over a few million primitives stay far below it.
const STACK: usize = 64;
/// Nodes at this depth become leaves whatever their size, so the traversal stack cannot overflow.
const MAX_DEPTH: u32 = STACK as u32 - 1;

/// One node: its box, and either its first child (interior, `count == 0`; the second child
/// is `first + 1`) or its first primitive and primitive count (leaf).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    lo: [f32; 3],
    first: u32,
    hi: [f32; 3],
    count: u32,
}

impl Node {
    /// Entry distance of the ray into this box within (0, t_max), or +∞ on a miss.
    #[inline(always)]
    fn hit(&self, r: &RayPre, t_max: f32) -> f32 {
        // SSE: both slabs of all three axes in two subtractions and two multiplications.
        let t0 = (Vec3A::from_array(self.lo) - r.o) * r.inv;
        let t1 = (Vec3A::from_array(self.hi) - r.o) * r.inv;
        let near = max(t0.min(t1).max_element(), 0.0) * NEAR_SLACK;
        let far = t0.max(t1).min_element() * ROUNDING_SLACK;
        if near <= min(far, t_max) {
            near
        } else {
            f32::INFINITY
        }
    }
}

/// Branch-free min, without `f32::min`'s NaN handling: NaN cannot occur here (ray directions
/// are made non-zero, boxes are finite).
#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Branch-free max, see [`min`].
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// 1 − 2γ(3): the entry distance is shrunk just as conservatively, because closest-hit
/// traversal culls boxes whose entry lies beyond the best hit (a triangle in a box face).
pub(super) const NEAR_SLACK: f32 = 1.0 - 2.0 * gamma(3);

/// 1 + 2γ(3): the widening of the slab test's far distance that keeps it conservative.
pub(super) const ROUNDING_SLACK: f32 = 1.0 + 2.0 * gamma(3);

/// Per-ray constants of the slab test.
struct RayPre {
    o: Vec3A,
    inv: Vec3A,
}

impl RayPre {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3) -> Self {
        Self {
            o: o.into(),
            inv: safe_inverse(d).into(),
        }
    }
}

/// 1/d per axis, with zero components replaced by ±1e-30 first: a zero would give 0·∞ = NaN in
/// the slab test, the tiny stand-in gives ±huge distances, which the min/max logic handles.
#[inline(always)]
pub(super) fn safe_inverse(d: Vec3) -> Vec3 {
    // All in Vec3A lanes (a select instead of three scalar branches) and one vector division
    // instead of three scalar ones (same IEEE quotients).
    let d = Vec3A::from(d);
    let tiny = d.abs().cmplt(Vec3A::splat(1e-30));
    Vec3::from(Vec3A::select(tiny, Vec3A::splat(1e-30).copysign(d), d).recip())
}

/// A binary BVH over primitive boxes (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Leaf order: position i of the reordered primitive array holds original primitive
    /// `indices[i]`.
    pub indices: Vec<u32>,
}

/// Box of a set of boxes.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: Vec3::INFINITY,
        hi: Vec3::NEG_INFINITY,
    };

    #[inline]
    fn grow(&mut self, lo: Vec3, hi: Vec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }

    /// Half the surface area (the SAH only compares ratios); 0 when empty.
    #[inline]
    fn half_area(&self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

impl Bvh {
    /// Build over the primitive boxes `bounds` (lo, hi); empty input gives an empty tree.
    pub fn build(bounds: &[(Vec3, Vec3)]) -> Self {
        let n = bounds.len();
        if n == 0 {
            return Self::default();
        }
        let centroids: Vec<Vec3> = bounds.iter().map(|(lo, hi)| (*lo + *hi) * 0.5).collect();
        let mut indices: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n);
        nodes.push(Node {
            lo: [0.0; 3],
            first: 0,
            hi: [0.0; 3],
            count: n as u32,
        });
        let mut todo = vec![(0usize, 0u32)];
        while let Some((ni, depth)) = todo.pop() {
            let first = nodes[ni].first as usize;
            let count = nodes[ni].count as usize;
            let range = &mut indices[first..first + count];
            let mut bb = Aabb::EMPTY;
            let mut cb = Aabb::EMPTY;
            for &i in range.iter() {
                let (lo, hi) = bounds[i as usize];
                bb.grow(lo, hi);
                cb.grow(centroids[i as usize], centroids[i as usize]);
            }
            nodes[ni].lo = bb.lo.to_array();
            nodes[ni].hi = bb.hi.to_array();
            if count <= 1 || depth >= MAX_DEPTH {
                continue;
            }
            let split = find_split(range, bounds, &centroids, &cb);
            let leaf_cost = count as f32 * bb.half_area();
            let mid = match split {
                Some((cost, axis, pos))
                    if count as u32 > MAX_LEAF
                        || TRAVERSAL_COST * bb.half_area() + cost < leaf_cost =>
                {
                    let (lo, scale) = bin_map(&cb, axis);
                    let k = partition(range, |i| {
                        bin_of(centroids[i as usize][axis], lo, scale) < pos
                    });
                    if k == 0 || k == count { count / 2 } else { k }
                }
                // No useful split plane (all centroids coincide): split by index if too big.
                None if count as u32 > MAX_LEAF => count / 2,
                _ => continue,
            };
            let left = nodes.len();
            for (f, c) in [(first, mid), (first + mid, count - mid)] {
                nodes.push(Node {
                    lo: [0.0; 3],
                    first: f as u32,
                    hi: [0.0; 3],
                    count: c as u32,
                });
            }
            nodes[ni].first = left as u32;
            nodes[ni].count = 0;
            todo.push((left + 1, depth + 1));
            todo.push((left, depth + 1));
        }
        Self { nodes, indices }
    }

    /// Box (lo, hi) of node `i` (the root is node 0); used to collapse this tree into a wide one.
    pub(super) fn node_bounds(&self, i: usize) -> (Vec3, Vec3) {
        let n = &self.nodes[i];
        (Vec3::from_array(n.lo), Vec3::from_array(n.hi))
    }

    /// Node `i` as `Ok(first child)` (the second is `first + 1`) or `Err(leaf-order range)`.
    pub(super) fn node_kind(&self, i: usize) -> Result<usize, std::ops::Range<usize>> {
        let n = &self.nodes[i];
        if n.count == 0 {
            Ok(n.first as usize)
        } else {
            Err(n.first as usize..(n.first + n.count) as usize)
        }
    }

    /// Number of nodes (for statistics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Closest hit of the ray (o, d) in (0, t_max). `test(prim, t_best)` returns the hit
    /// distance of leaf-order primitive `prim` if it is below `t_best`, else +∞.
    /// Returns (prim, t) of the closest hit.
    #[inline]
    pub fn closest(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        mut test: impl FnMut(usize, f32) -> f32,
    ) -> Option<(usize, f32)> {
        let root = self.nodes.first()?;
        let r = RayPre::new(o, d);
        let mut best = t_max;
        let mut hit = None;
        if root.hit(&r, best) == f32::INFINITY {
            return None;
        }
        let mut stack = [(0u32, 0f32); STACK];
        let mut sp = 0usize;
        let mut node = root;
        loop {
            if node.count > 0 {
                let first = node.first as usize;
                for i in first..first + node.count as usize {
                    let t = test(i, best);
                    if t < best {
                        best = t;
                        hit = Some(i);
                    }
                }
            } else {
                let c = node.first as usize;
                let (ta, tb) = (self.nodes[c].hit(&r, best), self.nodes[c + 1].hit(&r, best));
                let (near, far, t_near, t_far) = if ta <= tb {
                    (c, c + 1, ta, tb)
                } else {
                    (c + 1, c, tb, ta)
                };
                if t_near < f32::INFINITY {
                    if t_far < f32::INFINITY && sp < STACK {
                        stack[sp] = (far as u32, t_far);
                        sp += 1;
                    }
                    node = &self.nodes[near];
                    continue;
                }
            }
            // Pop the nearest pending subtree that can still hold a closer hit.
            loop {
                if sp == 0 {
                    return hit.map(|i| (i, best));
                }
                sp -= 1;
                let (ni, t) = stack[sp];
                if t < best {
                    node = &self.nodes[ni as usize];
                    break;
                }
            }
        }
    }

    /// True if `test(prim, t_max)` reports a hit for any leaf-order primitive whose box the
    /// ray (o, d) meets in (0, t_max); stops at the first hit.
    #[inline]
    pub fn any(&self, o: Vec3, d: Vec3, t_max: f32, mut test: impl FnMut(usize) -> bool) -> bool {
        let Some(root) = self.nodes.first() else {
            return false;
        };
        let r = RayPre::new(o, d);
        if root.hit(&r, t_max) == f32::INFINITY {
            return false;
        }
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut node = root;
        loop {
            if node.count > 0 {
                let first = node.first as usize;
                if (first..first + node.count as usize).any(&mut test) {
                    return true;
                }
            } else {
                let c = node.first as usize;
                let ta = self.nodes[c].hit(&r, t_max);
                let tb = self.nodes[c + 1].hit(&r, t_max);
                match (ta < f32::INFINITY, tb < f32::INFINITY) {
                    (true, true) => {
                        if sp < STACK {
                            stack[sp] = c as u32 + 1;
                            sp += 1;
                        }
                        node = &self.nodes[c];
                        continue;
                    }
                    (true, false) => {
                        node = &self.nodes[c];
                        continue;
                    }
                    (false, true) => {
                        node = &self.nodes[c + 1];
                        continue;
                    }
                    (false, false) => {}
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = &self.nodes[stack[sp] as usize];
        }
    }
}

/// Centroid-to-bin map of `axis`: bin = (c − lo)·scale.
#[inline]
fn bin_map(cb: &Aabb, axis: usize) -> (f32, f32) {
    let extent = cb.hi[axis] - cb.lo[axis];
    (cb.lo[axis], BINS as f32 * (1.0 - 1e-6) / extent)
}

#[inline]
fn bin_of(c: f32, lo: f32, scale: f32) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// Best binned SAH split: (cost = Σ count·half_area over both sides, axis, first right bin).
fn find_split(
    range: &[u32],
    bounds: &[(Vec3, Vec3)],
    centroids: &[Vec3],
    cb: &Aabb,
) -> Option<(f32, usize, usize)> {
    let mut best: Option<(f32, usize, usize)> = None;
    // `axis` indexes vector components and is part of the result, not an iterator position.
    #[allow(clippy::needless_range_loop)]
    for axis in 0..3 {
        // Boxes are finite, so the extent is never NaN.
        if cb.hi[axis] - cb.lo[axis] <= 0.0 {
            continue;
        }
        let (lo, scale) = bin_map(cb, axis);
        let mut boxes = [Aabb::EMPTY; BINS];
        let mut counts = [0u32; BINS];
        for &i in range {
            let b = bin_of(centroids[i as usize][axis], lo, scale);
            let (plo, phi) = bounds[i as usize];
            boxes[b].grow(plo, phi);
            counts[b] += 1;
        }
        // Right-to-left sweep stores the right-side costs; left-to-right completes them.
        let mut right_cost = [0f32; BINS];
        let (mut acc, mut n) = (Aabb::EMPTY, 0u32);
        for b in (1..BINS).rev() {
            acc.grow(boxes[b].lo, boxes[b].hi);
            n += counts[b];
            right_cost[b] = n as f32 * acc.half_area();
        }
        let (mut acc, mut n) = (Aabb::EMPTY, 0u32);
        for b in 1..BINS {
            acc.grow(boxes[b - 1].lo, boxes[b - 1].hi);
            n += counts[b - 1];
            if n == 0 || n as usize == range.len() {
                continue;
            }
            let cost = n as f32 * acc.half_area() + right_cost[b];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    best
}

/// Move the elements satisfying `left` to the front; returns how many there are.
fn partition(v: &mut [u32], mut left: impl FnMut(u32) -> bool) -> usize {
    let mut k = 0;
    for j in 0..v.len() {
        if left(v[j]) {
            v.swap(k, j);
            k += 1;
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_primitive_is_in_exactly_one_leaf() {
        let bounds: Vec<(Vec3, Vec3)> = (0..1000)
            .map(|i| {
                let c = Vec3::new((i % 10) as f32, ((i / 10) % 10) as f32, (i / 100) as f32);
                (c, c + 0.5)
            })
            .chain(std::iter::repeat_n((Vec3::ZERO, Vec3::ONE), 50))
            .collect();
        let bvh = Bvh::build(&bounds);
        let mut seen = vec![0u32; bounds.len()];
        for &i in &bvh.indices {
            seen[i as usize] += 1;
        }
        assert!(seen.iter().all(|&c| c == 1));
        let mut covered = vec![0u32; bounds.len()];
        for n in &bvh.nodes {
            if n.count > 0 {
                assert!(n.count <= MAX_LEAF);
                for i in n.first..n.first + n.count {
                    covered[i as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
    }
}
