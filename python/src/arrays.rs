//! NumPy arrays in and out. A C-contiguous array of the wanted dtype is
//! read in place (no copy); an array of another floating (or, for
//! indices, integer) dtype or layout, or a nested list, is converted once
//! by NumPy; anything else is refused with a `RequestError` that names the
//! argument, the dtype or shape it has and the one wanted.

use numpy::{
    Element, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::request_error;

/// The dtypes an argument accepts: floats (converted to float32) or
/// integers (converted to uint32 after a check of their range).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Float,
    Index,
}

impl Kind {
    /// Whether NumPy's kind character (`f`, `i`, `u`, `b`, ...) is accepted.
    fn accepts(self, kind: u8) -> bool {
        match self {
            Kind::Float => kind == b'f',
            Kind::Index => kind == b'i' || kind == b'u',
        }
    }

    fn wanted(self) -> &'static str {
        match self {
            Kind::Float => "float32 (other float dtypes are converted)",
            Kind::Index => "uint32 (other integer dtypes are converted)",
        }
    }
}

/// `value` as a NumPy array (`numpy.asarray`: no copy of an array).
fn as_array<'py>(argument: &str, value: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(array) = value.cast::<PyUntypedArray>() {
        return Ok(array.clone());
    }
    let numpy = value.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (value,))
        .map_err(|e| request_error(argument, format!("expected a NumPy array, got {}: {e}", type_name(value))))?;
    array.cast_into::<PyUntypedArray>().map_err(|_| request_error(argument, "expected a NumPy array"))
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value.get_type().name().map_or_else(|_| "an object".to_owned(), |n| n.to_string())
}

/// Checks the dtype kind of `array` and converts it to a C-contiguous
/// array of `T` if it is not one already (the only copy).
fn contiguous<'py, T: Element>(
    argument: &str,
    array: Bound<'py, PyUntypedArray>,
    kind: Kind,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    let py = array.py();
    let dtype = array.dtype();
    if !kind.accepts(dtype.kind()) {
        return Err(request_error(argument, format!("expected an array of {}, got dtype {dtype}", kind.wanted())));
    }
    if dtype.is_equiv_to(&numpy::dtype::<T>(py)) && array.is_c_contiguous() {
        return Ok(array);
    }
    let numpy = py.import("numpy")?;
    let converted = numpy.call_method1("ascontiguousarray", (&array, numpy::dtype::<T>(py)))?;
    Ok(converted.cast_into::<PyUntypedArray>()?)
}

fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
    if parts.len() == 1 { format!("({},)", parts[0]) } else { format!("({})", parts.join(", ")) }
}

/// An N×3 array of float32 (origins, directions, vertices), read in place
/// when it is one, C-contiguous.
pub fn rows3_f32<'py>(argument: &str, value: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray2<'py, f32>> {
    let array = as_array(argument, value)?;
    check_rows3(argument, &array)?;
    let array = contiguous::<f32>(argument, array, Kind::Float)?;
    Ok(array.cast_into::<PyArray2<f32>>()?.readonly())
}

fn check_rows3(argument: &str, array: &Bound<'_, PyUntypedArray>) -> PyResult<()> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(request_error(
            argument,
            format!("expected an array of shape (N, 3), got shape {}", shape_text(shape)),
        ));
    }
    Ok(())
}

