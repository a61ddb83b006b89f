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
use rtgi_math::{Rng, SurfacePoint, Vec2, luminance};
use rtgi_scene::{Camera, Scene};

use crate::lights::LightSet;
use crate::{CameraRays, default_sky, default_sun};

/// Below this fraction of the default sky and sun's irradiance on the
/// surfaces in view, the scene's own lights leave the view dark.
pub const UNLIT_VIEW: f32 = 0.02;

/// Probe rays per side of the view, and light samples per surface point.
const PROBES_PER_SIDE: u32 = 16;
const LIGHT_SAMPLES: u32 = 8;

/// The irradiance that the scene's own lights and emitters bring to the
/// surfaces `camera` sees, as a fraction of what the default sky and sun
/// would bring them (luminance, summed over the probe points). `None` when
/// the view shows no surface or no sky would reach it (an enclosed room,
/// where a sky would not help).
pub fn own_light_fraction<A: Accel + ?Sized>(scene: &Scene, accel: &A, camera: &Camera, aspect: f32) -> Option<f32> {
    let own = LightSet::new(scene, &[], true, None);
    let sky_environment = default_sky();
    let sky = LightSet::new(scene, std::slice::from_ref(&default_sun()), false, Some(sky_environment));
    let width = ((PROBES_PER_SIDE as f32 * aspect).round() as u32).clamp(1, 4 * PROBES_PER_SIDE);
    let rays = CameraRays::new(camera, width, PROBES_PER_SIDE);
    let mut rng = Rng::new(0x0176_4b17, 0);
    let (mut own_total, mut sky_total) = (0.0f64, 0.0f64);
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
                sky_total += irradiance(&sky, Some(sky_environment));
            }
        }
    }
    (sky_total > 0.0 && own_total.is_finite()).then(|| (own_total / sky_total) as f32)
}
