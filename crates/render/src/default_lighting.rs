//! The light a scene gets when it brings none of its own: a sky with a
//! visible gradient and a sun, so that the first render of a model shows
//! its shape. A uniform white sky, the earlier default, lights every side
//! the same and washes a white model out against its background.

use std::borrow::Cow;
use std::sync::LazyLock;

use rtgi_accel::Accel;
use rtgi_image::HdrImage;
use rtgi_math::glam::Quat;
use rtgi_math::{Ray, Vec3};
use rtgi_scene::{Camera, Light, LightKind, Scene};

use crate::up_axis::turned_up;
use crate::{Environment, EnvironmentMap};

/// Texels of the sky's equirectangular image: it varies with elevation
/// only, and its texels are constant (for exact sampling), so it takes
/// many rows: with 32, the sky behind a model showed bands 6 degrees apart.
const SKY_WIDTH: u32 = 16;
const SKY_HEIGHT: u32 = 512;

/// Radiance straight up, at the horizon, and of the ground below it.
const ZENITH: Vec3 = Vec3::new(0.32, 0.48, 0.85);
const HORIZON: Vec3 = Vec3::new(0.95, 0.95, 0.98);
const GROUND: Vec3 = Vec3::new(0.30, 0.28, 0.26);

/// The sun: from 55 degrees above the horizon, 35 degrees to the right of
/// +Z (where automatic views look from), so that it lights the sides the
/// camera sees and casts shadows down and away; irradiance in the units of
/// the scene's other lights (its colour a warm white).
const SUN_ELEVATION_DEGREES: f32 = 55.0;
const SUN_AZIMUTH_DEGREES: f32 = 35.0;
const SUN_IRRADIANCE: f32 = 2.0;
const SUN_COLOUR: Vec3 = Vec3::new(1.0, 0.95, 0.86);

/// The sun of a flat model seen straight on ([`flat_view_sun`]): this far
/// above the view and to its right, in degrees.
const FLAT_SUN_ELEVATION_DEGREES: f32 = 30.0;
const FLAT_SUN_AZIMUTH_DEGREES: f32 = 25.0;

static SKY: LazyLock<Environment> = LazyLock::new(|| {
    let mut image = HdrImage::new(SKY_WIDTH, SKY_HEIGHT);
    for y in 0..SKY_HEIGHT {
        // The elevation of the row's centre: +90 degrees in the top row.
        let elevation = std::f32::consts::FRAC_PI_2 * (1.0 - 2.0 * (y as f32 + 0.5) / SKY_HEIGHT as f32);
        let radiance = sky_radiance(elevation.sin());
        for x in 0..SKY_WIDTH {
            image.set(x, y, radiance);
        }
    }
    Environment::Map(EnvironmentMap::new(image))
});

/// The sky's radiance at a direction whose up component is `up` (sine of the elevation).
fn sky_radiance(up: f32) -> Vec3 {
    if up >= 0.0 {
        HORIZON.lerp(ZENITH, up.sqrt())
    } else {
        // A short blend below the horizon, then the ground.
        HORIZON.lerp(GROUND, (-up * 8.0).min(1.0))
    }
}

/// The default sky: blue overhead, white at the horizon, grey ground,
/// overhead being `up` (the model's, [`crate::up_axis`]).
pub fn default_sky(up: Vec3) -> Cow<'static, Environment> {
    let turn = turned_up(up);
    match &*SKY {
        Environment::Map(map) if turn != Quat::IDENTITY => Cow::Owned(Environment::Map(map.clone().turned(turn))),
        sky => Cow::Borrowed(sky),
    }
}

/// The default sun, a directional light, its elevation measured from `up`.
pub fn default_sun(up: Vec3) -> Light {
    let (elevation, azimuth) = (SUN_ELEVATION_DEGREES.to_radians(), SUN_AZIMUTH_DEGREES.to_radians());
    let towards_sun =
        turned_up(up) * Vec3::new(azimuth.sin() * elevation.cos(), elevation.sin(), azimuth.cos() * elevation.cos());
    sun_towards(towards_sun)
}

/// The sun for a flat model seen straight on from `from` (a unit vector
/// from the model towards the camera) with the camera's `up`: from the
/// view's upper right, 30 degrees above and 25 to the right of the
/// camera, so that it strikes the face at 0.78 where the default sun,
/// placed for a product shot, struck a cut-out facing +Z at 0.47 (one
/// facing +X at 0.33) and left it as grey as the sky behind it.
pub fn flat_view_sun(from: Vec3, up: Vec3) -> Vec3 {
    let right = up.cross(from).normalize_or_zero();
    let up = from.cross(right);
    let (elevation, azimuth) = (FLAT_SUN_ELEVATION_DEGREES.to_radians(), FLAT_SUN_AZIMUTH_DEGREES.to_radians());
    (from * (elevation.cos() * azimuth.cos()) + right * (elevation.cos() * azimuth.sin()) + up * elevation.sin())
        .normalize_or(from)
}

/// The sun of a render: towards `settings.sun_towards` where the view set
/// it, else [`default_sun`].
pub(crate) fn render_sun(settings: &crate::RenderSettings) -> Light {
    settings.sun_towards.map_or_else(|| default_sun(settings.up), sun_towards)
}

