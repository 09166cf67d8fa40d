//! A binary BVH in the neutral form that [`super::wide`] collapses: per node its box, its two
//! children or none (leaf), and the leaf-order range of primitives below it. It is made either
//! from penumbra's binned-SAH [`Bvh`] or from obvhs's PLOC builder followed by its reinsertion
//! optimiser, which moves large primitives (walls) up the tree so that any-hit queries meet them
//! after a node or two.

use super::bvh::Bvh;
use glam::Vec3;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::PlocBuilder;
use std::ops::Range;

/// Scenes up to this many primitives get obvhs's most thorough reinsertion settings.
pub const THOROUGH_BUILD_MAX: usize = 100_000;

/// One node of a [`Tree2`].
#[derive(Clone, Debug)]
pub struct Node2 {
    /// Box minimum.
    pub lo: Vec3,
    /// Box maximum.
    pub hi: Vec3,
    /// Child node indices; `None` for a leaf.
    pub children: Option<[usize; 2]>,
    /// Leaf-order positions of the primitives below this node (contiguous by construction).
    pub range: Range<usize>,
}

impl Node2 {
    /// Half the box surface area (SAH weight).
    pub fn half_area(&self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// A binary BVH (root = node 0) plus its leaf order: position i holds input primitive
/// `order[i]`.
#[derive(Clone, Debug, Default)]
pub struct Tree2 {
    /// Nodes, root first.
    pub nodes: Vec<Node2>,
    /// Leaf order.
    pub order: Vec<u32>,
}

impl Tree2 {
    /// Take over penumbra's binned-SAH BVH.
    pub fn from_bvh(bvh: Bvh) -> Self {
        let n = bvh.node_count();
        let mut nodes: Vec<Node2> = Vec::with_capacity(n);
        for i in 0..n {
            let (lo, hi) = bvh.node_bounds(i);
            let (children, range) = match bvh.node_kind(i) {
                Ok(c) => (Some([c, c + 1]), 0..0),
                Err(r) => (None, r),
            };
            nodes.push(Node2 {
                lo,
                hi,
                children,
                range,
            });
        }
        // Children have larger indices than their parent: fill interior ranges bottom-up.
        for i in (0..n).rev() {
            if let Some([a, b]) = nodes[i].children {
                nodes[i].range = nodes[a].range.start..nodes[b].range.end;
            }
        }
        Self {
            nodes,
            order: bvh.indices,
        }
    }

    /// Build with obvhs's PLOC + reinsertion over the primitive boxes (its `very_slow_build`
    /// settings up to [`THOROUGH_BUILD_MAX`] primitives, else `medium_build`); empty input gives
    /// an empty tree.
    pub fn ploc(boxes: &[(Vec3, Vec3)]) -> Self {
        if boxes.is_empty() {
            return Self::default();
        }
        let aabbs: Vec<Aabb> = boxes
            .iter()
            .map(|(lo, hi)| Aabb::new((*lo).into(), (*hi).into()))
            .collect();
        // Full reinsertion passes pay off in query speed (cornell: +9 % closest-hit) but cost
        // seconds on million-triangle meshes, so they are kept for small scenes.
        let p = if cfg!(fuzzing) {
            // Under the fuzzer's coverage instrumentation the thorough reinsertion was 80 % of
            // a PLY input's time (263 exec/s); the stable replay test builds as users do.
            obvhs::BvhBuildParams::very_fast_build()
        } else if aabbs.len() <= THOROUGH_BUILD_MAX {
            obvhs::BvhBuildParams::very_slow_build()
        } else {
            obvhs::BvhBuildParams::medium_build()
        };
        let mut bvh2 = PlocBuilder::with_capacity(aabbs.len()).build(
            p.ploc_search_distance,
            &aabbs,
            (0..aabbs.len() as u32).collect(),
            p.sort_precision,
            p.search_depth_threshold,
        );
        ReinsertionOptimizer::default().run(&mut bvh2, p.reinsertion_batch_ratio, None);
        let mut t = Self {
            nodes: Vec::with_capacity(bvh2.nodes.len()),
            order: Vec::with_capacity(boxes.len()),
        };
        t.copy_subtree(&bvh2, 0);
        t
    }

    /// Append obvhs node `i` and its subtree in depth-first order; returns its new index.
    fn copy_subtree(&mut self, bvh2: &Bvh2, i: usize) -> usize {
        let n = &bvh2.nodes[i];
        let idx = self.nodes.len();
        let start = self.order.len();
        self.nodes.push(Node2 {
            lo: n.aabb.min.into(),
            hi: n.aabb.max.into(),
            children: None,
            range: start..start,
        });
        if n.prim_count == 0 {
            let f = n.first_index as usize;
            let a = self.copy_subtree(bvh2, f);
            let b = self.copy_subtree(bvh2, f + 1);
            self.nodes[idx].children = Some([a, b]);
        } else {
            let f = n.first_index as usize;
            self.order
                .extend_from_slice(&bvh2.primitive_indices[f..f + n.prim_count as usize]);
        }
        self.nodes[idx].range = start..self.order.len();
        idx
    }

    /// Number of node levels (1 for a single leaf, 0 when empty).
    pub fn depth(&self) -> usize {
        let mut depth = vec![0usize; self.nodes.len()];
        let mut max = 0;
        // Parents precede their children in both constructions.
        for i in 0..self.nodes.len() {
            if i == 0 {
                depth[0] = 1;
            }
            max = max.max(depth[i]);
            if let Some([a, b]) = self.nodes[i].children {
                depth[a] = depth[i] + 1;
                depth[b] = depth[i] + 1;
            }
        }
        max
    }
}
