//! The node of a wide BVH and the references to its children.

use crate::simd::boxes::WideBoxes;

/// A node with up to `W` children: their boxes structure-of-arrays, so
/// that one ray tests all of them at once, and a [`ChildRef`] for each.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct WideNode<const W: usize> {
    pub(crate) boxes: WideBoxes<W>,
    pub(crate) children: [ChildRef; W],
}

impl<const W: usize> WideNode<W> {
    pub(crate) const EMPTY: Self = Self { boxes: WideBoxes::EMPTY, children: [ChildRef::NONE; W] };
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

    /// This reference in a tree whose nodes and blocks were moved up by
    /// `node_offset` and `block_offset`.
    pub(crate) fn relocated(self, node_offset: usize, block_offset: usize) -> Self {
        if self == ChildRef::NONE {
            self
        } else if self.is_leaf() {
            let blocks = self.blocks();
            ChildRef::leaf(blocks.start + block_offset, blocks.len())
        } else {
            ChildRef::node(self.node_index() + node_offset)
        }
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
