//! Light BVH (Conty Estevez & Kulla 2018; the layout follows pbrt-v4's `BVHLightSampler`):
//! a binary tree over the finite lights whose nodes bound position, emission directions and
//! power. Sampling walks from the root, choosing a child ∝ its [`importance`] at the shading
//! point; the pmf of a light is the product of those choices along its path, which is
//! recomputed from a per-light *bit trail* (bit k = "went to the second child at depth k").
//!
//! Nodes are 28 bytes (quantised box, octahedral axis, quantised cosines, f32 power), so the
//! 2N − 1 nodes plus an 8-byte trail take ≤ 64 bytes per light. Quantisation always widens the
//! bounds (boxes rounded outward, cones widened by the axis' quantisation error), so a child's
//! importance is zero only if the exact bounds' importance is: no contributing light loses its
//! probability.
//!
//! Build: binned SAOH (surface area × orientation × power), 12 buckets per axis, top levels in
//! parallel. The selection is unbiased as is (importances are conservative); there is no mixing.

use super::importance::{importance, union};
use super::{FiniteSelector, ShadingPoint};
use crate::lights::LightBounds;
use glam::Vec3;
use std::f32::consts::PI;

/// Bit 31 of [`Node::child`]: the node is a leaf and the low bits are a light index.
const LEAF: u32 = 1 << 31;
/// Bit 30 of [`Node::child`]: some light below emits on both sides.
const TWO_SIDED: u32 = 1 << 30;
/// The low 30 bits: second child's node index or the light index.
const INDEX_MASK: u32 = TWO_SIDED - 1;
/// Deepest tree the bit trails can describe; deeper subtrees are split by count.
const MAX_DEPTH: u32 = 64;
/// Buckets per axis of the SAOH split search.
const BUCKETS: usize = 12;
/// Subtrees with more lights than this are built in parallel.
const PARALLEL_MIN: usize = 4096;

/// A compact node: 28 bytes.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
pub struct Node {
    /// Power bound Φ of the lights below.
    phi: f32,
    /// Box, quantised outward relative to the root box (65535 steps per axis).
    qmin: [u16; 3],
    /// Box, quantised outward.
    qmax: [u16; 3],
    /// Emission axis, octahedral-encoded (2 × u16).
    w: [u16; 2],
    /// cos θo, quantised downward (wider cone).
    cos_o: u16,
    /// cos θe, quantised downward.
    cos_e: u16,
    /// Leaf flag, two-sided flag and the second child's index or the light index.
    child: u32,
}

/// Light BVH selector.
#[derive(Clone, Debug)]
pub struct BvhSelector {
    nodes: Vec<Node>,
    /// Bit trail of each light from the root.
    trails: Vec<u64>,
    /// Root box (dequantisation frame).
    origin: Vec3,
    /// Root box extent / 65535 per axis.
    scale: Vec3,
}

/// Quantise cos ∈ [-1, 1] downward to 16 bits.
fn quantize_cos_down(c: f32) -> u16 {
    let q = ((c.clamp(-1.0, 1.0) + 1.0) * 0.5 * 65535.0).floor() as i32 - 1;
    q.clamp(0, 65535) as u16
}

fn dequantize_cos(q: u16) -> f32 {
    q as f32 / 65535.0 * 2.0 - 1.0
}

/// Octahedral encoding of a unit vector.
fn oct_encode(v: Vec3) -> [u16; 2] {
    let l1 = v.x.abs() + v.y.abs() + v.z.abs();
    let (mut x, mut y) = if l1 > 0.0 {
        (v.x / l1, v.y / l1)
    } else {
        (0.0, 0.0)
    };
    if v.z < 0.0 {
        let (ox, oy) = (x, y);
        x = (1.0 - oy.abs()) * if ox >= 0.0 { 1.0 } else { -1.0 };
        y = (1.0 - ox.abs()) * if oy >= 0.0 { 1.0 } else { -1.0 };
    }
    let q = |a: f32| (((a.clamp(-1.0, 1.0) + 1.0) * 0.5 * 65535.0).round()) as u16;
    [q(x), q(y)]
}

/// Inverse of [`oct_encode`].
fn oct_decode(q: [u16; 2]) -> Vec3 {
    let x = q[0] as f32 / 65535.0 * 2.0 - 1.0;
    let y = q[1] as f32 / 65535.0 * 2.0 - 1.0;
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z < 0.0 {
        (
            (1.0 - y.abs()) * if x >= 0.0 { 1.0 } else { -1.0 },
            (1.0 - x.abs()) * if y >= 0.0 { 1.0 } else { -1.0 },
        )
    } else {
        (x, y)
    };
    Vec3::new(x, y, z).normalize_or(Vec3::Z)
}

