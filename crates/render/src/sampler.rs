use rtgi_math::{Rng, Vec2};

/// Where inside a pixel the samples go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelSampler {
    /// Every sample at the pixel's centre: no antialiasing, no noise.
    Center,
    /// Uniformly random positions in the pixel.
    Uniform,
}

impl PixelSampler {
    pub const ALL: &'static [PixelSampler] = &[PixelSampler::Center, PixelSampler::Uniform];

    pub fn name(self) -> &'static str {
        match self {
            PixelSampler::Center => "center",
            PixelSampler::Uniform => "uniform",
        }
    }

    /// The position in `[0, 1)²` of one sample of a pixel, drawing from that sample's generator.
    #[inline]
    pub fn offset(self, rng: &mut Rng) -> Vec2 {
        match self {
            PixelSampler::Center => Vec2::splat(0.5),
            PixelSampler::Uniform => Vec2::new(rng.next_f32(), rng.next_f32()),
        }
    }
}

rtgi_math::named_choices!(PixelSampler, "sampler");