/// An M×3 array of vertex indices as uint32: read in place when it is
/// C-contiguous uint32; other integer dtypes are converted, refusing
/// values outside 0..2^32.
pub fn rows3_u32(argument: &str, value: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    let array = as_array(argument, value)?;
    check_rows3(argument, &array)?;
    let dtype = array.dtype();
    if Kind::Index.accepts(dtype.kind()) && !dtype.is_equiv_to(&numpy::dtype::<u32>(array.py())) {
        // Negative or too large indices would wrap in a cast: read them as i64/u64 and check.
        let wide = if dtype.kind() == b'u' {
            let wide = contiguous::<u64>(argument, array, Kind::Index)?.cast_into::<PyArray2<u64>>()?;
            let wide = wide.readonly();
            narrow(argument, wide.as_slice()?.iter().map(|&v| u32::try_from(v).map_err(|_| v.to_string())))?
        } else {
            let wide = contiguous::<i64>(argument, array, Kind::Index)?.cast_into::<PyArray2<i64>>()?;
            let wide = wide.readonly();
            narrow(argument, wide.as_slice()?.iter().map(|&v| u32::try_from(v).map_err(|_| v.to_string())))?
        };
        return Ok(wide);
    }
    let array = contiguous::<u32>(argument, array, Kind::Index)?.cast_into::<PyArray2<u32>>()?;
    let array = array.readonly();
    Ok(array.as_slice()?.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

fn narrow(argument: &str, values: impl Iterator<Item = Result<u32, String>>) -> PyResult<Vec<[u32; 3]>> {
    let values: Vec<u32> = values
        .collect::<Result<_, String>>()
        .map_err(|v| request_error(argument, format!("index {v} is outside 0 to {}", u32::MAX)))?;
    Ok(values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// A per-ray bound (`tmin`, `tmax`): one number for every ray, or an
/// array of one float32 per ray.
#[derive(Debug)]
pub enum PerRay<'py> {
    /// The same value for every ray.
    Same(f32),
    /// One value per ray.
    Each(PyReadonlyArray1<'py, f32>),
}

impl<'py> PerRay<'py> {
    /// `value` (`None`: `default`) for `rays` rays.
    pub fn read(argument: &str, value: Option<&Bound<'py, PyAny>>, default: f32, rays: usize) -> PyResult<Self> {
        let Some(value) = value.filter(|v| !v.is_none()) else { return Ok(PerRay::Same(default)) };
        if let Ok(number) = value.extract::<f32>()
            && value.cast::<PyUntypedArray>().is_err()
        {
            if number.is_nan() {
                return Err(request_error(argument, "expected a number, got NaN"));
            }
            return Ok(PerRay::Same(number));
        }
        let array = as_array(argument, value)?;
        if array.shape() != [rays] {
            return Err(request_error(
                argument,
                format!("expected a number or an array of shape ({rays},), got shape {}", shape_text(array.shape())),
            ));
        }
        let array = contiguous::<f32>(argument, array, Kind::Float)?;
        Ok(PerRay::Each(array.cast_into::<PyArray1<f32>>()?.readonly()))
    }

    /// The values as a slice to index, or the one value.
    pub fn view(&self) -> PyResult<Bounds<'_>> {
        Ok(match self {
            PerRay::Same(value) => Bounds::Same(*value),
            PerRay::Each(array) => Bounds::Each(array.as_slice()?),
        })
    }
}

/// [`PerRay`] as plain data, to read without the GIL.
#[derive(Clone, Copy, Debug)]
pub enum Bounds<'a> {
    /// The same value for every ray.
    Same(f32),
    /// One value per ray.
    Each(&'a [f32]),
}

impl Bounds<'_> {
    /// The value of ray `index`.
    #[inline]
    pub fn get(&self, index: usize) -> f32 {
        match self {
            Bounds::Same(value) => *value,
            Bounds::Each(values) => values[index],
        }
    }
}

/// `values` (3 per row) as an N×3 float32 array, without a copy.
pub fn rows3_array(py: Python<'_>, values: Vec<f32>) -> PyResult<Bound<'_, PyArray2<f32>>> {
    let rows = values.len() / 3;
    PyArray1::from_vec(py, values).reshape([rows, 3])
}

/// Three optional numbers (`at`, `look`, `up`) as a vector, finite.
pub fn vec3(argument: &str, value: Option<[f32; 3]>) -> PyResult<Option<rtgi_math::Vec3>> {
    match value {
        Some(v) if v.iter().all(|c| c.is_finite()) => Ok(Some(rtgi_math::Vec3::from_array(v))),
        Some(v) => Err(request_error(argument, format!("expected three finite numbers, got {v:?}"))),
        None => Ok(None),
    }
}
