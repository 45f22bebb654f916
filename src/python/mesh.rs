//! Mesh measures (`spinal.Mesh`); the algorithms are in [`crate::math::mesh`].

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use super::convert::{triangles, vec3s};
use crate::math::mesh;

/// Signed volume of a closed triangle mesh, summed about the mean vertex.
#[pyfunction]
pub fn mesh_volume(
    py: Python<'_>,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, i64>,
) -> PyResult<f64> {
    let v = vec3s("vertices", &vertices)?;
    let f = triangles(&faces)?;
    Ok(py.detach(|| mesh::signed_volume_checked(v, f))?)
}
