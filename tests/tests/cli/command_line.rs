//! A [`RenderRequest`] and its `rtgi render` command line
//! ([`rtgi::render_command_line`]): parsing the words back gives the same
//! request, and running them as a process writes the bytes the library
//! writes for the request, for every option group.

use rtgi_accel::{AccelKind, Intersector, SahAxes};
use rtgi_job::{
    CancelToken, Checkpoints, Denoise, Ending, ImageSize, RenderRequest, SceneSource, Split, Structure, Tone,
    Unobserved,
};
use rtgi_math::Vec3;
use rtgi_render::{BounceSampling, DirectStrategy, EnvironmentSpec, FilterGlossy, Integrator, PixelSampler};
use rtgi_tests::scratch_dir;

use super::rtgi;

#[test]
fn every_option_group_survives_the_round_trip() {
    let plain = RenderRequest::new(SceneSource::BuiltIn, "out.png");
    let mut file = RenderRequest::new(SceneSource::file("scenes/a b.gltf"), "x.exr");
    if let SceneSource::File { options, .. } = &mut file.scene {
        options.allow_outside_folder = true;
        options.gltf_variant = Some("Dawn".into());
    }
    file.size = ImageSize { width: Some(320), height: None };
    file.sampling.samples_per_pixel = Some(64);
    file.sampling.sampler = Some(PixelSampler::Sobol);
    file.sampling.seed = 7;
    file.aovs = vec![Integrator::Albedo, Integrator::Normal];
    file.background = Vec3::new(0.0, 0.25, 1.5e-3);
    file.lighting.integrator = Integrator::Direct;
    file.lighting.max_depth = 3;
    file.lighting.roulette_start = 5;
    file.lighting.bounce_sampling = BounceSampling::Cosine;
    file.lighting.direct_strategy = DirectStrategy::Light;
    file.lighting.indirect_clamp = Some(2.5);
    file.lighting.filter_glossy = Some(FilterGlossy::all_lobes(0.3));
    file.lighting.environment = Some(EnvironmentSpec::Uniform(Vec3::new(0.1, 0.2, 0.3)));
    file.lighting.environment_scale = 2.0;
    file.lighting.lights = vec!["point:0,1,0:5:1,0.5,0.25".parse().unwrap()];
    file.lighting.effects = "+glossy,-textures".parse().unwrap();
    file.lighting.no_default_lighting = true;
    file.camera.index = Some(1);
    file.camera.at = Some(Vec3::new(1.0, -2.0, 3.5));
    file.camera.look = Some(Vec3::ZERO);
    file.camera.up = Some(Vec3::Z);
    file.camera.fov_degrees = Some(42.5);
    file.structure = Structure::of(AccelKind::Sah);
    file.structure.leaf_size = Some(2);
    file.structure.sah_bins = 12;
    file.structure.sah_axes = SahAxes::Longest;
    file.structure.traversal_cost = Some(1.5);
    file.structure.intersector = Intersector::ALL[Intersector::ALL.len() - 1];
    file.tone = Tone { exposure: Some(-1.5), operator: Some(rtgi_image::ToneOperator::Clamp) };
    file.denoise = Denoise::Off;
    let mut split = RenderRequest::new(SceneSource::file("s.obj"), "part.accum");
    split.split = Split { samples: Some(16..32), tile: Some((1, 4)) };
    split.checkpoints =
        Checkpoints { time_limit: Some(30.0), checkpoint: Some("c.accum".into()), every_seconds: 5.0, resume: None };
    split.threads = Some(3);
    let mut adaptive = RenderRequest::new(SceneSource::BuiltIn, "a.png");
    adaptive.sampling.noise = Some(0.02);
    adaptive.sampling.time = Some(12.5);
    adaptive.denoise = Denoise::On;
    let mut resumed = RenderRequest::new(SceneSource::BuiltIn, "r.exr");
    resumed.checkpoints.resume = Some("r.accum".into());
    resumed.lighting.environment = Some(EnvironmentSpec::File("sky.exr".into()));
    for mut request in [plain, file, split, adaptive, resumed] {
        let words = rtgi::render_command_line(&request);
        let parsed = rtgi::render_request(&words).unwrap_or_else(|e| panic!("{words:?}: {e}"));
        // Threads not given are RTGI_THREADS, which the test's environment may set.
        if request.threads.is_none() {
            request.threads = parsed.threads;
        }
        assert_eq!(parsed, request, "{words:?}");
    }
}