/// The sun's light, shining from `towards_sun`.
fn sun_towards(towards_sun: Vec3) -> Light {
    Light {
        name: "default sun".into(),
        kind: LightKind::Directional,
        position: Vec3::ZERO,
        direction: -towards_sun,
        color: SUN_COLOUR,
        intensity: SUN_IRRADIANCE,
        range: None,
    }
}

/// Directions probed by [`sky_visibility`].
const VISIBILITY_PROBES: u32 = 256;

/// The fraction of directions from `position` in which a ray leaves the
/// scene: about 0.5 on open ground, 0 inside a closed room, where a sky
/// lights nothing. The directions are a Fibonacci spiral over the sphere.
pub fn sky_visibility<A: Accel + ?Sized>(accel: &A, position: Vec3) -> f32 {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let escaped = (0..VISIBILITY_PROBES)
        .filter(|&i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / VISIBILITY_PROBES as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            let direction = Vec3::new(r * phi.cos(), z, r * phi.sin());
            accel.intersect(&Ray::new(position, direction)).is_none()
        })
        .count();
    escaped as f32 / VISIBILITY_PROBES as f32
}

/// Below this [`sky_visibility`] a camera is taken to be enclosed.
pub const ENCLOSED: f32 = 0.02;

/// The room light hangs this fraction of the way from the floor in view to the ceiling.
const ROOM_LIGHT_HEIGHT: f32 = 0.5;

/// A light for a camera enclosed by an unlit scene (a room with no lamps),
/// hung like a ceiling lamp with a shade over the room the camera looks
/// into: a spot light shining down, above the point halfway between the
/// camera and what its central ray hits, halfway up to the ceiling there
/// (with no ceiling, a tenth of the scene's size up). Its intensity gives
/// an irradiance of about π where the central ray hits, so that what the
/// camera looks at is lit directly, not only by bounces. The shade keeps
/// the ceiling over the lamp dark: a bare bulb close to it made a hot spot
/// that every bounce off the ceiling turned into a firefly.
pub fn room_light<A: Accel + ?Sized>(scene: &Scene, accel: &A, camera: &Camera, up: Vec3) -> Light {
    let up_direction = up.try_normalize().unwrap_or(Vec3::Y);
    let size = scene.bounds().extent().length().max(1e-6);
    let view = Ray::new(camera.position, camera.direction);
    let looked_at = accel.intersect(&view).map_or(camera.position + camera.direction, |hit| view.at(hit.t));
    let below = camera.position.lerp(looked_at, 0.5);
    let rise = accel.intersect(&Ray::new(below, up_direction)).map_or(0.1 * size, |hit| ROOM_LIGHT_HEIGHT * hit.t);
    let position = below + up_direction * rise;
    let distance = position.distance(looked_at).max(1e-6);
    Light {
        name: "default room light".into(),
        kind: LightKind::Point,
        position,
        direction: -up_direction,
        color: SUN_COLOUR,
        intensity: std::f32::consts::PI * distance * distance,
        range: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sky_darkens_upwards_and_the_ground_is_darker_still() {
        let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let (zenith, horizon, ground) = (sky_radiance(1.0), sky_radiance(0.0), sky_radiance(-1.0));
        assert!(luminance(zenith) < 0.7 * luminance(horizon));
        assert!(luminance(ground) < luminance(zenith));
        assert!(zenith.z > zenith.x, "the zenith is blue");
        let sky = default_sky(Vec3::Y);
        let Environment::Map(map) = &*sky else { panic!("the sky is a map") };
        let top = map.image().get(0, 0);
        let bottom = map.image().get(0, SKY_HEIGHT - 1);
        assert!(
            luminance(top) < luminance(map.image().get(0, SKY_HEIGHT / 2 - 1)) && luminance(bottom) < luminance(top)
        );
    }

    #[test]
    fn the_sun_shines_down_from_the_front() {
        let sun = default_sun(Vec3::Y);
        assert!(sun.direction.y < -0.7 && sun.direction.z < 0.0);
        assert!((sun.direction.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sky_and_sun_follow_the_models_up() {
        // +Z up: the zenith's blue overhead at +Z, the ground below -Z, the
        // sun high over +Z and in front (-Y, where a Z-up model's front view looks from).
        let sky = default_sky(Vec3::Z);
        let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        assert!((sky.radiance(Vec3::Z) - sky_radiance(1.0)).length() < 0.01, "{}", sky.radiance(Vec3::Z));
        assert!(luminance(sky.radiance(Vec3::NEG_Z)) < luminance(sky.radiance(Vec3::Y)));
        // The Y-up sky's horizon is +Z up's horizon too where they agree.
        assert_eq!(sky.radiance(Vec3::X), default_sky(Vec3::Y).radiance(Vec3::X));
        let sun = default_sun(Vec3::Z);
        assert!(sun.direction.z < -0.7 && sun.direction.y > 0.0, "{}", sun.direction);
        // Its sampling density still matches its draws, turned.
        let mut rng = rtgi_math::Rng::new(1, 2);
        for _ in 0..200 {
            let (direction, radiance, pdf) = sky.sample(rtgi_math::Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!((sky.pdf(direction) - pdf).abs() <= 1e-3 * pdf, "{direction}: {pdf} vs {}", sky.pdf(direction));
            assert_eq!(sky.radiance(direction), radiance);
        }
    }
}
