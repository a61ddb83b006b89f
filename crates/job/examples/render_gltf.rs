//! Renders a glTF file with a chosen acceleration structure through the
//! library, as `rtgi render FILE -o OUT --accel sah --width 160 --spp 16` would.
//!
//! `cargo run -p rtgi-job --example render_gltf -- MODEL.gltf out.png`;
//! without arguments, Khronos' DamagedHelmet from the shared scenes
//! (`../shared/scenes`, or `$RTGI_SCENES`) to the temporary folder.

use std::path::PathBuf;

use rtgi_accel::AccelKind;
use rtgi_job::{CancelToken, RenderRequest, SceneSource, Structure, Unobserved, render};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args_os().skip(1);
    let scenes = std::env::var_os("RTGI_SCENES")
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"), PathBuf::from);
    let scene = args.next().map_or_else(|| scenes.join("gltf/DamagedHelmet/glTF/DamagedHelmet.gltf"), PathBuf::from);
    let output = args.next().map_or_else(|| std::env::temp_dir().join("render_gltf.png"), PathBuf::from);

    let mut request = RenderRequest::new(SceneSource::file(scene), output);
    request.structure = Structure::of(AccelKind::Sah);
    request.size.width = Some(160);
    request.sampling.samples_per_pixel = Some(16);

    let rendered = render(&request, &Unobserved, &CancelToken::new())?;
    let (scene, build, passes) = (&rendered.outcome.scene, &rendered.outcome.build, &rendered.outcome.render);
    println!("{}: {} triangles, {} built in {:.1} ms", scene.name, scene.triangles, build.variant, build.ms);
    println!("{}x{}: {:.0} ms, {:.2} Mrays/s", passes.width, passes.height, passes.ms, passes.mrays_per_second);
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example renders");
}
