//! The scene rendered when none is named: the Cornell box as measured at
//! Cornell University, compiled into the program so that it works from any
//! folder.

use std::path::Path;

use anyhow::Result;
use rtgi_scene::Scene;
use rtgi_scene::description::Description;

pub(crate) const NAME: &str = "built-in Cornell box (scenes/cornell-box.toml)";

const DESCRIPTION: &str = include_str!("../../../scenes/cornell-box.toml");
const OBJ: &str = include_str!("../../../scenes/cornell-box/cornell-box.obj");
const MTL: &str = include_str!("../../../scenes/cornell-box/cornell-box.mtl");

pub(crate) fn load() -> Result<Scene> {
    let description = Description::parse(DESCRIPTION, Path::new("scenes/cornell-box.toml"))?;
    let mut scene = rtgi_scene::obj::load_from_text(OBJ, MTL, "scenes/cornell-box/cornell-box.obj")?;
    scene.cameras.extend(description.camera());
    Ok(scene)
}