/// `rtgi render` with the words of a request writes the bytes the library
/// writes for it, for every option group: size and samples, lighting,
/// camera, structure, tone, denoising, AOVs, adaptive sampling, a split
/// part, and a checkpoint resumed.
#[test]
fn a_request_renders_the_bytes_of_its_command_line() {
    let dir = scratch_dir("request-bytes");
    let room = rtgi_tests::workspace_root().join("tests/scenes/closed-room.toml");
    let base = |name: &str| {
        let mut request = RenderRequest::new(SceneSource::BuiltIn, dir.join(name));
        request.size = ImageSize::exactly(24, 16);
        request.sampling.samples_per_pixel = Some(4);
        request.threads = Some(2);
        request
    };
    let mut cases = Vec::new();
    let mut lit = base("lit.exr");
    lit.lighting.direct_strategy = DirectStrategy::Light;
    lit.lighting.max_depth = 3;
    lit.lighting.indirect_clamp = Some(4.0);
    lit.lighting.lights = vec!["point:278,500,280:20000".parse().unwrap()];
    lit.lighting.environment = Some(EnvironmentSpec::Uniform(Vec3::new(0.2, 0.3, 0.4)));
    lit.camera.at = Some(Vec3::new(278.0, 273.0, -600.0));
    lit.camera.fov_degrees = Some(50.0);
    lit.structure = Structure::of(AccelKind::Sah);
    lit.structure.leaf_size = Some(2);
    lit.sampling.seed = 9;
    lit.aovs = vec![Integrator::Albedo];
    cases.push(lit);
    let mut png = base("toned.png");
    png.scene = SceneSource::file(&room);
    png.tone = Tone { exposure: Some(1.5), operator: Some(rtgi_image::ToneOperator::Clamp) };
    png.sampling.sampler = Some(PixelSampler::Sobol);
    cases.push(png);
    let mut denoised = base("denoised.png");
    denoised.denoise = Denoise::On;
    denoised.sampling.samples_per_pixel = Some(8);
    cases.push(denoised);
    let mut adaptive = base("adaptive.exr");
    adaptive.sampling.noise = Some(0.2);
    adaptive.sampling.samples_per_pixel = Some(32);
    cases.push(adaptive);
    let mut part = base("part.accum");
    part.split = Split { samples: Some(1..3), tile: Some((1, 2)) };
    cases.push(part);
    let mut first_half = base("half.accum");
    first_half.split.samples = Some(0..2);
    let mut resumed = base("resumed.exr");
    resumed.checkpoints.resume = Some(dir.join("half.accum"));
    cases.push(resumed);

    let render = |request: &RenderRequest| rtgi_job::render(request, &Unobserved, &CancelToken::new()).unwrap();
    render(&first_half);
    for request in cases {
        let ours = render(&request);
        let library_bytes: Vec<Vec<u8>> =
            ours.outcome.outputs.iter().map(|o| std::fs::read(&o.path).unwrap()).collect();
        assert!(!library_bytes.is_empty() && ours.ending == Ending::Complete, "{:?}", ours.outcome.outputs);
        // The command must write every file again, not find the library's.
        for output in &ours.outcome.outputs {
            std::fs::remove_file(&output.path).unwrap();
        }
        // The resumed file is the checkpoint too: start the command from the half again.
        if request.checkpoints.resume.is_some() {
            render(&first_half);
        }
        let words = rtgi::render_command_line(&request);
        let run = rtgi(&words.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(run.success, "{words:?}: {}", run.stderr);
        for (bytes, output) in library_bytes.iter().zip(&ours.outcome.outputs) {
            assert!(*bytes == std::fs::read(&output.path).unwrap(), "{}: {words:?}", output.path);
        }
    }
}
