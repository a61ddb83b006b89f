//! The exact intersection of a ray with a triangle whose coordinates are
//! single-precision numbers: the reference that `rtgi experiment precision`
//! measures the triangle tests against.
//!
//! Every finite `f32` is an integer multiple of 2^-149 (the smallest
//! subnormal), so scaled by 2^149 the ray and the corners are integers, and
//! Cramer's rule gives `t`, `beta` and `gamma` as ratios of integers with
//! one common denominator (triple products all, so the scale cancels).
//! Big integers hold them without rounding: the only rounding is the last
//! step, a ratio to `f64` for a person to read, which is within 2^-62 of
//! the exact value relatively.

use num_bigint::BigInt;
use rtgi_math::Vec3;

/// An `f32` times 2^149: an integer for every finite value.
fn scaled(x: f32) -> BigInt {
    assert!(x.is_finite(), "exact arithmetic needs finite inputs, not {x}");
    let bits = x.to_bits();
    let (exponent, fraction) = ((bits >> 23) & 0xff, bits & 0x7f_ffff);
    // Normal numbers are (2^23 + fraction) · 2^(exponent − 150); subnormal
    // ones fraction · 2^-149.
    let magnitude =
        if exponent == 0 { BigInt::from(fraction) } else { BigInt::from(fraction | 0x80_0000) << (exponent - 1) };
    if bits >> 31 == 1 { -magnitude } else { magnitude }
}

type Vector = [BigInt; 3];

fn vector(v: Vec3) -> Vector {
    v.to_array().map(scaled)
}

