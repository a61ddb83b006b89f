//! Light transport converges to what physics says: furnaces (closed
//! emitting spheres and BSDFs under a uniform sky), a point light's
//! analytic irradiance, and the effects planner's promise that leaving an
//! effect out changes nothing where the scene does not need it.

use std::f32::consts::PI;

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_image::HdrImage;
use rtgi_math::{Vec2, Vec3};
use rtgi_render::{
    BounceSampling, CameraRays, DirectStrategy, Effect, EffectOverrides, EffectPlan, EffectSet, Environment,
    Integrator, PixelSampler, ROULETTE_START, RenderSettings, render,
};
use rtgi_scene::{Camera, Light, LightKind, Material, MeshBuilder, Scene, SurfaceModel};

use rtgi_experiment::analytic::sphere_scene;

fn render_scene(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> HdrImage {
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    render(scene, accel.as_ref(), camera, settings, &|_| {}).0
}

fn mean_and_extremes(image: &HdrImage) -> (f32, f32, f32) {
    let values: Vec<f32> = image.pixels().iter().map(|p| p.x).collect();
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    let min = values.iter().copied().fold(f32::INFINITY, f32::min);
    let max = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    (mean, min, max)
}

#[test]
fn white_furnace_converges_to_emission_over_one_minus_albedo() {
    // Inside a closed sphere whose walls reflect ρ and emit Le, radiance is
    // Le (1 + ρ + ρ² + ...) = Le / (1 - ρ) everywhere, whatever the
    // direct-light strategy.
    let (albedo, emitted) = (0.6, 0.4);
    let expected = emitted / (1.0 - albedo);
    let wall = Material {
        name: "furnace".into(),
        base_color: Vec3::splat(albedo),
        emission: Vec3::splat(emitted),
        ..Material::default()
    };
    let scene = sphere_scene(wall, true);
    let camera = Camera::look_at(Vec3::new(0.1, -0.2, 0.05), Vec3::new(1.0, 0.3, -2.0), Vec3::Y, 1.2);
    // Every direct-light strategy with every way of drawing bounces (the
    // hemisphere ones weigh MIS by their own density), and the roulette
    // started late: all unbiased, so all converge to the same radiance.
    let mut cases: Vec<(DirectStrategy, BounceSampling, u32)> = Vec::new();
    for &strategy in DirectStrategy::ALL {
        for &sampling in BounceSampling::ALL {
            cases.push((strategy, sampling, ROULETTE_START));
        }
    }
    cases.push((DirectStrategy::Bsdf, BounceSampling::Bsdf, 6));
    for (strategy, bounce_sampling, roulette_start) in cases {
        let settings = RenderSettings {
            width: 24,
            height: 24,
            samples_per_pixel: 64,
            sampler: PixelSampler::Stratified,
            max_depth: 1000,
            direct_strategy: strategy,
            bounce_sampling,
            roulette_start,
            ..RenderSettings::default()
        };
        let case = format!("{strategy}, bounces from {bounce_sampling}, roulette from bounce {roulette_start}");
        let (mean, min, max) = mean_and_extremes(&render_scene(&scene, &camera, &settings));
        println!("furnace, {case}: mean {mean}, pixels {min}..{max}, expected {expected}");
        assert!((mean - expected).abs() < 0.01 * expected, "{case}: mean {mean}, expected {expected}");
        // Single pixels are noisy (64 samples); the check is for gross failures (black, NaN, doubled).
        assert!(min > 0.6 * expected && max < 1.4 * expected, "{case}: pixels {min}..{max}");
    }
}

#[test]
fn every_bsdf_passes_a_furnace_under_a_white_sky() {
    // A convex object under a uniform sky of radiance 1 looks like the sky
    // when its BSDF loses no energy: lossless models give 1 everywhere,
    // rough GGX less by its single-scattering loss (a few per cent at this
    // roughness), never more.
    let white = Vec3::ONE;
    let gltf = |metallic: f32, roughness: f32, transmission: f32| Material {
        model: SurfaceModel::MetallicRoughness,
        base_color: white,
        metallic,
        roughness,
        transmission,
        ..Material::default()
    };
    // (name, material, lowest and highest mean): lossless models give 1;
    // rough GGX loses its single-scattering share (about 6% for a white
    // metal at roughness 0.5); glTF's dielectric model, a Lambert base under
    // a Fresnel-weighted GGX lobe, balances energy only approximately.
    let lossless = (0.99, 1.005);
    let cases: Vec<(&str, Material, (f32, f32))> = vec![
        ("lambert", Material { base_color: white, ..Material::default() }, lossless),
        (
            "mirror",
            Material { base_color: Vec3::ZERO, specular: white, roughness: 0.0, ..Material::default() },
            lossless,
        ),
        (
            "solid glass",
            Material { base_color: Vec3::ZERO, transmission: 1.0, ior: 1.5, ..Material::default() },
            lossless,
        ),
        ("thin glass", gltf(0.0, 0.0, 1.0), lossless),
        // Through a sphere of rough sheets light meets two rough surfaces, each losing its share.
        ("rough thin glass", gltf(0.0, 0.5, 1.0), (0.85, 1.005)),
        ("smooth metal", gltf(1.0, 0.0, 0.0), lossless),
        ("rough metal", gltf(1.0, 0.5, 0.0), (0.9, 1.005)),
        ("rough dielectric", gltf(0.0, 0.5, 0.0), (0.95, 1.02)),
        // MTL's Kd + Ks often exceed 1; summed as given, this one would
        // look 15% brighter than the sky that lights it.
        (
            "mtl colours beyond one",
            Material {
                base_color: Vec3::splat(0.8),
                specular: Vec3::splat(0.55),
                roughness: 0.5,
                ..Material::default()
            },
            (0.95, 1.005),
        ),
        // glTF's layers (KHR_materials_*): each may lose what its albedo
        // scaling keeps from the layer below (a white sheen of roughness
        // 0.5 returns 0.87 at normal incidence), none may gain.
        ("sheen over white", Material { sheen: Some(sheen()), ..gltf(0.0, 0.5, 0.0) }, (0.8, 1.005)),
        ("clearcoat over rough metal", Material { clearcoat: Some(coat()), ..gltf(1.0, 0.5, 0.0) }, (0.8, 1.005)),
        ("iridescent dielectric", Material { iridescence: Some(film()), ior: 1.8, ..gltf(0.0, 0.3, 0.0) }, (0.9, 1.01)),
        (
            "every layer",
            Material {
                sheen: Some(sheen()),
                clearcoat: Some(coat()),
                iridescence: Some(film()),
                dielectric_specular: rtgi_scene::DielectricSpecular { factor: 0.7, ..Default::default() },
                ..gltf(0.5, 0.4, 0.0)
            },
            (0.75, 1.005),
        ),
    ];
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, Vec3::Y, 0.6);
    for (name, material, (lowest, highest)) in cases {
        let scene = sphere_scene(material, false);
        let settings = RenderSettings {
            width: 24,
            height: 24,
            samples_per_pixel: 32,
            sampler: PixelSampler::Stratified,
            max_depth: 64,
            environment: Some(Environment::Uniform(Vec3::ONE)),
            ..RenderSettings::default()
        };
        let (mean, min, max) = mean_and_extremes(&render_scene(&scene, &camera, &settings));
        println!("{name}: mean {mean}, pixels {min}..{max}");
        assert!(mean >= lowest && mean <= highest, "{name}: mean {mean}, expected {lowest}..{highest}");
        // Single pixels of 32 samples are noisy; this catches gross failures.
        assert!(min > lowest - 0.35 && max < highest + 0.35, "{name}: pixels {min}..{max}");
    }
}

