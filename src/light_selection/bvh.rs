//! Light BVH (Conty Estevez & Kulla 2018; importance as in pbrt-v4's `BVHLightSampler`), laid
//! out for speed: an **8-wide** tree over the finite lights whose nodes hold their children's
//! bounds (centre, bounding radius, emission axis, cos/sin θo, cos θe, power) as f32 lanes, so
//! one pass of straight-line code scores all eight children at once (compiled per instruction
//! set through [`Cpu::dispatch`]: AVX2/AVX-512 when the CPU has them, SSE2 otherwise — all round
//! identically: no FMA contraction, and sqrt/div are exact IEEE operations, so the choice of
//! ISA never changes a sample).
//!
//! Sampling walks from the root, choosing a child ∝ its importance at the shading point:
//! ⌈log₈ N⌉ levels (5 for 10k lights, 7 for 1M) instead of the binary tree's log₂ N levels of
//! two evaluations each. The importance has no acos/atan: angles are combined through
//! (sin, cos) pairs, with `sin θo` stored per child, so it costs four square roots and two
//! divisions per lane — all of them taken from d² directly (the pairs are carried scaled by
//! d), so they run side by side instead of waiting on each other; the running sums of a
//! node's importances are added as a tree, four additions deep. The pmf for MIS is the product along the light's path, found by walking
//! *up* from the light's slot through parent links (no search from the root); `sample`
//! multiplies its per-level probabilities in the same bottom-up order, so both return the same
//! f32 bit for bit.
//!
//! The bounds are exact f32 (no quantisation), so a child's importance is zero only if no light
//! below it can reach the receiver's upper hemisphere: no contributing light loses its
//! probability (`tests/many_selection.rs`). A walk can still reach a node whose children all
//! score zero although the node did not; `sample` then returns `None` and the pmf sums to
//! P(Some) < 1 — consistent (unbiased), slightly wasteful.
//!
//! Build: the binary SAOH tree (surface area × orientation × power, 12 buckets per axis, top
//! levels in parallel), then collapsed: each wide node takes its binary node's two children and
//! keeps replacing the one with the most lights by its own two children until it has eight.

use super::importance::{cone_angle, union, union_angles};
use super::{FiniteSelector, ShadingPoint};
use crate::isa::{Cpu, Kernel, Token};
use crate::lights::LightBounds;
use glam::Vec3;
use std::f32::consts::PI;

/// Children per node.
pub const WIDTH: usize = 8;
/// Bit 31 of a child slot: the slot is a light (low bits: its local index).
const LEAF: u32 = 1 << 31;
/// Marks an empty slot (its power is zero, so its importance is too).
const EMPTY: u32 = u32::MAX;
/// Deepest binary tree; deeper subtrees are split by count (the wide tree is never deeper).
const MAX_DEPTH: u32 = 64;
/// Buckets per axis of the SAOH split search.
const BUCKETS: usize = 12;
/// Subtrees with more lights than this are built in parallel.
const PARALLEL_MIN: usize = 4096;
/// Importances are clamped here so a receiver on top of a point light cannot make a pmf NaN.
const MAX_IMPORTANCE: f32 = 1e30;

/// One wide node: the bounds of its (up to) eight children, structure of arrays: 384 bytes,
/// six cache lines, so a level of the walk touches six lines.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub struct WideNode {
    cx: [f32; WIDTH],
    cy: [f32; WIDTH],
    cz: [f32; WIDTH],
    /// Half the diagonal of the child's box (its bounding sphere's radius).
    r: [f32; WIDTH],
    wx: [f32; WIDTH],
    wy: [f32; WIDTH],
    wz: [f32; WIDTH],
    /// The child's power Φ ≥ 0, its sign bit set where some light below emits on both sides
    /// (a seventh cache line for that one flag would cost more than the `abs` it takes).
    phi: [f32; WIDTH],
    cos_o: [f32; WIDTH],
    sin_o: [f32; WIDTH],
    cos_e: [f32; WIDTH],
    /// `LEAF | light`, a child node's index, or [`EMPTY`].
    child: [u32; WIDTH],
}

impl Default for WideNode {
    fn default() -> Self {
        Self {
            cx: [0.0; WIDTH],
            cy: [0.0; WIDTH],
            cz: [0.0; WIDTH],
            r: [0.0; WIDTH],
            wx: [0.0; WIDTH],
            wy: [0.0; WIDTH],
            wz: [1.0; WIDTH],
            phi: [0.0; WIDTH],
            cos_o: [1.0; WIDTH],
            sin_o: [0.0; WIDTH],
            cos_e: [0.0; WIDTH],
            child: [EMPTY; WIDTH],
        }
    }
}

/// `x.max(0.0)` for every x, NaN included (a NaN becomes 0), in one compare and one mask.
#[inline(always)]
fn pos(x: f32) -> f32 {
    if x > 0.0 { x } else { 0.0 }
}

