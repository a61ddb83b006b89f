use glam::Vec3;

/// An orthonormal frame: three unit vectors `x`, `y`, `z` at right angles.
///
/// Shading code works in the local frame of a surface, where the normal is
/// `z`, so that cosines are plain `z` components.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent, unit length.
    pub x: Vec3,
    /// Second tangent, unit length, completing the right-handed frame `(x, y, z)`.
    pub y: Vec3,
    /// The frame's axis (a surface's normal), unit length.
    pub z: Vec3,
}

impl Frame {
    /// A frame whose `z` is the given unit vector, with `x` and `y` chosen
    /// continuously and without a branch on a near-parallel axis (Duff et al.,
    /// "Building an Orthonormal Basis, Revisited", JCGT 2017).
    #[inline]
    pub fn from_z(z: Vec3) -> Self {
        let sign = 1.0f32.copysign(z.z);
        let a = -1.0 / (sign + z.z);
        let b = z.x * z.y * a;
        let x = Vec3::new(1.0 + sign * z.x * z.x * a, sign * b, -sign * z.x);
        let y = Vec3::new(b, sign + z.y * z.y * a, -z.y);
        Self { x, y, z }
    }

    /// A frame whose `z` is the given unit vector and whose `x` is `x_hint`
    /// made perpendicular to it (an anisotropic surface's direction of
    /// stretch); [`Frame::from_z`] where the hint is parallel to `z` or zero.
    #[inline]
    pub fn from_z_and_x(z: Vec3, x_hint: Vec3) -> Self {
        let x = (x_hint - z * z.dot(x_hint)).normalize_or_zero();
        if x == Vec3::ZERO {
            return Self::from_z(z);
        }
        Self { x, y: z.cross(x), z }
    }

    #[inline]
    /// `v` in this frame's coordinates (its components along `x`, `y`, `z`).
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    #[inline]
    /// The world vector whose coordinates in this frame are `v`.
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.x + v.y * self.y + v.z * self.z
    }
}

/// A direction uniformly distributed on the unit sphere from two uniform numbers.
pub fn uniform_sphere(u: f32, v: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * v;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_frame_from_a_hint_points_x_along_it_and_falls_back_where_it_is_parallel() {
        let z = Vec3::new(0.0, 0.6, 0.8);
        let frame = Frame::from_z_and_x(z, Vec3::new(1.0, 1.0, 0.0));
        assert!(frame.x.dot(z).abs() < 1e-6 && (frame.x.length() - 1.0).abs() < 1e-6);
        assert!(frame.x.x > 0.7, "x follows the hint: {}", frame.x);
        assert!((frame.x.cross(frame.y) - z).length() < 1e-6, "right-handed");
        assert_eq!(Frame::from_z_and_x(z, z * 2.0), Frame::from_z(z));
        assert_eq!(Frame::from_z_and_x(z, Vec3::ZERO), Frame::from_z(z));
    }

    proptest! {
        #[test]
        fn frame_is_orthonormal(x in -1.0f32..1.0, y in -1.0f32..1.0, z in -1.0f32..1.0) {
            let v = Vec3::new(x, y, z);
            prop_assume!(v.length() > 1e-3);
            let f = Frame::from_z(v.normalize());
            prop_assert!((f.x.length() - 1.0).abs() < 1e-5);
            prop_assert!((f.y.length() - 1.0).abs() < 1e-5);
            prop_assert!(f.x.dot(f.y).abs() < 1e-5);
            prop_assert!(f.x.dot(f.z).abs() < 1e-5);
            prop_assert!(f.y.dot(f.z).abs() < 1e-5);
            // Right-handed, so that local-to-world keeps orientation.
            prop_assert!((f.x.cross(f.y) - f.z).length() < 1e-5);
            let w = Vec3::new(0.3, -0.2, 0.9);
            prop_assert!((f.to_world(f.to_local(w)) - w).length() < 1e-5);
        }
    }

    #[test]
    fn frame_of_negative_z() {
        let f = Frame::from_z(-Vec3::Z);
        assert!((f.x.cross(f.y) - f.z).length() < 1e-6);
    }
}
