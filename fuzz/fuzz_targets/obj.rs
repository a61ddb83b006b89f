#![no_main]
//! OBJ text, with `*.mtl`, `*.png` references answered from memory.

use libfuzzer_sys::fuzz_target;
use rtgi_fuzz::{REFERENCED_MTL, referenced};
use rtgi_scene::Scene;

fuzz_target!(|data: &[u8]| {
    let _ = Scene::load_from_bytes("input.obj", data, &|name| referenced(name, REFERENCED_MTL.as_bytes()));
});
