use rtgi_math::{Rng, Vec2, hash_u64, next_float_down, next_float_up};

/// Where inside a pixel the samples go, and how the random numbers of each
/// path's first vertex (light choice, point on the light, BSDF direction)
/// are spread over the pixel's samples ([`PixelSampler::vertex`]):
/// the stratified and low-discrepancy samplers spread them as they spread
/// positions, the others draw them at random.
///
/// Every sampler but `Center` is unbiased for every sample count `n`: over
/// the pixel's random choices each sample is uniform either over the whole
/// pixel (uniform, low-discrepancy) or over its own cell of a grid of `n`
/// cells that tile the pixel (stratified), so the mean of the samples
/// estimates the mean over the pixel. Sample `i` of `n` depends only on
/// `i`, `n`, the pixel's [`PixelSample::pixel_shift`] and the sample's own
/// generator, never on other samples, so images are the same for any
/// number of threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum PixelSampler {
    /// Every sample at the pixel's centre: no antialiasing, no noise.
    Center,
    /// Uniformly random positions in the pixel.
    Uniform,
    /// Correlated multi-jittered: one sample in each cell of a grid, and in each row and column.
    ///
    /// Correlated multi-jittered sampling (Kensler, "Correlated
    /// Multi-Jittered Sampling", Pixar technical memo 13-01, 2013) on an
    /// `m × k` grid with `m · k = n` exactly, `m` the largest divisor of `n`
    /// not above `√n`: each of the grid's cells, and each of the `n` strips
    /// across x and the `n` strips across y, holds exactly one sample. The
    /// permutations that place the samples within their cells are chosen
    /// per pixel from its shift, the jitter comes from each sample's
    /// generator. For a prime `n` the grid is `1 × n`: the samples are then
    /// stratified in x and in y separately (n-rooks), but not in 2D.
    Stratified,
    /// The R2 low-discrepancy sequence, shifted per pixel.
    ///
    /// The R2 low-discrepancy sequence (Roberts 2018), shifted by a random
    /// offset per pixel (Cranley-Patterson rotation) so that neighbouring
    /// pixels do not repeat the same pattern; computed in 64-bit fixed
    /// point, exact for every index.
    LowDiscrepancy,
    /// An Owen-scrambled Sobol sequence, scrambled per pixel.
    ///
    /// The Sobol sequence's first two dimensions with Owen scrambling and a
    /// shuffled index (Burley 2020, "Practical Hash-based Owen
    /// Scrambling", through the `sobol_burley` crate), each pixel and each
    /// pair of numbers with its own seed, so that pairs are not correlated
    /// (padding). Every point of an Owen-scrambled sequence is uniform over
    /// the square, so it is unbiased for every count; for powers of two the
    /// points also fall one in each elementary interval (strata of every
    /// shape), which is where its error falls fastest. Indices past 2^16
    /// continue in another independently scrambled sequence.
    Sobol,
}

/// Which sample of how many, in a pixel with its own random shift: what
/// the samplers that spread samples over a pixel need to know.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSample {
    /// Which sample of the pixel, from 0.
    pub index: u32,
    /// How many samples the pixel takes in the whole render.
    pub count: u32,
    /// Uniform in `[0, 1)²`, the same for every sample of the pixel: the
    /// low-discrepancy sampler's shift, and the seed of the stratified
    /// sampler's permutations.
    pub pixel_shift: Vec2,
}

/// The plastic number's reciprocals 1/ρ and 1/ρ², the R2 sequence's
/// increments, in 0.64 fixed point.
const R2: [u64; 2] = [0xc13f_a9a9_02a6_328f, 0x91e1_0da5_c79e_7b1d];

impl PixelSampler {
    /// Every sampler, in the order help texts list them.
    pub const ALL: &'static [PixelSampler] = &[
        PixelSampler::Center,
        PixelSampler::Uniform,
        PixelSampler::Stratified,
        PixelSampler::LowDiscrepancy,
        PixelSampler::Sobol,
    ];

    /// The sampler's name on command lines and in reports (`center`, `uniform`, `stratified`, `low-discrepancy`).
    pub fn name(self) -> &'static str {
        match self {
            PixelSampler::Center => "center",
            PixelSampler::Uniform => "uniform",
            PixelSampler::Stratified => "stratified",
            PixelSampler::LowDiscrepancy => "low-discrepancy",
            PixelSampler::Sobol => "sobol",
        }
    }

    /// The position in `[0, 1)²` of one sample of a pixel, drawing from that
    /// sample's generator where the sampler is random.
    #[inline]
    pub fn offset(self, sample: &PixelSample, rng: &mut Rng) -> Vec2 {
        self.pattern(sample.count, sample.pixel_shift).offset(sample.index, rng)
    }

    /// What every sample of a pixel shares: the sampler's seeds for the
    /// pixel, hashed from its shift once rather than for every sample.
    pub fn pattern(self, count: u32, pixel_shift: Vec2) -> PixelPattern {
        let count = count.max(1);
        let pixel = pixel_seed(pixel_shift);
        PixelPattern {
            sampler: self,
            count,
            grid: grid(count),
            pixel_shift,
            pixel,
            first_vertex: std::array::from_fn(|pair| PairSeeds::of(pixel, 1 + pair as u64)),
        }
    }
}

