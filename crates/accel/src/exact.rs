//! Exact signs for the watertight triangle test, for the rare edges whose
//! single-precision value is too close to zero to trust.
//!
//! The watertight test's edge function for the edge from `p` to `q` has
//! the sign of `((p − o) × (q − o)) · d` (the sheared 2D cross product is
//! that triple product over `d[kz]`, and the axis swap for `d[kz] < 0`
//! cancels the division's sign). With single-precision inputs this value
//! is a sum of products of three numbers that double precision holds only
//! approximately. Double precision with an error bound decides most edges;
//! the rest are split into products that are exact as two doubles each,
//! whose exact sum is found by error-free summation sweeps and, for sums at
//! zero, a floating-point *expansion* (Shewchuk, "Adaptive Precision
//! Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997):
//! a list of doubles whose exact sum is the value, whose largest term has
//! the value's sign.
//!
//! Every `f32` difference is exact as two doubles, and every product of
//! three `f32`-sized factors stays far inside the range of doubles
//! (`2^-447` to `2^387`), so no step underflows or overflows: the sign is
//! exact for every finite input.

use rtgi_math::Vec3A;

/// `a + b` as `(sum, error)`, exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let sum = a + b;
    let b_virtual = sum - a;
    let a_virtual = sum - b_virtual;
    (sum, (a - a_virtual) + (b - b_virtual))
}

/// `a` as two halves of 26 bits each whose sum is `a` (Veltkamp's split).
#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let high = c - (c - a);
    (high, a - high)
}

/// `a · b` as `(product, error)`, exactly (Dekker's product: no fused
/// multiply-add, which x86-64-v2 lacks and software emulates slowly).
#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let product = a * b;
    let ((a_high, a_low), (b_high, b_low)) = (split(a), split(b));
    let error = ((a_high * b_high - product) + a_low * b_high + a_high * b_low) + a_low * b_low;
    (product, error)
}

/// Most terms an edge's value takes ([`product_terms`]): two per product.
const MOST_TERMS: usize = 36;

/// A floating-point expansion held in place (the exact path allocates nothing).
struct Expansion {
    /// Non-overlapping, increasing magnitude, no zeros.
    terms: [f64; MOST_TERMS],
    len: usize,
}

impl Expansion {
    fn new() -> Expansion {
        Expansion { terms: [0.0; MOST_TERMS], len: 0 }
    }

    /// Adds `b`, keeping the terms' properties (Shewchuk's Grow-Expansion
    /// with zero elimination).
    fn grow(&mut self, b: f64) {
        let mut carry = b;
        let mut kept = 0;
        for i in 0..self.len {
            let (sum, error) = two_sum(carry, self.terms[i]);
            if error != 0.0 {
                self.terms[kept] = error;
                kept += 1;
            }
            carry = sum;
        }
        if carry != 0.0 {
            self.terms[kept] = carry;
            kept += 1;
        }
        self.len = kept;
    }

    /// The expansion of the sum of `terms` (at most [`MOST_TERMS`]).
    fn of(terms: &[f64]) -> Expansion {
        let mut sum = Expansion::new();
        for &term in terms {
            sum.grow(term);
        }
        sum
    }

    /// The sign of the exact sum: its largest term's (the others sum to
    /// less than half its unit in the last place).
    fn sign(&self) -> i32 {
        match self.terms[..self.len].last() {
            Some(&top) if top > 0.0 => 1,
            Some(&top) if top < 0.0 => -1,
            _ => 0,
        }
    }
}

