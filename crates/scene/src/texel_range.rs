//! The range of one channel's bytes over each 2 × 2 block of texels: what
//! a bilinear lookup there can return, found with one read instead of
//! four texels and their filtering.
//!
//! A cut-out's alpha test runs for every candidate hit on its surface, and
//! in foliage most candidates lie where the mask is wholly opaque or
//! wholly clear. A bilinear lookup blends two neighbouring columns and two
//! neighbouring rows (the next one, or for the wrap modes at a border the
//! same one or, mirrored, the previous one), so the least and greatest
//! byte of the block they span bound it. Where those bounds decide a test,
//! the texels need not be read.

/// For every texel `(x, y)`, the least and greatest value of one channel's
/// bytes over the texels `x` and `x + 1` of rows `y` and `y + 1` (modulo
/// the image's size).
#[derive(Clone)]
pub(crate) struct TexelRanges {
    width: usize,
    ranges: Box<[[u8; 2]]>,
}

impl TexelRanges {
    /// The ranges of channel `channel` of `texels`, an image `width` texels wide.
    pub(crate) fn of(texels: &[[u8; 4]], width: usize, channel: usize) -> Self {
        let height = texels.len() / width;
        // Rows first, then columns: a block's range is a range of ranges.
        let mut pairs = vec![[0u8; 2]; texels.len()];
        for y in 0..height {
            let row = &texels[y * width..(y + 1) * width];
            for x in 0..width {
                let (a, b) = (row[x][channel], row[(x + 1) % width][channel]);
                pairs[y * width + x] = [a.min(b), a.max(b)];
            }
        }
        let mut ranges = vec![[0u8; 2]; texels.len()];
        for y in 0..height {
            let below = (y + 1) % height;
            for x in 0..width {
                let [a, b] = [pairs[y * width + x], pairs[below * width + x]];
                ranges[y * width + x] = [a[0].min(b[0]), a[1].max(b[1])];
            }
        }
        Self { width, ranges: ranges.into_boxed_slice() }
    }

    /// The least and greatest byte of the block that holds the columns
    /// `columns` and the rows `rows`, each a texel and one beside it (the
    /// next, modulo the size, or the same, or the previous).
    #[inline]
    pub(crate) fn spanning(&self, columns: [u32; 2], rows: [u32; 2]) -> [u8; 2] {
        // The block starts at the first of the two, unless the second is
        // the one before it.
        let start = |[a, b]: [u32; 2]| if b.wrapping_add(1) == a { b } else { a };
        self.ranges[start(rows) as usize * self.width + start(columns) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_range_spans_its_block_cyclically() {
        // A 4 × 3 image whose alpha is ten times its texel's number.
        let texels: Vec<[u8; 4]> = (0..12).map(|i| [0, 0, 0, i as u8 * 10]).collect();
        let ranges = TexelRanges::of(&texels, 4, 3);
        // Texels 5, 6, 9 and 10.
        assert_eq!(ranges.spanning([1, 2], [1, 2]), [50, 100]);
        // The last column and row wrap to the first: texels 11, 8, 3 and 0.
        assert_eq!(ranges.spanning([3, 0], [2, 0]), [0, 110]);
        // A column with its previous one (mirrored): texels 4, 5, 8 and 9.
        assert_eq!(ranges.spanning([1, 0], [1, 2]), [40, 90]);
        // A column with itself (clamped at a border) is in its block: texels 0, 1, 4 and 5.
        assert_eq!(ranges.spanning([0, 0], [0, 1]), [0, 50]);
    }
}
