//! The library's typed errors as Python exceptions, with the library's
//! messages: a scene that cannot be loaded is a `SceneError`; a request,
//! an argument, an array or an option value that cannot be used is a
//! `RequestError`, whose message names the argument. Both derive from
//! `RtgiError`.

use std::fmt::Display;

use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use serde::Serialize;

pyo3::create_exception!(
    rtgi,
    RtgiError,
    PyException,
    "Base class of the errors rtgi raises, each with the library's message."
);
pyo3::create_exception!(
    rtgi,
    SceneError,
    RtgiError,
    "A scene could not be loaded or made: the message names the file (or array) and what is wrong."
);
pyo3::create_exception!(
    rtgi,
    RequestError,
    RtgiError,
    "An argument, an array or a request that cannot be used: the message names the argument and what is wrong."
);

/// A `RequestError` naming `argument`: "argument: why".
pub fn request_error(argument: &str, why: impl Display) -> PyErr {
    RequestError::new_err(format!("{argument}: {why}"))
}

/// A `RequestError` with the library's message as it is.
pub fn request(why: impl Display) -> PyErr {
    RequestError::new_err(why.to_string())
}

/// A scene that could not be loaded.
pub fn scene_error(error: rtgi_scene::SceneError) -> PyErr {
    SceneError::new_err(error.to_string())
}

/// A render that could not be done: its scene's errors are `SceneError`,
/// the others `RequestError`.
pub fn job_error(error: rtgi_job::JobError) -> PyErr {
    match error {
        rtgi_job::JobError::Scene(error) => scene_error(error),
        other => request(other),
    }
}

/// A serialisable value of the libraries (an outcome, a report) as Python
/// objects: dicts, lists, numbers, strings, `None`, through its JSON.
pub fn to_python<'py>(py: Python<'py>, value: &impl Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(request)?;
    py.import("json")?.call_method1("loads", (text,))
}
