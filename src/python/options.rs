//! Request objects of the binding: the options of a call come as one `dict` built by the
//! Python wrapper, read here into a typed struct per call. A value's own conversion error is
//! passed on unchanged (so a bad `method` still reads `"method: unknown method …"`), a
//! missing required key raises `KeyError` naming it.

use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The `dict` of options of one call.
pub struct Options<'py>(Bound<'py, PyDict>);

impl<'py> FromPyObject<'_, 'py> for Options<'py> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'_, 'py, PyAny>) -> PyResult<Self> {
        Ok(Options(obj.cast::<PyDict>()?.to_owned()))
    }
}

impl<'py> Options<'py> {
    /// The value of a required option.
    pub fn get<T: FromPyObjectOwned<'py>>(&self, key: &str) -> PyResult<T> {
        match self.0.get_item(key)? {
            Some(v) => v.extract().map_err(Into::into),
            None => Err(PyKeyError::new_err(format!("options: missing '{key}'"))),
        }
    }

    /// The value of an option, `default` when absent or `None`.
    pub fn get_or<T: FromPyObjectOwned<'py>>(&self, key: &str, default: T) -> PyResult<T> {
        match self.0.get_item(key)? {
            Some(v) if !v.is_none() => v.extract().map_err(Into::into),
            _ => Ok(default),
        }
    }

    /// The value of an optional option (`None` when absent or `None`).
    pub fn opt<T: FromPyObjectOwned<'py>>(&self, key: &str) -> PyResult<Option<T>> {
        match self.0.get_item(key)? {
            Some(v) if !v.is_none() => v.extract().map_err(Into::into).map(Some),
            _ => Ok(None),
        }
    }
}
