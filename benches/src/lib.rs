//! Helpers shared by the benchmarks: finding scenes.

use std::path::{Path, PathBuf};

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
