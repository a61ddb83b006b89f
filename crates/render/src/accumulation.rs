//! Per-pixel sums of samples, kept exactly, so that a render cut into
//! passes, sample ranges or bands of rows adds up to the very same bits as
//! the render in one go.
//!
//! Floating-point sums depend on the order of their terms: the sum of
//! samples 0–31 plus the sum of samples 32–63 is not, in general, the sum
//! of samples 0–63 taken in order. So each sample is first rounded to a
//! fixed-point integer (2^-40 per unit, [`FIXED_POINT_BITS`]), and integers
//! are added: integer addition is associative, and whatever the passes,
//! jobs or checkpoints a render went through, every pixel holds the same
//! integer sum and so gives the same mean. A sample loses only what lies
//! below 2^-40 (about 10^-12), and magnitudes are capped at 2^60
//! ([`SAMPLE_LIMIT`]): with 128-bit sums, 2^26 samples per pixel cannot
//! overflow. Samples that come out infinite or NaN count as black.

use std::fmt;
use std::ops::Range;

use rtgi_image::HdrImage;
use rtgi_math::Vec3;

use crate::identity::RenderIdentity;

/// Fractional bits of the fixed-point sums.
pub const FIXED_POINT_BITS: i32 = 40;

/// Largest magnitude a sample's channel keeps; brighter values are clamped to it.
pub const SAMPLE_LIMIT: f64 = (1u64 << 60) as f64;

/// The fixed-point sum of one pixel's samples, per channel.
pub type PixelSum = [i128; 3];

/// A sample's value as the integers that are summed.
#[inline]
pub(crate) fn to_fixed(value: Vec3) -> PixelSum {
    if !value.is_finite() {
        return [0; 3];
    }
    value.to_array().map(|c| {
        let scaled = (c as f64).clamp(-SAMPLE_LIMIT, SAMPLE_LIMIT) * (1u64 << FIXED_POINT_BITS) as f64;
        round_to_integer(scaled)
    })
}

/// `x.round() as i128`. Samples of ordinary brightness fit in 64 bits,
/// where the conversion is one instruction; to 128 bits it is a call into
/// the compiler's runtime, 2.4% of a path-traced Cornell box's time.
#[inline]
fn round_to_integer(x: f64) -> i128 {
    const FITS_IN_I64: f64 = (1u64 << 62) as f64;
    let rounded = x.round();
    if rounded.abs() < FITS_IN_I64 { rounded as i64 as i128 } else { rounded as i128 }
}

/// The mean of `count` samples whose fixed-point sum is `sum`.
#[inline]
pub(crate) fn mean(sum: &PixelSum, count: u32) -> Vec3 {
    let scale = 1.0 / ((1u64 << FIXED_POINT_BITS) as f64 * count.max(1) as f64);
    Vec3::from_array(sum.map(|c| (c as f64 * scale) as f32))
}

/// A `width × height` image whose rows from `first_row` on hold the means
/// of `count` samples with fixed-point sums `sums`; the rest is black.
pub(crate) fn image_of_sums(width: u32, height: u32, first_row: u32, sums: &[PixelSum], count: u32) -> HdrImage {
    let mut image = HdrImage::new(width, height);
    let start = first_row as usize * width as usize;
    for (pixel, sum) in image.pixels_mut()[start..].iter_mut().zip(sums) {
        *pixel = mean(sum, count);
    }
    image
}

#[inline]
pub(crate) fn add(sum: &mut PixelSum, value: &PixelSum) {
    for (s, v) in sum.iter_mut().zip(value) {
        *s = s.saturating_add(*v);
    }
}

/// The state of a render in progress, or a part of one: for a band of rows
/// of the image, the sums of a contiguous range of every pixel's samples.
///
/// A render in one go is one `Accumulation` over all rows and samples
/// `0..spp`; progressive renders grow `samples` pass by pass; a job of a
/// split render holds its band and its range. [`Accumulation::merge`] puts
/// parts together, and the result is the same, bit for bit, as a render of
/// the union in one go.
#[derive(Clone, PartialEq)]
pub struct Accumulation {
    identity: RenderIdentity,
    rows: Range<u32>,
    samples: Range<u32>,
    /// Per pixel of `rows`, row by row.
    sums: Vec<PixelSum>,
}

