//! Which knobs run on which scenes, and where their results go: for one
//! knob on one scene, or for the report (`rtgi experiment all` without a
//! scene), every knob on the shared scenes it is meant for.

use std::path::{Path, PathBuf};

use crate::{Knob, Scenes};

/// One experiment to run.
#[derive(Clone, Debug)]
pub struct Run {
    /// The knob.
    pub knob: &'static dyn Knob,
    /// The scene file (`None`: the built-in Cornell box).
    pub scene: Option<PathBuf>,
    /// The name the report gives the scene (`None`: the scene's own name).
    pub name: Option<String>,
    /// The folder of the results.
    pub folder: PathBuf,
}

/// The runs of `knobs`: with `report`, each knob whose scenes are the
/// subject's on every scene of [`Scenes::Subject`] that exists (the
/// missing ones are returned beside, by path), else on `scene`. A knob's
/// folder is `out_root/KNOB` (with a subfolder per scene where it has
/// several), or `single_folder` when given.
pub fn runs(
    knobs: &[&'static dyn Knob],
    scene: Option<&Path>,
    out_root: &Path,
    single_folder: Option<&Path>,
    report: bool,
) -> (Vec<Run>, Vec<(&'static dyn Knob, PathBuf)>) {
    let (mut runs, mut missing) = (Vec::new(), Vec::new());
    for &knob in knobs {
        let folder = single_folder.map_or_else(|| out_root.join(knob.name()), Path::to_owned);
        let scenes = match knob.scenes() {
            Scenes::Subject(scenes) if report => scenes,
            _ => {
                runs.push(Run { knob, scene: scene.map(Path::to_owned), name: None, folder });
                continue;
            }
        };
        for scene in scenes {
            let (path, name) = report_scene(scene);
            if !path.is_file() {
                missing.push((knob, path));
                continue;
            }
            let stem = path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().to_lowercase());
            let folder = if scenes.len() > 1 { folder.join(stem) } else { folder.clone() };
            runs.push(Run { knob, scene: Some(path), name: Some(name), folder });
        }
    }
    (runs, missing)
}

/// Where a report scene is: `project:NAME` in this workspace's `scenes/`,
/// anything else in the shared scenes ([`scenes_folder`]); and the name it
/// is reported under (not this machine's absolute path).
pub fn report_scene(scene: &str) -> (PathBuf, String) {
    match scene.strip_prefix("project:") {
        Some(name) => (Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name), format!("scenes/{name}")),
        None => {
            let path = scenes_folder().join(scene);
            let name = if std::env::var_os(SCENES_VARIABLE).is_some() {
                path.display().to_string()
            } else {
                format!("../shared/scenes/{scene}")
            };
            (path, name)
        }
    }
}

/// The environment variable that points at the shared scenes' folder.
pub const SCENES_VARIABLE: &str = "RTGI_SCENES";

/// The folder of shared scenes: `$RTGI_SCENES`, else `../shared/scenes`
/// beside the workspace this library was built in, else beside the current folder.
pub fn scenes_folder() -> PathBuf {
    if let Some(folder) = std::env::var_os(SCENES_VARIABLE) {
        return folder.into();
    }
    let built_in = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    if built_in.is_dir() { built_in } else { PathBuf::from("../shared/scenes") }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::KNOBS;

    /// The report runs each knob of the subject's scenes once per scene
    /// that exists, in a subfolder per scene where it has several, and
    /// names the missing ones; outside the report every knob runs once.
    #[test]
    fn the_report_runs_knobs_on_their_scenes() {
        let out = Path::new("out");
        let (report, missing) = runs(KNOBS, None, out, None, true);
        for knob in KNOBS {
            let mine: Vec<&Run> = report.iter().filter(|r| r.knob == *knob).collect();
            let lost = missing.iter().filter(|(k, _)| *k == *knob).count();
            match knob.scenes() {
                Scenes::Own(_) => assert!(mine.len() == 1 && mine[0].scene.is_none(), "{knob}"),
                Scenes::Subject(scenes) => {
                    assert_eq!(mine.len() + lost, scenes.len(), "{knob}");
                    for run in mine {
                        let scene = run.scene.as_ref().unwrap();
                        assert!(scene.is_file() && run.folder.starts_with(out.join(knob.name())), "{run:?}");
                        assert_eq!(run.folder == out.join(knob.name()), scenes.len() == 1, "{run:?}");
                    }
                }
            }
        }
        let (single, none) = runs(KNOBS, Some(Path::new("a.obj")), out, Some(Path::new("here")), false);
        assert!(none.is_empty() && single.len() == KNOBS.len());
        assert!(single.iter().all(|r| r.folder == Path::new("here") && r.scene.as_deref() == Some(Path::new("a.obj"))));
    }
}
