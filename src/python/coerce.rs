//! Coercion of Python objects for the methods that have no Python wrapper (`Field.__call__`):
//! the same rules and messages as `spinal._validate.as_points` and `as_real`, done here so
//! that the core never imports the package's Python modules. An array-like becomes a
//! C-contiguous, aligned float64 `(n, 3)` array (integers converted exactly as NumPy's
//! `astype` does); a real number becomes an `f64`.

use numpy::{PyArrayDescrMethods, PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods, dtype};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBool, PyBytes, PyString, PyType};

fn type_name(x: &Bound<'_, PyAny>) -> String {
    x.get_type()
        .name()
        .map_or_else(|_| "?".to_string(), |n| n.to_string())
}

/// For a mesh or polyline object passed where an array is expected: what it is and which of
/// its arrays to pass (`""` for other objects).
fn object_hint(x: &Bound<'_, PyAny>) -> String {
    let ty = x.get_type();
    let module = ty
        .module()
        .map_or_else(|_| String::new(), |m| m.to_string());
    let root = module.split('.').next().unwrap_or("");
    let kind = format!("{root}.{}", type_name(x));
    if kind == "trimesh.Trimesh" || kind == "spinal.Mesh" {
        return format!(
            "{kind}; pass its vertices (mesh.vertices), or the mesh itself where a mesh is \
             expected (deform, stamp, fields.mesh_curl)"
        );
    }
    if kind == "trimesh.Path3D" {
        return format!("{kind}; pass the points of one polyline (path.discrete[0])");
    }
    if kind.starts_with("pyvista.") || kind.starts_with("vtkmodules.") {
        return format!(
            "{kind}; pass its points (data.points), or for the lines of a PolyData a list of \
             one (n, 3) array per line"
        );
    }
    String::new()
}

/// `x` as a float64 ndarray (a new array or a read-only view; never written to).
fn float_array<'py>(x: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    let py = x.py();
    if x.is_instance_of::<PyString>() || x.is_instance_of::<PyBytes>() {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected an array of real numbers, got {}",
            type_name(x)
        )));
    }
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    let asarray = ASARRAY.import(py, "numpy", "asarray")?;
    let arr = match asarray.call1((x,)) {
        Ok(a) => a.cast_into::<PyUntypedArray>()?,
        Err(e) if e.is_instance_of::<PyValueError>(py) || e.is_instance_of::<PyTypeError>(py) => {
            return Err(PyValueError::new_err(format!(
                "{name}: cannot be read as an array ({})",
                e.value(py)
            )));
        }
        Err(e) => return Err(e),
    };
    let f64_dtype = dtype::<f64>(py);
    let descr = arr.dtype();
    let kind = descr.kind();
    if matches!(kind, b'i' | b'u' | b'f') {
        let kw = pyo3::types::PyDict::new(py);
        kw.set_item("copy", false)?;
        let out = arr
            .call_method("astype", (f64_dtype,), Some(&kw))?
            .cast_into::<PyUntypedArray>()?;
        let aligned: bool = out.getattr("flags")?.getattr("aligned")?.extract()?;
        return if aligned {
            Ok(out)
        } else {
            Ok(out.call_method0("copy")?.cast_into::<PyUntypedArray>()?)
        };
    }
    if kind == b'O' {
        if let Ok(out) = arr.call_method1("astype", (f64_dtype,)) {
            return Ok(out.cast_into::<PyUntypedArray>()?);
        }
        if arr.ndim() == 0 {
            let hint = object_hint(x);
            if !hint.is_empty() {
                return Err(PyTypeError::new_err(format!(
                    "{name}: expected an array of real numbers, got a {hint}"
                )));
            }
        }
    }
    Err(PyTypeError::new_err(format!(
        "{name}: expected an array of real numbers, got dtype {}{}",
        descr.str()?,
        if kind == b'c' {
            " (complex values are not accepted)"
        } else {
            ""
        }
    )))
}

/// An `(n, 3)` C-contiguous float64 array (`spinal._validate.as_points`).
pub fn points<'py>(x: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let arr = float_array(x, name)?;
    if arr.ndim() != 2 || arr.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an array of shape (n, 3), got shape {}",
            arr.getattr("shape")?.str()?
        )));
    }
    let arr = if arr.is_c_contiguous() {
        arr
    } else {
        arr.call_method0("copy")?.cast_into::<PyUntypedArray>()?
    };
    arr.extract()
}

/// A float from a real number, not a bool (`spinal._validate.as_real`): the type only, any
/// value.
pub fn real(x: &Bound<'_, PyAny>, name: &str) -> PyResult<f64> {
    static REAL: PyOnceLock<Py<PyType>> = PyOnceLock::new();
    let real = REAL.import(x.py(), "numbers", "Real")?;
    if !x.is_instance_of::<PyBool>() && x.is_instance(real)? {
        return x.extract::<f64>();
    }
    if let Ok(a) = x.cast::<PyUntypedArray>()
        && a.ndim() == 0
        && matches!(a.dtype().kind(), b'i' | b'u' | b'f')
    {
        return a.call_method0("item")?.extract::<f64>();
    }
    Err(PyTypeError::new_err(format!(
        "{name}: expected a real number, got {}",
        type_name(x)
    )))
}