/// Cost of a child with bounds `b` of a node of extent `parent` split along `dim` (pbrt-v4's
/// SAOH: power × orientation measure × surface area × the parent's aspect penalty, which
/// discourages splitting along the node's short axes).
fn saoh_cost(b: &LightBounds, parent: Vec3, dim: usize) -> f32 {
    let theta_o = b.cos_theta_o.clamp(-1.0, 1.0).acos();
    let theta_e = b.cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = (1.0 - b.cos_theta_o * b.cos_theta_o).max(0.0).sqrt();
    let m_omega = 2.0 * PI * (1.0 - b.cos_theta_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + b.cos_theta_o);
    let d = b.max - b.min;
    let kr = if parent[dim] > 0.0 {
        parent.max_element() / parent[dim]
    } else {
        1.0
    };
    let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    // A tiny area floor keeps coplanar point-like groups comparable.
    b.phi.max(1e-30) * m_omega * kr * area.max(1e-12)
}

/// Item being built: its bounds and local light index.
#[derive(Clone, Copy)]
struct Item {
    b: LightBounds,
    centroid: Vec3,
    light: u32,
}

/// A subtree under construction: nodes with child indices relative to its first node.
struct Built {
    nodes: Vec<Node>,
    bounds: LightBounds,
}

impl BvhSelector {
    /// Build over `bounds` (local light i = `bounds[i]`).
    pub fn new(bounds: &[LightBounds]) -> Self {
        let mut items: Vec<Item> = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| Item {
                b: *b,
                centroid: (b.min + b.max) * 0.5,
                light: i as u32,
            })
            .collect();
        if items.is_empty() {
            return Self {
                nodes: Vec::new(),
                trails: Vec::new(),
                origin: Vec3::ZERO,
                scale: Vec3::ONE,
            };
        }
        let (lo, hi) = bounds
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), b| {
                (lo.min(b.min), hi.max(b.max))
            });
        let ext = (hi - lo).max(Vec3::splat(1e-20));
        let q = Quantizer {
            origin: lo,
            inv: Vec3::splat(65535.0) / ext,
        };
        let built = build(&mut items, 0, &q);
        let mut s = Self {
            nodes: built.nodes,
            trails: vec![0; bounds.len()],
            origin: lo,
            scale: ext / 65535.0,
        };
        s.fill_trails();
        s
    }

    /// Record every light's path from the root.
    fn fill_trails(&mut self) {
        let mut stack = vec![(0usize, 0u64, 0u32)];
        while let Some((i, trail, depth)) = stack.pop() {
            let n = self.nodes[i];
            if n.child & LEAF != 0 {
                self.trails[(n.child & INDEX_MASK) as usize] = trail;
            } else {
                stack.push((i + 1, trail, depth + 1));
                stack.push((
                    (n.child & INDEX_MASK) as usize,
                    trail | (1 << depth),
                    depth + 1,
                ));
            }
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Memory of nodes and trails divided by the number of lights.
    pub fn bytes_per_light(&self) -> f64 {
        let bytes = self.nodes.len() * std::mem::size_of::<Node>() + self.trails.len() * 8;
        bytes as f64 / self.trails.len().max(1) as f64
    }

    /// The dequantised bounds of node `i`.
    #[inline]
    fn bounds(&self, i: usize) -> LightBounds {
        let n = &self.nodes[i];
        let v = |q: [u16; 3]| Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32);
        LightBounds {
            min: self.origin + v(n.qmin) * self.scale,
            max: self.origin + v(n.qmax) * self.scale,
            w: oct_decode(n.w),
            phi: n.phi,
            cos_theta_o: dequantize_cos(n.cos_o),
            cos_theta_e: dequantize_cos(n.cos_e),
            two_sided: n.child & TWO_SIDED != 0,
        }
    }

    /// Importance of node `i` at `ctx`.
    #[inline]
    fn node_importance(&self, ctx: &ShadingPoint, i: usize) -> f32 {
        importance(ctx.p, ctx.n, &self.bounds(i))
    }

    /// Path of `light` from the root: (bounds of the node taken, its importance, its sibling's
    /// importance) per level — for diagnosing selection quality.
    pub fn path(&self, ctx: &ShadingPoint, light: u32) -> Vec<(LightBounds, f32, f32)> {
        let mut out = Vec::new();
        let Some(&trail) = self.trails.get(light as usize) else {
            return out;
        };
        let mut i = 0usize;
        let mut depth = 0;
        while self.nodes[i].child & LEAF == 0 {
            let c1 = (self.nodes[i].child & INDEX_MASK) as usize;
            let (take, other) = if trail >> depth & 1 == 0 {
                (i + 1, c1)
            } else {
                (c1, i + 1)
            };
            out.push((
                self.bounds(take),
                self.node_importance(ctx, take),
                self.node_importance(ctx, other),
            ));
            i = take;
            depth += 1;
        }
        out
    }

    /// Importance of the lowest-level bounds (the leaf) of every light — for tests comparing
    /// against the exact bounds.
    pub fn leaf_importance(&self, ctx: &ShadingPoint, light: u32) -> f32 {
        let Some(&trail) = self.trails.get(light as usize) else {
            return 0.0;
        };
        let mut i = 0usize;
        let mut depth = 0;
        while self.nodes[i].child & LEAF == 0 {
            i = if trail >> depth & 1 == 0 {
                i + 1
            } else {
                (self.nodes[i].child & INDEX_MASK) as usize
            };
            depth += 1;
        }
        self.node_importance(ctx, i)
    }
}

