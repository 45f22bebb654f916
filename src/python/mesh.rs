//! Mesh measures (`spinal.Mesh`); the algorithms are in [`crate::math::mesh`].

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use super::convert::{detach_in_pool, triangles, vec3s};
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
    Ok(detach_in_pool(py, || mesh::signed_volume_checked(v, f))??)
}

/// Volume and centroid of the solid bounded by a closed, outward-wound mesh (errors name
/// `mesh`: not watertight, inconsistently oriented, non-positive volume).
#[pyfunction]
pub fn mesh_closed_centroid(
    py: Python<'_>,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, i64>,
) -> PyResult<(f64, [f64; 3])> {
    let v = vec3s("mesh", &vertices)?;
    let f = triangles(&faces)?;
    let (vol, c) = detach_in_pool(py, || mesh::closed_volume_centroid(v, f))??;
    Ok((vol, c.to_array()))
}
