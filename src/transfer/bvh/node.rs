//! The two node layouts: the binary [`Node`] the builders make, and the [`WideNode`] the rays
//! walk, four binary nodes' boxes side by side.

use super::bounds::Aabb;
use glam::{Vec3A, Vec4};

/// A binary node: 32 bytes. Its children are not stored side by side: an inner node's first
/// child is the node right after it (depth-first order), so only the second needs an index.
#[derive(Debug, Clone, Copy)]
pub(super) struct Node {
    pub min: [f32; 3],
    /// An inner node's second child; a leaf's first triangle, in leaf order.
    pub right_or_first: u32,
    pub max: [f32; 3],
    /// How many triangles a leaf holds; 0 marks an inner node.
    pub count: u32,
}

impl Node {
    pub fn inner(b: &Aabb, right: u32) -> Node {
        Node { min: b.min.to_array(), right_or_first: right, max: b.max.to_array(), count: 0 }
    }

    pub fn leaf(b: &Aabb, first: usize, count: usize) -> Node {
        Node { min: b.min.to_array(), right_or_first: first as u32, max: b.max.to_array(), count: count as u32 }
    }

    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// Half its box's surface area, as the build's cost model counts it.
    pub fn area(&self) -> f32 {
        Aabb { min: Vec3A::from(self.min), max: Vec3A::from(self.max) }.area()
    }
}

/// A four-wide node: 128 bytes, two cache lines. The children's boxes are stored by axis so
/// that one node's four slab tests are four-lane vector operations.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct WideNode {
    /// The children's boxes by axis: `min[0]` holds the four children's smallest x.
    pub min: [Vec4; 3],
    pub max: [Vec4; 3],
    /// Per child: an inner child's node index, or a leaf's first triangle (in leaf order).
    pub child: [u32; 4],
    /// Per child: 0 for an inner node, else the leaf's triangle count.
    pub count: [u8; 4],
    /// Bit `k` set when child `k` exists: the lowest two to four lanes (one lane only at the root
    /// of a tree that is a single leaf).
    pub lanes: u32,
}

impl WideNode {
    pub(super) fn empty() -> WideNode {
        WideNode { min: [Vec4::ZERO; 3], max: [Vec4::ZERO; 3], child: [0; 4], count: [0; 4], lanes: 0 }
    }

    /// Whether child `lane` exists.
    #[inline]
    pub fn has(&self, lane: usize) -> bool {
        self.lanes & (1 << lane) != 0
    }

    /// Whether child `lane` is a leaf (its triangles are `child[lane]..child[lane] + count[lane]`).
    #[inline]
    pub fn is_leaf(&self, lane: usize) -> bool {
        self.count[lane] > 0
    }

    /// Makes `n`'s box child `lane`'s; the caller sets what the child is.
    pub(super) fn set_box(&mut self, lane: usize, n: &Node) {
        for a in 0..3 {
            self.min[a][lane] = n.min[a];
            self.max[a][lane] = n.max[a];
        }
        self.lanes |= 1 << lane;
    }
}

/// A tree's four-wide nodes, as the rays index them: a vector, or on a large HIGH a zeroed
/// mapping in which each part of the build wrote its nodes into slots of its own (`morton.rs`):
/// the slots left over hold zeros (no lanes), are never read, and stay pages never made present.
pub struct Nodes(Store);

enum Store {
    Heap(Vec<WideNode>),
    Mapped(memmap2::MmapMut, usize),
}

impl Nodes {
    pub(super) fn heap(v: Vec<WideNode>) -> Nodes {
        Nodes(Store::Heap(v))
    }

    /// `len` nodes of zeros, their pages made present only where written.
    pub(super) fn zeroed(len: usize) -> Nodes {
        let bytes = len * std::mem::size_of::<WideNode>();
        match memmap2::MmapOptions::new().len(bytes.max(1)).no_reserve_swap().map_anon() {
            Ok(map) => Nodes(Store::Mapped(map, len)),
            // No mapping to be had: the same zeros, made present now.
            Err(_) => Nodes::heap(vec![WideNode::empty(); len]),
        }
    }
}

impl std::ops::Deref for Nodes {
    type Target = [WideNode];
    fn deref(&self) -> &[WideNode] {
        match &self.0 {
            Store::Heap(v) => v,
            // SAFETY: the mapping holds `len` nodes' bytes, page-aligned (beyond a node's 64);
            // each is zeros, which is a node (all its fields are numbers), or a node written
            // through `deref_mut`; it lives as long as `self`.
            Store::Mapped(map, len) => unsafe { std::slice::from_raw_parts(map.as_ptr().cast(), *len) },
        }
    }
}

impl std::ops::DerefMut for Nodes {
    fn deref_mut(&mut self) -> &mut [WideNode] {
        match &mut self.0 {
            Store::Heap(v) => v,
            // SAFETY: as in `deref`, and `&mut self` makes the borrow unique.
            Store::Mapped(map, len) => unsafe { std::slice::from_raw_parts_mut(map.as_mut_ptr().cast(), *len) },
        }
    }
}

impl Clone for Nodes {
    fn clone(&self) -> Nodes {
        Nodes::heap(self.to_vec())
    }
}

impl std::fmt::Debug for Nodes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Nodes({})", self.len())
    }
}

// The sizes the comments above and the memory figures count on.
const _: () = assert!(std::mem::size_of::<Node>() == 32 && std::mem::size_of::<WideNode>() == 128);
