use rtgi_math::{Rng, Vec2};

/// Where inside a pixel the samples go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelSampler {
    /// Every sample at the pixel's centre: no antialiasing, no noise.
    Center,
    /// Uniformly random positions in the pixel.
    Uniform,
    /// Jittered: the pixel is cut into ⌈√n⌉ × ⌈√n⌉ cells, sample `i` falls
    /// at a random position in cell `i`.
    Stratified,
    /// The R2 low-discrepancy sequence (Roberts 2018), shifted by a random
    /// offset per pixel (Cranley-Patterson rotation) so that neighbouring
    /// pixels do not repeat the same pattern.
    LowDiscrepancy,
}

/// Which sample of how many, in a pixel with its own random shift: what
/// the samplers that spread samples over a pixel need to know.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSample {
    pub index: u32,
    pub count: u32,
    /// Uniform in `[0, 1)²`, the same for every sample of the pixel.
    pub pixel_shift: Vec2,
}

/// The plastic number's reciprocals: the R2 sequence's increments.
const R2: Vec2 = Vec2::new(0.754_877_7, 0.569_840_3);

impl PixelSampler {
    pub const ALL: &'static [PixelSampler] =
        &[PixelSampler::Center, PixelSampler::Uniform, PixelSampler::Stratified, PixelSampler::LowDiscrepancy];

    pub fn name(self) -> &'static str {
        match self {
            PixelSampler::Center => "center",
            PixelSampler::Uniform => "uniform",
            PixelSampler::Stratified => "stratified",
            PixelSampler::LowDiscrepancy => "low-discrepancy",
        }
    }

    /// The position in `[0, 1)²` of one sample of a pixel, drawing from that
    /// sample's generator where the sampler is random.
    #[inline]
    pub fn offset(self, sample: &PixelSample, rng: &mut Rng) -> Vec2 {
        match self {
            PixelSampler::Center => Vec2::splat(0.5),
            PixelSampler::Uniform => Vec2::new(rng.next_f32(), rng.next_f32()),
            PixelSampler::Stratified => {
                let side = (sample.count as f32).sqrt().ceil().max(1.0) as u32;
                let cell = sample.index % (side * side);
                let corner = Vec2::new((cell % side) as f32, (cell / side) as f32);
                ((corner + Vec2::new(rng.next_f32(), rng.next_f32())) / side as f32).min(Vec2::splat(ONE_BELOW_ONE))
            }
            PixelSampler::LowDiscrepancy => {
                // Indices wrap at 2^24 so that the products stay exact in f32.
                let i = (sample.index & 0xFF_FFFF) as f32;
                let point = Vec2::splat(0.5) + R2 * i + sample.pixel_shift;
                (point - point.floor()).min(Vec2::splat(ONE_BELOW_ONE))
            }
        }
    }
}

/// The largest f32 below 1, so that offsets stay inside their pixel.
const ONE_BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

rtgi_math::named_choices!(PixelSampler, "sampler");

#[cfg(test)]
mod tests {
    use super::*;

    fn offsets(sampler: PixelSampler, count: u32, pixel: u64) -> Vec<Vec2> {
        let mut shift_rng = Rng::for_sample(1, pixel, u64::MAX);
        let pixel_shift = Vec2::new(shift_rng.next_f32(), shift_rng.next_f32());
        (0..count)
            .map(|index| {
                let mut rng = Rng::for_sample(1, pixel, index as u64);
                sampler.offset(&PixelSample { index, count, pixel_shift }, &mut rng)
            })
            .collect()
    }

    #[test]
    fn stratified_samples_fill_every_cell_once() {
        let points = offsets(PixelSampler::Stratified, 16, 3);
        let mut cells = [0u32; 16];
        for p in points {
            assert!(p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all());
            cells[(p.y * 4.0) as usize * 4 + (p.x * 4.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1), "{cells:?}");
    }

    #[test]
    fn spread_samplers_integrate_better_than_uniform() {
        // Mean error of 64-sample estimates of ∫∫ x·y = 1/4 over 200 pixels.
        let error = |sampler: PixelSampler| {
            let mut total = 0.0;
            for pixel in 0..200 {
                let points = offsets(sampler, 64, pixel);
                assert!(points.iter().all(|p| p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all()));
                let estimate: f32 = points.iter().map(|p| p.x * p.y).sum::<f32>() / 64.0;
                total += (estimate - 0.25).abs();
            }
            total / 200.0
        };
        let uniform = error(PixelSampler::Uniform);
        for sampler in [PixelSampler::Stratified, PixelSampler::LowDiscrepancy] {
            let e = error(sampler);
            assert!(e < 0.5 * uniform, "{sampler}: {e} against uniform {uniform}");
        }
    }
}