fn sheen() -> rtgi_scene::Sheen {
    rtgi_scene::Sheen { color: Vec3::ONE, color_texture: None, roughness: 0.5, roughness_texture: None }
}

fn coat() -> rtgi_scene::Clearcoat {
    rtgi_scene::Clearcoat {
        factor: 1.0,
        factor_texture: None,
        roughness: 0.2,
        roughness_texture: None,
        normal_texture: None,
    }
}

fn film() -> rtgi_scene::Iridescence {
    rtgi_scene::Iridescence {
        factor: 1.0,
        factor_texture: None,
        ior: 1.3,
        thickness_min: 100.0,
        thickness_max: 400.0,
        thickness_texture: None,
    }
}

#[test]
fn hemisphere_bounces_converge_to_what_bsdf_sampling_gives() {
    // Drawing bounces from the cosine or uniform hemisphere instead of the
    // BSDF changes the noise, never the mean: under a white sky, diffuse
    // and glossy spheres come out as bright whichever is used, at every
    // sample count (the tolerance shrinks with the noise).
    let glossy = |model, roughness| Material {
        model,
        base_color: Vec3::splat(0.7),
        specular: Vec3::splat(0.25),
        metallic: if model == SurfaceModel::MetallicRoughness { 1.0 } else { 0.0 },
        roughness,
        ..Material::default()
    };
    let cases = [
        ("lambert", Material { base_color: Vec3::splat(0.7), ..Material::default() }),
        ("diffuse and glossy (MTL)", glossy(SurfaceModel::DiffuseSpecular, 0.6)),
        ("rough metal", glossy(SurfaceModel::MetallicRoughness, 0.7)),
    ];
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO, Vec3::Y, 0.6);
    for (name, material) in cases {
        let scene = sphere_scene(material, false);
        for (spp, tolerance) in [(16, 0.03), (128, 0.012)] {
            let mean = |bounce_sampling| {
                let settings = RenderSettings {
                    width: 24,
                    height: 24,
                    samples_per_pixel: spp,
                    sampler: PixelSampler::Stratified,
                    max_depth: 16,
                    bounce_sampling,
                    environment: Some(Environment::Uniform(Vec3::ONE)),
                    ..RenderSettings::default()
                };
                mean_and_extremes(&render_scene(&scene, &camera, &settings)).0
            };
            let reference = mean(BounceSampling::Bsdf);
            for sampling in [BounceSampling::Cosine, BounceSampling::Uniform] {
                let m = mean(sampling);
                println!("{name}, {spp} spp: {sampling} {m}, bsdf {reference}");
                assert!(
                    (m - reference).abs() < tolerance * reference,
                    "{name}, {spp} spp: {sampling} {m}, bsdf {reference}"
                );
            }
        }
    }
}