/// Random numbers of a vertex of a camera path that a sampler spreads over
/// the pixel's samples like their positions: the pairs that choose a light
/// and a lobe, a point on the light, and the BSDF's direction. At the first
/// vertices they decide the direct light and the first bounces, most of an
/// image's noise at low sample counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexNumbers {
    /// x chooses the light, y the lobe of a layered material.
    pub choices: Vec2,
    /// The point on the chosen light (or direction of the environment).
    pub light: Vec2,
    /// The direction drawn from the BSDF.
    pub bsdf: Vec2,
}

impl PixelSampler {
    /// The numbers of vertex `depth` (0 for the camera ray's hit) of sample
    /// `sample`'s path. The stratified and low-discrepancy samplers give
    /// each pair the pattern they give pixel positions (correlated
    /// multi-jittered strips and cells, or R2), with its own permutation of
    /// the sample indices and its own permutations or shift, so that the pairs are stratified across
    /// the pixel's samples but not correlated with each other or with the
    /// position (padding, as pbrt's samplers do); the others draw them from
    /// the sample's generator. Each number is uniform in `[0, 1)` for any
    /// sample count, so estimates stay unbiased.
    pub fn vertex(self, sample: &PixelSample, depth: u32, rng: &mut Rng) -> VertexNumbers {
        self.pattern(sample.count, sample.pixel_shift).vertex(sample.index, depth, rng)
    }
}

/// A pixel's seeds for its sampler ([`PixelSampler::pattern`]): sample `i`
/// of the pixel is [`PixelPattern::offset`] and [`PixelPattern::vertex`]
/// of `i`, the same numbers as [`PixelSampler::offset`] and
/// [`PixelSampler::vertex`] give, without hashing the seeds again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelPattern {
    sampler: PixelSampler,
    /// The pixel's samples in the whole render (at least 1).
    count: u32,
    /// The stratified sampler's columns and rows.
    grid: (u32, u32),
    pixel_shift: Vec2,
    /// The hash of the shift, which seeds everything else.
    pixel: u64,
    /// The seeds of the first vertex's three pairs (the rest are hashed when asked for).
    first_vertex: [PairSeeds; 3],
}

/// The seeds of one pair of numbers: two independent 64-bit seeds, one for
/// the permutation of the sample indices, one for the pattern's own
/// choices, and a third for the stratified sampler's y strips.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PairSeeds {
    seed: u64,
    pattern: u64,
    // Its own hash: the two strip permutations must be independent, or a
    // sample can reach only some of the sub-squares of its cell (half of
    // them, when the y permutation reused the x one's bits), which biased
    // small lights found by BSDF sampling by a third.
    y_pattern: u64,
}

impl PairSeeds {
    /// Pair `dimension` of the pixel whose seed is `pixel` (0 is the position in the pixel).
    fn of(pixel: u64, dimension: u64) -> Self {
        let seed = hash_u64(pixel ^ dimension.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let pattern = hash_u64(seed);
        PairSeeds { seed, pattern, y_pattern: hash_u64(pattern) }
    }
}

impl PixelPattern {
    /// The position in `[0, 1)²` of sample `index` of the pixel, drawing
    /// from that sample's generator where the sampler is random.
    #[inline]
    pub fn offset(&self, index: u32, rng: &mut Rng) -> Vec2 {
        match self.sampler {
            PixelSampler::Center => Vec2::splat(0.5),
            PixelSampler::Uniform => Vec2::new(rng.next_f32(), rng.next_f32()),
            PixelSampler::Stratified => {
                let count = self.count;
                let index = remainder(index, count);
                let (columns, rows) = self.grid;
                let (column, row) = (remainder(index, columns), quotient(index, columns));
                // The pixel's two permutations: of the rows within a column
                // (which x strip of its column a sample takes) and of the
                // columns within a row (which y strip of its row).
                let seed = self.pixel;
                let x_strip = column * rows + permute(row, rows, seed as u32);
                let y_strip = row * columns + permute(column, columns, (seed >> 32) as u32);
                Vec2::new(in_strip(x_strip, rng.next_f32(), count), in_strip(y_strip, rng.next_f32(), count))
            }
            PixelSampler::LowDiscrepancy => {
                let shift = self.pixel_shift.to_array().map(to_fixed);
                r2_point(index as u64, shift)
            }
            PixelSampler::Sobol => sobol_point(index, self.pixel),
        }
    }

