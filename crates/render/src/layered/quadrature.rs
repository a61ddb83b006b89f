//! Gauss–Legendre quadrature, for the tables' integrals: exact for
//! polynomials of degree 2n − 1 with n nodes, so smooth integrands need
//! far fewer evaluations than with the midpoint rule.

/// The nodes and weights of the `n`-point Gauss–Legendre rule on [0, 1]
/// (weights summing to 1): the roots of the Legendre polynomial P_n by
/// Newton's method from Tricomi's estimates cos(π (i + 3/4) / (n + 1/2)),
/// weights 2 / ((1 − x²) P_n′(x)²), both mapped from [−1, 1].
pub(super) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..50 {
                // P_n(x) and P_n−1(x) by the three-term recurrence.
                let (mut previous, mut p) = (1.0f64, x);
                for k in 2..=n {
                    (previous, p) = (p, ((2 * k - 1) as f64 * x * p - (k - 1) as f64 * previous) / k as f64);
                }
                derivative = n as f64 * (x * p - previous) / (x * x - 1.0);
                let dx = p / derivative;
                x -= dx;
                if dx.abs() < 1e-14 {
                    break;
                }
            }
            ((1.0 - x) / 2.0, 1.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        for n in [12, 24] {
            let rule = gauss_legendre(n);
            assert!((rule.iter().map(|&(_, w)| w).sum::<f64>() - 1.0).abs() < 1e-12);
            // Exact up to degree 2n − 1: ∫ x^k over [0, 1] = 1 / (k + 1).
            for k in [1, 5, 2 * n as i32 - 1] {
                let integral: f64 = rule.iter().map(|&(x, w)| w * x.powi(k)).sum();
                assert!((integral - 1.0 / (k + 1) as f64).abs() < 1e-12, "{n} nodes, x^{k}: {integral}");
            }
        }
    }
}