fn sub(a: &Vector, b: &Vector) -> Vector {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn cross(a: &Vector, b: &Vector) -> Vector {
    [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
}

fn dot(a: &Vector, b: &Vector) -> BigInt {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

/// `2^exponent · x` without overflow or underflow in the scale factor.
fn times_power_of_two(mut x: f64, mut exponent: i64) -> f64 {
    while exponent > 0 {
        let step = exponent.min(1000);
        x *= 2f64.powi(step as i32);
        exponent -= step;
    }
    while exponent < 0 {
        let step = exponent.max(-1000);
        x *= 2f64.powi(step as i32);
        exponent -= step;
    }
    x
}

/// `numerator / denominator` as the nearest `f64` but for a relative error
/// below 2^-62: the quotient is taken to 64 significant bits (truncated),
/// then rounded once to 53.
pub fn ratio_to_f64(numerator: &BigInt, denominator: &BigInt) -> f64 {
    assert!(denominator.bits() > 0, "division by zero");
    if numerator.bits() == 0 {
        return 0.0;
    }
    let negative = (numerator.sign() == num_bigint::Sign::Minus) != (denominator.sign() == num_bigint::Sign::Minus);
    let (n, d) = (numerator.magnitude(), denominator.magnitude());
    // Shift so that the integer quotient has 64 or 65 bits.
    let shift = 64 + d.bits() as i64 - n.bits() as i64;
    let quotient = if shift >= 0 { (n << shift as u64) / d } else { (n >> (-shift) as u64) / d };
    let quotient = u128::try_from(&quotient).expect("the quotient has at most 65 bits");
    let value = times_power_of_two(quotient as f64, -shift);
    if negative { -value } else { value }
}

/// Where a ray meets the plane of a triangle, exactly: `t` (in units of the
/// direction's length) and the barycentrics of the second and third
/// corners, each `numerator / det`.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactHit {
    det: BigInt,
    t: BigInt,
    beta: BigInt,
    gamma: BigInt,
}

impl ExactHit {
    /// The ray `origin + t · direction` against the triangle's plane, by
    /// Cramer's rule on `origin + t d = v0 + beta (v1 − v0) + gamma (v2 −
    /// v0)`; `None` when the ray is parallel to the plane or the triangle
    /// has no area.
    pub fn new(origin: Vec3, direction: Vec3, triangle: &[Vec3; 3]) -> Option<ExactHit> {
        let [v0, v1, v2] = triangle.map(vector);
        let (o, d) = (vector(origin), vector(direction));
        let (edge1, edge2, s) = (sub(&v1, &v0), sub(&v2, &v0), sub(&o, &v0));
        let p = cross(&d, &edge2);
        let det = dot(&edge1, &p);
        if det.bits() == 0 {
            return None;
        }
        let q = cross(&s, &edge1);
        Some(ExactHit { t: dot(&edge2, &q), beta: dot(&s, &p), gamma: dot(&d, &q), det })
    }

    /// Whether the ray meets the triangle's interior (all three
    /// barycentrics above zero) ahead of its origin.
    pub fn inside(&self) -> bool {
        let alpha = &self.det - &self.beta - &self.gamma;
        let positive = |n: &BigInt| n.bits() > 0 && n.sign() == self.det.sign();
        positive(&alpha) && positive(&self.beta) && positive(&self.gamma) && positive(&self.t)
    }

    /// The exact hit distance, rounded once to `f64`.
    pub fn t(&self) -> f64 {
        ratio_to_f64(&self.t, &self.det)
    }

    /// The exact barycentric coordinate of the second corner, rounded once to `f64`.
    pub fn beta(&self) -> f64 {
        ratio_to_f64(&self.beta, &self.det)
    }

    /// The exact barycentric coordinate of the third corner, rounded once to `f64`.
    pub fn gamma(&self) -> f64 {
        ratio_to_f64(&self.gamma, &self.det)
    }

    /// `|value − numerator / det|`, computed exactly and rounded once.
    fn distance(&self, value: f32, numerator: &BigInt) -> BigInt {
        let difference = scaled(value) * &self.det - (numerator << 149u32);
        BigInt::from_biguint(num_bigint::Sign::Plus, difference.magnitude().clone())
    }

    /// `|t − t_exact| / |t_exact|`.
    pub fn t_relative_error(&self, t: f32) -> f64 {
        if self.t.bits() == 0 {
            return if t == 0.0 { 0.0 } else { f64::INFINITY };
        }
        let denominator = BigInt::from_biguint(num_bigint::Sign::Plus, (&self.t << 149u32).magnitude().clone());
        ratio_to_f64(&self.distance(t, &self.t), &denominator)
    }

    /// `|beta − beta_exact|`.
    pub fn beta_error(&self, beta: f32) -> f64 {
        self.absolute_error(beta, &self.beta)
    }

    /// `|gamma − gamma_exact|`.
    pub fn gamma_error(&self, gamma: f32) -> f64 {
        self.absolute_error(gamma, &self.gamma)
    }

    fn absolute_error(&self, value: f32, numerator: &BigInt) -> f64 {
        let denominator = BigInt::from_biguint(num_bigint::Sign::Plus, (&self.det << 149u32).magnitude().clone());
        ratio_to_f64(&self.distance(value, numerator), &denominator)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_scale_to_exact_integers() {
        assert_eq!(scaled(1.0), BigInt::from(1) << 149u32);
        assert_eq!(scaled(-0.75), -(BigInt::from(3) << 147u32));
        assert_eq!(scaled(f32::from_bits(1)), BigInt::from(1));
        assert_eq!(scaled(0.0), BigInt::from(0));
        assert_eq!(scaled(f32::MAX), BigInt::from(0xff_ffffu32) << (104 + 149));
    }

    #[test]
    fn ratios_round_to_the_nearest_double() {
        let r = |n: i64, d: i64| ratio_to_f64(&BigInt::from(n), &BigInt::from(d));
        assert_eq!(r(1, 3), 1.0 / 3.0);
        assert_eq!(r(-2, 7), -2.0 / 7.0);
        assert_eq!(r(10, -4), -2.5);
        assert_eq!(r(0, 5), 0.0);
        // Far beyond f64's exponent range before the division, not after.
        let huge = BigInt::from(1) << 3000u32;
        assert_eq!(ratio_to_f64(&(&huge * 3), &(&huge * 4)), 0.75);
    }

    #[test]
    fn a_hand_computed_hit() {
        // The ray from (0.25, 0.5, -2) along +z meets the triangle (0,0,0),
        // (1,0,0), (0,1,0) at t = 2 with beta = 0.25 and gamma = 0.5.
        let triangle = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let hit = ExactHit::new(Vec3::new(0.25, 0.5, -2.0), Vec3::Z, &triangle).unwrap();
        assert_eq!((hit.t(), hit.beta(), hit.gamma()), (2.0, 0.25, 0.5));
        assert!(hit.inside());
        assert_eq!(hit.t_relative_error(2.0), 0.0);
        assert_eq!(hit.t_relative_error(2.5), 0.25);
        assert_eq!(hit.beta_error(0.5), 0.25);
        assert_eq!(hit.gamma_error(0.25), 0.25);
        // A direction of length 3 along -z from above: t = 1/3 of the distance 1.
        let hit = ExactHit::new(Vec3::new(0.1, 0.1, 1.0), Vec3::new(0.0, 0.0, -3.0), &triangle).unwrap();
        assert_eq!(hit.t(), 1.0 / 3.0);
        // f32(1/3) = 11184811 / 2^25, off from 1/3 by 1 / (3 · 2^25), relatively 2^-25.
        assert_eq!(hit.t_relative_error(1.0 / 3.0), 2f64.powi(-25));
    }

    #[test]
    fn outside_behind_and_parallel() {
        let triangle = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(!ExactHit::new(Vec3::new(0.8, 0.8, -1.0), Vec3::Z, &triangle).unwrap().inside());
        assert!(!ExactHit::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, &triangle).unwrap().inside());
        // On an edge is not inside.
        assert!(!ExactHit::new(Vec3::new(0.5, 0.0, -1.0), Vec3::Z, &triangle).unwrap().inside());
        assert!(ExactHit::new(Vec3::new(0.2, 0.2, 1.0), Vec3::X, &triangle).is_none());
        assert!(ExactHit::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, &[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]).is_none());
    }
}
