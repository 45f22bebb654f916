//! Mesh measures (`spinal.Mesh`); the algorithms are in [`crate::math::mesh`].

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use super::convert::{Stop, detach_stoppable, ensure_memory, triangles, vec3s};
use crate::mesh::closed::{self, CALL as CLOSED};
use crate::mesh::{intersect, measure};

/// Signed volume of a closed triangle mesh, summed about the mean vertex
/// ([`measure::volume`]).
#[pyfunction]
pub fn mesh_volume(
    py: Python<'_>,
    vertices: PyReadonlyArray2<'_, f64>,
    faces: PyReadonlyArray2<'_, i64>,
) -> PyResult<f64> {
    let v = vec3s("vertices", &vertices)?;
    let f = triangles(&faces)?;
    let stop = Stop::default();
    Ok(detach_stoppable(py, &stop, || {
        measure::volume(v, f, &|| stop.requested())
    })??)
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
    // the edge pass's distribution of the face slots and its count per vertex, as for
    // `mesh_edges`
    ensure_memory(
        CLOSED,
        f.len().saturating_mul(3).saturating_add(v.len()),
        16,
    )?;
    let stop = Stop::default();
    let (vol, c) = detach_stoppable(py, &stop, || {
        closed::closed_volume_centroid(v, f, &|| stop.requested())
    })??;
    Ok((vol, c.to_array()))
}

/// The `(k, 3)` rows of a C-contiguous array (errors name `arg`).
fn rows<'a, T: numpy::Element + bytemuck::Pod>(
    arg: &str,
    a: &'a PyReadonlyArray2<'_, T>,
) -> PyResult<&'a [[T; 3]]> {
    use numpy::PyUntypedArrayMethods;
    if a.shape()[1] != 3 {
        return Err(super::convert::value_error(format!(
            "{arg}: expected shape (n, 3), got {:?}",
            a.shape()
        )));
    }
    Ok(bytemuck::cast_slice(super::convert::slice_of(arg, a)?))
}

/// Vertices as NumPy holds them: `float64` or `float32`.
enum Vertices<'py> {
    F64(PyReadonlyArray2<'py, f64>),
    F32(PyReadonlyArray2<'py, f32>),
}

/// Faces as NumPy holds them: `int64` or `int32`.
enum Faces<'py> {
    I64(PyReadonlyArray2<'py, i64>),
    I32(PyReadonlyArray2<'py, i32>),
}

fn vertices_of<'py>(a: &Bound<'py, PyAny>) -> PyResult<Vertices<'py>> {
    if let Ok(v) = a.extract::<PyReadonlyArray2<'py, f64>>() {
        return Ok(Vertices::F64(v));
    }
    a.extract::<PyReadonlyArray2<'py, f32>>()
        .map(Vertices::F32)
        .map_err(|_| {
            super::convert::value_error("vertices: expected a float64 or float32 (n, 3) array")
        })
}

fn faces_of<'py>(a: &Bound<'py, PyAny>) -> PyResult<Faces<'py>> {
    if let Ok(f) = a.extract::<PyReadonlyArray2<'py, i64>>() {
        return Ok(Faces::I64(f));
    }
    a.extract::<PyReadonlyArray2<'py, i32>>()
        .map(Faces::I32)
        .map_err(|_| super::convert::value_error("faces: expected an int64 or int32 (F, 3) array"))
}

/// `$body` with `$v` / `$f` bound to the row slices of every dtype combination.
macro_rules! with_mesh {
    ($vs:expr, $fs:expr, |$v:ident, $f:ident| $body:expr) => {
        match ($vs, $fs) {
            (Vertices::F64(a), Faces::I64(b)) => {
                let ($v, $f) = (rows::<f64>("vertices", a)?, rows::<i64>("faces", b)?);
                $body
            }
            (Vertices::F64(a), Faces::I32(b)) => {
                let ($v, $f) = (rows::<f64>("vertices", a)?, rows::<i32>("faces", b)?);
                $body
            }
            (Vertices::F32(a), Faces::I64(b)) => {
                let ($v, $f) = (rows::<f32>("vertices", a)?, rows::<i64>("faces", b)?);
                $body
            }
            (Vertices::F32(a), Faces::I32(b)) => {
                let ($v, $f) = (rows::<f32>("vertices", a)?, rows::<i32>("faces", b)?);
                $body
            }
        }
    };
}