    /// The numbers of vertex `depth` of sample `index`'s path, as [`PixelSampler::vertex`] says.
    #[inline]
    pub fn vertex(&self, index: u32, depth: u32, rng: &mut Rng) -> VertexNumbers {
        let index = remainder(index, self.count);
        let seeds = |pair: u32| match self.first_vertex.get((3 * depth + pair) as usize) {
            Some(seeds) => *seeds,
            None => PairSeeds::of(self.pixel, 1 + 3 * depth as u64 + pair as u64),
        };
        VertexNumbers {
            choices: self.pair(index, seeds(0), rng),
            light: self.pair(index, seeds(1), rng),
            bsdf: self.pair(index, seeds(2), rng),
        }
    }

    /// One pair of numbers of sample `index` (below the count).
    #[inline]
    fn pair(&self, index: u32, PairSeeds { seed, pattern, y_pattern }: PairSeeds, rng: &mut Rng) -> Vec2 {
        let count = self.count;
        match self.sampler {
            PixelSampler::Center | PixelSampler::Uniform => Vec2::new(rng.next_f32(), rng.next_f32()),
            PixelSampler::Stratified => {
                let (columns, rows) = self.grid;
                // The index permutation decorrelates the pairs: it must
                // be a good one (an affine map would relate the pairs'
                // indices to each other, and their numbers with them).
                let j = permute(index, count, seed as u32);
                let (column, row) = (remainder(j, columns), quotient(j, columns));
                let x_strip = column * rows + shuffle(row, rows, pattern);
                let y_strip = row * columns + shuffle(column, columns, y_pattern);
                Vec2::new(in_strip(x_strip, rng.next_f32(), count), in_strip(y_strip, rng.next_f32(), count))
            }
            PixelSampler::LowDiscrepancy => {
                r2_point(permute(index, count, seed as u32) as u64, [pattern, pattern << 24])
            }
            // The index shuffle and scramble of its own seed decorrelate the pair.
            PixelSampler::Sobol => sobol_point(index, seed),
        }
    }
}

/// Point `i` of the Owen-scrambled Sobol sequence of `seed` (its first two
/// dimensions); past 2^16 points, the next block of 2^16 is another
/// sequence, independently scrambled.
#[inline]
fn sobol_point(i: u32, seed: u64) -> Vec2 {
    const BLOCK: u32 = 1 << 16;
    let seed = (seed ^ hash_u64((i / BLOCK) as u64)) as u32;
    let i = i % BLOCK;
    Vec2::new(sobol_burley::sample(i, 0, seed), sobol_burley::sample(i, 1, seed))
}

/// Point `i` of the R2 sequence shifted by `shift` (in 0.64 fixed point):
/// 1/2 + i·α + shift, modulo 1, where wrapping arithmetic is exact.
fn r2_point(i: u64, shift: [u64; 2]) -> Vec2 {
    let coordinate = |axis: usize| {
        let fixed = (1u64 << 63).wrapping_add(i.wrapping_mul(R2[axis])).wrapping_add(shift[axis]);
        // The top 24 bits, as `Rng::next_f32` makes them: in [0, 1).
        (fixed >> 40) as f32 * (1.0 / 16_777_216.0)
    };
    Vec2::new(coordinate(0), coordinate(1))
}

/// Element `i` of a pseudo-random permutation of `0..len` chosen by `seed`,
/// for the strips of the pairs of path vertices, whose only duty is to
/// place each sample uniformly within its cell: for a power of two an affine map
/// `a·i + b mod len` with `a` odd (a bijection, and for every `i` uniform
/// over the seeds, since `b` is: what unbiasedness needs), a few cycles
/// where [`permute`] takes dozens; [`permute`] for other lengths. Positions
/// in the pixel keep [`permute`], whose patterns the tests measured.
#[inline]
fn shuffle(i: u32, len: u32, seed: u64) -> u32 {
    if len.is_power_of_two() {
        ((seed as u32 | 1).wrapping_mul(i).wrapping_add((seed >> 32) as u32)) & (len - 1)
    } else {
        permute(i, len, seed as u32)
    }
}

/// The columns and rows of the stratified sampler's grid for `count`
/// samples: `columns · rows = count`, `columns` the largest divisor not
/// above `√count` (found by trial division: at most √count steps).
fn grid(count: u32) -> (u32, u32) {
    if count.is_power_of_two() {
        let columns = 1 << (count.trailing_zeros() / 2);
        return (columns, count >> columns.trailing_zeros());
    }
    let mut columns = count.isqrt().max(1);
    while !count.is_multiple_of(columns) {
        columns -= 1;
    }
    (columns, count / columns)
}

/// `a / b` and `a % b` with a shift and a mask when `b` is a power of two,
/// as sample counts usually are: the samplers divide by the count and the
/// grid's sides several times per sample, and an integer division costs
/// tens of cycles (a quarter of a sky-lit path's time before this).
#[inline]
fn quotient(a: u32, b: u32) -> u32 {
    if b.is_power_of_two() { a >> b.trailing_zeros() } else { a / b }
}

#[inline]
fn remainder(a: u32, b: u32) -> u32 {
    if b.is_power_of_two() { a & (b - 1) } else { a % b }
}

/// A hash of the pixel's shift: its permutations' seeds.
fn pixel_seed(shift: Vec2) -> u64 {
    hash_u64(((shift.x.to_bits() as u64) << 32) | shift.y.to_bits() as u64)
}

/// A position in strip `strip` of `count` equal strips of `[0, 1)`, at
/// `jitter ∈ [0, 1)` across it, inside the strip exactly despite rounding
/// (for counts up to 2^24, where strips are still wider than an f32 step).
fn in_strip(strip: u32, jitter: f32, count: u32) -> f32 {
    let position = strip as f64 + jitter as f64;
    // A power of two's reciprocal is exact, so multiplying by it gives the
    // quotient's bits. The division's line had 5% of a Cornell box render's
    // samples (perf), most of them waiting for its result; the render is
    // about 1% faster without it.
    let scaled = if count.is_power_of_two() {
        position * f64::from_bits((1023 - u64::from(count.trailing_zeros())) << 52)
    } else {
        position / count as f64
    };
    let (strip, count) = (strip as f64, count as f64);
    let mut x = scaled as f32;
    // x · count is exact in f64 (24 × 32 bits), so these tests are too.
    if x as f64 * count >= strip + 1.0 {
        x = next_float_down(x);
    } else if (x as f64 * count) < strip {
        x = next_float_up(x);
    }
    x.clamp(0.0, ONE_BELOW_ONE)
}

/// A value in `[0, 1)` in 0.64 fixed point (exact for an f32).
fn to_fixed(x: f32) -> u64 {
    (x.clamp(0.0, 1.0) as f64 * 18_446_744_073_709_551_616.0) as u64
}

/// Element `i` of a pseudo-random permutation of `0..len` chosen by `seed`,
/// computed on its own (Kensler 2013, listing 3): a hash that is a
/// bijection on the smallest power of two at least `len`, applied until its
/// value falls below `len` (cycle walking), then rotated by the seed.
fn permute(mut i: u32, len: u32, seed: u32) -> u32 {
    if len <= 1 {
        return 0;
    }
    let mut mask = len - 1;
    mask |= mask >> 1;
    mask |= mask >> 2;
    mask |= mask >> 4;
    mask |= mask >> 8;
    mask |= mask >> 16;
    loop {
        i ^= seed;
        i = i.wrapping_mul(0xe170_893d);
        i ^= seed >> 16;
        i ^= (i & mask) >> 4;
        i ^= seed >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= seed >> 23;
        i ^= (i & mask) >> 1;
        i = i.wrapping_mul(1 | seed >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & mask) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & mask) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & mask) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= mask;
        i ^= i >> 5;
        if i < len {
            break;
        }
    }
    // i < len, so i + (seed mod len) is below 2 len.
    let rotated = i + remainder(seed, len);
    if rotated >= len { rotated - len } else { rotated }
}