#[test]
fn diffuse_plane_under_a_point_light_matches_the_analytic_irradiance() {
    // L = ρ/π · I cos θ / d² at every pixel; with a point light and pixel
    // centres nothing is random, so the match is to rounding.
    let albedo = 0.6;
    let light_position = Vec3::new(0.3, -0.2, 2.0);
    let intensity = 5.0;
    let mut scene = Scene {
        materials: vec![Material { base_color: Vec3::splat(albedo), ..Material::default() }],
        lights: vec![Light {
            name: "bulb".into(),
            kind: LightKind::Point,
            position: light_position,
            direction: Vec3::NEG_Z,
            color: Vec3::ONE,
            intensity,
            range: None,
        }],
        ..Scene::default()
    };
    let corners = vec![
        Vec3::new(-10.0, -10.0, 0.0),
        Vec3::new(10.0, -10.0, 0.0),
        Vec3::new(10.0, 10.0, 0.0),
        Vec3::new(-10.0, 10.0, 0.0),
    ];
    let mut builder = MeshBuilder::new(corners, Vec::new(), Vec::new());
    builder.push([0, 1, 2], None, None, 0);
    builder.push([0, 2, 3], None, None, 0);
    builder.finish_into(&mut scene);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0);
    let (width, height) = (32, 32);
    for integrator in [Integrator::Direct, Integrator::Path] {
        let settings = RenderSettings {
            width,
            height,
            integrator,
            samples_per_pixel: 1,
            sampler: PixelSampler::Center,
            ..RenderSettings::default()
        };
        let image = render_scene(&scene, &camera, &settings);
        let rays = CameraRays::new(&camera, width, height);
        let mut worst = 0.0f32;
        for y in 0..height {
            for x in 0..width {
                let ray = rays.ray(x, y, Vec2::splat(0.5));
                let p = ray.at(-ray.origin.z / ray.direction.z);
                let to_light = light_position - p;
                let irradiance = intensity * to_light.normalize().z / to_light.length_squared();
                let expected = albedo / PI * irradiance;
                let error = (image.get(x, y).x - expected).abs() / expected;
                worst = worst.max(error);
            }
        }
        println!("{integrator}: largest relative error {worst}");
        assert!(worst < 1e-4, "{integrator}: relative error {worst}");
    }
}