impl WideNode {
    fn set(&mut self, k: usize, b: &LightBounds, child: u32) {
        let c = (b.min + b.max) * 0.5;
        let cos_o = b.cos_theta_o.clamp(-1.0, 1.0);
        self.cx[k] = c.x;
        self.cy[k] = c.y;
        self.cz[k] = c.z;
        self.r[k] = (b.max - b.min).length() * 0.5;
        self.wx[k] = b.w.x;
        self.wy[k] = b.w.y;
        self.wz[k] = b.w.z;
        let phi = if b.phi.is_nan() { 0.0 } else { b.phi.max(0.0) };
        self.phi[k] = if b.two_sided { -phi } else { phi };
        self.cos_o[k] = cos_o;
        self.sin_o[k] = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        self.cos_e[k] = b.cos_theta_e;
        self.child[k] = child;
    }

    /// Importance of the eight children for a receiver at `p` with geometric normal `n` (zero
    /// when unknown): the formula of [`super::importance::importance`] (Φ·cos θ′/d², times
    /// cos θ′ᵢ), lane by lane, branch-free: all eight children in one pass.
    #[inline(always)]
    fn importance(&self, p: Vec3, n: Vec3, out: &mut [f32; WIDTH]) {
        // A receiver without a normal (a medium, a two-sided probe) skips the receiver-side
        // cosine: one loop for each case keeps that test out of the lanes.
        if n != Vec3::ZERO {
            self.importance_lanes::<true>(p, n, out)
        } else {
            self.importance_lanes::<false>(p, n, out)
        }
    }

    #[inline(always)]
    // One index walks twelve lane arrays (clearer than a twelve-way zip).
    #[allow(clippy::needless_range_loop)]
    fn importance_lanes<const HAS_N: bool>(&self, p: Vec3, n: Vec3, out: &mut [f32; WIDTH]) {
        // Every angle is carried as its (sin, cos) pair scaled by the distance d (or d² for
        // products of two), so the four square roots and the two divisions all start from
        // d² at once instead of waiting on each other: a level's latency is one square root
        // and a few multiplies, not sqrt → div → sqrt → div.
        for k in 0..WIDTH {
            let tx = p.x - self.cx[k];
            let ty = p.y - self.cy[k];
            let tz = p.z - self.cz[k];
            let dd = tx * tx + ty * ty + tz * tz;
            let d = dd.sqrt();
            let rl = self.r[k];
            // pbrt-v4's floor: the half diagonal compared with a squared length (see importance.rs).
            // (`max` spelled as compares: a NaN distance takes the floor, as `f32::max` does.)
            let d2 = if dd > rl { dd } else { rl };
            let d2 = if d2 > 1e-12 { d2 } else { 1e-12 };
            let phi_signed = self.phi[k];
            let phi = phi_signed.abs();
            let phi_d2 = phi / d2;
            let inv_dd = 1.0 / dd;
            // A receiver inside the bounding sphere sees it in every direction: θb = π.
            let inside = (d <= rl) | (d == 0.0);
            // cos θb·d and sin θb·d = r.
            let cb = pos(dd - rl * rl).sqrt();
            // cos θw·d, with two-sided emitters facing the receiver with either side.
            let wt = self.wx[k] * tx + self.wy[k] * ty + self.wz[k] * tz;
            let wt = if phi_signed.is_sign_negative() {
                wt.abs()
            } else {
                wt
            };
            let sw = pos(dd - wt * wt).sqrt();
            let (cos_o, sin_o) = (self.cos_o[k], self.sin_o[k]);
            // θx = max(0, θw − θo), θ′ = max(0, θx − θb), as (sin, cos)·d pairs.
            let within_o = wt > cos_o * d;
            let cx = if within_o { d } else { wt * cos_o + sw * sin_o };
            let sx = if within_o {
                0.0
            } else {
                sw * cos_o - wt * sin_o
            };
            let cos_p = if inside | (cx > cb) {
                1.0
            } else {
                (cx * cb + sx * rl) * inv_dd
            };
            let mut imp = phi_d2 * cos_p;
            let mut below = false;
            if HAS_N {
                // The receiver's side: the angle between n and the direction to the bounds,
                // narrowed by θb; zero only if the whole sphere is below the tangent plane.
                // A receiver inside the bounds (θb = π) sees them on both sides.
                let ci = -(n.x * tx + n.y * ty + n.z * tz);
                let si = pos(dd - ci * ci).sqrt();
                let cos_pi = if ci > cb {
                    1.0
                } else {
                    (ci * cb + si * rl) * inv_dd
                };
                below = !inside & (cos_pi <= 0.0);
                imp = if inside { imp } else { imp * cos_pi };
            }
            let dead = (cos_p <= self.cos_e[k]) | (phi <= 0.0) | below | imp.is_nan();
            out[k] = if dead || !(imp < MAX_IMPORTANCE) {
                if dead { 0.0 } else { MAX_IMPORTANCE }
            } else {
                imp
            };
        }
    }
}

