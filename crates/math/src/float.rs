//! Helpers for reasoning about floating-point rounding error.

/// Half the distance between 1 and the next f32: the unit roundoff.
const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// The bound γ(n) = nε / (1 − nε) on the relative error of `n` successive
/// f32 operations (pbrt-v4, section 6.8.1; Higham, "Accuracy and Stability of
/// Numerical Algorithms", section 3.1).
#[inline]
pub const fn gamma(n: i32) -> f32 {
    let n_eps = n as f32 * MACHINE_EPSILON;
    n_eps / (1.0 - n_eps)
}

/// The smallest f32 greater than `x` (infinity and NaN are returned unchanged).
#[inline]
pub fn next_float_up(x: f32) -> f32 {
    if x.is_infinite() && x > 0.0 || x.is_nan() {
        return x;
    }
    // -0 and +0 both step to the smallest positive subnormal.
    let x = if x == -0.0 { 0.0 } else { x };
    let bits = x.to_bits();
    let bits = if x >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// The largest f32 less than `x` (infinity and NaN are returned unchanged).
#[inline]
pub fn next_float_down(x: f32) -> f32 {
    if x.is_infinite() && x < 0.0 || x.is_nan() {
        return x;
    }
    let x = if x == 0.0 { -0.0 } else { x };
    let bits = x.to_bits();
    let bits = if x > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_steps_one_ulp() {
        assert_eq!(next_float_up(1.0), 1.0 + f32::EPSILON);
        assert_eq!(next_float_down(1.0), 1.0 - f32::EPSILON / 2.0);
        assert_eq!(next_float_up(0.0), f32::from_bits(1));
        assert_eq!(next_float_up(-0.0), f32::from_bits(1));
        assert_eq!(next_float_down(0.0), -f32::from_bits(1));
        assert_eq!(next_float_up(-1.0), -1.0 + f32::EPSILON / 2.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
        assert_eq!(next_float_down(f32::MAX), f32::from_bits(f32::MAX.to_bits() - 1));
    }

    #[test]
    fn gamma_grows_with_n() {
        assert!(gamma(1) > 0.0);
        assert!(gamma(3) > 3.0 * MACHINE_EPSILON);
        assert!(gamma(3) < 3.01 * MACHINE_EPSILON);
    }
}
