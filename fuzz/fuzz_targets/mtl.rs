#![no_main]
//! MTL text, loaded as the material library of a small OBJ.

use libfuzzer_sys::fuzz_target;
use rtgi_fuzz::{MTL_HOST_OBJ, referenced};
use rtgi_scene::Scene;

fuzz_target!(|data: &[u8]| {
    let _ = Scene::load_from_bytes("host.obj", MTL_HOST_OBJ.as_bytes(), &|name| referenced(name, data));
});
