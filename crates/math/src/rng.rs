/// A PCG32 random number generator (O'Neill, "PCG: A Family of Simple Fast
/// Space-Efficient Statistically Good Algorithms for Random Number
/// Generation", 2014; the XSH-RR output on a 64-bit LCG).
///
/// Renderers create one per (seed, pixel, sample) with [`Rng::for_sample`],
/// so that the numbers a sample sees do not depend on which thread draws it
/// or in which order: images are bit-identical at any thread count.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    increment: u64,
}

const MULTIPLIER: u64 = 6364136223846793005;

impl Rng {
    /// A generator for sequence `stream` starting from `seed`; distinct
    /// streams give independent sequences for equal seeds.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Self { state: 0, increment: (stream << 1) | 1 };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The generator for one sample of one pixel of a render with `seed`.
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Self {
        let key = hash_u64(hash_u64(seed) ^ pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        Self::new(hash_u64(key ^ sample), key)
    }

    #[inline]
    /// The next 32 uniformly distributed bits (PCG32's XSH-RR output).
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULTIPLIER).wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rotation = (old >> 59) as u32;
        xorshifted.rotate_right(rotation)
    }

    /// Uniform in `[0, 1)`, with all 24 bits of an f32 mantissa random.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in `[0, bound)` without modulo bias (Lemire's method).
    pub fn next_below(&mut self, bound: u32) -> u32 {
        if bound == 0 {
            return 0;
        }
        let threshold = bound.wrapping_neg() % bound;
        loop {
            let product = self.next_u32() as u64 * bound as u64;
            if (product as u32) >= threshold {
                return (product >> 32) as u32;
            }
        }
    }
}

/// A 64-bit mixing function (the SplitMix64 finaliser): every input bit
/// affects every output bit, so neighbouring pixels get unrelated seeds.
#[inline]
pub fn hash_u64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_reference_pcg32() {
        // pcg32_srandom(42, 54) from the PCG reference implementation's demo.
        let mut rng = Rng::new(42, 54);
        let expected = [0xa15c02b7u32, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e];
        for e in expected {
            assert_eq!(rng.next_u32(), e);
        }
    }

    #[test]
    fn per_sample_generators_are_deterministic_and_distinct() {
        let a: Vec<u32> = (0..4).map(|_| Rng::for_sample(1, 2, 3).next_u32()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        let b = Rng::for_sample(1, 2, 4).next_u32();
        let c = Rng::for_sample(1, 3, 3).next_u32();
        let d = Rng::for_sample(2, 2, 3).next_u32();
        assert!(a[0] != b && a[0] != c && a[0] != d);
    }

    #[test]
    fn floats_are_in_unit_interval_with_plausible_mean() {
        let mut rng = Rng::new(7, 0);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let x = rng.next_f32();
            assert!((0.0..1.0).contains(&x));
            sum += x as f64;
        }
        let mean = sum / n as f64;
        // Standard error is 1/sqrt(12 n) ≈ 0.0009; 5 sigma.
        assert!((mean - 0.5).abs() < 0.0046, "mean {mean}");
        for bound in [1, 3, 10, 1000] {
            assert!((0..100).all(|_| rng.next_below(bound) < bound));
        }
    }
}
