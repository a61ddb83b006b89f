//! Lighting judged by what reaches the view: a scene whose own lights
//! leave the surfaces in view dark gets the default sky and sun, says why,
//! and keeps to its own light when told to.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_render::recipe::{CameraChoice, prepare};
use rtgi_render::{DefaultLighting, EffectPlan, RenderSettings};
use rtgi_scene::Scene;

/// A red box 4 × 1.5 × 2 with two bright lamps on its +X face, facing
/// away from it (headlights with nothing in front of them).
const CAR: &str = "mtllib car.mtl
v -2 0 -1\nv 2 0 -1\nv 2 1.5 -1\nv -2 1.5 -1\nv -2 0 1\nv 2 0 1\nv 2 1.5 1\nv -2 1.5 1
usemtl body
f 1 4 3 2\nf 5 6 7 8\nf 1 5 8 4\nf 2 3 7 6\nf 4 8 7 3\nf 1 2 6 5
v 2.01 0.8 0.5\nv 2.01 0.8 0.8\nv 2.01 1.1 0.8\nv 2.01 1.1 0.5
v 2.01 0.8 -0.8\nv 2.01 0.8 -0.5\nv 2.01 1.1 -0.5\nv 2.01 1.1 -0.8
usemtl lamp
f 12 11 10 9\nf 16 15 14 13
";
const CAR_MTL: &str = "newmtl body\nKd 0.6 0.1 0.1\nnewmtl lamp\nKd 0 0 0\nKe 400 400 380\n";

fn prepared(scene: &mut Scene, settings: &mut RenderSettings) -> EffectPlan {
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    prepare(scene, accel.as_ref(), settings, &CameraChoice::default()).unwrap();
    EffectPlan::new(scene, settings)
}

#[test]
fn lamps_that_light_nothing_in_view_get_the_default_sky_and_say_so() {
    let mut scene = rtgi_scene::obj::load_from_text(CAR, CAR_MTL, "car.obj").unwrap();
    let mut settings = RenderSettings::default();
    let plan = prepared(&mut scene, &mut settings);
    let DefaultLighting::ViewUnlit(fraction) = settings.default_lighting else {
        panic!("{:?}", settings.default_lighting)
    };
    assert!(fraction < 0.001, "{fraction}");
    assert!(plan.default_environment);
    assert!(plan.to_string().contains("the scene's own lights give the surfaces in view 0.0%"), "{plan}");
}

#[test]
fn lamps_that_light_the_view_keep_it_to_themselves() {
    // The same lamps turned round to face the box, a little way off so
    // that they light its side, not only the patches right behind them.
    let facing = CAR.replace("f 12 11 10 9\nf 16 15 14 13", "f 9 10 11 12\nf 13 14 15 16").replace("v 2.01 ", "v 2.5 ");
    let mut scene = rtgi_scene::obj::load_from_text(&facing, CAR_MTL, "car.obj").unwrap();
    let mut settings = RenderSettings::default();
    let plan = prepared(&mut scene, &mut settings);
    assert_eq!(settings.default_lighting, DefaultLighting::Auto);
    assert!(!plan.default_environment, "{plan}");
}

#[test]
fn no_default_lighting_keeps_to_the_scene_s_own_light() {
    let mut scene = rtgi_scene::obj::load_from_text(CAR, CAR_MTL, "car.obj").unwrap();
    let mut settings = RenderSettings { default_lighting: DefaultLighting::Off, ..RenderSettings::default() };
    let plan = prepared(&mut scene, &mut settings);
    assert_eq!(settings.default_lighting, DefaultLighting::Off);
    assert!(!plan.default_environment, "{plan}");
    // A scene with no light at all stays dark too, and the plan says why.
    let mut bare = rtgi_scene::obj::load_from_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "", "t.obj").unwrap();
    let plan = prepared(&mut bare, &mut settings);
    assert!(!plan.default_environment);
    assert!(plan.to_string().contains("default lighting is off (--no-default-lighting)"), "{plan}");
}

