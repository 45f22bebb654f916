//! Output buffers a caller hands in (`out=`): the array a call writes its result into is
//! either a fresh one or the caller's, checked to be exactly what a fresh one would be
//! (shape, dtype, C order) and writeable, so that the core writes into it with no copy.

use numpy::ndarray::Dimension;
use numpy::{Element, PyArray, PyArrayMethods, PyReadwriteArray, PyUntypedArrayMethods};
use pyo3::prelude::*;

use super::convert::{empty, value_error};

/// A shape as Python prints it: `(4, 3)`, `(5,)`.
fn tuple(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// The array `call` writes a result of `shape` into: `given` (named `name` in the errors)
/// when the caller passed one, else a fresh array. `given` must be a C-contiguous, writeable
/// NumPy array of exactly that shape and of dtype `T`; anything else is a `ValueError`.
pub fn output<'py, T: Element, D: Dimension>(
    py: Python<'py>,
    call: &'static str,
    shape: &[usize],
    given: Option<Bound<'py, PyAny>>,
    name: &str,
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let Some(given) = given else {
        return empty(py, call, shape);
    };
    let want = numpy::dtype::<T>(py);
    let expected = || format!("{name}: expected a C-contiguous writeable {want} array of shape");
    let Ok(a) = given.cast::<PyArray<T, D>>() else {
        let got = match given.cast::<numpy::PyUntypedArray>() {
            Ok(u) => format!("{} array of shape {}", u.dtype(), tuple(u.shape())),
            Err(_) => given.get_type().name()?.to_string(),
        };
        return Err(value_error(format!(
            "{} {}, got a {got}",
            expected(),
            tuple(shape)
        )));
    };
    if a.shape() != shape {
        return Err(value_error(format!(
            "{} {}, got shape {}",
            expected(),
            tuple(shape),
            tuple(a.shape())
        )));
    }
    if !a.is_c_contiguous() {
        return Err(value_error(format!(
            "{name}: must be C-contiguous (np.ascontiguousarray makes a copy that is)"
        )));
    }
    if !a
        .getattr("flags")?
        .getattr("writeable")?
        .extract::<bool>()?
    {
        return Err(value_error(format!("{name}: must be writeable")));
    }
    Ok(a.clone())
}

/// `a` borrowed for writing; a `ValueError` naming `name` when it cannot be (it shares its
/// memory with an input the call reads).
pub fn writing<'py, T: Element, D: Dimension>(
    a: &Bound<'py, PyArray<T, D>>,
    name: &str,
) -> PyResult<PyReadwriteArray<'py, T, D>> {
    a.try_readwrite()
        .map_err(|e| value_error(format!("{name}: cannot be written ({e})")))
}