/// The largest f32 below 1, so that offsets stay inside their pixel.
const ONE_BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

impl rtgi_math::NamedChoice for PixelSampler {
    const KIND: &'static str = "sampler";
    const ALL: &'static [Self] = PixelSampler::ALL;
    fn name(self) -> &'static str {
        PixelSampler::name(self)
    }
}

impl std::fmt::Display for PixelSampler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn offsets(sampler: PixelSampler, count: u32, pixel: u64) -> Vec<Vec2> {
        points(sampler, count, pixel, 0)
    }

    /// The pixel's samples of one pair of numbers: 0 is the position in the
    /// pixel, 1 to 3 the first vertex's choices, light and BSDF pairs, 4 to
    /// 6 the second vertex's.
    fn points(sampler: PixelSampler, count: u32, pixel: u64, pair: usize) -> Vec<Vec2> {
        // As `render` does: the pixel's shift from one generator past every sample's.
        let mut shift_rng = Rng::for_sample(1, pixel, u64::MAX);
        let pixel_shift = Vec2::new(shift_rng.next_f32(), shift_rng.next_f32());
        (0..count)
            .map(|index| {
                let mut rng = Rng::for_sample(1, pixel, index as u64);
                let sample = PixelSample { index, count, pixel_shift };
                let p = match pair {
                    0 => sampler.offset(&sample, &mut rng),
                    _ => {
                        let vertex = sampler.vertex(&sample, (pair as u32 - 1) / 3, &mut rng);
                        [vertex.choices, vertex.light, vertex.bsdf][(pair - 1) % 3]
                    }
                };
                assert!(p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all(), "{sampler} {index}/{count}: {p}");
                p
            })
            .collect()
    }

    /// The counts the tests try: every one up to 256, squares or not.
    const COUNTS: std::ops::RangeInclusive<u32> = 1..=256;
    const PIXELS: u64 = 128;

    /// Which of `count` equal strips of [0, 1) holds `x`, exactly (the
    /// product of an f32 and a small integer is exact in f64).
    fn strip(x: f32, count: u32) -> usize {
        (x as f64 * count as f64).floor() as usize
    }

    #[test]
    fn center_is_the_centre_for_every_count() {
        for count in COUNTS {
            assert!(offsets(PixelSampler::Center, count, 7).iter().all(|&p| p == Vec2::splat(0.5)));
        }
    }

    /// The bug of issue 12: with `n` not a square, the old stratified
    /// sampler cut the pixel into ⌈√n⌉² cells and left the last ones empty,
    /// which moved the mean of its samples away from the pixel's centre.
    #[test]
    fn every_sampler_centres_its_samples_for_every_count() {
        for &sampler in PixelSampler::ALL.iter().filter(|&&s| s != PixelSampler::Center) {
            for count in COUNTS {
                // Each pixel's mean position is one draw; their spread gives the standard error.
                let means: Vec<[f64; 2]> = (0..PIXELS)
                    .map(|pixel| {
                        let points = offsets(sampler, count, pixel);
                        let sum = points.iter().fold([0.0, 0.0], |s, p| [s[0] + p.x as f64, s[1] + p.y as f64]);
                        [sum[0] / count as f64, sum[1] / count as f64]
                    })
                    .collect();
                for axis in 0..2 {
                    let n = PIXELS as f64;
                    let mean = means.iter().map(|m| m[axis]).sum::<f64>() / n;
                    let variance = means.iter().map(|m| (m[axis] - mean).powi(2)).sum::<f64>() / (n - 1.0);
                    let standard_error = (variance / n).sqrt();
                    // 5σ, and a little for f32 positions (and next_f32's 2^-25 below the centre).
                    let tolerance = 5.0 * standard_error + 1e-6;
                    assert!(
                        (mean - 0.5).abs() < tolerance,
                        "{sampler}, {count} spp, axis {axis}: mean {mean} is {:.1} standard errors off",
                        (mean - 0.5).abs() / standard_error
                    );
                }
            }
        }
    }

    /// Over many pixels every sampler fills 16 strips across x and across y
    /// evenly: a chi-square test with 15 degrees of freedom, at its mean
    /// plus 8 standard deviations (a chance below 10⁻⁶ for a uniform sampler).
    #[test]
    fn every_sampler_covers_the_pixel_evenly() {
        const STRIPS: usize = 16;
        let limit = (STRIPS - 1) as f64 + 8.0 * (2.0 * (STRIPS - 1) as f64).sqrt();
        for &sampler in PixelSampler::ALL.iter().filter(|&&s| s != PixelSampler::Center) {
            for count in COUNTS {
                let mut counts = [[0u32; STRIPS]; 2];
                for pixel in 0..PIXELS {
                    for p in offsets(sampler, count, 1000 + pixel) {
                        counts[0][strip(p.x, STRIPS as u32)] += 1;
                        counts[1][strip(p.y, STRIPS as u32)] += 1;
                    }
                }
                let expected = (PIXELS * count as u64) as f64 / STRIPS as f64;
                for (axis, counts) in counts.iter().enumerate() {
                    let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
                    assert!(chi2 < limit, "{sampler}, {count} spp, axis {axis}: χ² = {chi2:.1}, strips {counts:?}");
                }
            }
        }
    }

    #[test]
    fn stratified_samples_fill_every_strip_and_cell_once() {
        for count in COUNTS {
            // m · k = count, m the largest divisor of count not above √count.
            let columns = (1..=count).filter(|m| count % m == 0 && m * m <= count).max().unwrap();
            let rows = count / columns;
            assert_eq!(grid(count), (columns, rows));
            for pixel in 0..PIXELS {
                let points = offsets(PixelSampler::Stratified, count, pixel);
                let mut x_strips = vec![0u32; count as usize];
                let mut y_strips = vec![0u32; count as usize];
                let mut cells = vec![0u32; count as usize];
                for p in points {
                    x_strips[strip(p.x, count)] += 1;
                    y_strips[strip(p.y, count)] += 1;
                    cells[strip(p.y, rows) * columns as usize + strip(p.x, columns)] += 1;
                }
                let once = |v: &[u32]| v.iter().all(|&c| c == 1);
                assert!(once(&x_strips), "{count} spp, pixel {pixel}: x strips {x_strips:?}");
                assert!(once(&y_strips), "{count} spp, pixel {pixel}: y strips {y_strips:?}");
                assert!(once(&cells), "{count} spp, pixel {pixel}: {columns}×{rows} cells {cells:?}");
            }
        }
    }

    /// The first vertex's pairs are spread as the positions are: for the
    /// stratified sampler every strip and cell once, for every count; for
    /// every sampler uniform over many pixels (their mean is the centre)
    /// and, for the center sampler too, random rather than constant.
    #[test]
    fn first_vertex_numbers_are_stratified_and_uniform() {
        for count in 1..=64u32 {
            let (columns, rows) = grid(count);
            for pixel in 0..32 {
                for pair in 1..=6 {
                    let mut strips = [vec![0u32; count as usize], vec![0u32; count as usize]];
                    let mut cells = vec![0u32; count as usize];
                    for p in points(PixelSampler::Stratified, count, pixel, pair) {
                        strips[0][strip(p.x, count)] += 1;
                        strips[1][strip(p.y, count)] += 1;
                        cells[strip(p.y, rows) * columns as usize + strip(p.x, columns)] += 1;
                    }
                    let once = |v: &[u32]| v.iter().all(|&c| c == 1);
                    assert!(once(&strips[0]) && once(&strips[1]) && once(&cells), "{count} spp, pair {pair}");
                }
            }
        }
        for &sampler in PixelSampler::ALL {
            for count in [1u32, 2, 3, 7, 16, 17] {
                for pair in 1..=3 {
                    let all: Vec<Vec2> = (0..PIXELS).flat_map(|pixel| points(sampler, count, pixel, pair)).collect();
                    let n = all.len() as f64;
                    let mean = all.iter().fold(rtgi_math::glam::DVec2::ZERO, |s, p| s + p.as_dvec2()) / n;
                    // A uniform coordinate's standard deviation is 1/√12; 5 standard errors.
                    let tolerance = 5.0 / (12.0 * n).sqrt();
                    assert!(
                        (mean - 0.5).abs().max_element() < tolerance,
                        "{sampler}, {count} spp, pair {pair}: {mean}"
                    );
                    assert!(all.iter().any(|p| *p != all[0]), "{sampler}, {count} spp, pair {pair}: constant");
                }
            }
        }
    }

    /// Over the pixels' random choices, one sample of a vertex's pair is
    /// uniform over the whole square (what makes it independent of the
    /// sample's position in the pixel), at the resolution of its strips: every one of the
    /// count × count sub-squares is reached equally often (χ² over them,
    /// at its mean plus 8 standard deviations). Strips and cells alone do
    /// not show this: with dependent strip permutations a sample reached
    /// only half the sub-squares of its cell.
    #[test]
    fn one_sample_of_a_pair_reaches_every_sub_square_of_the_pixel() {
        for sampler in [PixelSampler::Stratified, PixelSampler::LowDiscrepancy, PixelSampler::Sobol] {
            for count in [4u32, 6, 9, 16] {
                let bins = (count * count) as usize;
                let pixels = 100 * bins as u64;
                // Not pair 0: a stratified position stays in its own cell (the cells tile the pixel).
                for pair in [1usize, 3, 5] {
                    for index in [0u32, count - 1] {
                        let mut histogram = vec![0u32; bins];
                        for pixel in 0..pixels {
                            let p = points(sampler, count, 50_000 + pixel, pair)[index as usize];
                            histogram[strip(p.y, count) * count as usize + strip(p.x, count)] += 1;
                        }
                        let expected = pixels as f64 / bins as f64;
                        let chi2: f64 = histogram.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
                        let dof = (bins - 1) as f64;
                        assert!(
                            chi2 < dof + 8.0 * (2.0 * dof).sqrt(),
                            "{sampler}, {count} spp, pair {pair}, sample {index}: χ² = {chi2:.0} over {bins} sub-squares"
                        );
                    }
                }
            }
        }
    }

    /// Padding: the pairs of one sample (of its first two vertices) are not
    /// related to each other or to its position (the same pattern for every pair would tie the light
    /// sample to the BSDF sample). Pearson's correlation over 2048 samples
    /// stays within 5 standard errors (0.11) of 0.
    #[test]
    fn first_vertex_pairs_are_uncorrelated_with_each_other_and_the_position() {
        for sampler in [PixelSampler::Stratified, PixelSampler::LowDiscrepancy, PixelSampler::Sobol] {
            let pairs: Vec<Vec<Vec2>> =
                (0..=6).map(|pair| (0..PIXELS).flat_map(|pixel| points(sampler, 16, pixel, pair)).collect()).collect();
            let correlation = |a: &[f32], b: &[f32]| {
                let n = a.len() as f64;
                let (ma, mb) =
                    (a.iter().map(|&x| x as f64).sum::<f64>() / n, b.iter().map(|&x| x as f64).sum::<f64>() / n);
                let cov: f64 = a.iter().zip(b).map(|(&x, &y)| (x as f64 - ma) * (y as f64 - mb)).sum();
                let va: f64 = a.iter().map(|&x| (x as f64 - ma).powi(2)).sum();
                let vb: f64 = b.iter().map(|&y| (y as f64 - mb).powi(2)).sum();
                cov / (va * vb).sqrt()
            };
            for i in 0..pairs.len() {
                for j in i + 1..pairs.len() {
                    for (axis_i, axis_j) in [(0, 0), (1, 1), (0, 1)] {
                        let a: Vec<f32> = pairs[i].iter().map(|p| p[axis_i]).collect();
                        let b: Vec<f32> = pairs[j].iter().map(|p| p[axis_j]).collect();
                        let r = correlation(&a, &b);
                        assert!(r.abs() < 0.11, "{sampler}: pairs {i} and {j}, axes {axis_i}/{axis_j}: r = {r:.3}");
                    }
                }
            }
        }
    }

    #[test]
    fn sobol_points_fill_every_elementary_interval_for_powers_of_two() {
        // 2^k Owen-scrambled Sobol points put one point in each of the 2^k
        // boxes of every shape 2^a × 2^(k−a): positions and every vertex pair.
        for k in 0..=8u32 {
            let count = 1 << k;
            for pixel in 0..6 {
                let mut sets = vec![offsets(PixelSampler::Sobol, count, pixel)];
                for pair in 1..=3 {
                    sets.push(points(PixelSampler::Sobol, count, pixel, pair));
                }
                for points in sets {
                    for a in 0..=k {
                        let (columns, rows) = (1u32 << a, 1u32 << (k - a));
                        let mut seen = vec![false; count as usize];
                        for p in &points {
                            let (x, y) = ((p.x * columns as f32) as u32, (p.y * rows as f32) as u32);
                            let cell = (y * columns + x) as usize;
                            assert!(!seen[cell], "{count} points, {columns}×{rows} boxes: two in box {cell}");
                            seen[cell] = true;
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn stratified_patterns_differ_between_pixels() {
        // The permutations come from the pixel, so neighbours do not repeat a pattern.
        let strips =
            |pixel| offsets(PixelSampler::Stratified, 64, pixel).iter().map(|p| strip(p.x, 64)).collect::<Vec<_>>();
        let patterns: std::collections::HashSet<Vec<usize>> = (0..16).map(strips).collect();
        assert_eq!(patterns.len(), 16);
    }

    #[test]
    fn permutations_are_permutations() {
        for len in [1, 2, 3, 5, 7, 16, 17, 100, 255, 256, 257, 1000] {
            for seed in [0, 1, 0xdead_beef, u32::MAX] {
                let mut seen = vec![false; len as usize];
                for i in 0..len {
                    let j = permute(i, len, seed) as usize;
                    assert!(!seen[j], "permute(_, {len}, {seed}) repeats {j}");
                    seen[j] = true;
                }
            }
        }
    }

    /// `in_strip` multiplies by the reciprocal of a power-of-two count;
    /// the division it replaces is the definition.
    #[test]
    fn power_of_two_strips_are_the_quotients_bits() {
        let mut rng = Rng::new(7, 0);
        for count in (0..24).map(|k| 1u32 << k) {
            for _ in 0..2000 {
                let strip_index = rng.next_u32() % count;
                let jitter = if rng.next_f32() < 0.1 { 1.0 - f32::EPSILON / 2.0 } else { rng.next_f32() };
                let divided = ((strip_index as f64 + jitter as f64) / count as f64) as f32;
                let x = in_strip(strip_index, jitter, count);
                // Only the rounding correction may move it, and only inside the strip.
                if strip(divided, count) == strip_index as usize {
                    assert_eq!(x.to_bits(), divided.to_bits(), "strip {strip_index} of {count}, jitter {jitter}");
                }
                assert_eq!(strip(x, count), strip_index as usize, "strip {strip_index} of {count}, jitter {jitter}");
            }
        }
    }

    #[test]
    fn strips_hold_their_samples_despite_rounding() {
        for count in [1, 3, 7, 100, 255, 256, 1000, 65_521, 1 << 20] {
            for strip_index in [0, 1, count / 3, count - 1].into_iter().filter(|&s| s < count) {
                for jitter in [0.0, 0.5, 1.0 - f32::EPSILON / 2.0] {
                    let x = in_strip(strip_index, jitter, count);
                    assert_eq!(
                        strip(x, count),
                        strip_index as usize,
                        "strip {strip_index} of {count}, jitter {jitter}"
                    );
                }
            }
        }
    }

    /// R2's projections are Kronecker sequences {i α}; by the three-distance
    /// theorem their gaps take at most three lengths, set by the continued
    /// fractions of α = 1/ρ and 1/ρ². For n ≤ 256 the largest gap of n
    /// points (on the circle, so for any shift) is 4.21/n, at n = 50; so
    /// every interval of width 4.5/n holds a sample. (Jittered strips
    /// guarantee 2/n; n uniform points leave gaps of about ln n / n.)
    #[test]
    fn low_discrepancy_samples_leave_no_wide_gap() {
        for count in 4..=*COUNTS.end() {
            for pixel in 0..PIXELS / 4 {
                let points = offsets(PixelSampler::LowDiscrepancy, count, pixel);
                for axis in 0..2 {
                    let mut values: Vec<f64> = points.iter().map(|p| p.to_array()[axis] as f64).collect();
                    values.sort_by(f64::total_cmp);
                    let gaps = values.windows(2).map(|w| w[1] - w[0]);
                    let widest = gaps.chain([values[0], 1.0 - values[values.len() - 1]]).fold(0.0, f64::max);
                    assert!(widest * (count as f64) < 4.5, "{count} spp, pixel {pixel}, axis {axis}: gap {widest}");
                }
            }
        }
    }

    #[test]
    fn low_discrepancy_matches_the_r2_sequence() {
        // Fixed point against the f64 formula, for small and for large indices.
        let pixel_shift = Vec2::new(0.25, 0.625);
        let alpha = [0.754_877_666_246_692_7_f64, 0.569_840_290_998_053_2];
        for index in [0, 1, 2, 1000, 1 << 24, u32::MAX] {
            let sample = PixelSample { index, count: u32::MAX, pixel_shift };
            let p = PixelSampler::LowDiscrepancy.offset(&sample, &mut Rng::new(0, 0));
            let (got, shift) = (p.to_array(), pixel_shift.to_array());
            for (axis, alpha) in alpha.into_iter().enumerate() {
                let exact = (0.5 + index as f64 * alpha + shift[axis] as f64).fract();
                let difference = (got[axis] as f64 - exact).abs();
                // Distance on the circle; f64's own error grows with the index: about index · 2^-53.
                let tolerance = 2.0f64.powi(-23) + index as f64 * 2.0f64.powi(-50);
                assert!(difference.min(1.0 - difference) < tolerance, "index {index}, axis {axis}");
            }
        }
    }

    #[test]
    fn spread_samplers_integrate_better_than_uniform() {
        // Mean error of n-sample estimates of ∫∫ x·y = 1/4 over 200 pixels,
        // for a square count, a prime and a count of neither kind.
        for count in [64, 61, 96] {
            let error = |sampler: PixelSampler| {
                let mut total = 0.0;
                for pixel in 0..200 {
                    let points = offsets(sampler, count, pixel);
                    let estimate: f32 = points.iter().map(|p| p.x * p.y).sum::<f32>() / count as f32;
                    total += (estimate - 0.25).abs();
                }
                total / 200.0
            };
            let uniform = error(PixelSampler::Uniform);
            for sampler in [PixelSampler::Stratified, PixelSampler::LowDiscrepancy, PixelSampler::Sobol] {
                let e = error(sampler);
                assert!(e < 0.5 * uniform, "{sampler}, {count} spp: {e} against uniform {uniform}");
            }
        }
    }
}
