//! A job's share of a render: which rows and which samples of every pixel.

use std::ops::Range;

use crate::JobError;
use crate::request::Split;

impl Split {
    /// The rows and samples this job renders, of an image `height` rows
    /// high with `spp` samples per pixel.
    pub fn share(&self, height: u32, spp: u32) -> Result<(Range<u32>, Range<u32>), JobError> {
        let rows = match self.tile {
            None => 0..height,
            Some((index, count)) if count > height => return Err(JobError::TileTooFine { index, count, height }),
            Some((index, count)) => band(index, count, height),
        };
        let samples = match &self.samples {
            None => 0..spp,
            Some(range) if range.end > spp => return Err(JobError::SamplesBeyond { range: range.clone(), spp }),
            Some(range) => range.clone(),
        };
        Ok((rows, samples))
    }
}

/// Rows of band `index` of `count` bands of an image `height` rows high.
pub fn band(index: u32, count: u32, height: u32) -> Range<u32> {
    let edge = |i: u32| (i as u64 * height as u64 / count as u64) as u32;
    edge(index)..edge(index + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_the_rows_once() {
        for (count, height) in [(1, 7), (3, 7), (7, 7), (4, 1080)] {
            let bands: Vec<_> = (0..count).map(|i| band(i, count, height)).collect();
            assert_eq!(bands[0].start, 0);
            assert_eq!(bands[count as usize - 1].end, height);
            assert!(bands.windows(2).all(|w| w[0].end == w[1].start && !w[0].is_empty()));
        }
    }

    #[test]
    fn a_share_beyond_the_image_is_refused() {
        let split = Split { samples: Some(8..20), tile: None };
        assert!(matches!(split.share(10, 16), Err(JobError::SamplesBeyond { spp: 16, .. })));
        let split = Split { samples: None, tile: Some((0, 11)) };
        assert!(matches!(split.share(10, 16), Err(JobError::TileTooFine { height: 10, .. })));
        let split = Split { samples: Some(4..8), tile: Some((1, 2)) };
        assert_eq!(split.share(10, 16).unwrap(), (5..10, 4..8));
    }
}