impl fmt::Debug for Accumulation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Accumulation")
            .field("identity", &self.identity)
            .field("rows", &self.rows)
            .field("samples", &self.samples)
            .finish_non_exhaustive()
    }
}

/// Why parts cannot be merged, or an accumulation cannot become an image.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MergeError {
    /// The list of parts is empty.
    #[error("no parts to merge")]
    Empty,
    /// A part's identity (size, samples, seed, scene, settings) differs from the first part's.
    #[error("part {part} is of another render than part 0: {differences}")]
    DifferentRender {
        /// Index of the part, in the order given.
        part: usize,
        /// Each difference, named.
        differences: String,
    },
    /// Two parts hold the same samples of the same rows.
    #[error("parts {first} and {second} both hold samples {samples:?} of rows {rows:?}")]
    Overlap {
        /// Index of the first of the two parts.
        first: usize,
        /// Index of the second.
        second: usize,
        /// The band of rows both hold.
        rows: Range<u32>,
        /// The samples both hold.
        samples: Range<u32>,
    },
    /// Some samples of a band are in no part.
    #[error("no part holds samples {missing:?} of rows {rows:?}")]
    MissingSamples {
        /// The band of rows.
        rows: Range<u32>,
        /// The samples no part holds.
        missing: Range<u32>,
    },
    /// Some rows are in no part.
    #[error("rows {0:?} are in no part")]
    MissingRows(Range<u32>),
    /// Two parts' bands of rows overlap without being equal.
    #[error("parts cut rows differently: {0:?} overlaps {1:?} without being the same band")]
    Bands(Range<u32>, Range<u32>),
}

impl MergeError {
    /// The message with the parts named by `name` (a file, say) instead of their index.
    pub fn naming(&self, name: &dyn Fn(usize) -> String) -> String {
        match self {
            MergeError::DifferentRender { part, differences } => {
                format!("{} is of another render than {}: {differences}", name(*part), name(0))
            }
            MergeError::Overlap { first, second, rows, samples } => {
                format!("{} and {} both hold samples {samples:?} of rows {rows:?}", name(*first), name(*second))
            }
            other => other.to_string(),
        }
    }
}

impl Accumulation {
    /// No samples yet of rows `rows`, the next sample being `first_sample`.
    ///
    /// # Panics
    /// If `rows` is not inside the image or `first_sample` is past the render's samples.
    pub fn new(identity: RenderIdentity, rows: Range<u32>, first_sample: u32) -> Self {
        assert!(rows.start <= rows.end && rows.end <= identity.height, "rows {rows:?} outside the image");
        assert!(first_sample <= identity.samples_per_pixel, "sample {first_sample} past the render's samples");
        let pixels = (rows.end - rows.start) as usize * identity.width as usize;
        Self { identity, rows, samples: first_sample..first_sample, sums: vec![[0; 3]; pixels] }
    }

    /// Rebuilds an accumulation from its parts, checking that they agree.
    pub(crate) fn from_parts(
        identity: RenderIdentity,
        rows: Range<u32>,
        samples: Range<u32>,
        sums: Vec<PixelSum>,
    ) -> Result<Self, String> {
        if rows.start > rows.end || rows.end > identity.height {
            return Err(format!("rows {rows:?} outside an image of height {}", identity.height));
        }
        if samples.start > samples.end || samples.end > identity.samples_per_pixel {
            return Err(format!("samples {samples:?} outside 0..{}", identity.samples_per_pixel));
        }
        let pixels = (rows.end - rows.start) as usize * identity.width as usize;
        if sums.len() != pixels {
            return Err(format!("{} pixel sums for {pixels} pixels", sums.len()));
        }
        Ok(Self { identity, rows, samples, sums })
    }

    /// The render these sums belong to, which merging and resuming compare.
    pub fn identity(&self) -> &RenderIdentity {
        &self.identity
    }

    /// The band of rows this holds.
    pub fn rows(&self) -> Range<u32> {
        self.rows.clone()
    }

    /// The samples of every pixel summed so far.
    pub fn samples(&self) -> Range<u32> {
        self.samples.clone()
    }

    /// Samples of every pixel summed so far.
    pub fn samples_done(&self) -> u32 {
        self.samples.end - self.samples.start
    }

