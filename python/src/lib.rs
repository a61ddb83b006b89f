//! The Python package `rtgi` (its extension module `rtgi._rtgi`): scenes,
//! acceleration structures, ray queries, ray generators, renders, the
//! verifier and the experiments, on NumPy arrays, through the typed
//! library API (`rtgi-scene`, `rtgi-accel`, `rtgi-render`, `rtgi-job`,
//! `rtgi-experiment`), never the command line.
//!
//! Errors become Python exceptions with the library's message
//! ([`errors`]); arrays are read without copies where their layout allows
//! ([`arrays`]); tracing releases the GIL and runs on rayon's threads
//! ([`accel`]). The Python side (`rtgi/__init__.py`, the `.pyi` stubs) is
//! beside this crate; `pip install ./python` builds both with maturin.

// The workspace's `deny(unsafe_code)` holds here too: pyo3's macros mark
// the FFI glue they generate themselves, and this crate has no `unsafe`.

use pyo3::prelude::*;

pub mod accel;
pub mod arrays;
pub mod errors;
pub mod render;
pub mod scene;
pub mod tools;

/// The extension module: its classes, functions and exceptions, which
/// `rtgi/__init__.py` re-exports.
#[pymodule]
fn _rtgi(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("RtgiError", py.get_type::<errors::RtgiError>())?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("RequestError", py.get_type::<errors::RequestError>())?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<accel::Accel>()?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(scene::cornell_box, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(tools::verify, m)?)?;
    m.add_function(wrap_pyfunction!(tools::experiment, m)?)?;
    m.add_function(wrap_pyfunction!(tools::names, m)?)?;
    m.add("MISS", accel::MISS)?;
    m.add("BATCH_RAYS", rtgi_accel::parallel::BATCH_RAYS)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("EMBREE", cfg!(feature = "embree"))?;
    Ok(())
}
