//! The arithmetic of the ray/triangle tests, written once for one lane
//! (`f32`) and for four (`Vec4`): the scalar tests and the four-triangle
//! block tests evaluate the same expressions in the same order, so every
//! lane of a block test computes the bits the scalar test computes for
//! that triangle. (Rust never fuses `a * b + c` into one rounding, and
//! `Vec4`'s operators round each lane as `f32`'s do.)

use std::ops::{Add, Div, Mul, Sub};

use rtgi_math::Vec4;

/// Numbers with IEEE single-precision arithmetic in every lane.
pub(crate) trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    fn splat(value: f32) -> Self;
    fn abs(self) -> Self;
    /// The larger of two numbers, neither of them NaN.
    fn max(self, other: Self) -> Self;
}

impl Lanes for f32 {
    #[inline(always)]
    fn splat(value: f32) -> Self {
        value
    }

    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self > other { self } else { other }
    }
}

impl Lanes for Vec4 {
    #[inline(always)]
    fn splat(value: f32) -> Self {
        Vec4::splat(value)
    }

    #[inline(always)]
    fn abs(self) -> Self {
        Vec4::abs(self)
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Vec4::max(self, other)
    }
}

/// `a × b`, each component a difference of two products.
#[inline(always)]
pub(crate) fn cross<L: Lanes>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `a · b`, summed left to right.
#[inline(always)]
pub(crate) fn dot<L: Lanes>(a: [L; 3], b: [L; 3]) -> L {
    (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]
}

#[inline(always)]
pub(crate) fn sub<L: Lanes>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The values of the Möller-Trumbore test: `(det, beta, gamma, t)`, where
/// `beta`, `gamma` and `t` are already divided by `det`.
#[inline(always)]
pub(crate) fn moller_trumbore<L: Lanes>(origin: [L; 3], direction: [L; 3], v: [[L; 3]; 3]) -> [L; 4] {
    let edge1 = sub(v[1], v[0]);
    let edge2 = sub(v[2], v[0]);
    let p = cross(direction, edge2);
    let det = dot(edge1, p);
    let inv_det = L::splat(1.0) / det;
    let s = sub(origin, v[0]);
    let beta = dot(s, p) * inv_det;
    let q = cross(s, edge1);
    let gamma = dot(direction, q) * inv_det;
    let t = dot(edge2, q) * inv_det;
    [det, beta, gamma, t]
}

/// The first step of the watertight test (Woop, Benthin and Wald 2013):
/// the corners relative to the origin, permuted so that the direction's
/// largest axis is z, sheared so that the ray runs along +z. Returns the
/// sheared x, y and z of the three corners.
///
/// `relative[c][k]` is corner `c` minus the origin along the permuted axis `k`.
#[inline(always)]
pub(crate) fn watertight_shear<L: Lanes>(relative: [[L; 3]; 3], shear: [f32; 3]) -> [[L; 3]; 3] {
    let (sx, sy, sz) = (L::splat(shear[0]), L::splat(shear[1]), L::splat(shear[2]));
    [relative.map(|c| c[0] - sx * c[2]), relative.map(|c| c[1] - sy * c[2]), relative.map(|c| c[2] * sz)]
}

/// Section 3 of Woop et al.: `kz` is the dimension where the direction
/// is largest in magnitude; `kx`, `ky` follow cyclically and swap when
/// `d[kz] < 0`, so that the winding of triangles is preserved. Returns
/// `[kx, ky, kz]`. The scalar test and the packet test choose their axes
/// here, so a packet shares the permutation its rays would each choose.
#[inline(always)]
pub(crate) fn watertight_axes(direction: [f32; 3]) -> [usize; 3] {
    let d = direction;
    let a = direction.map(f32::abs);
    let kz = if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    };
    let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 { [ky, kx, kz] } else { [kx, ky, kz] }
}

/// The scaled barycentrics `(U, V, W)`: the 2D edge functions of the
/// sheared corners. A shared edge gives exactly negated values in the two
/// triangles (products commute and `x - y = -(y - x)` exactly).
#[inline(always)]
pub(crate) fn watertight_edges<L: Lanes>(xs: [L; 3], ys: [L; 3]) -> [L; 3] {
    [xs[2] * ys[1] - ys[2] * xs[1], xs[0] * ys[2] - ys[0] * xs[2], xs[1] * ys[0] - ys[1] * xs[0]]
}

/// A bound on the difference between the single-precision edge functions
/// of [`watertight_edges`] and the exact ones (of the exact ray and
/// corners): an edge function larger than this in magnitude has the exact
/// sign, and a smaller one is decided exactly ([`crate::exact`]).
///
/// A sheared coordinate `x' = (v − o)ₓ − sₓ (v − o)_z` is off by at most
/// about `5ε (X + |sₓ| Z)` (rounding in the two differences, the shear
/// factor, its product and the subtraction), with `X`, `Y` the largest
/// sheared magnitudes and `Z` the largest unsheared height; an edge
/// function, a difference of two products, then by about
/// `24ε X Y + 10ε Z (X |s_y| + Y |sₓ|)`. The bound is `32ε` times
/// `X Y + Z (X |s_y| + Y |sₓ|)` (ε = 2⁻²⁴), plus a few units of the
/// smallest subnormal for products that underflow. `relative_z` are the
/// corners' unsheared heights.
#[inline(always)]
pub(crate) fn watertight_edge_bound<L: Lanes>(xs: [L; 3], ys: [L; 3], relative_z: [L; 3], shear: [f32; 3]) -> L {
    let largest = |v: [L; 3]| v[0].abs().max(v[1].abs()).max(v[2].abs());
    let (x, y, z) = (largest(xs), largest(ys), largest(relative_z));
    let spread = z * (x * L::splat(shear[1].abs()) + y * L::splat(shear[0].abs()));
    L::splat(32.0 * f32::EPSILON / 2.0) * (x * y + spread) + L::splat(f32::from_bits(1 << 4))
}

/// A bound on the error of the scaled distance `t · det` of
/// [`watertight_det_and_scaled_t`] for a triangle the ray hits (edge
/// functions of one sign, so `Σ|e| = |det|`): each term `e z` carries the
/// edge function's error (at most `bound`) and a few roundings of its own,
/// less than `(8ε |det| + 3 bound) max|z|`. A scaled distance within it may
/// have the wrong sign or no digit right: the corners lie on both sides of
/// the origin and the terms cancel (a long triangle beside the ray's
/// origin), and the distance is taken from the triangle's plane instead.
#[inline(always)]
pub(crate) fn watertight_t_bound<L: Lanes>(det: L, zs: [L; 3], bound: L) -> L {
    let z = zs[0].abs().max(zs[1].abs()).max(zs[2].abs());
    (L::splat(8.0 * f32::EPSILON / 2.0) * det.abs() + L::splat(3.0) * bound) * z
}

/// The watertight test's determinant and its distance scaled by the
/// determinant, from the scaled barycentrics and the sheared corner heights.
#[inline(always)]
pub(crate) fn watertight_det_and_scaled_t<L: Lanes>(uvw: [L; 3], zs: [L; 3]) -> (L, L) {
    ((uvw[0] + uvw[1]) + uvw[2], dot(uvw, zs))
}
