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

/// `1 + 2γ(3)`: slab exit distances are moved later by this factor so that
/// rounding never drops a box the ray touches (Ize, "Robust BVH Ray
/// Traversal", JCGT 2013; pbrt-v4 `Bounds3::IntersectP`). Positive exits
/// are multiplied by it and negative ones divided by it ([`later_exit`]).
pub const ROBUST_FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// `1 / (1 + 2γ(3))`, the factor of negative exits ([`later_exit`]).
pub const ROBUST_FAR_SHRINK: f32 = 1.0 / ROBUST_FAR_SCALE;

/// A slab test's exit distance moved later by the robust factor whatever
/// its sign: `max(t·(1 + 2γ), t / (1 + 2γ))`, for one number (`f32::max`)
/// or several lanes (`Vec4::max`). For `t ≥ 0` that is `t·(1 + 2γ)`, bit
/// for bit; for `t < 0` multiplying would move it earlier, and a ray whose
/// range starts behind its origin (a negative `t_min`) would miss boxes it
/// touches there: a flat box (an axis-aligned triangle's) is entered and
/// left at one distance. Both products are monotone in `t`, and so is
/// their maximum, which exact culling needs. A NaN stays NaN, which the
/// slab tests ignore.
#[inline(always)]
pub fn later_exit<T: Copy + std::ops::Mul<f32, Output = T>>(t: T, max: impl Fn(T, T) -> T) -> T {
    max(t * ROBUST_FAR_SCALE, t * ROBUST_FAR_SHRINK)
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