    /// Whether every row and every sample of the render is in.
    pub fn is_complete(&self) -> bool {
        self.missing().is_empty()
    }

    /// What a complete render has that this one lacks ("samples 0..16",
    /// "the rows outside 0..32 of 0..64"); empty when complete.
    pub fn missing(&self) -> Vec<String> {
        let (rows, samples, identity) = (self.rows(), self.samples(), self.identity());
        let mut missing = Vec::new();
        if samples.start > 0 {
            missing.push(format!("samples {:?}", 0..samples.start));
        }
        if samples.end < identity.samples_per_pixel {
            missing.push(format!("samples {:?}", samples.end..identity.samples_per_pixel));
        }
        if rows != (0..identity.height) {
            missing.push(format!("the rows outside {rows:?} of 0..{}", identity.height));
        }
        missing
    }

    pub(crate) fn sums(&self) -> &[PixelSum] {
        &self.sums
    }

    /// Adds a pass: the sums of the next `count` samples of every pixel.
    pub(crate) fn add_pass(&mut self, pass: Vec<PixelSum>, count: u32) {
        debug_assert_eq!(pass.len(), self.sums.len());
        if self.samples.is_empty() {
            self.sums = pass;
        } else {
            for (sum, value) in self.sums.iter_mut().zip(&pass) {
                add(sum, value);
            }
        }
        self.samples.end += count;
    }

    /// The image: each pixel the mean of its samples. Rows outside the band are black.
    pub fn image(&self) -> HdrImage {
        let (width, height) = (self.identity.width, self.identity.height);
        image_of_sums(width, height, self.rows.start, &self.sums, self.samples_done())
    }

    /// Puts parts of one render together: bands of rows, and within a band,
    /// ranges of samples. Parts must be of the same render
    /// ([`RenderIdentity`]), no two may hold the same samples of the same
    /// rows, the bands must be the same wherever they overlap and follow
    /// one another without a gap, and every band must end up with the same
    /// samples, one contiguous range. The result has the bits a render of
    /// those rows and samples in one go would have.
    ///
    /// [`Accumulation::merge_files`] does the same from files, one part in
    /// memory at a time.
    pub fn merge(parts: Vec<Accumulation>) -> Result<Accumulation, MergeError> {
        let spans: Vec<PartSpan> = parts
            .iter()
            .map(|p| PartSpan { identity: p.identity.clone(), rows: p.rows(), samples: p.samples() })
            .collect();
        let plan = MergePlan::new(&spans)?;
        let mut merged = plan.empty();
        for (part, offset) in parts.iter().zip(&plan.offsets) {
            for (sum, value) in merged.sums[*offset..].iter_mut().zip(&part.sums) {
                add(sum, value);
            }
        }
        Ok(merged)
    }

    /// Adds `value` to the sum of pixel `index` of the band (row by row).
    pub(crate) fn add_to_pixel(&mut self, index: usize, value: &PixelSum) {
        add(&mut self.sums[index], value);
    }
}

/// What a part holds, as its file's header says: enough to check a merge
/// before any sums are read.
#[derive(Clone, Debug, PartialEq)]
pub struct PartSpan {
    /// The render it is a part of.
    pub identity: RenderIdentity,
    /// Its band of rows.
    pub rows: Range<u32>,
    /// Its samples of every pixel.
    pub samples: Range<u32>,
}

/// A checked merge: the result's span, and where each part's sums go in it.
#[derive(Debug)]
pub(crate) struct MergePlan {
    identity: RenderIdentity,
    rows: Range<u32>,
    samples: Range<u32>,
    /// Per part, in the order given: the index in the result's sums of the part's first pixel.
    pub(crate) offsets: Vec<usize>,
}

