use rtgi_math::{Ray, Vec2, Vec3};
use rtgi_scene::Camera;

/// Generates primary rays for a camera and an image size.
///
/// As in the course: the image plane lies one unit along the viewing
/// direction `w`; it spans `tan(fov / 2)` up and down along `v` and
/// `aspect · tan(fov / 2)` left and right along `u`, where `u = w × up` and
/// `v = u × w`. Pixel `(x, y)` counts from the top left; a position inside it
/// is given as an offset in `[0, 1)²`, `(0.5, 0.5)` being its centre.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    origin: Vec3,
    w: Vec3,
    u: Vec3,
    v: Vec3,
    half_width: f32,
    half_height: f32,
    pixel_size: Vec2,
}

impl CameraRays {
    /// The camera rays of an image of `width` × `height` pixels through `camera`.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let w = camera.direction.normalize();
        let u = w.cross(camera.up).normalize();
        let v = u.cross(w);
        let aspect = camera.aspect.unwrap_or(width as f32 / height as f32);
        let half_height = (0.5 * camera.vertical_fov).tan();
        Self {
            origin: camera.position,
            w,
            u,
            v,
            half_width: aspect * half_height,
            half_height,
            pixel_size: Vec2::new(1.0 / width as f32, 1.0 / height as f32),
        }
    }

    /// The ray through `offset` within pixel `(x, y)`; its direction is unit length.
    #[inline]
    pub fn ray(&self, x: u32, y: u32, offset: Vec2) -> Ray {
        let ndc_x = 2.0 * (x as f32 + offset.x) * self.pixel_size.x - 1.0;
        let ndc_y = 1.0 - 2.0 * (y as f32 + offset.y) * self.pixel_size.y;
        let direction = self.w + ndc_x * self.half_width * self.u + ndc_y * self.half_height * self.v;
        Ray::new(self.origin, direction.normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_and_corners_span_the_field_of_view() {
        let camera = Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 90f32.to_radians());
        let rays = CameraRays::new(&camera, 200, 100);
        // With an even size the image centre is the corner between four pixels.
        let centre = rays.ray(100, 50, Vec2::ZERO);
        assert!((centre.direction - -Vec3::Z).length() < 1e-6);
        // Top-left corner: 45 degrees up, and aspect 2 means tan = 2 to the left.
        let corner = rays.ray(0, 0, Vec2::ZERO);
        let expected = Vec3::new(-2.0, 1.0, -1.0).normalize();
        assert!((corner.direction - expected).length() < 1e-6, "{}", corner.direction);
        let bottom_right = rays.ray(199, 99, Vec2::ONE);
        assert!((bottom_right.direction - Vec3::new(2.0, -1.0, -1.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn camera_aspect_overrides_image_aspect() {
        let mut camera = Camera::look_at(Vec3::ZERO, Vec3::X, Vec3::Y, 90f32.to_radians());
        camera.aspect = Some(1.0);
        let rays = CameraRays::new(&camera, 300, 100);
        let right_edge = rays.ray(299, 50, Vec2::new(1.0, 0.0));
        assert!((right_edge.direction - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
    }
}
