//! How far one image is from another: the error measures of the
//! time-against-error comparisons.

use serde::Serialize;

use crate::HdrImage;

/// Differences between a test image and a reference of the same size,
/// over all channels of all pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Difference {
    /// Root mean square error.
    pub rmse: f64,
    /// Mean of (test − reference)² / (reference² + 0.01): an error that
    /// weighs dark and bright regions alike (relMSE, as in the denoising literature).
    pub relative_mse: f64,
    /// Largest absolute difference of a channel, and the pixel it is in.
    pub max_abs: f64,
    /// `(x, y)` of the pixel holding that largest difference.
    pub max_at: (u32, u32),
    /// Mean over channels and pixels, of the test image and of the reference.
    pub mean: f64,
    /// Mean of the reference over channels and pixels.
    pub reference_mean: f64,
}

/// Compares `test` with `reference`; `None` if their sizes differ.
pub fn compare(test: &HdrImage, reference: &HdrImage) -> Option<Difference> {
    if (test.width, test.height) != (reference.width, reference.height) {
        return None;
    }
    let n = (test.pixels.len() * 3).max(1) as f64;
    let mut d =
        Difference { rmse: 0.0, relative_mse: 0.0, max_abs: 0.0, max_at: (0, 0), mean: 0.0, reference_mean: 0.0 };
    for (i, (a, b)) in test.pixels.iter().zip(&reference.pixels).enumerate() {
        for (a, b) in a.to_array().into_iter().zip(b.to_array()) {
            let (a, b) = (a as f64, b as f64);
            let error = a - b;
            d.rmse += error * error;
            d.relative_mse += error * error / (b * b + 0.01);
            d.mean += a;
            d.reference_mean += b;
            if error.abs() > d.max_abs || error.is_nan() {
                d.max_abs = error.abs();
                d.max_at = (i as u32 % test.width, i as u32 / test.width);
            }
        }
    }
    d.rmse = (d.rmse / n).sqrt();
    d.relative_mse /= n;
    d.mean /= n;
    d.reference_mean /= n;
    Some(d)
}

/// The lines `rtgi compare` prints.
impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "rmse          {:.6}", self.rmse)?;
        writeln!(f, "relative mse  {:.6}", self.relative_mse)?;
        writeln!(f, "max abs       {:.6} at pixel ({}, {})", self.max_abs, self.max_at.0, self.max_at.1)?;
        writeln!(f, "mean          {:.6} (reference {:.6})", self.mean, self.reference_mean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Vec3;

    #[test]
    fn measures_the_difference() {
        let mut a = HdrImage::new(2, 2);
        let b = HdrImage::new(2, 2);
        a.set(1, 1, Vec3::new(3.0, 0.0, 0.0));
        let d = compare(&a, &b).unwrap();
        assert!((d.rmse - (9.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!((d.max_abs, d.max_at), (3.0, (1, 1)));
        assert!((d.mean - 0.25).abs() < 1e-12 && d.reference_mean == 0.0);
        assert!(compare(&a, &HdrImage::new(1, 2)).is_none());
        assert_eq!(compare(&a, &a).unwrap().rmse, 0.0);
    }
}