impl MergePlan {
    /// Checks that `parts` make one accumulation (see [`Accumulation::merge`]).
    pub(crate) fn new(parts: &[PartSpan]) -> Result<MergePlan, MergeError> {
        let first = parts.first().ok_or(MergeError::Empty)?;
        let identity = first.identity.clone();
        for (index, part) in parts.iter().enumerate() {
            let differences = identity.differences(&part.identity);
            if !differences.is_empty() {
                let differences: Vec<String> = differences.iter().map(|d| d.to_string()).collect();
                return Err(MergeError::DifferentRender { part: index, differences: differences.join("; ") });
            }
        }
        // Parts by band, in order of rows, then of samples.
        let mut order: Vec<usize> = (0..parts.len()).collect();
        order.sort_by_key(|&i| (parts[i].rows.start, parts[i].rows.end, parts[i].samples.start));
        let mut bands: Vec<(Range<u32>, Vec<usize>)> = Vec::new();
        for i in order {
            let rows = parts[i].rows.clone();
            match bands.last_mut() {
                Some((band, members)) if *band == rows => members.push(i),
                Some((band, _)) if band.end > rows.start => return Err(MergeError::Bands(band.clone(), rows)),
                _ => bands.push((rows, vec![i])),
            }
        }
        // Within each band, ranges of samples must follow one another.
        let mut band_samples = Vec::with_capacity(bands.len());
        for (rows, members) in &bands {
            let mut covered = parts[members[0]].samples.clone();
            for pair in members.windows(2) {
                let (a, b) = (&parts[pair[0]], &parts[pair[1]]);
                if b.samples.start < a.samples.end && !b.samples.is_empty() && !a.samples.is_empty() {
                    return Err(MergeError::Overlap {
                        first: pair[0],
                        second: pair[1],
                        rows: rows.clone(),
                        samples: b.samples.start..a.samples.end.min(b.samples.end),
                    });
                }
                if b.samples.start > covered.end {
                    return Err(MergeError::MissingSamples {
                        rows: rows.clone(),
                        missing: covered.end..b.samples.start,
                    });
                }
                covered.end = covered.end.max(b.samples.end);
            }
            band_samples.push(covered);
        }
        let samples = band_samples[0].clone();
        for ((rows, _), covered) in bands.iter().zip(&band_samples) {
            if *covered != samples {
                let missing = if covered.start > samples.start {
                    samples.start..covered.start
                } else if covered.end < samples.end {
                    covered.end..samples.end
                } else if samples.start > covered.start {
                    covered.start..samples.start
                } else {
                    samples.end..covered.end
                };
                let rows = if covered.len() < samples.len() { rows.clone() } else { bands[0].0.clone() };
                return Err(MergeError::MissingSamples { rows, missing });
            }
        }
        for pair in bands.windows(2) {
            if pair[0].0.end != pair[1].0.start {
                return Err(MergeError::MissingRows(pair[0].0.end..pair[1].0.start));
            }
        }
        let rows = bands[0].0.start..bands[bands.len() - 1].0.end;
        let width = identity.width as usize;
        let offsets = parts.iter().map(|part| (part.rows.start - rows.start) as usize * width).collect();
        Ok(MergePlan { identity, rows, samples, offsets })
    }

