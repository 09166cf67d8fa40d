//! Collapsing a binary BVH into the 4-wide one, and its leaves into 4-triangle packets.

use super::{LEAF, MAX_TREE_DEPTH, Node4, PREFETCH_BYTES, SingleLeaf, WideBvh};
use crate::geometry::primitive::{PrimKind, Primitive};
use crate::geometry::tree2::Tree2;
use crate::geometry::tri4::TriPacket;
use crate::isa::Isa;
use glam::{Vec3, Vec4};
use std::ops::Range;

/// Subtrees with at most this many primitives become a single leaf.
const LEAF_PRIMS: usize = 4;

/// Whether binary node `k` becomes one leaf of the wide trees (at most [`LEAF_PRIMS`]
/// primitives, or no children).
pub(super) fn is_leaf(tree: &Tree2, k: usize) -> bool {
    tree.nodes[k].range.len() <= LEAF_PRIMS || tree.nodes[k].children.is_none()
}

/// The children of a wide node over binary node `n2`: its two children, then the one with the
/// largest surface area opened in place until there are `width` (or only leaves are left); a
/// subtree of at most [`LEAF_PRIMS`] primitives stays one leaf. The 4-wide and 8-wide
/// collapses share it, so both trees' leaves are the same packets.
pub(super) fn open_children(tree: &Tree2, n2: usize, width: usize) -> Vec<usize> {
    let nodes = &tree.nodes;
    let mut kids: Vec<usize> = match nodes[n2].children {
        Some(c) if !is_leaf(tree, n2) => c.to_vec(),
        _ => vec![n2],
    };
    while kids.len() < width {
        let widest = kids
            .iter()
            .enumerate()
            .filter(|&(_, &k)| !is_leaf(tree, k))
            .max_by(|a, b| nodes[*a.1].half_area().total_cmp(&nodes[*b.1].half_area()));
        let Some((i, &k)) = widest else { break };
        let Some([a, b]) = nodes[k].children else {
            break;
        };
        kids[i] = a;
        kids.push(b);
    }
    kids
}

impl Node4 {
    /// No child: inverted boxes, which every ray misses.
    const EMPTY: Node4 = Node4 {
        b: [[Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3]],
        child: [LEAF; 4],
    };
}

impl WideBvh {
    /// Collapse `tree` over `prims` (input order; `tree.order` maps leaf order to it). Returns
    /// `None` if the tree is deeper than [`MAX_TREE_DEPTH`] (the traversal stack's bound).
    /// Triangles i with `called_back[i]` (input order; an empty slice: none) go to the
    /// packets' `other` lanes like quadrics, so the traversal asks the caller about them
    /// (alpha cut-outs).
    pub fn build(tree: &Tree2, prims: &[Primitive], called_back: &[bool]) -> Option<Self> {
        let mut w = Self::default();
        if !tree.nodes.is_empty() {
            if tree.depth() > MAX_TREE_DEPTH {
                return None;
            }
            // The leaf reference of each binary node that became a leaf, for the 8-wide
            // collapse, which shares the packets (its leaves are the same binary nodes).
            let mut leaf_of = vec![u32::MAX; tree.nodes.len()];
            w.collapse(tree, prims, called_back, &mut leaf_of, 0);
            if Isa::detect() >= Isa::Avx2 {
                w.nodes8 = super::build8::collapse8(tree, &leaf_of);
            }
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
        w.large =
            size_of_val(w.nodes.as_slice()) + size_of_val(w.packets.as_slice()) > PREFETCH_BYTES;
        Some(w)
    }

    /// True if the tree is too large to stay in cache ([`PREFETCH_BYTES`]), so that
    /// prefetching what a query will read soon pays.
    #[inline(always)]
    pub fn is_large(&self) -> bool {
        self.large
    }

    /// True if the 8-wide nodes exist (built when the CPU runs AVX2), which the one-ray
    /// queries `closest8` and `any8` traverse.
    #[inline(always)]
    pub fn has_nodes8(&self) -> bool {
        !self.nodes8.is_empty()
    }

    /// Bytes of the 4-wide nodes, the 8-wide nodes and the leaf packets.
    #[cfg(test)]
    pub fn bytes(&self) -> [usize; 3] {
        [
            size_of_val(self.nodes.as_slice()),
            size_of_val(self.nodes8.as_slice()),
            size_of_val(self.packets.as_slice()),
        ]
    }

    /// True if the whole tree is one leaf (most scenes' emitter-only geometry).
    pub fn is_single_leaf(&self) -> bool {
        self.single_leaf.is_some()
    }

    /// Emit the wide node for binary node `n2`: its children, with the largest interior child
    /// repeatedly replaced by its two children (largest surface area first, as in the SAH) until
    /// there are four. Subtrees of at most [`LEAF_PRIMS`] primitives become one leaf: a packet
    /// tests four triangles for little more than the price of one.
    /// `leaf_of[k]` is set to the `LEAF` reference made for binary node k.
    fn collapse(
        &mut self,
        tree: &Tree2,
        prims: &[Primitive],
        called_back: &[bool],
        leaf_of: &mut [u32],
        n2: usize,
    ) {
        let nodes = &tree.nodes;
        let kids = open_children(tree, n2, 4);
        let idx = self.nodes.len();
        self.nodes.push(Node4::EMPTY);
        for (lane, &k) in kids.iter().enumerate() {
            let child = if is_leaf(tree, k) {
                let child = LEAF | self.leaf(tree, prims, called_back, nodes[k].range.clone());
                leaf_of[k] = child;
                child
            } else {
                let child = self.nodes.len() as u32;
                self.collapse(tree, prims, called_back, leaf_of, k);
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
    fn leaf(
        &mut self,
        tree: &Tree2,
        prims: &[Primitive],
        called_back: &[bool],
        range: Range<usize>,
    ) -> u32 {
        let first = self.packets.len();
        let ids: Vec<usize> = range.collect();
        for chunk in ids.chunks(4) {
            let mut pk = TriPacket::EMPTY;
            for (lane, &id) in chunk.iter().enumerate() {
                let input = tree.order[id] as usize;
                let p = &prims[input];
                match p.kind {
                    PrimKind::Triangle { .. } if called_back.get(input) == Some(&true) => {
                        pk.set_other(lane, id as u32)
                    }
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
            let Some(fast) = WideBvh::build(&Tree2::ploc(&boxes(&prims)), &prims, &[]) else {
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
            let Some(w) = WideBvh::build(&tree, &prims, &[]) else {
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
