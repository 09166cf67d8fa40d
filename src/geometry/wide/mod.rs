//! A 4-wide BVH: a binary BVH ([`Tree2`](super::tree2::Tree2): obvhs's PLOC tree or
//! penumbra's binned-SAH one) collapsed so that each node holds up to four children whose
//! boxes are tested together (SoA, one `Vec4` per box plane), and leaves are runs of
//! [`TriPacket`]s whose four triangles are tested together
//! ([`RayShear4`](super::tri4::RayShear4)).
//!
//! [`build`] makes it, [`ray`] traces one ray through it, [`packet`] sixteen at once. On CPUs
//! with AVX2 the same binary tree is also collapsed into 8-wide nodes ([`build8`], over the
//! same leaf packets), which the one-ray queries of [`ray8`] traverse instead.

#[cfg(all(test, target_arch = "x86_64"))]
mod agree8;
mod build;
mod build8;
mod packet;
mod ray;
#[cfg(target_arch = "x86_64")]
mod ray8;

pub(super) use packet::PacketHits;

use super::tri4::TriPacket;
use glam::{Vec3, Vec4};

/// Child-reference flag: the low bits are the first packet of a leaf, not a node index.
const LEAF: u32 = 1 << 31;
/// Deepest binary tree that is collapsed (deeper ones are rejected by [`WideBvh::build`]).
const MAX_TREE_DEPTH: usize = 96;
/// Traversal stack depth: each wide level consumes at least one binary level, and a node
/// pushes at most three children.
const STACK: usize = 3 * MAX_TREE_DEPTH + 1;

/// Traversal stack depth of the 8-wide nodes: a node pushes at most seven children.
const STACK8: usize = 7 * MAX_TREE_DEPTH + 1;

/// Triangle barycentrics (b0, b1, b2) of a hit (unused for other primitives).
pub type Bary = [f32; 3];

/// One node: `b[0][axis]` / `b[1][axis]` hold the lower / upper box plane of the four children.
/// Aligned to a cache line, so that a node (112 bytes, padded to 128) spans exactly two lines
/// instead of three for half of them.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    /// Box planes: `b[side][axis]` lane c = that plane of child c.
    b: [[Vec4; 3]; 2],
    /// Node index, or `LEAF | first packet` (unused slots have inverted boxes and are never
    /// followed).
    child: [u32; 4],
}

/// One 8-wide node: `b[side][axis]` lane c = that box plane of child c, as in [`Node4`].
/// 224 bytes padded to 256, aligned to a cache line: exactly four lines, the boxes in the
/// first three.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node8 {
    /// Box planes: `b[side][axis]` lane c = that plane of child c.
    b: [[[f32; 8]; 3]; 2],
    /// Node index (into `nodes8`), or `LEAF | first packet`; unused slots have inverted
    /// boxes and are never followed.
    child: [u32; 8],
}

/// The 4-wide BVH (see the module docs). Primitive ids are leaf-order indices of the BVH2.
#[derive(Clone, Debug, Default)]
pub struct WideBvh {
    nodes: Vec<Node4>,
    /// The 8-wide nodes over the same packets (empty unless the CPU runs AVX2).
    nodes8: Vec<Node8>,
    packets: Vec<TriPacket>,
    /// Set when the whole tree is one leaf (the emitter-only geometry of most scenes): its
    /// box (the root's lane 0) and leaf reference, for [`WideBvh::closest`]'s fast path.
    single_leaf: Option<SingleLeaf>,
    /// Nodes and packets exceed [`PREFETCH_BYTES`]: the traversal prefetches what it pushes.
    large: bool,
}

/// BVH size above which prefetching pays: below it (cornell: 3 KB) the tree stays in the
/// core's caches, and the prefetches' address arithmetic was 4 % of the one-ray query's
/// instructions for nothing.
const PREFETCH_BYTES: usize = 256 << 10;

/// The box and leaf reference of a tree that is a single leaf.
#[derive(Clone, Copy, Debug)]
struct SingleLeaf {
    lo: Vec3,
    hi: Vec3,
    child: u32,
}
