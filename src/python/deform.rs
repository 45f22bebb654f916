//! Velocity fields, advection and the contact stamper (`spinal.fields`, `spinal.deform`);
//! the algorithms are in [`crate::deform`].

use glam::DVec3;
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use super::convert::{
    Ticker, empty, slice_mut, slice_of, triangles, value_error, vec3_array, vec3s,
};
use crate::deform::{self, advect::Method, refine};

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

type DeformArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<i64>>,
    (usize, usize, usize, bool, f64, f64),
);

/// Deform a closed mesh along a field, refining after every step (see `deform::refine`):
/// `(vertices, rest_vertices, faces, vertices after each step, (passes, torn vertices, edges
/// over the threshold, bounded, integration seconds, refinement seconds))`. `refine=None`
/// only advects. Ctrl-C stops it between steps; `progress(done, total)` is called after
/// every step when given.
#[pyfunction]
#[pyo3(signature = (vertices, faces, rows, t0, duration, steps, refine, max_vertices,
                    max_passes, progress))]
#[allow(clippy::too_many_arguments)]
pub fn deform_mesh<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    rows: PyReadonlyArray2<'py, f64>,
    t0: f64,
    duration: f64,
    steps: usize,
    refine: Option<f64>,
    max_vertices: usize,
    max_passes: usize,
    progress: Option<Py<PyAny>>,
) -> PyResult<DeformArrays<'py>> {
    let field = field_of(&rows)?;
    let x = vec3s("mesh", &vertices)?;
    // negative indices become out of range, which the core reports
    let f: Vec<[usize; 3]> = triangles(&faces)?
        .iter()
        .map(|t| t.map(|i| usize::try_from(i).unwrap_or(usize::MAX)))
        .collect();
    let opts = refine.map(|ratio| refine::Refinement {
        ratio,
        max_vertices,
        max_passes,
    });
    let mut ticker = Ticker::new(progress);
    let out = py.detach(|| {
        let runs = refine::schedule(&field, t0, duration, steps);
        refine::deform(&field, x, &f, &runs, opts, &mut |d, n| ticker.tick(d, n))
    })?;
    ticker.finish()?;
    let d = out.ok_or_else(|| value_error("deform: stopped"))?;
    let faces: Vec<i64> = d.faces.iter().flatten().map(|&i| i as i64).collect();
    let nf = d.faces.len();
    let counts: Vec<i64> = d.step_vertices.iter().map(|&c| c as i64).collect();
    Ok((
        vec3_array(py, d.vertices)?,
        vec3_array(py, d.rest)?,
        PyArray1::from_vec(py, faces).reshape([nf, 3])?,
        PyArray1::from_vec(py, counts),
        (
            d.passes,
            d.torn,
            d.over_threshold,
            d.bounded,
            d.time_integrate,
            d.time_refine,
        ),
    ))
}

/// The slopes `dγ/dS` of the clamped C² spline through a strip axis, which is checked for a
/// tube of `radius + reach` (see `deform::tube::strip_axis`; errors name `points`).
#[pyfunction]
pub fn strip_axis<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    s: PyReadonlyArray1<'py, f64>,
    m0: [f64; 3],
    m1: [f64; 3],
    radius: f64,
    reach: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let x = vec3s("points", &points)?;
    let s = slice_of("points", &s)?;
    let axis = py.detach(|| {
        deform::tube::strip_axis(x, s, DVec3::from(m0), DVec3::from(m1), radius, reach)
    })?;
    vec3_array(py, axis.into_iter().map(|a| a.m).collect())
}

type StampArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Contact stamper (see `deform::stamp`): a new vertex array and per-frame rows
/// `(dent, time, residual, contact)`. Ctrl-C stops it between frames.
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
    let mut ticker = Ticker::new(None);
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
            &mut |d, n| ticker.tick(d, n),
        )
    })?;
    ticker.finish()?;
    if rep.len() < frames {
        return Err(value_error("stamp: stopped"));
    }
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
