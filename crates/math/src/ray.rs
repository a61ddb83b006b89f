use glam::Vec3;

use crate::float::exit_inverses;

/// A ray `origin + t * direction` for `t` in `[t_min, t_max]`.
///
/// The direction need not be normalised; `t` is measured in multiples of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (`t = 0`).
    pub origin: Vec3,
    /// The direction, not necessarily unit length.
    pub direction: Vec3,
    /// Nearest distance counted as a hit, in multiples of `direction`.
    pub t_min: f32,
    /// Farthest distance counted as a hit (`f32::INFINITY` for an unbounded ray).
    pub t_max: f32,
}

impl Ray {
    /// A ray over `[0, ∞)`.
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Self { origin, direction, t_min: 0.0, t_max: f32::INFINITY }
    }

    /// A ray over `[t_min, t_max]`.
    #[inline]
    pub fn with_range(origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> Self {
        Self { origin, direction, t_min, t_max }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }

    /// True when the ray can hit anything at all: finite origin and direction,
    /// a non-zero direction and a non-empty parameter range. Queries answer
    /// "no hit" for other rays instead of producing NaN-driven nonsense.
    #[inline]
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.direction.is_finite()
            && self.direction != Vec3::ZERO
            && self.t_min <= self.t_max
            && !self.t_min.is_nan()
    }

    /// The ray with its reciprocal direction precomputed, for box tests.
    #[inline]
    pub fn with_inverse(&self) -> RayWithInverse {
        RayWithInverse::new(self)
    }
}

/// A ray with `1 / direction` precomputed, as the slab test wants it.
///
/// A direction component of +0 gives +∞ and -0 gives -∞, which is exactly
/// what the slab test relies on; nothing is clamped (clamping tiny components
/// to a "safe" value makes near-axis rays miss boxes they pass through).
#[derive(Clone, Copy, Debug)]
pub struct RayWithInverse {
    /// Where the ray starts, as in [`Ray::origin`].
    pub origin: Vec3,
    /// The direction, as in [`Ray::direction`].
    pub direction: Vec3,
    /// `1 / direction` per component, `±∞` for `±0`.
    pub inv_direction: Vec3,
    /// The inverse for exit distances ahead of the origin, and for those
    /// behind it, per component ([`crate::exit_inverses`]).
    pub inv_exit: (Vec3, Vec3),
    /// Nearest distance counted as a hit.
    pub t_min: f32,
    /// Farthest distance counted as a hit.
    pub t_max: f32,
}

impl RayWithInverse {
    #[inline]
    /// Precomputes the inverse direction of `ray`.
    pub fn new(ray: &Ray) -> Self {
        let inv_direction = Vec3::ONE / ray.direction;

        Self {
            origin: ray.origin,
            direction: ray.direction,
            inv_direction,
            inv_exit: exit_inverses(inv_direction, ray.t_min),
            t_min: ray.t_min,
            t_max: ray.t_max,
        }
    }

    /// Which of the two box faces a ray enters first, per axis: 1 where the
    /// direction is negative, taken from the sign bit so that -0 counts as
    /// negative, consistently with its reciprocal -∞.
    #[inline]
    pub fn octant(&self) -> [usize; 3] {
        [
            self.inv_direction.x.is_sign_negative() as usize,
            self.inv_direction.y.is_sign_negative() as usize,
            self.inv_direction.z.is_sign_negative() as usize,
        ]
    }
}