/// Running sums of a node's eight importances in f64, `cum[k]` = Σ imp[..k], added as a tree
/// (four additions deep instead of eight in a row: a level of the walk waits on them):
/// pairs, then the first quad, then quad + pair, each sum extending one already made. Every
/// `cum[k + 1]` is `cum[k]` or a sum made from it plus non-negative terms, so rounding keeps
/// them non-decreasing and a zero importance adds exactly nothing (its slot's interval is
/// empty). The total is `cum[WIDTH]`: the one place both `sample` and `pmf` add importances,
/// so every probability is the same f64 in both.
#[inline(always)]
fn running_sums(imp: &[f32; WIDTH]) -> [f64; WIDTH + 1] {
    let a = imp.map(|x| x as f64);
    let p01 = a[0] + a[1];
    let p23 = a[2] + a[3];
    let p45 = a[4] + a[5];
    let p67 = a[6] + a[7];
    let q0 = p01 + p23;
    let h6 = q0 + p45;
    [
        0.0,
        a[0],
        p01,
        p01 + a[2],
        q0,
        q0 + a[4],
        h6,
        h6 + a[6],
        h6 + p67,
    ]
}

/// One level of the walk: the child picked ∝ importance by `u`, `u` rescaled to that
/// child's share, and the child's probability; `None` where no child has importance.
#[inline(always)]
fn descend(imp: &[f32; WIDTH], cum: &[f64; WIDTH + 1], u: f64) -> Option<(usize, f64, f64)> {
    let total = cum[WIDTH];
    if !(total > 0.0) {
        return None;
    }
    let target = u * total;
    let pick = pick_slot(imp, cum, target);
    let x = imp[pick] as f64;
    // `target − cum[pick]` ≥ 0 is exact in sign (cum[pick] ≤ target, or the fallback slot's
    // sum, below the total).
    let next = ((target - cum[pick]) / x).clamp(0.0, 1.0 - f64::EPSILON);
    Some((pick, next, x / total))
}

/// The pmf of a walk: its levels' probabilities multiplied bottom-up (as `pmf_impl` does).
#[inline(always)]
fn walk_pmf(probs: &[f64]) -> f32 {
    let mut pmf = 1.0f64;
    for &p in probs.iter().rev() {
        pmf *= p;
    }
    pmf as f32
}

/// The child whose share of the running sums `cum` (from [`running_sums`]) holds `target`:
/// cum[pick] ≤ target < cum[pick + 1], i.e. the number of running sums past slot 0 that do not
/// exceed it. Such a slot has a positive importance (its running sum grows), so this is the
/// first positive child whose sum passes `target`, found by counting (branch-free) instead of
/// searching. If rounding put `target` at or past the total: the last positive child.
#[inline(always)]
fn pick_slot(imp: &[f32; WIDTH], cum: &[f64; WIDTH + 1], target: f64) -> usize {
    let mut pick = 0;
    for &c in &cum[1..] {
        pick += (c <= target) as usize;
    }
    if pick == WIDTH {
        pick = imp.iter().rposition(|&x| x > 0.0).unwrap_or(0);
    }
    pick
}

/// Light BVH selector.
#[derive(Clone, Debug)]
pub struct BvhSelector {
    nodes: Vec<WideNode>,
    /// Per node: `parent << 3 | slot` (the root: `u32::MAX`).
    parent: Vec<u32>,
    /// Per light: `node << 3 | slot` of its leaf slot.
    slot: Vec<u32>,
    /// The instruction set the traversal runs on ([`Cpu::dispatch`]).
    cpu: Cpu,
    /// Levels of the deepest walk (wide nodes from the root to a leaf's node).
    levels: usize,
}

/// Walks at most this deep (every tree below 8^16 lights unless degenerate) record their
/// per-level probabilities in a 16-entry array: zeroing it per sample costs a quarter of
/// the full `MAX_DEPTH` one's stores.
const SHALLOW: usize = 16;

