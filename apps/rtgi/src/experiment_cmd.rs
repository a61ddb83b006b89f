//! `rtgi experiment`: parses the options, prepares the subject as a render
//! would, and hands it to `rtgi-experiment`, which measures and writes.

use std::path::PathBuf;

use anyhow::Result;
use rtgi_experiment::{Knob, Options, Subject};
use rtgi_render::{PixelSampler, RenderSettings};

use crate::cli::{ExperimentArgs, KnobChoice};
use crate::common::{LoadedScene, apply_lighting, choose_camera, load_scene, thread_pool};

pub(crate) fn run(args: &ExperimentArgs) -> Result<()> {
    let knobs: Vec<Knob> = match args.knob {
        KnobChoice::One(knob) => vec![knob],
        KnobChoice::All => Knob::ALL.to_vec(),
    };
    let out_root = args.out.clone().unwrap_or_else(|| PathBuf::from("experiments"));
    let folder = |knob: Knob| match (args.knob, &args.out) {
        (KnobChoice::One(_), Some(out)) => out.clone(),
        _ => out_root.join(knob.name()),
    };
    let pool = thread_pool(args.threads)?;
    let LoadedScene { mut scene, name, .. } = load_scene(args.scene.as_deref())?;
    let side = if args.quick { 32 } else { 128 };
    let (width, height) = (args.width.unwrap_or(side), args.height.unwrap_or(side));
    let mut settings = RenderSettings {
        width,
        height,
        samples_per_pixel: 1,
        sampler: PixelSampler::Stratified,
        ..RenderSettings::default()
    };
    apply_lighting(&args.lighting, &mut scene, &mut settings)?;
    let accel = pool.install(|| args.accel.build(&scene))?;
    let camera = choose_camera(&scene, accel.as_ref(), &args.camera, width as f32 / height as f32)?;
    let subject = Subject { name, scene, camera, accel, settings };
    let options = Options {
        repeats: args.repeats as usize,
        quick: args.quick,
        command: std::env::args().collect::<Vec<_>>().join(" "),
        threads: pool.current_num_threads(),
        cache: (!args.no_cache).then(|| args.cache.clone().unwrap_or_else(|| out_root.join(".references"))),
        reference_spp: args.reference_spp,
    };
    for knob in knobs {
        eprintln!("experiment {knob}: {}", knob.question());
        let report = pool.install(|| rtgi_experiment::run(knob, &subject, &options, &|line| eprintln!("  {line}")))?;
        for finding in &report.findings {
            println!("{knob}: {finding}");
        }
        for path in report.write(&folder(knob))? {
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}