#[test]
fn mirrors_under_a_point_light_get_a_dim_grey_world_to_reflect_that_the_camera_does_not_see() {
    use rtgi_math::Vec3;
    use rtgi_scene::{Light, LightKind};
    // A glossy box on a matte floor under a point light.
    let obj = "mtllib m.mtl
v -1 0 -1\nv 1 0 -1\nv 1 1 -1\nv -1 1 -1\nv -1 0 1\nv 1 0 1\nv 1 1 1\nv -1 1 1
usemtl shiny
f 1 4 3 2\nf 5 6 7 8\nf 1 5 8 4\nf 2 3 7 6\nf 4 8 7 3
v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4
usemtl floor
f 9 12 11 10
";
    let mtl = "newmtl shiny\nKd 0.05 0.05 0.05\nKs 0.9 0.9 0.9\nNs 2000\nnewmtl floor\nKd 0.5 0.5 0.5\n";
    let mut scene = rtgi_scene::obj::load_from_text(obj, mtl, "shiny.obj").unwrap();
    scene.lights.push(Light {
        name: "bulb".into(),
        kind: LightKind::Point,
        position: Vec3::new(2.0, 4.0, 3.0),
        direction: Vec3::NEG_Y,
        color: Vec3::ONE,
        intensity: 50.0,
        range: None,
    });
    let background = Vec3::new(0.05, 0.05, 0.06);
    let mut settings =
        RenderSettings { width: 32, height: 32, samples_per_pixel: 4, background, ..RenderSettings::default() };
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    let prepared = prepare(&mut scene, accel.as_ref(), &mut settings, &CameraChoice::default()).unwrap();
    let DefaultLighting::Reflections(radiance) = settings.default_lighting else {
        panic!("{:?}", settings.default_lighting)
    };
    assert!(radiance > 0.0 && radiance.is_finite(), "{radiance}");
    let plan = EffectPlan::new(&scene, &settings);
    assert!(plan.to_string().contains("a dim grey environment"), "{plan}");
    // The camera sees the background where its rays miss, not the grey.
    let (image, _) = rtgi_render::render(&scene, accel.as_ref(), &prepared.camera.camera, &settings, &|_| {});
    let missed = (0..32).flat_map(|x| (0..32).map(move |y| (x, y))).filter(|&(x, y)| image.get(x, y) == background);
    assert!(missed.count() > 10, "no pixel shows the background");
}

/// `rtgi info` prints the plan `rtgi render` follows, probe of the view
/// included: the headlamp box gets the default sky in both, with and
/// without a camera placed by options.
#[test]
fn info_prints_the_plan_the_render_follows() {
    let dir = rtgi_tests::scratch_dir("info-plan");
    std::fs::write(dir.join("car.obj"), CAR).unwrap();
    std::fs::write(dir.join("car.mtl"), CAR_MTL).unwrap();
    let scene = dir.join("car.obj");
    let scene = scene.to_str().unwrap();
    let rtgi = env!("CARGO_BIN_EXE_rtgi-under-test");
    let plan = |stdout: &str| -> String {
        let start = stdout.find("plan:").expect("a plan");
        stdout[start..]
            .lines()
            .take_while(|l| l.starts_with("plan:") || l.starts_with("  "))
            .collect::<Vec<_>>()
            .join("\n")
    };
    for camera in [&[][..], &["--at", "8,2,1"][..]] {
        let info = rtgi_tests::run_cli(rtgi, &[&["info", scene][..], camera].concat());
        let out = dir.join("car.png");
        let args = [&["render", scene, "-o", out.to_str().unwrap(), "--quick"][..], camera].concat();
        let render = rtgi_tests::run_cli(rtgi, &args);
        assert!(info.success && render.success, "{info:?} {render:?}");
        assert_eq!(plan(&info.stdout), plan(&render.stdout), "{camera:?}");
        assert!(plan(&info.stdout).contains("the scene's own lights give the surfaces in view"), "{info:?}");
    }
}

#[test]
fn a_flat_cut_out_seen_straight_on_is_lit_from_the_view_s_upper_right() {
    use rtgi_math::Vec3;
    // A gingerbread-like flat outline facing +Z (woody's shape, coarsely),
    // and the same stood up facing +X: seen straight on, each is lit from
    // the camera's upper right, and brighter than the model's default sun
    // (placed for a product shot) would light it.
    let outline = "v -1 0 0\nv 1 0 0\nv 1 2 0\nv -1 2 0\nv -0.4 2 0\nv 0.4 2 0\nv 0 2.8 0\nf 1 2 3 4\nf 5 6 7\n";
    for facing in [Vec3::Z, Vec3::X] {
        let text = if facing == Vec3::X {
            outline.lines().map(|l| swap_x_and_z(l) + "\n").collect::<String>()
        } else {
            outline.to_owned()
        };
        let mut scene = rtgi_scene::obj::load_from_text(&text, "", "flat.obj").unwrap();
        let mut settings = RenderSettings::default();
        let plan = prepared(&mut scene, &mut settings);
        assert!(plan.default_environment, "{plan}");
        let towards = settings.sun_towards.expect("the flat view places the sun");
        // 30 degrees above the view and 25 to its right: 0.78 on the face.
        assert!((towards.dot(facing) - 0.785).abs() < 0.01 && towards.y > 0.4, "{facing}: {towards}");
        let default = rtgi_render::default_sun(Vec3::Y).direction;
        assert!(towards.dot(facing) > 1.5 * (-default).dot(facing), "{facing}: {towards} against {default}");
    }
    // A model with depth keeps the sun placed for the product shot.
    let mut cube = rtgi_scene::obj::load_from_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n",
        "",
        "cube.obj",
    )
    .unwrap();
    let mut settings = RenderSettings::default();
    prepared(&mut cube, &mut settings);
    assert_eq!(settings.sun_towards, None);
}

/// An OBJ `v` line with its x and z swapped (other lines as they are).
fn swap_x_and_z(line: &str) -> String {
    match line.split_whitespace().collect::<Vec<_>>()[..] {
        ["v", x, y, z] => format!("v {z} {y} {x}"),
        _ => line.to_owned(),
    }
}
