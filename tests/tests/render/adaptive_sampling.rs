//! Clean images in bounded time.
//!
//! Adaptive sampling (`rtgi render --noise`, `--time`): deterministic, close
//! to the converged reference at every noise target (its stopping rule
//! could bias it; the tests measure how much), fewer samples where the image
//! is smooth, and refused where it cannot work.
//!
//! The denoiser (`rtgi render --denoise`): against the converged Cornell
//! box at several sample counts it must lower the error without moving the
//! image's brightness, and the command applies it to PNG output only.

use rtgi_accel::{Accel, AccelKind, BuildParams};
use rtgi_image::HdrImage;
use rtgi_math::luminance;
use rtgi_render::adaptive::{AdaptiveError, AdaptiveOutcome, FIRST_ROUND};
use rtgi_render::{
    AdaptiveSampling, DenoiseSettings, Guides, PixelSampler, RenderSettings, frame_scene, render, render_adaptive,
    render_denoised,
};
use rtgi_scene::{Camera, Scene};
use rtgi_tests::{CORNELL_SIZE, Run, run_cli, scratch_dir, shared_scene, workspace_root};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

fn rtgi(args: &[&str]) -> Run {
    run_cli(RTGI, args)
}

/// The shared Cornell box, framed as its reference was rendered.
fn cornell() -> Option<(Scene, Box<dyn Accel>, Camera)> {
    let scene = Scene::load(&shared_scene("cornell-box/CornellBox-Original.obj")?).unwrap();
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = frame_scene(&scene, accel.as_ref(), 40f32.to_radians(), 1.0);
    Some((scene, accel, camera))
}

fn settings(size: u32, spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        samples_per_pixel: spp,
        sampler: PixelSampler::Sobol,
        seed,
        ..RenderSettings::default()
    }
}

fn adaptive(noise: Option<f32>, seconds: Option<f64>) -> AdaptiveSampling {
    AdaptiveSampling { noise, seconds }
}

fn render_with(
    (scene, accel, camera): &(Scene, Box<dyn Accel>, Camera),
    settings: &RenderSettings,
    sampling: &AdaptiveSampling,
) -> (HdrImage, AdaptiveOutcome) {
    let settings = RenderSettings { adaptive: Some(*sampling), ..settings.clone() };
    render_adaptive(scene, accel.as_ref(), camera, &settings, &mut |_| {}).unwrap()
}

fn bits(image: &HdrImage) -> Vec<u32> {
    image.pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn the_same_seed_gives_the_same_bits_on_any_number_of_threads() {
    let Some(box_) = cornell() else { return };
    let settings = settings(32, 256, 7);
    let sampling = adaptive(Some(0.05), None);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| render_with(&box_, &settings, &sampling))
    };
    let ((one, one_outcome), (two, two_outcome)) = (on(1), on(2));
    assert_eq!(bits(&one), bits(&two));
    assert_eq!(one_outcome.samples, two_outcome.samples);
    // It adapted: some pixels stopped early, others went on.
    let (fewest, most) = (one_outcome.samples.iter().min().unwrap(), one_outcome.samples.iter().max().unwrap());
    assert!(*fewest < *most, "every pixel took {fewest} samples");
    assert!(*fewest >= FIRST_ROUND.min(256));
}

