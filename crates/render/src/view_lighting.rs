//! Whether a scene's own lights light what the camera sees.
//!
//! A scene with lights gets no default sky, but its lights may not reach
//! the view: a car whose only emitters are its headlights and indicators
//! rendered as a black silhouette on grey. Probe rays through the view find
//! the surfaces it shows; light sampling at each, with shadow rays, gives
//! the irradiance the scene's own lights and emitters bring there and the
//! irradiance the default sky and sun would bring. Where the first is a
//! small fraction of the second, the view is unlit.

use rtgi_accel::Accel;
use rtgi_math::{Rng, SurfacePoint, Vec2, Vec3, luminance};
use rtgi_scene::{Camera, Scene};

use crate::lights::LightSet;
use crate::{CameraRays, default_sky, default_sun};

/// Below this fraction of the default sky and sun's irradiance on the
/// surfaces in view, the scene's own lights leave the view dark.
pub const UNLIT_VIEW: f32 = 0.02;

/// The irradiance a dim grey environment brings, as a share of the scene's
/// own lights' on the surfaces in view: enough for metals and glossy
/// surfaces to show a reflection, too little to change how the scene is lit.
pub const REFLECTED_SHARE: f32 = 0.1;

/// Probe rays per side of the view, and light samples per surface point.
const PROBES_PER_SIDE: u32 = 16;
const LIGHT_SAMPLES: u32 = 8;

/// The light on the surfaces a view shows: the mean irradiance (luminance)
/// that the scene's own lights and emitters bring them, and that the
/// default sky and sun would.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewLight {
    /// From the scene's own lights and emitters.
    pub own: f32,
    /// From the default sky and sun; zero where no sky reaches (an enclosed room).
    pub sky: f32,
}

impl ViewLight {
    /// The scene's own light as a fraction of the sky's, where a sky would reach.
    pub fn own_fraction(&self) -> Option<f32> {
        (self.sky > 0.0).then(|| self.own / self.sky)
    }
}

/// The light on the surfaces `camera` sees ([`ViewLight`]); `None` when
/// the view shows no surface.
pub fn view_light(scene: &Scene, accel: &dyn Accel, camera: &Camera, aspect: f32, up: Vec3) -> Option<ViewLight> {
    let own = LightSet::new(scene, &[], true, None);
    let sky_environment = default_sky(up);
    let sky = LightSet::new(scene, &[default_sun(up)], false, Some(&sky_environment));
    let width = ((PROBES_PER_SIDE as f32 * aspect).round() as u32).clamp(1, 4 * PROBES_PER_SIDE);
    let rays = CameraRays::new(camera, width, PROBES_PER_SIDE);
    let mut rng = Rng::new(0x0176_4b17, 0);
    let (mut own_total, mut sky_total, mut samples) = (0.0f64, 0.0f64, 0u32);
    for y in 0..PROBES_PER_SIDE {
        for x in 0..width {
            let ray = rays.ray(x, y, Vec2::splat(0.5));
            let Some(hit) = accel.intersect(&ray) else { continue };
            let corners = scene.triangles[hit.triangle as usize].vertices.map(|v| scene.vertices[v as usize].position);
            let mut point = SurfacePoint::on_triangle(&corners, hit.beta, hit.gamma);
            // The side the camera sees.
            if point.normal.dot(ray.direction) > 0.0 {
                point.normal = -point.normal;
            }
            for _ in 0..LIGHT_SAMPLES {
                let (u_choice, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
                let irradiance = |set: &LightSet, environment| {
                    let Some(sample) = set.sample(scene, environment, &point, u_choice, u) else { return 0.0 };
                    let cosine = sample.wi.dot(point.normal);
                    if cosine <= 0.0 || sample.pdf <= 0.0 || accel.occluded(&sample.shadow_ray) {
                        return 0.0;
                    }
                    f64::from(luminance(sample.radiance) * cosine / sample.pdf)
                };
                own_total += irradiance(&own, None);
                sky_total += irradiance(&sky, Some(&sky_environment));
                samples += 1;
            }
        }
    }
    let mean = |total: f64| (total / f64::from(samples)) as f32;
    (samples > 0 && own_total.is_finite()).then(|| ViewLight { own: mean(own_total), sky: mean(sky_total) })
}