/// Maps world positions to the root box's 16-bit grid.
struct Quantizer {
    origin: Vec3,
    inv: Vec3,
}

impl Quantizer {
    /// A compact node for `b`; `child` holds the flags and index bits.
    fn node(&self, b: &LightBounds, child: u32) -> Node {
        let lo = ((b.min - self.origin) * self.inv).floor() - Vec3::ONE;
        let hi = ((b.max - self.origin) * self.inv).ceil() + Vec3::ONE;
        let c = |x: f32| x.clamp(0.0, 65535.0) as u16;
        let w = oct_encode(b.w);
        // Widen the normal cone by the angle the axis moved when quantised.
        let err = oct_decode(w).dot(b.w).clamp(-1.0, 1.0).acos() + 1e-4;
        let cos_o = if b.cos_theta_o <= -1.0 {
            -1.0
        } else {
            (b.cos_theta_o.clamp(-1.0, 1.0).acos() + err).min(PI).cos()
        };
        Node {
            phi: b.phi,
            qmin: [c(lo.x), c(lo.y), c(lo.z)],
            qmax: [c(hi.x), c(hi.y), c(hi.z)],
            w,
            cos_o: quantize_cos_down(cos_o),
            cos_e: quantize_cos_down(b.cos_theta_e),
            child: child | if b.two_sided { TWO_SIDED } else { 0 },
        }
    }
}

/// Build the subtree over `items` at `depth`.
fn build(items: &mut [Item], depth: u32, q: &Quantizer) -> Built {
    if items.len() == 1 {
        let b = items[0].b;
        return Built {
            nodes: vec![q.node(&b, LEAF | items[0].light)],
            bounds: b,
        };
    }
    let mid = split(items, depth);
    let (left, right) = items.split_at_mut(mid);
    let (l, r) = if left.len() + right.len() > PARALLEL_MIN {
        rayon::join(|| build(left, depth + 1, q), || build(right, depth + 1, q))
    } else {
        (build(left, depth + 1, q), build(right, depth + 1, q))
    };
    let b = union(&l.bounds, &r.bounds);
    let second = 1 + l.nodes.len();
    let mut nodes = Vec::with_capacity(1 + l.nodes.len() + r.nodes.len());
    nodes.push(q.node(&b, second as u32));
    let shift = |n: &Node, off: usize| {
        let mut n = *n;
        if n.child & LEAF == 0 {
            n.child = (n.child & !INDEX_MASK) | ((n.child & INDEX_MASK) + off as u32);
        }
        n
    };
    nodes.extend(l.nodes.iter().map(|n| shift(n, 1)));
    nodes.extend(r.nodes.iter().map(|n| shift(n, second)));
    Built { nodes, bounds: b }
}