#[test]
fn a_pixel_that_stops_holds_the_mean_of_its_first_samples_as_a_fixed_count_render_gives_it() {
    // Rounds take the first samples of each pixel's Sobol sequence: a pixel
    // stopped at n samples has the value a render of n samples gives it.
    let Some(box_) = cornell() else { return };
    let (image, outcome) = render_with(&box_, &settings(24, 128, 3), &adaptive(Some(0.08), None));
    let mut checked = 0;
    for count in [16u32, 32, 64, 128] {
        let (scene, accel, camera) = &box_;
        let fixed = render(scene, accel.as_ref(), camera, &settings(24, count, 3), &|_| {}).0;
        for (i, &n) in outcome.samples.iter().enumerate() {
            if n == count {
                assert_eq!(
                    image.pixels()[i].to_array().map(f32::to_bits),
                    fixed.pixels()[i].to_array().map(f32::to_bits)
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 24 * 24);
}

/// Relative RMS error of `image` against `reference` over pixels brighter
/// than a tenth of the mean, the whole image's relative bias, and the
/// largest relative bias of an 8 × 8 block.
fn errors(image: &HdrImage, reference: &HdrImage) -> (f64, f64, f64) {
    let lum = |img: &HdrImage| img.pixels().iter().map(|&p| luminance(p) as f64).collect::<Vec<f64>>();
    let (a, r) = (lum(image), lum(reference));
    let mean_r = r.iter().sum::<f64>() / r.len() as f64;
    let lit: Vec<(f64, f64)> = a.iter().zip(&r).filter(|&(_, &r)| r > 0.1 * mean_r).map(|(&a, &r)| (a, r)).collect();
    let relative_rms = (lit.iter().map(|(a, r)| ((a - r) / r).powi(2)).sum::<f64>() / lit.len() as f64).sqrt();
    let bias = a.iter().sum::<f64>() / r.iter().sum::<f64>() - 1.0;
    let side = image.width() as usize;
    let mut worst_block = 0.0f64;
    for by in (0..side).step_by(8) {
        for bx in (0..side).step_by(8) {
            let sum = |v: &[f64]| -> f64 {
                (by..by + 8).flat_map(|y| (bx..bx + 8).map(move |x| y * side + x)).map(|i| v[i]).sum()
            };
            let (sa, sr) = (sum(&a), sum(&r));
            if sr > 64.0 * 0.1 * mean_r {
                worst_block = worst_block.max((sa / sr - 1.0).abs());
            }
        }
    }
    (relative_rms, bias, worst_block)
}

#[test]
fn noise_targets_are_met_and_converge_to_the_reference_without_a_visible_bias() {
    // The stopping rule looks at the samples it stops: a pixel whose first
    // samples missed the bright paths looks calm and could stop low. The
    // first round of 16 and the neighbourhood rule keep that small; here it
    // is measured against the 16,384-sample reference at three targets.
    let Some(box_) = cornell() else { return };
    let reference_path = workspace_root().join("tests/references/cornell-box-path.exr");
    let reference = HdrImage::read_exr(&reference_path).unwrap();
    let mut previous = f64::INFINITY;
    for target in [0.2f32, 0.1, 0.05] {
        let (image, outcome) = render_with(&box_, &settings(CORNELL_SIZE, 2048, 11), &adaptive(Some(target), None));
        let (relative_rms, bias, worst_block) = errors(&image, &reference);
        let mean_samples = outcome.total_samples() as f64 / outcome.samples.len() as f64;
        println!(
            "target {target}: relative RMS error {relative_rms:.4}, image bias {bias:+.4}, worst 8x8 block \
             {worst_block:.4}, {mean_samples:.1} samples per pixel on average, at most {}",
            outcome.samples_reached
        );
        // Pixels stop at or below the target; their neighbours below it.
        assert!(relative_rms <= 1.2 * target as f64, "target {target}: relative RMS error {relative_rms}");
        assert!(relative_rms < previous, "a tighter target gave no better image");
        previous = relative_rms;
        // The image's mean is known to ~0.1% from 4096 pixels of at most
        // `target` noise: a bias of the stopping rule larger than 1% shows.
        assert!(bias.abs() < 0.01, "target {target}: the image is off by {bias:+.4}");
        assert!(worst_block < 0.05 + target as f64 / 2.0, "target {target}: an 8x8 block is off by {worst_block}");
    }
}

#[test]
fn a_time_bound_stops_between_rounds_and_a_bound_large_enough_changes_nothing() {
    let Some(box_) = cornell() else { return };
    let settings = settings(32, 64, 5);
    let (by_noise, noise_outcome) = render_with(&box_, &settings, &adaptive(Some(0.1), None));
    let (bounded, bounded_outcome) = render_with(&box_, &settings, &adaptive(Some(0.1), Some(3600.0)));
    assert_eq!(bits(&by_noise), bits(&bounded));
    assert!(!bounded_outcome.stopped_by_time && bounded_outcome.samples == noise_outcome.samples);
    // A bound shorter than the first round: that round runs, and only it.
    // (A bound of a few rounds cuts the last to what fits: the command's
    // test below repeats such a render from the --spp it names.)
    let (_, short) = render_with(&box_, &settings, &adaptive(None, Some(1e-9)));
    assert!(short.stopped_by_time && short.rounds.len() == 1, "{:?}", short.rounds);
    assert!(short.samples.iter().all(|&n| n == FIRST_ROUND / 2));
}

#[test]
fn samplers_laid_out_for_a_fixed_count_and_meaningless_targets_are_refused() {
    let Some(box_) = cornell() else { return };
    let (scene, accel, camera) = &box_;
    let run = |sampler: PixelSampler, sampling: AdaptiveSampling| {
        let settings = RenderSettings { sampler, adaptive: Some(sampling), ..settings(8, 16, 1) };
        render_adaptive(scene, accel.as_ref(), camera, &settings, &mut |_| {}).err()
    };
    for sampler in [PixelSampler::Stratified, PixelSampler::LowDiscrepancy] {
        assert_eq!(run(sampler, adaptive(Some(0.1), None)), Some(AdaptiveError::Sampler(sampler)));
    }
    assert_eq!(run(PixelSampler::Sobol, adaptive(None, None)), Some(AdaptiveError::NoTarget));
    assert_eq!(run(PixelSampler::Uniform, adaptive(Some(-1.0), None)), Some(AdaptiveError::Noise(-1.0)));
    assert_eq!(run(PixelSampler::Center, adaptive(None, Some(0.0))), Some(AdaptiveError::Seconds(0.0)));
}

#[test]
fn the_command_says_how_it_adapted_and_its_time_bound_names_the_render_that_repeats_it() {
    let dir = scratch_dir("adaptive-cli");
    let first = dir.join("bounded.png");
    let run = rtgi(&[
        "render",
        "--width",
        "48",
        "--height",
        "48",
        "--noise",
        "0.05",
        "--time",
        "0.3",
        "-o",
        first.to_str().unwrap(),
    ]);
    assert!(run.success, "{}", run.stderr);
    assert!(run.stdout.contains("round       16 samples per pixel"), "{}", run.stdout);
    let summary =
        run.stdout.lines().find(|l| l.starts_with("adaptive    ")).unwrap_or_else(|| panic!("{}", run.stdout));
    // Either the bound ended it, naming the --spp that repeats it, or the noise target did.
    let spp = match summary.split_once("--spp ") {
        Some((_, rest)) if summary.contains("--time 0.3 ended it") => {
            rest.split_whitespace().next().unwrap().to_owned()
        }
        _ => {
            assert!(summary.contains("every pixel reached the noise target"), "{summary}");
            "1024".to_owned()
        }
    };
    let again = dir.join("again.png");
    let run = rtgi(&[
        "render",
        "--width",
        "48",
        "--height",
        "48",
        "--noise",
        "0.05",
        "--spp",
        &spp,
        "-o",
        again.to_str().unwrap(),
    ]);
    assert!(run.success, "{}", run.stderr);
    assert_eq!(std::fs::read(&first).unwrap(), std::fs::read(&again).unwrap(), "{summary}");
    // What cannot go with it is refused before any work, naming the option.
    for (option, value) in
        [("--tile", "1/2"), ("--samples", "0..8"), ("--checkpoint", "c.accum"), ("--time-limit", "9")]
    {
        let run =
            rtgi(&["render", "--quick", "--noise", "0.1", option, value, "-o", dir.join("x.png").to_str().unwrap()]);
        assert!(!run.success && run.stderr.contains(option), "{option}: {}", run.stderr);
        assert!(run.stderr.contains("render in one go"), "{}", run.stderr);
    }
    let run = rtgi(&[
        "render",
        "--quick",
        "--noise",
        "0.1",
        "--sampler",
        "stratified",
        "-o",
        dir.join("x.png").to_str().unwrap(),
    ]);
    assert!(!run.success && run.stderr.contains("stratified sampler"), "{}", run.stderr);
    let run = rtgi(&["render", "--quick", "--noise", "2", "-o", dir.join("x.png").to_str().unwrap()]);
    assert!(!run.success && run.stderr.contains("a fraction between 0 and 1"), "{}", run.stderr);
}

fn mean_luminance(image: &HdrImage) -> f64 {
    image.pixels().iter().map(|&p| luminance(p) as f64).sum::<f64>() / image.pixels().len() as f64
}

#[test]
fn the_denoised_cornell_box_is_closer_to_the_converged_one_at_every_sample_count_and_as_bright() {
    // The filter is biased by design (blur, fireflies taken out): against
    // the 16,384-sample reference, its error must still fall with the
    // samples, stay below the samples' mean, and leave the brightness.
    let Some(box_) = cornell() else { return };
    let (scene, accel, camera) = &box_;
    let reference = HdrImage::read_exr(&workspace_root().join("tests/references/cornell-box-path.exr")).unwrap();
    let mut previous = f64::INFINITY;
    for spp in [4u32, 16, 64] {
        let settings = settings(CORNELL_SIZE, spp, 3);
        let denoise = DenoiseSettings::for_samples(spp);
        let (clean, raw) = render_denoised(scene, accel.as_ref(), camera, &settings, &denoise);
        let guides = Guides::render(scene, accel.as_ref(), camera, &settings);
        let inside = interior(&guides);
        let (raw_inside, clean_inside) =
            (relative_rms_where(&raw, &reference, &inside), relative_rms_where(&clean, &reference, &inside));
        let (raw_all, clean_all) = (errors(&raw, &reference).0, errors(&clean, &reference).0);
        let brightness = mean_luminance(&clean) / mean_luminance(&reference) - 1.0;
        println!(
            "{spp} spp: relative RMS error {raw_inside:.4} raw, {clean_inside:.4} denoised away from edges \
             ({} pixels); {raw_all:.4} and {clean_all:.4} over the lit image; denoised brightness {brightness:+.4}",
            inside.iter().filter(|&&b| b).count()
        );
        // Away from edges the noise is what the filter takes out.
        assert!(clean_inside < 0.6 * raw_inside, "{spp} spp: {clean_inside} denoised against {raw_inside} raw");
        // Edges (anti-aliasing noise the guides keep apart) it cannot
        // smooth, but it must not make the whole image worse.
        assert!(clean_all <= raw_all, "{spp} spp: {clean_all} denoised against {raw_all} raw over the image");
        assert!(clean_inside < previous, "{spp} spp: more samples did not lower the denoised error");
        previous = clean_inside;
        // The filter moves light between pixels and takes out fireflies: the
        // image as a whole must keep its brightness within 3%.
        assert!(brightness.abs() < 0.03, "{spp} spp: the denoised image is off by {brightness:+.4}");
    }
}

#[test]
fn png_previews_are_denoised_and_exr_and_split_renders_keep_the_samples_mean() {
    let dir = scratch_dir("denoise-cli");
    let render = |extra: &[&str]| -> Run {
        let mut args = vec!["render", "--width", "32", "--height", "32", "--spp", "4"];
        args.extend_from_slice(extra);
        rtgi(&args)
    };
    let out = |name: &str| dir.join(name).to_str().unwrap().to_owned();

    let png = render(&["-o", &out("a.png")]);
    assert!(png.success && png.stdout.contains("denoised "), "{}", png.stdout);
    let exr = render(&["-o", &out("a.exr")]);
    assert!(exr.success && !exr.stdout.contains("denoised "), "{}", exr.stdout);
    let off = render(&["-o", &out("b.png"), "--denoise", "off"]);
    assert!(off.success && !off.stdout.contains("denoised "), "{}", off.stdout);
    let exr_on = render(&["-o", &out("b.exr"), "--denoise", "on"]);
    assert!(exr_on.success && exr_on.stdout.contains("denoised "), "{}", exr_on.stdout);
    // The AOV integrators are not noisy light: auto leaves them, on is refused.
    let albedo = render(&["-o", &out("c.png"), "--integrator", "albedo"]);
    assert!(albedo.success && !albedo.stdout.contains("denoised "), "{}", albedo.stdout);
    let refused = render(&["-o", &out("d.png"), "--integrator", "albedo", "--denoise", "on"]);
    assert!(!refused.success && refused.stderr.contains("--denoise on is for the direct and path integrators"));
    let accumulation = render(&["-o", &out("e.accum"), "--denoise", "on"]);
    assert!(
        !accumulation.success && accumulation.stderr.contains("keeps the samples' sums"),
        "{}",
        accumulation.stderr
    );
    assert!(!dir.join("e.accum").exists() && !dir.join("d.png").exists());
}

/// The pixels whose 3 × 3 neighbourhood shows one flat, non-emitting
/// surface (the guides' normals agree): away from edges, where a pixel's
/// error is noise and blur rather than the edge's anti-aliasing.
fn interior(guides: &Guides) -> Vec<bool> {
    let (w, h) = (guides.normal.width() as i64, guides.normal.height() as i64);
    let at = |x: i64, y: i64| guides.normal.get(x as u32, y as u32);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if x == 0
                || y == 0
                || x == w - 1
                || y == h - 1
                || guides.emission.get(x as u32, y as u32).max_element() > 0.0
            {
                return false;
            }
            let n = at(x, y);
            n.length() > 0.99
                && (-1..=1).all(|dy| (-1..=1).all(|dx| at(x + dx, y + dy).dot(n) > 0.99 * n.length_squared()))
        })
        .collect()
}

/// Relative RMS error of the luminance over the pixels `mask` selects.
fn relative_rms_where(image: &HdrImage, reference: &HdrImage, mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for ((a, r), &inside) in image.pixels().iter().zip(reference.pixels()).zip(mask) {
        let r = luminance(*r) as f64;
        if inside && r > 0.0 {
            sum += ((luminance(*a) as f64 - r) / r).powi(2);
            n += 1;
        }
    }
    (sum / n.max(1) as f64).sqrt()
}