/// The exact sign (−1, 0 or 1) of `((p − o) × (q − o)) · d`.
///
/// Double precision with a bound on its rounding error decides almost
/// every edge the single-precision test could not; the expansion is for
/// rays within that bound of the edge's plane.
pub(crate) fn edge_sign(p: Vec3A, q: Vec3A, origin: Vec3A, direction: Vec3A) -> i32 {
    let (o, d) = (origin.as_dvec3(), direction.as_dvec3());
    let (a, b) = (p.as_dvec3() - o, q.as_dvec3() - o);
    let products = [
        d.x * (a.y * b.z),
        -d.x * (a.z * b.y),
        d.y * (a.z * b.x),
        -d.y * (a.x * b.z),
        d.z * (a.x * b.y),
        -d.z * (a.y * b.x),
    ];
    let value = d.x * (a.y * b.z - a.z * b.y) + d.y * (a.z * b.x - a.x * b.z) + d.z * (a.x * b.y - a.y * b.x);
    let magnitude: f64 = products.iter().map(|t| t.abs()).sum();
    // Each difference, product, subtraction and sum above rounds once, for
    // at most 7 units of 2^-53 of the magnitude (plus second-order terms);
    // 8 · 2^-52 leaves a factor of two to spare. No step under- or
    // overflows for f32 inputs, so the bound holds for every finite input.
    let bound = 8.0 * f64::EPSILON * magnitude;
    if value > bound {
        return 1;
    }
    if value < -bound {
        return -1;
    }
    if magnitude == 0.0 {
        // Every product is exactly zero (none underflows), so is the value.
        return 0;
    }
    swept_sign(p, q, origin, direction)
}

/// The exact product terms of `((p − o) × (q − o)) · d`: at most
/// [`MOST_TERMS`] doubles whose exact sum is the value.
///
/// The value is rewritten as `d · (p × q) + (p − q) · (d × o)` (the `o × o`
/// part of the product is zero), in which every product of two `f32`s is
/// exact in one double: six terms `d_i (p_j q_k)` and the exact difference
/// `p − q` times the six exact products `d_j o_k`, each product of two
/// doubles as two. Unlike the differences from `o`, which for an origin far
/// from the edge keep the origin's huge parts to cancel later, this form
/// has nothing to cancel when the ray runs through the world's origin.
fn product_terms(p: Vec3A, q: Vec3A, origin: Vec3A, direction: Vec3A) -> ([f64; MOST_TERMS], usize) {
    let (p, q) = (p.to_array().map(f64::from), q.to_array().map(f64::from));
    let (o, d) = (origin.to_array().map(f64::from), direction.to_array().map(f64::from));
    let (mut terms, mut len) = ([0.0; MOST_TERMS], 0);
    let mut push = |(high, low): (f64, f64)| {
        for term in [high, low] {
            if term != 0.0 {
                terms[len] = term;
                len += 1;
            }
        }
    };
    for (i, j, k) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
        // d_i (p_j q_k − p_k q_j), the inner products exact.
        push(two_product(d[i], p[j] * q[k]));
        push(two_product(-d[i], p[k] * q[j]));
        // (p_i − q_i)(d_j o_k − d_k o_j), the difference as (high, low).
        let (high, low) = two_sum(p[i], -q[i]);
        for part in [high, low] {
            if part != 0.0 {
                push(two_product(part, d[j] * o[k]));
                push(two_product(-part, d[k] * o[j]));
            }
        }
    }
    (terms, len)
}

/// [`edge_sign`] past the double-precision filter: a few error-free
/// summation sweeps (Ogita, Rump and Oishi's VecSum, "Accurate Sum and Dot
/// Product", 2005), each of which keeps the exact sum and moves it into the
/// last term, until that term outweighs all the others together; the
/// expansion when that does not happen within a few sweeps (sums at or
/// extremely near zero). A sweep costs as much as adding one term to the
/// expansion, which is what makes the difference for rays from extremely
/// far away, whose differences all carry a low half.
fn swept_sign(p: Vec3A, q: Vec3A, origin: Vec3A, direction: Vec3A) -> i32 {
    let (mut terms, len) = product_terms(p, q, origin, direction);
    let terms = &mut terms[..len];
    if terms.is_empty() {
        return 0;
    }
    for _ in 0..4 {
        for i in 1..terms.len() {
            let (sum, error) = two_sum(terms[i], terms[i - 1]);
            (terms[i], terms[i - 1]) = (sum, error);
        }
        let (top, rest) = terms.split_last().expect("not empty");
        let rest: f64 = rest.iter().map(|t| t.abs()).sum();
        // The computed sum of n magnitudes is within a factor (1 ± ε)^n of
        // the exact one; 1 + 4nε covers it with room to spare.
        if top.abs() > rest * (1.0 + 4.0 * terms.len() as f64 * f64::EPSILON) {
            return if *top > 0.0 { 1 } else { -1 };
        }
        if *top == 0.0 && rest == 0.0 {
            return 0;
        }
    }
    Expansion::of(terms).sign()
}

