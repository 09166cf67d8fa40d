//! Collapsing the binary BVH into 8-wide nodes over the 4-wide BVH's leaf packets.
//!
//! The same rule as the 4-wide collapse with eight slots: the largest interior child is
//! replaced by its two children until there are eight. A binary node is a leaf of either tree
//! exactly when it is a leaf candidate whose ancestors are not (leaves are never split), so
//! both trees have the same leaves and share their packets.

use super::build::{is_leaf, open_children};
use super::{LEAF, Node8};
use crate::geometry::tree2::Tree2;

impl Node8 {
    /// No child: inverted boxes, which every ray misses.
    const EMPTY: Node8 = Node8 {
        b: [[[f32::INFINITY; 8]; 3], [[f32::NEG_INFINITY; 8]; 3]],
        child: [LEAF; 8],
    };
}

/// The 8-wide nodes of `tree` (root first), given the `LEAF` reference `leaf_of[k]` the
/// 4-wide collapse made for each of its leaf nodes k (`u32::MAX` for the others). Empty (the
/// queries then use the 4-wide nodes) if a leaf has no reference, which the argument above
/// rules out: the traversal follows references unchecked, so this is checked, not assumed.
pub(super) fn collapse8(tree: &Tree2, leaf_of: &[u32]) -> Vec<Node8> {
    let mut nodes = Vec::new();
    if tree.nodes.is_empty() || collapse(tree, leaf_of, &mut nodes, 0).is_none() {
        return Vec::new();
    }
    nodes
}

/// Emit the 8-wide node of binary node `n2` and, depth first, its interior children; `None`
/// if a leaf has no reference.
fn collapse(tree: &Tree2, leaf_of: &[u32], out: &mut Vec<Node8>, n2: usize) -> Option<()> {
    let nodes = &tree.nodes;
    let kids = open_children(tree, n2, 8);
    let idx = out.len();
    out.push(Node8::EMPTY);
    for (lane, &k) in kids.iter().enumerate() {
        let child = if is_leaf(tree, k) {
            let child = leaf_of[k];
            if child & LEAF == 0 || child == u32::MAX {
                return None;
            }
            child
        } else {
            let child = out.len() as u32;
            collapse(tree, leaf_of, out, k)?;
            child
        };
        let node = &mut out[idx];
        for a in 0..3 {
            node.b[0][a][lane] = nodes[k].lo[a];
            node.b[1][a][lane] = nodes[k].hi[a];
        }
        node.child[lane] = child;
    }
    Some(())
}
