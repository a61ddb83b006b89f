//! Renders a glTF file with a chosen acceleration structure through the
//! library, as `rtgi render FILE -o OUT --accel sah --width 256 --height 256 --spp 16`
//! would.
//!
//! `cargo run -p rtgi-job --example render_gltf -- MODEL.gltf out.png`;
//! without arguments, Khronos' DamagedHelmet from the shared scenes
//! (`../shared/scenes`, or `$RTGI_SCENES`) to the temporary folder.

use std::path::PathBuf;

use rtgi_accel::AccelKind;
use rtgi_job::{CancelToken, ImageSize, RenderRequest, SceneSource, Structure, Unobserved, render};

fn shared_helmet() -> PathBuf {
    let scenes = std::env::var_os("RTGI_SCENES")
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"), PathBuf::from);
    scenes.join("gltf/DamagedHelmet/glTF/DamagedHelmet.gltf")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args_os().skip(1);
    let scene = args.next().map_or_else(shared_helmet, PathBuf::from);
    let output = args.next().map_or_else(|| std::env::temp_dir().join("render_gltf.png"), PathBuf::from);

    let mut request = RenderRequest::new(SceneSource::file(scene), output);
    request.structure = Structure::of(AccelKind::Sah);
    request.size = ImageSize::exactly(256, 256);
    request.sampling.samples_per_pixel = Some(16);

    let rendered = render(&request, &Unobserved, &CancelToken::new())?;
    let (scene, build, passes) = (&rendered.outcome.scene, &rendered.outcome.build, &rendered.outcome.render);
    println!("{}: {} triangles, {} built in {:.1} ms", scene.name, scene.triangles, build.variant, build.ms);
    println!("{}x{}: {:.0} ms, {:.2} Mrays/s", passes.width, passes.height, passes.ms, passes.mrays_per_second);
    Ok(())
}

#[test]
fn runs() {
    // Without the shared scenes the test says so and passes, unless CI requires them.
    if !shared_helmet().is_file() && std::env::var_os("RTGI_REQUIRE_SCENES").is_none() {
        eprintln!("skipped: {} is missing (set RTGI_SCENES)", shared_helmet().display());
        return;
    }
    main().expect("the example renders");
}
