//! Helpers shared by the benchmarks: scenes and ray batches.

use std::path::{Path, PathBuf};

use rtgi_math::{Ray, Vec2};
use rtgi_render::{CameraRays, frame_scene};
use rtgi_scene::Scene;

/// The workspace's root folder.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("benches/ sits inside the workspace").to_path_buf()
}

/// A scene of the project's own `scenes/` folder.
pub fn project_scene(relative: &str) -> Scene {
    let path = workspace_root().join("scenes").join(relative);
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A shared scene (`$RTGI_SCENES` or `../shared/scenes`), or `None` after saying why it is skipped.
pub fn shared_scene(relative: &str) -> Option<Scene> {
    let folder =
        std::env::var_os("RTGI_SCENES").map(PathBuf::from).unwrap_or_else(|| workspace_root().join("../shared/scenes"));
    let path = folder.join(relative);
    if !path.is_file() {
        eprintln!("skipping {}: not found (set RTGI_SCENES)", path.display());
        return None;
    }
    Some(Scene::load(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// One ray through the centre of every pixel of a `width` × `height` view
/// from the scene's camera (or the automatic framing), row by row.
pub fn primary_rays(scene: &Scene, width: u32, height: u32) -> Vec<Ray> {
    let camera = scene.cameras.first().copied().unwrap_or_else(|| {
        let accel =
            rtgi_accel::AccelKind::Linear.build(&scene.triangle_positions(), &rtgi_accel::BuildParams::default());
        frame_scene(scene, accel.as_ref(), 40f32.to_radians(), width as f32 / height as f32)
    });
    let rays = CameraRays::new(&camera, width, height);
    (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| rays.ray(x, y, Vec2::splat(0.5))).collect()
}

/// Million rays per second of `trace` over `rays` on a pool of `threads`
/// threads: the median of `repeats` runs (see [`rtgi_render::rays::throughput`]).
pub fn mrays_per_second(rays: &[Ray], threads: usize, repeats: usize, trace: impl Fn(&Ray) -> bool + Sync) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("cannot start threads");
    rtgi_render::rays::throughput(rays, &pool, repeats, trace)
}