    /// The result with every sum zero, for the parts to be added to.
    pub(crate) fn empty(&self) -> Accumulation {
        let pixels = (self.rows.end - self.rows.start) as usize * self.identity.width as usize;
        Accumulation {
            identity: self.identity.clone(),
            rows: self.rows.clone(),
            samples: self.samples.clone(),
            sums: vec![[0; 3]; pixels],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 64-bit shortcut rounds as the 128-bit conversion does, on both
    /// sides of its threshold, at halves and at the sample limit.
    #[test]
    fn rounding_to_integers_agrees_with_the_128_bit_conversion() {
        let scale = (1u64 << FIXED_POINT_BITS) as f64;
        let mut values = vec![0.0, -0.0, 0.5, -0.5, 1.5, -2.5, 4.5e15, SAMPLE_LIMIT * scale, -SAMPLE_LIMIT * scale];
        for power in 0..=101 {
            let x = 2f64.powi(power);
            values.extend([x, -x, x * 0.75, -x * 0.75, x - 0.5, 0.5 - x, x + 0.5]);
            values.extend([x, -x].map(|x: f64| f64::from_bits(x.to_bits() - 1)));
            values.extend([x, -x].map(|x: f64| f64::from_bits(x.to_bits() + 1)));
        }
        let mut rng = rtgi_math::Rng::new(3, 1);
        values.extend((0..100_000).map(|_| (rng.next_f32() as f64 - 0.5) * 2f64.powi((rng.next_u32() % 100) as i32)));
        for x in values {
            assert_eq!(round_to_integer(x), x.round() as i128, "{x:e}");
        }
    }

    fn identity(height: u32, spp: u32) -> RenderIdentity {
        RenderIdentity::for_tests(4, height, spp)
    }

    fn part(rows: Range<u32>, samples: Range<u32>, value: i128) -> Accumulation {
        let identity = identity(8, 16);
        let pixels = (rows.end - rows.start) as usize * 4;
        Accumulation::from_parts(identity, rows, samples, vec![[value; 3]; pixels]).unwrap()
    }

    #[test]
    fn fixed_point_sums_are_exact_in_any_order() {
        let values = [1.0e8f32, 1.0, 1.0, 1.0e-9, 0.1, 1.0, 1.0e-6, 1.0];
        let sum_in = |order: &[usize]| {
            let mut sum = [0i128; 3];
            for &i in order {
                add(&mut sum, &to_fixed(Vec3::splat(values[i])));
            }
            sum
        };
        assert_eq!(sum_in(&[0, 1, 2, 3, 4, 5, 6, 7]), sum_in(&[7, 3, 5, 1, 2, 6, 4, 0]));
        // The float sums in these two orders differ: that is the point.
        let float_sum = |order: &[usize]| order.iter().fold(0.0f32, |s, &i| s + values[i]);
        assert_ne!(float_sum(&[0, 1, 2, 3, 4, 5, 6, 7]), float_sum(&[7, 3, 5, 1, 2, 6, 4, 0]));
    }

    #[test]
    fn non_finite_samples_count_as_black_and_huge_ones_are_capped() {
        assert_eq!(to_fixed(Vec3::new(f32::NAN, 1.0, 1.0)), [0; 3]);
        assert_eq!(to_fixed(Vec3::new(f32::INFINITY, 1.0, 1.0)), [0; 3]);
        let capped = to_fixed(Vec3::splat(f32::MAX))[0];
        assert_eq!(capped, 1i128 << (60 + FIXED_POINT_BITS));
        // 2^26 capped samples still fit.
        assert!(capped.checked_mul(1 << 26).is_some());
    }

    #[test]
    fn means_round_trip_ordinary_values() {
        for value in [0.0f32, 1.0, 0.5, 3.25, 1234.5678, 1.0e-3] {
            let sum = to_fixed(Vec3::splat(value));
            assert_eq!(mean(&sum, 1), Vec3::splat(value), "{value}");
        }
    }

    #[test]
    fn merge_puts_bands_and_ranges_together() {
        let parts = vec![part(4..8, 8..16, 2), part(0..4, 0..8, 1), part(4..8, 0..8, 1), part(0..4, 8..16, 2)];
        let merged = Accumulation::merge(parts).unwrap();
        assert_eq!(merged.rows(), 0..8);
        assert_eq!(merged.samples(), 0..16);
        assert!(merged.is_complete());
        assert!(merged.sums().iter().all(|s| *s == [3; 3]));
    }

    #[test]
    fn merge_refuses_overlaps_gaps_and_other_renders() {
        let overlap = Accumulation::merge(vec![part(0..8, 0..8, 1), part(0..8, 4..16, 1)]);
        assert!(matches!(overlap, Err(MergeError::Overlap { .. })), "{overlap:?}");
        let gap = Accumulation::merge(vec![part(0..8, 0..4, 1), part(0..8, 8..16, 1)]);
        assert_eq!(gap, Err(MergeError::MissingSamples { rows: 0..8, missing: 4..8 }));
        let rows = Accumulation::merge(vec![part(0..2, 0..16, 1), part(4..8, 0..16, 1)]);
        assert_eq!(rows, Err(MergeError::MissingRows(2..4)));
        let uneven = Accumulation::merge(vec![part(0..4, 0..16, 1), part(4..8, 0..8, 1)]);
        assert!(matches!(uneven, Err(MergeError::MissingSamples { .. })), "{uneven:?}");
        let bands = Accumulation::merge(vec![part(0..4, 0..8, 1), part(2..8, 8..16, 1)]);
        assert!(matches!(bands, Err(MergeError::Bands(..))), "{bands:?}");
        let mut other = part(0..8, 8..16, 1);
        other.identity.seed = 7;
        let different = Accumulation::merge(vec![part(0..8, 0..8, 1), other]);
        assert!(matches!(different, Err(MergeError::DifferentRender { part: 1, .. })), "{different:?}");
    }
}
