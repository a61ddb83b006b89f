//! MTL transparency: `map_d` masks cut holes like glTF's alpha mask, and
//! `d` below 1 lets light through; `rtgi info` says what the renderer does.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_render::{Integrator, PixelSampler, RenderSettings, render};
use rtgi_scene::{AlphaMode, Camera, Scene};
use rtgi_tests::scratch_dir;

/// A unit quad facing +Z with material `m`, whose MTL has `statements`:
/// `q.obj` in the folder returned.
fn quad(test: &str, statements: &str) -> rtgi_tests::ScratchDir {
    let dir = scratch_dir(test);
    // The mask: black (a hole) on the left half, white on the right.
    let mask = image::GrayImage::from_fn(8, 8, |x, _| image::Luma([if x < 4 { 0 } else { 255 }]));
    mask.save(dir.join("mask.png")).unwrap();
    std::fs::write(dir.join("q.mtl"), format!("newmtl m\nKd 0.8 0.8 0.8\n{statements}\n")).unwrap();
    let obj = "mtllib q.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n";
    std::fs::write(dir.join("q.obj"), obj).unwrap();
    dir
}

/// How much of the left and right thirds of a head-on view of the quad is covered (0 to 1).
fn coverage(scene: &Scene) -> (f32, f32) {
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = Camera::look_at(rtgi_math::Vec3::new(0.0, 0.0, 3.0), rtgi_math::Vec3::ZERO, rtgi_math::Vec3::Y, 0.6);
    let settings = RenderSettings {
        width: 30,
        height: 30,
        samples_per_pixel: 16,
        sampler: PixelSampler::Stratified,
        integrator: Integrator::Albedo,
        ..RenderSettings::default()
    };
    let (image, _) = render(scene, accel.as_ref(), &camera, &settings, &|_| {});
    // The albedo is 0.8 where the quad is hit, 0 where a ray goes through.
    let covered = |x0: u32, x1: u32| {
        let mut sum = 0.0;
        for y in 10..20 {
            for x in x0..x1 {
                sum += image.get(x, y).x / 0.8;
            }
        }
        (sum / (10 * (x1 - x0)) as f32 * 100.0).round() / 100.0
    };
    (covered(0, 10), covered(20, 30))
}

#[test]
fn a_map_d_mask_cuts_holes() {
    let scene = Scene::load(&quad("map-d", "map_d mask.png").join("q.obj")).unwrap();
    assert!(matches!(scene.materials[0].alpha_mode, AlphaMode::Mask { .. }), "{:?}", scene.materials[0]);
    let (left, right) = coverage(&scene);
    assert_eq!((left, right), (0.0, 1.0));
}

#[test]
fn a_dissolve_below_one_lets_part_of_the_light_through() {
    let scene = Scene::load(&quad("dissolve", "d 0.25").join("q.obj")).unwrap();
    assert_eq!(scene.materials[0].alpha_mode, AlphaMode::Blend);
    let (left, right) = coverage(&scene);
    for covered in [left, right] {
        assert!((covered - 0.25).abs() < 0.05, "{covered}");
    }
    let opaque = Scene::load(&quad("opaque", "d 1").join("q.obj")).unwrap();
    assert_eq!(opaque.materials[0].alpha_mode, AlphaMode::Opaque);
    assert_eq!(coverage(&opaque), (1.0, 1.0));
}

#[test]
fn info_says_which_materials_are_cut_out_blended_or_transmissive() {
    let dir = quad("info-alpha", "map_d mask.png");
    let path = dir.join("q.obj");
    let run = rtgi_tests::run_cli(env!("CARGO_BIN_EXE_rtgi-under-test"), &["info", path.to_str().unwrap()]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("cut-out (alpha mask, cutoff 0.5, from a mask texture)"), "{run:?}");
    assert!(run.stdout.contains("+ alpha"), "{run:?}");
}
