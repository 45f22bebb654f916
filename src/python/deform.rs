//! Velocity fields, advection and the contact stamper (`spinal.fields`, `spinal.deform`);
//! the algorithms are in [`crate::deform`].

use glam::DVec3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use super::convert::{empty, slice_mut, slice_of, triangles, value_error, vec3_array, vec3s};
use crate::deform::{self, advect::Method};

/// A field from its `(k, ROW)` element rows (see `_core.pyi` for the layouts).
fn field_of(rows: &PyReadonlyArray2<'_, f64>) -> PyResult<deform::Field> {
    if rows.shape()[1] != deform::ROW {
        return Err(value_error(format!(
            "field: expected element rows of shape (k, {}), got {:?}",
            deform::ROW,
            rows.shape()
        )));
    }
    Ok(deform::Field::parse(slice_of("field", rows)?)?)
}

/// Velocities of a field at points; see `spinal.fields`.
#[pyfunction]
pub fn field_eval<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    rows: PyReadonlyArray2<'py, f64>,
    t: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let field = field_of(&rows)?;
    let x = vec3s("points", &points)?;
    let out = empty::<f64, numpy::Ix2>(py, &[x.len(), 3])?;
    {
        let mut w = out.readwrite();
        let o: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        py.detach(|| deform::advect::eval_into(&field, x, t, o));
    }
    Ok(out)
}

/// `(max_speed, length_scale, default steps for duration)` of a field.
#[pyfunction]
pub fn field_info(rows: PyReadonlyArray2<'_, f64>, duration: f64) -> PyResult<(f64, f64, usize)> {
    let field = field_of(&rows)?;
    Ok((
        field.max_speed(),
        field.length_scale(),
        field.default_steps(duration),
    ))
}

/// Advect points: `steps` steps of size `h` from `t0`; a new array.
#[pyfunction]
pub fn advect<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    rows: PyReadonlyArray2<'py, f64>,
    t0: f64,
    h: f64,
    steps: usize,
    method: Method,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let field = field_of(&rows)?;
    if method == Method::Split && !field.has_potential() {
        return Err(value_error(
            "method: 'split' needs curl potentials; only fields.translation tools have one",
        ));
    }
    let x = vec3s("vertices", &points)?;
    let out = empty::<f64, numpy::Ix2>(py, &[x.len(), 3])?;
    {
        let mut w = out.readwrite();
        let o: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        o.copy_from_slice(x);
        py.detach(|| deform::advect::advect_in_place(&field, o, t0, h, steps, method));
    }
    Ok(out)
}

type StampArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Contact stamper (see `deform::stamp`): a new vertex array and per-frame rows
/// `(dent, time, residual, contact)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn stamp<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    start: [f64; 3],
    end: [f64; 3],
    radius: f64,
    reach: f64,
    frames: usize,
    iterations: usize,
) -> PyResult<StampArrays<'py>> {
    let x = vec3s("vertices", &vertices)?;
    // negative indices become out of range, which the stamper reports
    let f: Vec<[usize; 3]> = triangles(&faces)?
        .iter()
        .map(|t| t.map(|i| usize::try_from(i).unwrap_or(usize::MAX)))
        .collect();
    let mut v = x.to_vec();
    let rep = py.detach(|| {
        deform::stamp::stamp(
            &mut v,
            &f,
            DVec3::from(start),
            DVec3::from(end),
            radius,
            reach,
            frames,
            iterations,
        )
    })?;
    let n = rep.len();
    let rows: Vec<f64> = rep
        .iter()
        .flat_map(|r| [r.dent, r.time, r.residual, r.contact as f64])
        .collect();
    Ok((
        vec3_array(py, v)?,
        PyArray1::from_vec(py, rows).reshape([n, 4])?,
    ))
}
