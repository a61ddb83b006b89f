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

/// `1 + 2⁻²¹ = 1 + 8ε` (exact in f32): the factor by which a ray's
/// inverse direction is enlarged, once per ray, to give slab *exit*
/// distances that rounding never moves before the true exit (Ize, "Robust
/// BVH Ray Traversal", JCGT 2013; Embree folds `1 ± 3 ulp` into its
/// `rdir_near` and `rdir_far` the same way). See [`exit_inverses`].
pub const EXIT_FOLD: f32 = 1.0 + 1.0 / (1u32 << 21) as f32;

/// The two inverses of one direction component that a slab test's exit
/// distances are computed with ([`later_exit`]): `inv · (1 + 2⁻²¹)` for
/// exits ahead of the origin and, for a ray whose range starts behind it
/// (`t_min < 0` or NaN), `inv / (1 + 2⁻²¹)` for exits behind it. A ray
/// whose range starts at or after its origin gets the first twice.
///
/// Why the factor suffices. A plane's distance is `fl(fl(p − o) · i)`, with
/// `i = fl(1 / d)`: an entry carries three roundings, each a factor in
/// `[1 − ε, 1 + ε]` (ε = 2⁻²⁴). An exit carries four: those three and the
/// rounding of `fl(i · k)`. For a box the exact ray touches, exact entry
/// `≤` exact exit; the computed ones keep that order when
/// `k (1 − ε)⁴ ≥ (1 + ε)³` for exits ahead of the origin and
/// `(1 + ε)⁴ / k ≤ (1 − ε)³` for exits behind it, both about
/// `k ≥ 1 + 7ε`. `k = 1 + 8ε` covers them. (Roundings into the subnormal
/// range are outside this argument, as in pbrt's and Embree's.)
///
/// Why `t_min ≥ 0` needs one product. Rounding keeps signs, so an exit
/// computed negative is exactly negative, and such a box lies wholly
/// behind the range `[t_min, …]` and is missed whatever its exit's
/// magnitude. Only a range that starts behind the origin needs the second
/// inverse, whose product keeps negative exits late.
///
/// For one component (`f32`) or several at once (`Vec3`, `Vec3A`), with
/// the same operations lane by lane.
#[inline(always)]
pub fn exit_inverses<T>(inv: T, t_min: f32) -> (T, T)
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Div<f32, Output = T>,
{
    let ahead = inv * EXIT_FOLD;
    let behind = if starts_behind(t_min) { inv / EXIT_FOLD } else { ahead };
    (ahead, behind)
}

/// Whether a range starting at `t_min` starts behind the ray's origin
/// (`t_min < 0`, or NaN): only then do the two [`exit_inverses`] differ.
#[inline(always)]
pub fn starts_behind(t_min: f32) -> bool {
    t_min < 0.0 || t_min.is_nan()
}

/// A slab test's exit distance from the far plane's offset `to_far = p − o`
/// and the ray's [`exit_inverses`] `(ahead, behind)`: `max(to_far · ahead,
/// to_far · behind)`, for one number (`f32::max`) or several lanes
/// (`Vec4::max`). Where `ahead == behind` (every ray whose range starts at
/// or after its origin) that is one product, bit for bit, and a kernel
/// that knows it may compute only that. Both products are monotone in the
/// plane, and so is their maximum, which exact culling needs (a box that
/// contains another is never left earlier). A NaN (`0 · ∞`, an origin on
/// the plane along a zero component) stays NaN, which the slab tests
/// ignore.
#[inline(always)]
pub fn later_exit<T: Copy + std::ops::Mul<T, Output = T>>(
    to_far: T,
    ahead: T,
    behind: T,
    max: impl Fn(T, T) -> T,
) -> T {
    max(to_far * ahead, to_far * behind)
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
    fn the_exit_fold_covers_four_roundings_against_three() {
        let eps = f64::from(MACHINE_EPSILON);
        let k = f64::from(EXIT_FOLD);
        assert_eq!(EXIT_FOLD.to_bits(), 1.0f32.to_bits() + 4, "1 + 2^-21 is exact: 4 ulp above 1");
        assert!(k * (1.0 - eps).powi(4) >= (1.0 + eps).powi(3));
        assert!((1.0 + eps).powi(4) / k <= (1.0 - eps).powi(3));
    }

    #[test]
    fn a_range_from_the_origin_needs_one_exit_inverse() {
        for inv in [2.0f32, -0.37, f32::INFINITY, f32::NEG_INFINITY, 3.0e38] {
            let (ahead, behind) = exit_inverses(inv, 0.0);
            assert_eq!(ahead.to_bits(), behind.to_bits());
            assert_eq!(exit_inverses(inv, -0.0), (ahead, behind));
            let (ahead, behind) = exit_inverses(inv, -1.0);
            assert!(ahead.abs() >= inv.abs() && behind.abs() <= inv.abs(), "{inv}: {ahead} {behind}");
        }
        let (ahead, behind) = exit_inverses(1.0, f32::NAN);
        assert!(behind < ahead, "a NaN range start takes both inverses");
        // Positive exits take the enlarged product, negative ones the reduced one.
        let (ahead, behind) = exit_inverses(1.0, -1.0);
        assert_eq!(later_exit(2.0, ahead, behind, f32::max), 2.0 * EXIT_FOLD);
        assert!(later_exit(-2.0, ahead, behind, f32::max) > -2.0);
    }

    #[test]
    fn gamma_grows_with_n() {
        assert!(gamma(1) > 0.0);
        assert!(gamma(3) > 3.0 * MACHINE_EPSILON);
        assert!(gamma(3) < 3.01 * MACHINE_EPSILON);
    }
}
