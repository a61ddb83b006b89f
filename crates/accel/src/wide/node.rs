//! The node of a wide BVH, the references to its children, and what
//! traversal asks of a node however it stores its boxes ([`NodeLayout`]).

use crate::simd::Isa;
use crate::simd::boxes::{PlaneRay, WideBoxes};
use crate::simd::packet::IntervalRay;

/// A node with up to `W` children: their boxes structure-of-arrays, so
/// that one ray tests all of them at once, and a reference to each child.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WideNode<const W: usize> {
    pub(crate) boxes: WideBoxes<W>,
    pub(crate) children: [ChildRef; W],
}

impl<const W: usize> WideNode<W> {
    pub(crate) const EMPTY: Self = Self { boxes: WideBoxes::EMPTY, children: [ChildRef::NONE; W] };
}

/// How a wide BVH stores its nodes: as built ([`WideNode`], 32-bit
/// planes) or compressed ([`super::quantised::QuantisedNode`]). Traversal
/// asks a node only these questions, so that both layouts share it.
///
/// A layout's boxes may be larger than the built ones, never smaller:
/// every box a layout answers for holds the built box of its child, so
/// that the robust slab test, which is monotone in the planes, enters it
/// wherever it enters the built box, no later. That keeps the answers
/// exact (see the crate's exactness contract).
pub(crate) trait NodeLayout<const W: usize>: Copy + std::fmt::Debug + Send + Sync + 'static {
    /// The suffix of the variant's name in reports (`bvh8` + `q`).
    const NAME_SUFFIX: &'static str;

    /// The built nodes in this layout, in the same order.
    fn from_built(nodes: Vec<WideNode<W>>) -> Vec<Self>;

    /// The references to the node's children ([`ChildRef::NONE`] for
    /// empty lanes).
    fn children(&self) -> &[ChildRef; W];

    /// [`Isa::enter_boxes`] on the node's boxes: where one ray enters each
    /// child, and the mask of the children it enters.
    fn enter<I: Isa>(&self, isa: I, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]);

    /// [`Isa::enter_interval`] on the node's boxes.
    fn enter_interval<I: Isa>(&self, isa: I, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]);

    /// The box of the child in `lane`, as its minimum and maximum.
    fn child_box(&self, lane: usize) -> ([f32; 3], [f32; 3]);
}

impl<const W: usize> NodeLayout<W> for WideNode<W> {
    const NAME_SUFFIX: &'static str = "";

    fn from_built(nodes: Vec<WideNode<W>>) -> Vec<Self> {
        nodes
    }

    #[inline(always)]
    fn children(&self) -> &[ChildRef; W] {
        &self.children
    }

    #[inline(always)]
    fn enter<I: Isa>(&self, isa: I, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        isa.enter_boxes(&self.boxes, ray, t_max)
    }

    #[inline(always)]
    fn enter_interval<I: Isa>(&self, isa: I, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]) {
        isa.enter_interval(&self.boxes, ray, t_max)
    }

    #[inline(always)]
    fn child_box(&self, lane: usize) -> ([f32; 3], [f32; 3]) {
        self.boxes.lane(lane)
    }
}

/// A child of a wide node, packed in 32 bits: another node (its index,
/// top bit clear), a leaf (top bit set; the first of its triangle blocks
/// and how many there are), or no child.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub(crate) struct ChildRef(u32);

const LEAF_BIT: u32 = 1 << 31;
/// Bits of a leaf reference holding its number of blocks, less one.
const BLOCK_COUNT_BITS: u32 = 5;

impl ChildRef {
    pub(crate) const NONE: ChildRef = ChildRef(u32::MAX);
    /// Most triangle blocks in one leaf.
    pub(crate) const MAX_LEAF_BLOCKS: usize = 1 << BLOCK_COUNT_BITS;
    /// Most nodes, and most triangle blocks, a tree may have.
    pub(crate) const MAX_NODES: usize = LEAF_BIT as usize;
    pub(crate) const MAX_BLOCKS: usize = 1 << (31 - BLOCK_COUNT_BITS);

    pub(crate) fn node(index: usize) -> Self {
        assert!(index < Self::MAX_NODES, "too many nodes for a wide BVH");
        ChildRef(index as u32)
    }

    pub(crate) fn leaf(first_block: usize, blocks: usize) -> Self {
        assert!(first_block < Self::MAX_BLOCKS, "too many triangles for a wide BVH");
        assert!((1..=Self::MAX_LEAF_BLOCKS).contains(&blocks), "leaf of {blocks} blocks");
        ChildRef(LEAF_BIT | (first_block as u32) << BLOCK_COUNT_BITS | (blocks as u32 - 1))
    }

    /// This reference in a tree whose nodes were moved up by `node_offset`
    /// (blocks are placed once, for the whole tree).
    pub(crate) fn relocated(self, node_offset: usize) -> Self {
        if self == ChildRef::NONE || self.is_leaf() { self } else { ChildRef::node(self.node_index() + node_offset) }
    }

    #[inline(always)]
    pub(crate) fn to_bits(self) -> u32 {
        self.0
    }

    #[inline(always)]
    pub(crate) fn from_bits(bits: u32) -> Self {
        ChildRef(bits)
    }

    #[inline(always)]
    pub(crate) fn is_leaf(self) -> bool {
        self.0 & LEAF_BIT != 0
    }

    /// The node index of an interior child.
    #[inline(always)]
    pub(crate) fn node_index(self) -> usize {
        self.0 as usize
    }

    /// The range of triangle blocks of a leaf.
    #[inline(always)]
    pub(crate) fn blocks(self) -> std::ops::Range<usize> {
        let first = ((self.0 & !LEAF_BIT) >> BLOCK_COUNT_BITS) as usize;
        let count = (self.0 & ((1 << BLOCK_COUNT_BITS) - 1)) as usize + 1;
        first..first + count
    }
}
