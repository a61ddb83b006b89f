//! A render cut into passes, sample ranges and bands of rows, checkpointed
//! to files and merged, has the same bits as the render in one go.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_image::HdrImage;
use rtgi_render::{
    Accumulation, Integrator, MergeError, PassControl, PixelSampler, RenderIdentity, RenderSettings, render,
    render_pass,
};
use rtgi_scene::Scene;

fn bits(image: &HdrImage) -> Vec<u32> {
    image.pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect()
}

const NEVER: PassControl<'static> = PassControl { progress: &|_| {}, cancelled: &|| false };

/// Every sampler (the stratified one's pattern depends on the total count),
/// path tracing with its random bounces, and the AOVs.
fn cases() -> Vec<RenderSettings> {
    let base = RenderSettings { width: 29, height: 21, samples_per_pixel: 12, seed: 5, ..RenderSettings::default() };
    let mut cases: Vec<RenderSettings> =
        PixelSampler::ALL.iter().map(|&sampler| RenderSettings { sampler, ..base.clone() }).collect();
    cases.push(RenderSettings { integrator: Integrator::Normal, sampler: PixelSampler::Stratified, ..base.clone() });
    cases.push(RenderSettings { samples_per_pixel: 7, sampler: PixelSampler::Stratified, ..base });
    cases
}

#[test]
fn passes_ranges_bands_and_files_add_up_to_the_render_in_one_go() {
    let scene = Scene::load(&rtgi_tests::workspace_root().join("scenes/cornell-box.toml")).unwrap();
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = scene.cameras[0];
    let folder = rtgi_tests::scratch_dir("split_render");
    for settings in cases() {
        let spp = settings.samples_per_pixel;
        let (whole, _) = render(&scene, accel.as_ref(), &camera, &settings, &|_| {});
        let identity = RenderIdentity::new(&scene, &camera, &settings);

        // Progressive: passes of uneven sizes, written and read back between passes.
        let checkpoint = folder.join("checkpoint.accum");
        let mut progressive = Accumulation::new(identity.clone(), 0..settings.height, 0);
        let mut pass = 1;
        while progressive.samples_done() < spp {
            let count = pass.min(spp - progressive.samples_done());
            render_pass(&scene, accel.as_ref(), &camera, &settings, &mut progressive, count, &NEVER).unwrap();
            progressive.write(&checkpoint).unwrap();
            progressive = Accumulation::read(&checkpoint).unwrap();
            pass += 2;
        }
        assert!(progressive.is_complete());
        assert_eq!(bits(&progressive.image()), bits(&whole), "{settings:?}: progressive");

        // Split: 4 sample ranges × 3 bands of rows, each a job of its own, merged in a shuffled order.
        let cuts = [0, 3, spp / 2, spp - 1, spp];
        let bands = [0..5, 5..6, 6..settings.height];
        let mut parts = Vec::new();
        for range in cuts.windows(2) {
            for rows in &bands {
                let mut part = Accumulation::new(identity.clone(), rows.clone(), range[0]);
                let count = range[1] - range[0];
                render_pass(&scene, accel.as_ref(), &camera, &settings, &mut part, count, &NEVER).unwrap();
                let path = folder.join(format!("part-{}-{}.accum", range[0], rows.start));
                part.write(&path).unwrap();
                parts.push(Accumulation::read(&path).unwrap());
            }
        }
        parts.reverse();
        parts.swap(1, 7);
        let merged = Accumulation::merge(parts.clone()).unwrap();
        assert!(merged.is_complete());
        assert_eq!(bits(&merged.image()), bits(&whole), "{settings:?}: merged");

        // Without one part, the merge says which samples of which rows are missing.
        parts.remove(3);
        let error = Accumulation::merge(parts).unwrap_err();
        assert!(matches!(error, MergeError::MissingSamples { .. }), "{error}");
    }
}

#[test]
fn a_cancelled_pass_leaves_the_accumulation_as_it_was() {
    let scene = Scene::load(&rtgi_tests::workspace_root().join("scenes/cornell-box.toml")).unwrap();
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = scene.cameras[0];
    let settings = RenderSettings { width: 40, height: 40, samples_per_pixel: 8, ..RenderSettings::default() };
    let identity = RenderIdentity::new(&scene, &camera, &settings);
    let mut accumulation = Accumulation::new(identity, 0..40, 0);
    render_pass(&scene, accel.as_ref(), &camera, &settings, &mut accumulation, 2, &NEVER).unwrap();
    let before = accumulation.clone();
    // Cancelled after some blocks have been rendered.
    let polls = std::sync::atomic::AtomicU32::new(0);
    let cancelled = || polls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) > 20;
    let control = PassControl { progress: &|_| {}, cancelled: &cancelled };
    let result = render_pass(&scene, accel.as_ref(), &camera, &settings, &mut accumulation, 6, &control);
    assert!(result.is_err());
    assert_eq!(accumulation, before);
}

#[test]
fn identities_name_what_differs() {
    let scene = Scene::load(&rtgi_tests::workspace_root().join("scenes/cornell-box.toml")).unwrap();
    let camera = scene.cameras[0];
    let settings = RenderSettings { width: 40, height: 30, samples_per_pixel: 8, ..RenderSettings::default() };
    let identity = RenderIdentity::new(&scene, &camera, &settings);
    assert!(identity.differences(&RenderIdentity::new(&scene, &camera, &settings)).is_empty());
    let deeper = RenderSettings { max_depth: 3, seed: 2, ..settings.clone() };
    let differences = identity.differences(&RenderIdentity::new(&scene, &camera, &deeper));
    let differences: Vec<String> = differences.iter().map(|d| d.to_string()).collect();
    assert_eq!(differences, ["seed 0 vs 2", "max depth 8 vs 3"]);
    let mut moved = scene.clone();
    moved.vertices[0].position.x += 1e-3;
    let differences = identity.differences(&RenderIdentity::new(&moved, &camera, &settings));
    assert_eq!(differences.len(), 1);
    assert_eq!(differences[0].what, "scene", "{differences:?}");
}