/// Reorder `items` and return the split position (both sides non-empty).
fn split(items: &mut [Item], depth: u32) -> usize {
    let n = items.len();
    let (clo, chi) = items
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), it| {
            (lo.min(it.centroid), hi.max(it.centroid))
        });
    let ext = chi - clo;
    let (blo, bhi) = items
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), it| {
            (lo.min(it.b.min), hi.max(it.b.max))
        });
    let parent = bhi - blo;
    let by_count = |items: &mut [Item]| {
        let dim = ext.max_position();
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| a.centroid[dim].total_cmp(&b.centroid[dim]));
        mid
    };
    // Halving from here on needs ⌈log2 n⌉ more levels: switch to it while they still fit.
    let halving_depth = usize::BITS - (n - 1).leading_zeros();
    if depth + halving_depth + 2 >= MAX_DEPTH || ext.max_element() <= 0.0 {
        return by_count(items);
    }
    let mut best = (f32::INFINITY, 0usize, 0usize);
    for dim in 0..3 {
        if ext[dim].is_nan() || ext[dim] <= 0.0 {
            continue;
        }
        let bucket_of =
            |c: Vec3| (((c[dim] - clo[dim]) / ext[dim] * BUCKETS as f32) as usize).min(BUCKETS - 1);
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for it in items.iter() {
            let k = bucket_of(it.centroid);
            buckets[k] = Some(match &buckets[k] {
                Some(b) => union(b, &it.b),
                None => it.b,
            });
        }
        // Suffix unions so every split costs O(1) unions.
        let mut suffix: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        let mut acc: Option<LightBounds> = None;
        for k in (0..BUCKETS).rev() {
            acc = merge(acc, buckets[k]);
            suffix[k] = acc;
        }
        let mut prefix: Option<LightBounds> = None;
        for k in 0..BUCKETS - 1 {
            prefix = merge(prefix, buckets[k]);
            if let (Some(a), Some(b)) = (prefix, suffix[k + 1]) {
                let cost = saoh_cost(&a, parent, dim) + saoh_cost(&b, parent, dim);
                if cost < best.0 {
                    best = (cost, dim, k);
                }
            }
        }
    }
    if !best.0.is_finite() {
        return by_count(items);
    }
    let (_, dim, k) = best;
    let bucket_of =
        |c: Vec3| (((c[dim] - clo[dim]) / ext[dim] * BUCKETS as f32) as usize).min(BUCKETS - 1);
    let mid = partition(items, |it| bucket_of(it.centroid) <= k);
    if mid == 0 || mid == n {
        by_count(items)
    } else {
        mid
    }
}

fn merge(a: Option<LightBounds>, b: Option<LightBounds>) -> Option<LightBounds> {
    match (a, b) {
        (Some(a), Some(b)) => Some(union(&a, &b)),
        (x, None) | (None, x) => x,
    }
}

/// In-place partition: items satisfying `pred` first; returns their count.
fn partition(items: &mut [Item], pred: impl Fn(&Item) -> bool) -> usize {
    let mut i = 0;
    for j in 0..items.len() {
        if pred(&items[j]) {
            items.swap(i, j);
            i += 1;
        }
    }
    i
}

impl FiniteSelector for BvhSelector {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        // f64 keeps the rescaled number from running out of bits as fast along deep paths.
        let mut u = u as f64;
        let mut pmf = 1.0f64;
        let mut i = 0usize;
        loop {
            let n = self.nodes[i];
            if n.child & LEAF != 0 {
                // Below the root, a leaf was reached only through a child of positive importance.
                if i > 0 || self.node_importance(ctx, 0) > 0.0 {
                    return Some((n.child & INDEX_MASK, pmf as f32));
                }
                return None;
            }
            let c1 = (n.child & INDEX_MASK) as usize;
            let i0 = self.node_importance(ctx, i + 1) as f64;
            let i1 = self.node_importance(ctx, c1) as f64;
            let total = i0 + i1;
            if total.is_nan() || total <= 0.0 {
                return None;
            }
            let p0 = i0 / total;
            if u < p0 {
                u = (u / p0).min(1.0 - f64::EPSILON);
                pmf *= p0;
                i += 1;
            } else {
                u = ((u - p0) / (1.0 - p0)).clamp(0.0, 1.0 - f64::EPSILON);
                pmf *= 1.0 - p0;
                i = c1;
            }
        }
    }

    fn pmf(&self, ctx: &ShadingPoint, light: u32) -> f32 {
        let Some(&trail) = self.trails.get(light as usize) else {
            return 0.0;
        };
        if self.nodes.is_empty() {
            return 0.0;
        }
        let mut pmf = 1.0f64;
        let mut i = 0usize;
        let mut depth = 0;
        loop {
            let n = self.nodes[i];
            if n.child & LEAF != 0 {
                if i == 0 && self.node_importance(ctx, 0) <= 0.0 {
                    return 0.0;
                }
                return pmf as f32;
            }
            let c1 = (n.child & INDEX_MASK) as usize;
            let i0 = self.node_importance(ctx, i + 1) as f64;
            let i1 = self.node_importance(ctx, c1) as f64;
            let total = i0 + i1;
            if total.is_nan() || total <= 0.0 {
                return 0.0;
            }
            if trail >> depth & 1 == 0 {
                pmf *= i0 / total;
                i += 1;
            } else {
                pmf *= i1 / total;
                i = c1;
            }
            depth += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_28_bytes() {
        assert_eq!(std::mem::size_of::<Node>(), 28);
    }

    #[test]
    fn octahedral_round_trip_is_close() {
        for &v in &[
            Vec3::X,
            -Vec3::Y,
            Vec3::new(0.3, -0.5, -0.8).normalize(),
            -Vec3::Z,
        ] {
            let d = oct_decode(oct_encode(v));
            assert!(d.dot(v) > 0.9999, "{v:?} -> {d:?}");
        }
    }
}