/// [`edge_sign`] by the exact sum alone (Shewchuk's expansion).
#[cfg(test)]
fn expansion_sign(p: Vec3A, q: Vec3A, origin: Vec3A, direction: Vec3A) -> i32 {
    let (terms, len) = product_terms(p, q, origin, direction);
    Expansion::of(&terms[..len]).sign()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32, z: f32) -> Vec3A {
        Vec3A::new(x, y, z)
    }

    #[test]
    fn signs_of_plain_triple_products() {
        let o = v(0.0, 0.0, 0.0);
        assert_eq!(edge_sign(v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), o, v(0.0, 0.0, 1.0)), 1);
        assert_eq!(edge_sign(v(0.0, 1.0, 0.0), v(1.0, 0.0, 0.0), o, v(0.0, 0.0, 1.0)), -1);
        assert_eq!(edge_sign(v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0), o, v(0.0, 0.0, 1.0)), 0);
        // The ray through the edge's line exactly.
        assert_eq!(edge_sign(v(1.0, 1.0, 1.0), v(1.0, 1.0, 3.0), v(1.0, 1.0, 0.0), v(0.0, 0.0, 1.0)), 0);
    }

    /// The sign in 128-bit integers, for integer-valued inputs.
    fn integer_sign(p: [i64; 3], q: [i64; 3], o: [i64; 3], d: [i64; 3]) -> i32 {
        let a: [i128; 3] = std::array::from_fn(|i| (p[i] - o[i]) as i128);
        let b: [i128; 3] = std::array::from_fn(|i| (q[i] - o[i]) as i128);
        let c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        let value = c[0] * d[0] as i128 + c[1] * d[1] as i128 + c[2] * d[2] as i128;
        value.signum() as i32
    }

    #[test]
    fn near_and_exactly_coplanar_edges_far_out_match_integer_arithmetic() {
        // Integer coordinates up to 2^24 and directions up to 2^18: triple
        // products near 2^68, past what doubles hold. Edges whose plane
        // contains the ray exactly (p = o + k d), then nudged by one unit.
        let mut rng = rtgi_math::Rng::new(7, 0);
        let mut coordinate = |limit: i64| (rng.next_f32() as f64 * (2 * limit) as f64) as i64 - limit;
        let (mut zeros, mut doubles_wrong) = (0, 0);
        for _ in 0..20_000 {
            let o = [coordinate(1 << 23), coordinate(1 << 23), coordinate(1 << 23)];
            let d = [coordinate(1 << 18), coordinate(1 << 18), coordinate(1 << 18)];
            let k = coordinate(32);
            let mut p: [i64; 3] = std::array::from_fn(|i| o[i] + k * d[i]);
            let q = [coordinate(1 << 23), coordinate(1 << 23), coordinate(1 << 23)];
            let nudge = coordinate(2);
            p[(k & 1) as usize] += nudge;
            if p.iter().chain(&q).any(|c| c.abs() >= 1 << 24) || d == [0; 3] {
                continue;
            }
            let f = |c: [i64; 3]| Vec3A::new(c[0] as f32, c[1] as f32, c[2] as f32);
            let exact = integer_sign(p, q, o, d);
            assert_eq!(edge_sign(f(p), f(q), f(o), f(d)), exact, "p {p:?} q {q:?} o {o:?} d {d:?}");
            assert_eq!(edge_sign(f(q), f(p), f(o), f(d)), -exact);
            // The sweeps and the expansion alone agree too, wherever the filter decided.
            assert_eq!(swept_sign(f(p), f(q), f(o), f(d)), exact, "p {p:?} q {q:?} o {o:?} d {d:?}");
            assert_eq!(expansion_sign(f(p), f(q), f(o), f(d)), exact, "p {p:?} q {q:?} o {o:?} d {d:?}");
            zeros += (exact == 0) as u32;
            // How often plain doubles would have got the sign wrong here.
            let g = |c: [i64; 3], o: [i64; 3]| [0, 1, 2].map(|i| (c[i] - o[i]) as f64);
            let (a, b) = (g(p, o), g(q, o));
            let naive = d[0] as f64 * (a[1] * b[2] - a[2] * b[1])
                + d[1] as f64 * (a[2] * b[0] - a[0] * b[2])
                + d[2] as f64 * (a[0] * b[1] - a[1] * b[0]);
            doubles_wrong += (naive.signum() as i32 != exact && !(naive == 0.0 && exact == 0)) as u32;
        }
        assert!(zeros > 1000, "too few exactly coplanar cases: {zeros}");
        assert!(doubles_wrong > 100, "the cases are not hard: doubles got {doubles_wrong} wrong");
    }

    /// The sign by the differences from the origin, summed as one
    /// expansion: the way [`product_terms`] does not take, as a check on it.
    fn sign_from_differences(p: Vec3A, q: Vec3A, o: Vec3A, d: Vec3A) -> i32 {
        let difference = |v: Vec3A| -> [[f64; 2]; 3] {
            let (v, o) = (v.to_array(), o.to_array());
            std::array::from_fn(|axis| {
                let (high, low) = two_sum(f64::from(v[axis]), -f64::from(o[axis]));
                [high, low]
            })
        };
        let (a, b, d) = (difference(p), difference(q), d.to_array().map(f64::from));
        let mut terms = Vec::new();
        for (i, j, k) in [(0, 1, 2), (1, 2, 0), (2, 0, 1)] {
            for (x, y, sign) in [(a[j], b[k], 1.0), (a[k], b[j], -1.0)] {
                for (xs, ys) in x.into_iter().flat_map(|xs| y.map(|ys| (xs, ys))) {
                    let (product, error) = two_product(xs, ys);
                    for part in [product, error] {
                        let (high, low) = two_product(part, sign * d[i]);
                        terms.extend([high, low]);
                    }
                }
            }
        }
        // Grown in pieces: one expansion holds at most MOST_TERMS terms.
        let mut sum = Expansion::new();
        for term in terms {
            sum.grow(term);
            assert!(sum.len < MOST_TERMS, "the check's expansion outgrew its array");
        }
        sum.sign()
    }

    #[test]
    fn rays_from_far_away_through_small_edges_keep_their_sign() {
        // Origins up to 2^100 away aimed at edges near the world's origin,
        // exactly through it (d = −o) and nudged off it: the differences
        // from the origin lose the edge entirely in double precision.
        let mut rng = rtgi_math::Rng::new(11, 0);
        let mut next = || rng.next_f32() * 2.0 - 1.0;
        let (mut nonzero, mut zeros) = (0, 0);
        for case in 0..20_000 {
            let far = 2f32.powi(case % 101);
            let o = v(next(), next(), next()) * far;
            let p = v(next(), next(), next()) * 8.0;
            let q = if case % 3 == 0 { p * 2.0 } else { v(next(), next(), next()) * 8.0 };
            let d = match case % 4 {
                0 => -o,
                1 => p - o,
                _ => -o + v(next(), next(), next()) * 8.0,
            };
            let expected = sign_from_differences(p, q, o, d);
            assert_eq!(edge_sign(p, q, o, d), expected, "p {p:?} q {q:?} o {o:?} d {d:?}");
            assert_eq!(swept_sign(p, q, o, d), expected, "p {p:?} q {q:?} o {o:?} d {d:?}");
            assert_eq!(expansion_sign(p, q, o, d), expected, "p {p:?} q {q:?} o {o:?} d {d:?}");
            nonzero += (expected != 0) as u32;
            zeros += (expected == 0) as u32;
        }
        assert!(nonzero > 10_000 && zeros > 100, "{nonzero} non-zero, {zeros} zero");
    }

    #[test]
    fn extreme_magnitudes_keep_their_sign() {
        let tiny = f32::from_bits(1); // the smallest subnormal
        let huge = f32::MAX;
        let o = v(0.0, 0.0, 0.0);
        let d = v(0.0, 0.0, 1.0);
        assert_eq!(edge_sign(v(tiny, 0.0, 0.0), v(0.0, tiny, 0.0), o, d), 1);
        assert_eq!(edge_sign(v(huge, 0.0, 0.0), v(0.0, huge, 0.0), o, d), 1);
        assert_eq!(edge_sign(v(huge, tiny, 0.0), v(-huge, 0.0, 0.0), o, d), 1);
        assert_eq!(edge_sign(v(huge, tiny, 0.0), v(-huge, -tiny, 0.0), o, d), 0);
    }
}