/// Cost of a child with bounds `b` of a node of extent `parent` split along `dim` (pbrt-v4's
/// SAOH: power × orientation measure × surface area × the parent's aspect penalty, which
/// discourages splitting along the node's short axes).
/// `m_omega` is `b`'s [`orientation_measure`].
fn saoh_cost(b: &LightBounds, m_omega: f32, parent: Vec3, dim: usize) -> f32 {
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

/// The solid-angle measure of the directions a cone of normals (cos θo, with angles
/// `(theta_o, theta_e)` from [`cone_angle`]) can emit into: the SAOH's orientation term.
fn orientation_measure(cos_o: f32, (theta_o, theta_e): (f32, f32)) -> f32 {
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
    2.0 * PI * (1.0 - cos_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + cos_o)
}

/// The last [`orientation_measure`] taken and the cone it was for (cos θo, cos θe bits): the
/// split search's running unions keep the same cone over many buckets once it is wide, so
/// most candidates reuse it instead of taking a cosine.
#[derive(Default)]
struct MeasureMemo(Option<(u64, f32)>);

impl MeasureMemo {
    fn get(&mut self, (b, t): &Bounds) -> f32 {
        let key = (b.cos_theta_o.to_bits() as u64) << 32 | b.cos_theta_e.to_bits() as u64;
        match self.0 {
            Some((k, m)) if k == key => m,
            _ => {
                let m = orientation_measure(b.cos_theta_o, *t);
                self.0 = Some((key, m));
                m
            }
        }
    }
}

/// Item being built: its bounds, their cone angles and local light index.
#[derive(Clone, Copy)]
struct Item {
    b: LightBounds,
    /// `b`'s (θo, θe) ([`cone_angle`]): taken once per light instead of at every union.
    t: (f32, f32),
    centroid: Vec3,
    light: u32,
}

/// A node of the binary build tree (indices relative to its subtree's first node while built).
#[derive(Clone, Copy)]
struct BNode {
    b: LightBounds,
    left: u32,
    right: u32,
    /// Local light index for a leaf, `u32::MAX` for an inner node.
    light: u32,
    count: u32,
}

/// Build the binary subtree over `items` at `depth`; its root is its first node.
fn build_binary(items: &mut [Item], depth: u32) -> Vec<BNode> {
    if items.len() == 1 {
        return vec![BNode {
            b: items[0].b,
            left: 0,
            right: 0,
            light: items[0].light,
            count: 1,
        }];
    }
    let mid = split(items, depth);
    let (left, right) = items.split_at_mut(mid);
    let (l, r) = if left.len() + right.len() > PARALLEL_MIN {
        rayon::join(
            || build_binary(left, depth + 1),
            || build_binary(right, depth + 1),
        )
    } else {
        (
            build_binary(left, depth + 1),
            build_binary(right, depth + 1),
        )
    };
    let second = 1 + l.len() as u32;
    let mut nodes = Vec::with_capacity(1 + l.len() + r.len());
    nodes.push(BNode {
        b: union(&l[0].b, &r[0].b),
        left: 1,
        right: second,
        light: u32::MAX,
        count: l[0].count + r[0].count,
    });
    let shift = |n: &BNode, off: u32| {
        let mut n = *n;
        if n.light == u32::MAX {
            n.left += off;
            n.right += off;
        }
        n
    };
    nodes.extend(l.iter().map(|n| shift(n, 1)));
    nodes.extend(r.iter().map(|n| shift(n, second)));
    nodes
}

/// Collapse the binary tree below `b` (an index into `bin`) into wide node `out.nodes.len()`,
/// depth first; returns its index.
fn collapse(bin: &[BNode], b: usize, parent: u32, level: usize, out: &mut BvhSelector) -> u32 {
    out.levels = out.levels.max(level);
    let mut kids: Vec<usize> = if bin[b].light == u32::MAX {
        vec![bin[b].left as usize, bin[b].right as usize]
    } else {
        vec![b]
    };
    while kids.len() < WIDTH {
        // Open the inner child with the most lights (keeps the tree shallow).
        let Some(j) = (0..kids.len())
            .filter(|&j| bin[kids[j]].light == u32::MAX)
            .max_by_key(|&j| bin[kids[j]].count)
        else {
            break;
        };
        let n = bin[kids[j]];
        kids[j] = n.left as usize;
        kids.insert(j + 1, n.right as usize);
    }
    let me = out.nodes.len() as u32;
    out.nodes.push(WideNode::default());
    out.parent.push(parent);
    for (k, &c) in kids.iter().enumerate() {
        let child = if bin[c].light == u32::MAX {
            collapse(bin, c, me << 3 | k as u32, level + 1, out)
        } else {
            out.slot[bin[c].light as usize] = me << 3 | k as u32;
            LEAF | bin[c].light
        };
        out.nodes[me as usize].set(k, &bin[c].b, child);
    }
    me
}

impl BvhSelector {
    /// Build over `bounds` (local light i = `bounds[i]`).
    pub fn new(bounds: &[LightBounds]) -> Self {
        let mut s = Self {
            nodes: Vec::new(),
            parent: Vec::new(),
            slot: vec![u32::MAX; bounds.len()],
            cpu: Cpu::detect(),
            levels: 0,
        };
        if bounds.is_empty() {
            return s;
        }
        assert!(bounds.len() < 1 << 28, "too many lights for the light BVH");
        let mut items: Vec<Item> = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| Item {
                b: *b,
                t: (cone_angle(b.cos_theta_o), cone_angle(b.cos_theta_e)),
                centroid: (b.min + b.max) * 0.5,
                light: i as u32,
            })
            .collect();
        let bin = build_binary(&mut items, 0);
        s.nodes.reserve(bin.len() / (WIDTH - 1) + 1);
        collapse(&bin, 0, u32::MAX, 1, &mut s);
        s
    }

    /// Number of (wide) nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Memory of nodes, parent links and light slots divided by the number of lights.
    pub fn bytes_per_light(&self) -> f64 {
        let bytes = self.nodes.len() * (std::mem::size_of::<WideNode>() + 4) + self.slot.len() * 4;
        bytes as f64 / self.slot.len().max(1) as f64
    }

    /// Depth of the deepest light (wide levels).
    pub fn depth(&self) -> usize {
        (0..self.slot.len())
            .map(|l| {
                let mut d = 1;
                let mut code = self.parent[(self.slot[l] >> 3) as usize];
                while code != u32::MAX {
                    d += 1;
                    code = self.parent[(code >> 3) as usize];
                }
                d
            })
            .max()
            .unwrap_or(0)
    }

    /// The walk from the root: pick a child ∝ importance per level, multiply the per-level
    /// probabilities bottom-up (as `pmf_impl` does).
    #[inline(always)]
    fn sample_impl(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        if self.levels <= SHALLOW {
            self.sample_walk::<SHALLOW>(ctx, u)
        } else {
            self.sample_walk::<{ MAX_DEPTH as usize }>(ctx, u)
        }
    }

    /// [`Self::sample_impl`] for trees at most `N` levels deep.
    #[inline(always)]
    fn sample_walk<const N: usize>(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut probs = [0.0f64; N];
        let mut levels = 0;
        let mut u = u as f64;
        let mut i = 0usize;
        let mut imp = [0.0f32; WIDTH];
        loop {
            let node = &self.nodes[i];
            node.importance(ctx.p, ctx.n, &mut imp);
            let (pick, next, prob) = descend(&imp, &running_sums(&imp), u)?;
            u = next;
            probs[levels] = prob;
            levels += 1;
            let c = node.child[pick];
            if c & LEAF != 0 {
                return Some((c & !LEAF, walk_pmf(&probs[..levels])));
            }
            i = c as usize;
        }
    }

    #[inline(always)]
    /// The pmf of `light` by walking up from its slot, and the light's own importance (its
    /// lane in its leaf node, the first node of the walk; 0 with a zero pmf).
    fn pmf_impl(&self, ctx: &ShadingPoint, light: u32) -> (f32, f32) {
        let Some(&code) = self.slot.get(light as usize) else {
            return (0.0, 0.0);
        };
        let mut code = code;
        let mut pmf = 1.0f64;
        let mut imp = [0.0f32; WIDTH];
        let mut leaf = None;
        while code != u32::MAX {
            let i = (code >> 3) as usize;
            let node = &self.nodes[i];
            node.importance(ctx.p, ctx.n, &mut imp);
            let total = running_sums(&imp)[WIDTH];
            let x = imp[(code & 7) as usize];
            if !(total > 0.0) || x <= 0.0 {
                return (0.0, 0.0);
            }
            leaf.get_or_insert(x);
            pmf *= x as f64 / total;
            code = self.parent[i];
        }
        (pmf as f32, leaf.unwrap_or(0.0))
    }

    /// [`Self::sample_impl`] for each of the numbers `us` (`out[i]` = `sample(ctx, us[i])`, bit
    /// for bit, plus the light's own importance: its lane in the leaf node), evaluating each node at most once per level while consecutive walks pass
    /// through it: with `us` ascending (RIS's stratified candidates, `ris_bvh.rs`) the walks
    /// go through the tree in order, so the root is scored once instead of K times and a child
    /// holding several candidates once instead of once per candidate.
    #[inline(always)]
    fn sample_many_impl(
        &self,
        ctx: &ShadingPoint,
        us: &[f32],
        out: &mut [Option<(u32, f32, f32)>],
    ) {
        if self.levels <= SHALLOW {
            self.sample_many_walk::<SHALLOW>(ctx, us, out)
        } else {
            self.sample_many_walk::<{ MAX_DEPTH as usize }>(ctx, us, out)
        }
    }

    /// [`Self::sample_many_impl`] for trees at most `N` levels deep.
    #[inline(always)]
    fn sample_many_walk<const N: usize>(
        &self,
        ctx: &ShadingPoint,
        us: &[f32],
        out: &mut [Option<(u32, f32, f32)>],
    ) {
        const CACHED: usize = 8;
        let mut cached = [u32::MAX; CACHED];
        let mut imps = [[0.0f32; WIDTH]; CACHED];
        let mut cums = [[0.0f64; WIDTH + 1]; CACHED];
        let mut imp_deep = [0.0f32; WIDTH];
        let mut cum_deep;
        for (o, &u0) in out.iter_mut().zip(us) {
            *o = None;
            if self.nodes.is_empty() {
                continue;
            }
            let mut probs = [0.0f64; N];
            let mut levels = 0;
            let mut u = u0 as f64;
            let mut i = 0usize;
            loop {
                let node = &self.nodes[i];
                let (imp, cum) = if levels < CACHED {
                    if cached[levels] != i as u32 {
                        node.importance(ctx.p, ctx.n, &mut imps[levels]);
                        cums[levels] = running_sums(&imps[levels]);
                        cached[levels] = i as u32;
                    }
                    (&imps[levels], &cums[levels])
                } else {
                    node.importance(ctx.p, ctx.n, &mut imp_deep);
                    cum_deep = running_sums(&imp_deep);
                    (&imp_deep, &cum_deep)
                };
                let Some((pick, next, prob)) = descend(imp, cum, u) else {
                    break;
                };
                u = next;
                probs[levels] = prob;
                levels += 1;
                let c = node.child[pick];
                if c & LEAF != 0 {
                    *o = Some((c & !LEAF, walk_pmf(&probs[..levels]), imp[pick]));
                    break;
                }
                i = c as usize;
            }
        }
    }

    /// [`FiniteSelector::sample`] for each of `us` (`out[i]` for `us[i]`, with the chosen
    /// light's own importance as a third number; fastest with `us` ascending, which shares the
    /// walks' common nodes).
    pub fn sample_many(&self, ctx: &ShadingPoint, us: &[f32], out: &mut [Option<(u32, f32, f32)>]) {
        self.cpu.dispatch(SampleManyKernel {
            bvh: self,
            ctx,
            us,
            out,
        })
    }

    /// Importance of the eight children of node `i` (for tests and diagnostics).
    pub fn child_importance(&self, ctx: &ShadingPoint, i: usize) -> [f32; WIDTH] {
        let mut imp = [0.0; WIDTH];
        self.nodes[i].importance(ctx.p, ctx.n, &mut imp);
        imp
    }
}

