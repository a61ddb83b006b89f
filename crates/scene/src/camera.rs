use rtgi_math::Vec3;

/// A pinhole camera as the course defines it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The pinhole's position, the centre of projection.
    pub position: Vec3,
    /// The central viewing direction (need not be unit length).
    pub direction: Vec3,
    /// The world's up direction; the image's vertical is `up` made orthogonal to `direction`.
    pub up: Vec3,
    /// The vertical field of view, in radians.
    pub vertical_fov: f32,
    /// Width over height, if the camera prescribes one; otherwise the image's.
    pub aspect: Option<f32>,
}

impl Camera {
    /// A camera at `position` looking at `target`.
    pub fn look_at(position: Vec3, target: Vec3, up: Vec3, vertical_fov: f32) -> Self {
        Self { position, direction: target - position, up, vertical_fov, aspect: None }
    }

    /// Whether the camera can produce rays: finite values, a non-zero
    /// direction not parallel to `up`, and a field of view in (0, π).
    pub fn is_valid(&self) -> bool {
        self.position.is_finite()
            && self.direction.is_finite()
            && self.up.is_finite()
            && self.direction.cross(self.up).length_squared() > 0.0
            && self.vertical_fov > 0.0
            && self.vertical_fov < std::f32::consts::PI
    }
}

impl Camera {
    /// A camera that looks at `bounds` along -Z from the +Z side, with +Y
    /// up, far enough back that the box's bounding sphere fills the view.
    /// `aspect` is the image's width over height.
    pub fn framing(bounds: &rtgi_math::Aabb, vertical_fov: f32, aspect: f32) -> Self {
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.centroid(), (0.5 * bounds.extent().length()).max(f32::MIN_POSITIVE))
        };
        // The narrower of the two fields of view decides the distance.
        let half_vertical = 0.5 * vertical_fov;
        let half_horizontal = (half_vertical.tan() * aspect).atan();
        let distance = radius / half_vertical.min(half_horizontal).sin();
        Self {
            position: center + Vec3::new(0.0, 0.0, distance),
            // Aimed at the centre, so that position + direction is the point looked at.
            direction: Vec3::new(0.0, 0.0, -distance),
            up: Vec3::Y,
            vertical_fov,
            aspect: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Aabb;

    #[test]
    fn framing_keeps_the_bounding_sphere_in_view() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.0, -3.0), Vec3::new(3.0, 2.0, 1.0));
        let fov = 40f32.to_radians();
        for aspect in [0.5, 1.0, 2.0] {
            let c = Camera::framing(&bounds, fov, aspect);
            assert!(c.is_valid());
            let to_center = bounds.centroid() - c.position;
            assert!(to_center.normalize().dot(c.direction.normalize()) > 0.9999);
            let radius = 0.5 * bounds.extent().length();
            let half_angle = (radius / to_center.length()).asin();
            let half_horizontal = ((0.5 * fov).tan() * aspect).atan();
            assert!(half_angle <= 0.5 * fov + 1e-5 && half_angle <= half_horizontal + 1e-5);
        }
    }
}
