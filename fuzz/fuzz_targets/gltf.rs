#![no_main]
//! glTF: binary `.glb` when the input starts with its magic, JSON `.gltf`
//! otherwise; `*.bin` and `*.png` references are answered from memory.

use libfuzzer_sys::fuzz_target;
use rtgi_fuzz::{REFERENCED_MTL, referenced};
use rtgi_scene::Scene;

fuzz_target!(|data: &[u8]| {
    let name = if data.starts_with(b"glTF") { "input.glb" } else { "input.gltf" };
    let _ = Scene::load_from_bytes(name, data, &|name| referenced(name, REFERENCED_MTL.as_bytes()));
});