/// `sample` as a [`Kernel`]: compiled once per instruction set.
struct SampleKernel<'a> {
    bvh: &'a BvhSelector,
    ctx: &'a ShadingPoint,
    u: f32,
}

impl Kernel for SampleKernel<'_> {
    type Output = Option<(u32, f32)>;
    #[inline(always)]
    fn run<T: Token>(self, _t: T) -> Self::Output {
        self.bvh.sample_impl(self.ctx, self.u)
    }
}

/// `sample_many` as a [`Kernel`].
struct SampleManyKernel<'a> {
    bvh: &'a BvhSelector,
    ctx: &'a ShadingPoint,
    us: &'a [f32],
    out: &'a mut [Option<(u32, f32, f32)>],
}

impl Kernel for SampleManyKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn run<T: Token>(self, _t: T) -> Self::Output {
        self.bvh.sample_many_impl(self.ctx, self.us, self.out)
    }
}

/// `pmf` (and the light's own importance) as a [`Kernel`].
struct PmfKernel<'a> {
    bvh: &'a BvhSelector,
    ctx: &'a ShadingPoint,
    light: u32,
}

impl Kernel for PmfKernel<'_> {
    type Output = (f32, f32);
    #[inline(always)]
    fn run<T: Token>(self, _t: T) -> Self::Output {
        self.bvh.pmf_impl(self.ctx, self.light)
    }
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
    let (mut memo_lo, mut memo_hi) = (MeasureMemo::default(), MeasureMemo::default());
    for dim in 0..3 {
        if ext[dim].is_nan() || ext[dim] <= 0.0 {
            continue;
        }
        let bucket_of =
            |c: Vec3| (((c[dim] - clo[dim]) / ext[dim] * BUCKETS as f32) as usize).min(BUCKETS - 1);
        let mut buckets: [Option<Bounds>; BUCKETS] = [None; BUCKETS];
        for it in items.iter() {
            let k = bucket_of(it.centroid);
            buckets[k] = Some(match &buckets[k] {
                Some((b, t)) => union_angles(b, *t, &it.b, it.t),
                None => (it.b, it.t),
            });
        }
        // Suffix unions so every split costs O(1) unions.
        let mut suffix: [Option<Bounds>; BUCKETS] = [None; BUCKETS];
        let mut acc: Option<Bounds> = None;
        for k in (0..BUCKETS).rev() {
            merge_into(&mut acc, &buckets[k]);
            suffix[k] = acc;
        }
        let mut prefix: Option<Bounds> = None;
        for k in 0..BUCKETS - 1 {
            merge_into(&mut prefix, &buckets[k]);
            if let (Some(a), Some(b)) = (&prefix, &suffix[k + 1]) {
                let cost = saoh_cost(&a.0, memo_lo.get(a), parent, dim)
                    + saoh_cost(&b.0, memo_hi.get(b), parent, dim);
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

/// Bounds with their cone angles (θo, θe), as the split search carries them.
type Bounds = (LightBounds, (f32, f32));

/// `acc` ∪ `b` into `acc` (an empty side contributes nothing), by reference: an empty bucket
/// then costs no copy of the running bounds.
fn merge_into(acc: &mut Option<Bounds>, b: &Option<Bounds>) {
    if let Some((b, tb)) = b {
        *acc = Some(match acc {
            Some((a, ta)) => union_angles(a, *ta, b, *tb),
            None => (*b, *tb),
        });
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
        self.cpu.dispatch(SampleKernel { bvh: self, ctx, u })
    }

    fn pmf(&self, ctx: &ShadingPoint, light: u32) -> f32 {
        self.pmf_and_importance(ctx, light).0
    }
}

impl BvhSelector {
    /// [`FiniteSelector::pmf`] of `light` and the light's own importance as the BVH scores it
    /// (its lane in its leaf node: what [`Self::sample_many`] returns with it).
    pub fn pmf_and_importance(&self, ctx: &ShadingPoint, light: u32) -> (f32, f32) {
        self.cpu.dispatch(PmfKernel {
            bvh: self,
            ctx,
            light,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light_selection::importance::importance;

    #[test]
    fn wide_importance_matches_scalar_zeros() {
        // The lane formula and the scalar one agree (up to rounding) and on every zero.
        let b = LightBounds {
            min: Vec3::new(-1.0, -1.0, 2.0),
            max: Vec3::new(1.0, 1.0, 2.5),
            w: -Vec3::Z,
            phi: 3.0,
            cos_theta_o: 0.8,
            cos_theta_e: 0.0,
            two_sided: false,
        };
        let mut node = WideNode::default();
        node.set(0, &b, LEAF);
        let mut imp = [0.0; WIDTH];
        for &(p, n) in &[
            (Vec3::ZERO, Vec3::Z),
            (Vec3::ZERO, -Vec3::Z),
            (Vec3::new(0.0, 0.0, 5.0), Vec3::Z),
            (Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO),
            (Vec3::new(0.0, 0.0, 2.2), Vec3::X),
        ] {
            node.importance(p, n, &mut imp);
            let s = importance(p, n, &b);
            assert_eq!(imp[0] > 0.0, s > 0.0, "{p} {n}: {} vs {s}", imp[0]);
            assert!(
                (imp[0] - s).abs() <= 1e-4 * s.abs(),
                "{p} {n}: {} vs {s}",
                imp[0]
            );
            assert!(imp[1..].iter().all(|&x| x == 0.0));
        }
    }

    #[test]
    fn counted_pick_matches_the_linear_search() {
        // The search `sample` used before: the first positive child whose running sum passes
        // `target`, else the last positive one. The tree of running sums rounds differently,
        // so the two may differ only for targets within rounding of a boundary.
        let search = |imp: &[f32; WIDTH], target: f64| {
            let (mut cum, mut pick) = (0.0f64, WIDTH);
            for (k, &x) in imp.iter().enumerate() {
                if x > 0.0 {
                    pick = k;
                    if target < cum + x as f64 {
                        break;
                    }
                }
                cum += x as f64;
            }
            pick
        };
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut agreed = 0;
        for _ in 0..20_000 {
            let mut imp = [0.0f32; WIDTH];
            for x in imp.iter_mut() {
                let r = next();
                // Zeros, tiny and huge values next to each other (sums that stop growing).
                *x = match r % 4 {
                    0 => 0.0,
                    1 => (r >> 40) as f32 * 1e-30,
                    2 => (r >> 40) as f32,
                    _ => (r >> 40) as f32 * 1e20,
                };
            }
            let sums = running_sums(&imp);
            let total = sums[WIDTH];
            if !(total > 0.0) {
                continue;
            }
            let mut cum = [0.0f64; WIDTH + 1];
            for k in 0..WIDTH {
                cum[k + 1] = cum[k] + imp[k] as f64;
            }
            for k in 0..WIDTH {
                assert!(sums[k] <= sums[k + 1], "{imp:?}: {sums:?}");
                // A zero importance adds nothing (a tiny one next to a huge one may not either).
                assert!(imp[k] > 0.0 || sums[k] == sums[k + 1], "{imp:?}: {sums:?}");
            }
            let tol = 1e-12 * total;
            let u = (next() >> 11) as f64 / (1u64 << 53) as f64;
            // Random targets, every running sum exactly, the total and past it (rounding of
            // u · total).
            let mut targets = vec![u * total, total * (1.0 + 1e-15)];
            targets.extend(sums);
            for target in targets {
                let p = pick_slot(&imp, &sums, target);
                assert!(imp[p] > 0.0, "{imp:?} {target}: slot {p}");
                assert!(
                    target >= sums[p] || target >= total,
                    "{imp:?} {target}: slot {p}"
                );
                let near_boundary = cum.iter().any(|&c| (c - target).abs() <= tol);
                if !near_boundary && target < cum[WIDTH] {
                    assert_eq!(p, search(&imp, target), "{imp:?} {target}");
                    agreed += 1;
                }
            }
        }
        assert!(agreed > 10_000, "{agreed}");
    }

    #[test]
    fn sample_and_pmf_return_the_same_bits() {
        // The pmf MIS uses is the probability `sample` reported, bit for bit: both add a
        // node's importances through `sums` and multiply the levels bottom-up.
        let bounds: Vec<LightBounds> = (0..5000)
            .map(|i| {
                let f = i as f32;
                let c = Vec3::new((f * 0.37).sin() * 9.0, (f * 0.11).cos() * 9.0, f * 0.002);
                LightBounds {
                    min: c - Vec3::splat(0.05 + (i % 3) as f32 * 0.1),
                    max: c + Vec3::splat(0.05),
                    w: Vec3::new((f * 0.7).sin(), (f * 0.3).cos(), 0.5).normalize(),
                    phi: 1.0 + (i % 11) as f32 * 10.0,
                    cos_theta_o: if i % 4 == 0 { -1.0 } else { 0.7 },
                    cos_theta_e: 0.0,
                    two_sided: i % 5 == 0,
                }
            })
            .collect();
        let bvh = BvhSelector::new(&bounds);
        // The walk's probability array is sized by the recorded depth.
        assert_eq!(bvh.levels, bvh.depth());
        let mut checked = 0;
        for j in 0..200 {
            let f = j as f32;
            let ctx = ShadingPoint {
                p: Vec3::new(
                    (f * 0.9).sin() * 8.0,
                    (f * 0.4).cos() * 8.0,
                    (f * 0.1).sin() * 5.0,
                ),
                n: if j % 7 == 0 {
                    Vec3::ZERO
                } else {
                    Vec3::new((f * 1.3).sin(), (f * 0.6).cos(), 0.3).normalize()
                },
                wo: Vec3::Z,
            };
            for k in 0..50 {
                let u = ((k as f32 + 0.5) / 50.0 + f * 0.618).fract();
                if let Some((l, p)) = bvh.sample(&ctx, u) {
                    assert!(p > 0.0);
                    assert_eq!(
                        p.to_bits(),
                        bvh.pmf(&ctx, l).to_bits(),
                        "light {l} at {ctx:?}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 5000, "{checked}");
    }

    #[test]
    fn two_sided_flag_in_the_sign_of_power() {
        // A two-sided emitter facing away scores as if facing the receiver; zero power stays
        // dead on either side.
        let mut b = LightBounds {
            min: Vec3::new(-0.1, -0.1, 2.0),
            max: Vec3::new(0.1, 0.1, 2.0),
            w: Vec3::Z,
            phi: 2.0,
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: true,
        };
        let mut node = WideNode::default();
        node.set(0, &b, LEAF);
        b.w = -Vec3::Z;
        node.set(1, &b, LEAF | 1);
        b.phi = 0.0;
        node.set(2, &b, LEAF | 2);
        let mut imp = [0.0; WIDTH];
        node.importance(Vec3::ZERO, Vec3::Z, &mut imp);
        assert!(imp[0] > 0.0 && imp[0] == imp[1], "{imp:?}");
        assert_eq!(imp[2], 0.0);
        assert!(
            (imp[0]
                - importance(Vec3::ZERO, Vec3::Z, &{
                    let mut c = b;
                    c.phi = 2.0;
                    c
                }))
            .abs()
                <= 1e-4 * imp[0]
        );
    }

    #[test]
    fn vector_and_portable_paths_agree_bitwise() {
        let bounds: Vec<LightBounds> = (0..300)
            .map(|i| {
                let f = i as f32;
                let c = Vec3::new((f * 0.37).sin() * 5.0, (f * 0.11).cos() * 5.0, f * 0.01);
                LightBounds {
                    min: c - Vec3::splat(0.1),
                    max: c + Vec3::splat(0.1),
                    w: Vec3::new((f * 0.7).sin(), (f * 0.3).cos(), 0.5).normalize(),
                    phi: 1.0 + (i % 7) as f32,
                    cos_theta_o: 1.0,
                    cos_theta_e: 0.0,
                    two_sided: i % 5 == 0,
                }
            })
            .collect();
        let mut bvh = BvhSelector::new(&bounds);
        assert!(bvh.depth() <= 4, "depth {}", bvh.depth());
        let ctx = ShadingPoint {
            p: Vec3::new(0.3, -0.2, 1.0),
            n: Vec3::new(0.1, 0.2, 1.0).normalize(),
            wo: Vec3::Z,
        };
        let fast: Vec<_> = (0..64).map(|j| bvh.sample(&ctx, j as f32 / 64.0)).collect();
        let fast_pmf: Vec<_> = (0..300).map(|l| bvh.pmf(&ctx, l)).collect();
        bvh.cpu = crate::isa::Isa::Portable.cpu();
        let slow: Vec<_> = (0..64).map(|j| bvh.sample(&ctx, j as f32 / 64.0)).collect();
        let slow_pmf: Vec<_> = (0..300).map(|l| bvh.pmf(&ctx, l)).collect();
        assert_eq!(fast, slow);
        assert_eq!(fast_pmf, slow_pmf);
        for (l, p) in slow.into_iter().flatten() {
            assert_eq!(p.to_bits(), slow_pmf[l as usize].to_bits());
        }
        // The pmf sums to P(sample is Some) (walks can end at a node whose children all
        // score zero): compare with stratified u.
        let sum: f64 = slow_pmf.iter().map(|&p| p as f64).sum();
        let m = 8192;
        let some = (0..m)
            .filter(|&j| bvh.sample(&ctx, (j as f32 + 0.5) / m as f32).is_some())
            .count() as f64
            / m as f64;
        assert!(
            sum <= 1.0 + 1e-4 && (sum - some).abs() < 2e-3,
            "{sum} vs {some}"
        );
    }
}
