//! Sampling discrete choices in proportion to weights: lights by power,
//! environment-map rows and columns by brightness.

/// A piecewise-constant distribution over `0..n`, sampled by inverting its
/// cumulative sum.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// `cdf[i]` is the probability of choosing an index below `i`; `cdf[n]` = 1.
    cdf: Vec<f32>,
    total: f64,
}

impl Distribution1D {
    /// A distribution proportional to `weights`; negative and non-finite
    /// weights count as zero. When every weight is zero, it is uniform.
    pub fn new(weights: impl IntoIterator<Item = f32>) -> Self {
        let weights: Vec<f64> =
            weights.into_iter().map(|w| if w.is_finite() && w > 0.0 { w as f64 } else { 0.0 }).collect();
        let total: f64 = weights.iter().sum();
        let n = weights.len();
        let mut cdf = Vec::with_capacity(n + 1);
        let mut running = 0.0f64;
        cdf.push(0.0);
        for w in &weights {
            running += if total > 0.0 { w / total } else { 1.0 / n as f64 };
            cdf.push(running as f32);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self { cdf, total }
    }

    /// Number of entries the distribution chooses between.
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// Whether there is nothing to choose from.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The sum of the weights.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The probability of choosing `index`.
    pub fn probability(&self, index: usize) -> f32 {
        self.cdf[index + 1] - self.cdf[index]
    }

    /// Chooses an index for a uniform `u` in [0, 1); returns it with its
    /// probability and `u` stretched back to [0, 1) within the index's
    /// interval, so that the number can be used again. Never chooses an
    /// index of probability zero. Panics if the distribution is empty.
    pub fn sample(&self, u: f32) -> (usize, f32, f32) {
        // The first index whose interval ends above u.
        let index = self.cdf[1..].partition_point(|&c| c <= u).min(self.len() - 1);
        let probability = self.probability(index);
        let remapped =
            if probability > 0.0 { ((u - self.cdf[index]) / probability).clamp(0.0, 0.999_999_94) } else { 0.5 };
        (index, probability, remapped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_follow_the_weights() {
        let d = Distribution1D::new([1.0, 0.0, 3.0, 4.0]);
        assert_eq!(d.probability(1), 0.0);
        assert_eq!(d.probability(3), 0.5);
        let mut counts = [0usize; 4];
        let n = 80_000;
        for i in 0..n {
            let (index, p, remapped) = d.sample((i as f32 + 0.5) / n as f32);
            assert!(p > 0.0 && (0.0..1.0).contains(&remapped));
            counts[index] += 1;
        }
        assert_eq!(counts, [10_000, 0, 30_000, 40_000]);
        assert_eq!(d.sample(0.999_999_94).0, 3);
        assert_eq!(d.sample(0.0).0, 0);
    }

    #[test]
    fn zero_weights_give_a_uniform_choice() {
        let d = Distribution1D::new([0.0, f32::NAN, -1.0]);
        assert!((d.probability(2) - 1.0 / 3.0).abs() < 1e-6);
        assert_eq!(d.total(), 0.0);
    }
}