/// `"volume"` (signed, about the mean vertex) or `"area"` of a triangle mesh with `float64`
/// or `float32` vertices and `int64` or `int32` faces (indices checked, errors name `faces`).
#[pyfunction]
pub fn mesh_measure(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<f64> {
    let (vs, fs) = (vertices_of(vertices)?, faces_of(faces)?);
    let area = match what {
        "volume" => false,
        "area" => true,
        _ => {
            return Err(super::convert::value_error(format!(
                "what: unknown measure {what:?}"
            )));
        }
    };
    let stop = Stop::default();
    let cancel = || stop.requested();
    with_mesh!(&vs, &fs, |v, f| Ok(detach_stoppable(py, &stop, || {
        if area {
            measure::area(v, f, &cancel)
        } else {
            measure::volume(v, f, &cancel)
        }
    })??))
}

/// The pairs of faces that cross (`(K, 2)` int64, sorted; see
/// [`crate::mesh::intersect`]) and whether the list stopped at `limit` pairs. Ctrl-C stops it
/// between blocks of faces.
#[pyfunction]
pub fn mesh_self_intersections<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    limit: usize,
) -> PyResult<(Bound<'py, PyArray2<i64>>, bool)> {
    let (vs, fs) = (vertices_of(vertices)?, faces_of(faces)?);
    let stop = Stop::default();
    let cancel = || stop.requested();
    let found = with_mesh!(&vs, &fs, |v, f| detach_stoppable(py, &stop, || {
        intersect::self_intersections(v, f, limit, &cancel)
    })??);
    // a stop raised KeyboardInterrupt above; `None` is then not reached
    let (pairs, truncated) = found.unwrap_or_default();
    let flat: Vec<i64> = pairs.iter().flatten().map(|&i| i as i64).collect();
    let n = pairs.len();
    Ok((PyArray1::from_vec(py, flat).reshape([n, 2])?, truncated))
}

/// Edge statistics of the faces over `n` vertices: `(edges, boundary, non_manifold,
/// inconsistent, degenerate)` (see `crate::mesh::measure::EdgeStats`).
#[pyfunction]
pub fn mesh_edges(
    py: Python<'_>,
    faces: &Bound<'_, PyAny>,
    n: usize,
) -> PyResult<(usize, usize, usize, usize, usize)> {
    let faces = faces_of(faces)?;
    // a slot count per vertex and a key per face corner (sorted in place)
    let slots = match &faces {
        Faces::I64(a) => 3 * a.shape()[0],
        Faces::I32(a) => 3 * a.shape()[0],
    };
    ensure_memory("mesh edges", slots.saturating_add(n), 16)?;
    let stop = Stop::default();
    let cancel = || stop.requested();
    let e = match faces {
        Faces::I64(a) => {
            let f = rows::<i64>("faces", &a)?;
            detach_stoppable(py, &stop, || measure::edges(f, n, &cancel))??
        }
        Faces::I32(a) => {
            let f = rows::<i32>("faces", &a)?;
            detach_stoppable(py, &stop, || measure::edges(f, n, &cancel))??
        }
    };
    Ok((
        e.edges,
        e.boundary,
        e.non_manifold,
        e.inconsistent,
        e.degenerate,
    ))
}

/// Refuse a NaN or an infinity in an `(n, k)` float64 or float32 array of a mesh (vertices,
/// normals, uv), naming `arg` and the first such row.
#[pyfunction]
pub fn mesh_check_finite(py: Python<'_>, values: &Bound<'_, PyAny>, arg: &str) -> PyResult<()> {
    let stop = Stop::default();
    let cancel = || stop.requested();
    let row = if let Ok(a) = values.extract::<numpy::PyReadonlyArray2<'_, f64>>() {
        let width = a.shape()[1];
        let v = super::convert::slice_of(arg, &a)?;
        detach_stoppable(py, &stop, || {
            measure::first_non_finite_row(v, width, &cancel)
        })?
    } else {
        let a = values.extract::<numpy::PyReadonlyArray2<'_, f32>>()?;
        let width = a.shape()[1];
        let v = super::convert::slice_of(arg, &a)?;
        detach_stoppable(py, &stop, || {
            measure::first_non_finite_row(v, width, &cancel)
        })?
    };
    match row {
        Some(i) => Err(super::convert::value_error(format!(
            "{arg}: non-finite value (NaN or inf) at row {i}"
        ))),
        None => Ok(()),
    }
}

/// Refuse face indices outside `0..n` (errors name `faces`).
#[pyfunction]
pub fn mesh_check_faces(py: Python<'_>, faces: &Bound<'_, PyAny>, n: usize) -> PyResult<()> {
    let stop = Stop::default();
    let cancel = || stop.requested();
    match faces_of(faces)? {
        Faces::I64(a) => {
            let f = rows::<i64>("faces", &a)?;
            Ok(detach_stoppable(py, &stop, || {
                measure::check_faces(f, n, &cancel)
            })??)
        }
        Faces::I32(a) => {
            let f = rows::<i32>("faces", &a)?;
            Ok(detach_stoppable(py, &stop, || {
                measure::check_faces(f, n, &cancel)
            })??)
        }
    }
}
