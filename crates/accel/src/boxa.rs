//! A SIMD-friendly axis-aligned box for the builders' and traversal's inner loops.

use rtgi_math::{Aabb, Vec3, Vec3A};

/// An axis-aligned box stored as two 16-byte vectors; the empty box has
/// `min = +∞`, `max = -∞`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BoxA {
    pub(crate) min: Vec3A,
    pub(crate) max: Vec3A,
}

impl Default for BoxA {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl BoxA {
    pub(crate) const EMPTY: BoxA = BoxA { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    #[inline(always)]
    pub(crate) fn from_triangle(t: &[Vec3; 3]) -> Self {
        let [a, b, c] = t.map(Vec3A::from);
        Self { min: a.min(b).min(c), max: a.max(b).max(c) }
    }

    #[inline(always)]
    pub(crate) fn union(self, other: BoxA) -> BoxA {
        BoxA { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    #[inline(always)]
    pub(crate) fn grow(self, p: Vec3A) -> BoxA {
        BoxA { min: self.min.min(p), max: self.max.max(p) }
    }

    /// Half the surface area; 0 for empty boxes.
    #[inline(always)]
    pub(crate) fn half_area(self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        e.dot(Vec3A::new(e.y, e.z, e.x))
    }

    pub(crate) fn to_aabb(self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }
}

impl BoxA {
    /// The box with both corners multiplied by `factor`.
    pub(crate) fn scaled(self, factor: f32) -> BoxA {
        BoxA { min: self.min * factor, max: self.max * factor }
    }
}