fn cornell_box() -> (Scene, Camera) {
    let scene = Scene::load(&rtgi_tests::workspace_root().join("scenes/cornell-box.toml")).unwrap();
    let camera = scene.cameras[0];
    (scene, camera)
}

/// Renders with the plan and with each effect the plan leaves out forced
/// on; the images must agree (the same paths, the same random numbers).
fn assert_omissions_change_nothing(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> usize {
    let planned = render_scene(scene, camera, settings);
    let plan = EffectPlan::new(scene, settings);
    let omitted = plan.omitted();
    for effect in omitted.iter() {
        if effect == Effect::Indirect && settings.integrator != Integrator::Path {
            continue;
        }
        let forced = RenderSettings {
            effects: EffectOverrides { on: EffectSet::of(&[effect]), off: EffectSet::EMPTY },
            ..settings.clone()
        };
        assert!(EffectPlan::new(scene, &forced).has(effect));
        let image = render_scene(scene, camera, &forced);
        let worst = planned
            .pixels()
            .iter()
            .zip(image.pixels())
            .map(|(a, b)| ((*a - *b).abs() / a.abs().max(Vec3::splat(1e-3))).max_element())
            .fold(0.0f32, f32::max);
        println!("+{effect}: largest relative difference {worst}");
        assert!(worst < 1e-4, "forcing {effect} on changed the image by {worst}");
    }
    omitted.len()
}

#[test]
fn effects_the_plan_omits_change_nothing_when_forced_on() {
    let (scene, camera) = cornell_box();
    for integrator in [Integrator::Path, Integrator::Direct] {
        let settings = RenderSettings {
            width: 40,
            height: 40,
            samples_per_pixel: 4,
            sampler: PixelSampler::Stratified,
            integrator,
            ..RenderSettings::default()
        };
        let omitted = assert_omissions_change_nothing(&scene, &camera, &settings);
        assert!(omitted >= 5, "the Cornell box needs no textures, alpha, glossy, refraction or environment");
    }
    // A textured glTF model: different omissions (no emission, no alpha...).
    if let Some(path) = rtgi_tests::shared_scene("gltf/BoxTextured/glTF/BoxTextured.gltf") {
        let scene = Scene::load(&path).unwrap();
        let camera = Camera::look_at(Vec3::new(1.5, 1.2, 2.5), Vec3::ZERO, Vec3::Y, 0.8);
        let settings = RenderSettings { width: 32, height: 32, samples_per_pixel: 4, ..RenderSettings::default() };
        assert!(EffectPlan::new(&scene, &settings).has(Effect::Textures));
        assert_omissions_change_nothing(&scene, &camera, &settings);
        // Forcing a needed effect off does change the image.
        let untextured = RenderSettings {
            effects: EffectOverrides { on: EffectSet::EMPTY, off: EffectSet::of(&[Effect::Textures]) },
            ..settings.clone()
        };
        let a = render_scene(&scene, &camera, &settings);
        let b = render_scene(&scene, &camera, &untextured);
        assert!(rtgi_image::compare(&a, &b).unwrap().max_abs > 0.05);
        // The preview integrator follows the same decision.
        let primary = RenderSettings { integrator: Integrator::Primary, ..settings.clone() };
        let a = render_scene(&scene, &camera, &primary);
        let b = render_scene(&scene, &camera, &RenderSettings { integrator: Integrator::Primary, ..untextured });
        assert!(rtgi_image::compare(&a, &b).unwrap().max_abs > 0.05);
    }
}

#[test]
fn plans_name_what_each_scene_needs() {
    let (scene, _) = cornell_box();
    let plan = EffectPlan::new(&scene, &RenderSettings::default());
    for effect in [Effect::Emission, Effect::DirectLight, Effect::Indirect] {
        assert!(plan.has(effect), "{plan}");
    }
    for effect in [Effect::Glossy, Effect::Refraction, Effect::Textures, Effect::Alpha, Effect::Environment] {
        assert!(!plan.has(effect), "{plan}");
    }
    let text = plan.to_string();
    assert!(text.contains("+ emission") && text.contains("'light'"), "{text}");
    assert!(text.contains("- glossy        every material is diffuse"), "{text}");
    // The primary integrator needs no light at all.
    let primary = EffectPlan::new(&scene, &RenderSettings { integrator: Integrator::Primary, ..Default::default() });
    assert!(!primary.has(Effect::DirectLight) && !primary.has(Effect::Indirect));
    // Without lights or emitters, a default sky and sun light the scene, and say so.
    let mut dark = scene.clone();
    for m in &mut dark.materials {
        m.emission = Vec3::ZERO;
    }
    let plan = EffectPlan::new(&dark, &RenderSettings::default());
    assert!(plan.default_environment && plan.has(Effect::Environment), "{plan}");
    assert!(plan.to_string().contains("a default sky (blue overhead, grey ground) and a sun"), "{plan}");
    // Emitters far too weak to light the scene keep the sky, and the plan says how weak.
    let mut glowing = scene.clone();
    for m in &mut glowing.materials {
        m.emission *= 1e-5;
    }
    let plan = EffectPlan::new(&glowing, &RenderSettings::default());
    assert!(plan.default_environment && plan.has(Effect::Emission), "{plan}");
    assert!(plan.to_string().contains("of the light a sky would, too little to light it"), "{plan}");
    // The Cornell box's own light is strong enough to light it.
    assert!(!EffectPlan::new(&scene, &RenderSettings::default()).default_environment);
    // Forcing shows in the plan.
    let forced = RenderSettings { effects: "+glossy,-indirect".parse().unwrap(), ..Default::default() };
    let plan = EffectPlan::new(&scene, &forced);
    assert!(plan.has(Effect::Glossy) && !plan.has(Effect::Indirect) && plan.max_depth == 1);
    assert!(plan.to_string().contains("+!glossy"), "{plan}");
    // MTL colours that reflect more than all light are scaled down, and the plan names them.
    let mut bright = scene.clone();
    bright.materials[0].specular = Vec3::splat(0.5);
    bright.materials[0].base_color = Vec3::new(0.9, 0.6, 0.3);
    let plan = EffectPlan::new(&bright, &RenderSettings::default()).to_string();
    let named = format!(
        "1 of them reflects more than it receives (Kd + Ks up to 1.40), scaled down to reflect at most all: '{}'",
        bright.materials[0].name
    );
    assert!(plan.contains(&named), "{plan}");
}

#[test]
fn light_bsdf_and_mis_sampling_agree_on_a_glossy_floor_under_an_area_light() {
    // Each strategy is unbiased on its own, so all three converge to the same
    // image; a wrong density in a MIS weight (a BSDF pdf that disagrees with
    // its sampler, a light pdf in the wrong measure) breaks the agreement.
    let floor = Material {
        name: "floor".into(),
        model: SurfaceModel::MetallicRoughness,
        base_color: Vec3::splat(0.9),
        metallic: 1.0,
        roughness: 0.4,
        ..Material::default()
    };
    let lamp =
        Material { name: "lamp".into(), base_color: Vec3::ZERO, emission: Vec3::splat(3.0), ..Material::default() };
    let mut scene = Scene { materials: vec![floor, lamp], ..Scene::default() };
    let positions = vec![
        Vec3::new(-2.0, -2.0, 0.0),
        Vec3::new(2.0, -2.0, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
        Vec3::new(-2.0, 2.0, 0.0),
        Vec3::new(-0.6, -0.3, 1.0),
        Vec3::new(0.6, -0.3, 1.0),
        Vec3::new(0.6, 0.3, 1.0),
        Vec3::new(-0.6, 0.3, 1.0),
    ];
    let mut builder = MeshBuilder::new(positions, Vec::new(), Vec::new()).with_flat_normals();
    builder.push([0, 1, 2], None, None, 0);
    builder.push([0, 2, 3], None, None, 0);
    // Wound clockwise seen from above, so the lamp shines down.
    builder.push([4, 6, 5], None, None, 1);
    builder.push([4, 7, 6], None, None, 1);
    builder.finish_into(&mut scene);
    let camera = Camera::look_at(Vec3::new(0.0, -3.0, 1.5), Vec3::new(0.0, 0.5, 0.0), Vec3::Z, 0.9);
    let means: Vec<f32> = DirectStrategy::ALL
        .iter()
        .map(|&direct_strategy| {
            let settings = RenderSettings {
                width: 32,
                height: 32,
                samples_per_pixel: 256,
                sampler: PixelSampler::Stratified,
                integrator: Integrator::Direct,
                direct_strategy,
                background: Vec3::ZERO,
                ..RenderSettings::default()
            };
            let image = render_scene(&scene, &camera, &settings);
            // The floor only: the lamp's own pixels are the same for every strategy.
            let floor: Vec<f32> = image.pixels().iter().map(|p| p.x).filter(|&v| v < 2.9).collect();
            let mean = floor.iter().sum::<f32>() / floor.len() as f32;
            println!("{direct_strategy}: mean of the floor {mean}");
            mean
        })
        .collect();
    let mis = means[2];
    assert!(mis > 0.01, "the floor is lit");
    for (strategy, mean) in DirectStrategy::ALL.iter().zip(&means) {
        assert!((mean - mis).abs() < 0.02 * mis, "{strategy}: {mean} against MIS {mis}");
    }
}

#[test]
fn light_through_a_volume_is_attenuated_by_beer_lambert() {
    // KHR_materials_volume: a unit sphere of a medium that leaves light the
    // attenuation colour c after the attenuation distance d, of index 1 (so
    // rays pass straight through), under a white sky. Through its centre
    // light travels 2 units, so the centre pixels see c^(2/d); the same
    // sphere without a volume is a thin sheet and lets the sky through.
    let attenuation = Vec3::new(0.5, 0.25, 0.9);
    let volume = rtgi_scene::Volume {
        thickness: 1.0,
        thickness_texture: None,
        attenuation_distance: 2.0,
        attenuation_color: attenuation,
    };
    let glass = |volume: Option<rtgi_scene::Volume>| Material {
        model: SurfaceModel::MetallicRoughness,
        base_color: Vec3::ONE,
        roughness: 0.0,
        transmission: 1.0,
        ior: 1.0,
        volume,
        ..Material::default()
    };
    // A narrow view of the centre: its rays cross the sphere within 1% of its diameter.
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 0.01);
    let settings = RenderSettings {
        width: 4,
        height: 4,
        samples_per_pixel: 16,
        max_depth: 16,
        environment: Some(Environment::Uniform(Vec3::ONE)),
        ..RenderSettings::default()
    };
    let mean = |scene: &Scene| {
        let image = render_scene(scene, &camera, &settings);
        image.pixels().iter().fold(Vec3::ZERO, |sum, p| sum + *p) / image.pixels().len() as f32
    };
    // The icosphere's faces lie a little inside the unit sphere, so the path is a little short of 2.
    let through = mean(&sphere_scene(glass(Some(volume)), false));
    for channel in 0..3 {
        let expected = attenuation[channel];
        assert!(
            (through[channel] - expected).abs() < 0.02 * expected,
            "channel {channel}: {through} through the medium, expected {attenuation}"
        );
    }
    let sheet = mean(&sphere_scene(glass(None), false));
    assert!((sheet - Vec3::ONE).abs().max_element() < 0.01, "a thin sheet lets the sky through: {sheet}");
}
