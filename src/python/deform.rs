//! Velocity fields, advection and the contact stamper (`spinal.fields`, `spinal.deform`);
//! the algorithms are in [`crate::deform`].

use glam::DVec3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::convert::{
    Stop, Ticker, detach_stoppable, slice_mut, triangles, value_error, vec3_array, vec3s,
};
use super::fields::PyField;
use super::options::Options;
use super::out::{output, writing};
use crate::deform::{self, advect::Method, refine};
use crate::run::alloc;

/// Advect points: `steps` steps of size `h` from `t0`, into a new array (or `out`: see
/// [`advect_runs`], which also reports progress: one run gives the same bits). Ctrl-C stops
/// it between blocks of steps (`KeyboardInterrupt`).
#[pyfunction]
#[pyo3(signature = (points, field, t0, h, steps, method, out=None))]
#[allow(clippy::too_many_arguments)] // seven from Python, and the GIL token
pub fn advect<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    field: PyRef<'py, PyField>,
    t0: f64,
    h: f64,
    steps: usize,
    method: Method,
    out: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let run = deform::advect::Run {
        t0,
        h,
        count: steps,
    };
    advect_runs_impl(py, points, &field, &[run], method, None, 0, out)
}

/// Advect points through runs of equal steps one after the other, `runs` a list of
/// `(t0, h, steps)` (the sub-intervals between a field's breakpoints), in one call: the
/// points are put in their spatial order once. The bits are those of [`advect`] called for
/// each run in turn. `progress(done, total)` counts the steps of all the runs. `out`: the
/// `(n, 3)` float64 array to write the positions into (else a new one).
#[pyfunction]
#[pyo3(signature = (points, field, runs, method, progress=None, every=0, out=None))]
#[allow(clippy::too_many_arguments)]
pub fn advect_runs<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    field: PyRef<'py, PyField>,
    runs: Vec<(f64, f64, usize)>,
    method: Method,
    progress: Option<Py<PyAny>>,
    every: usize,
    out: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let total = runs
        .iter()
        .try_fold(0usize, |s, r| s.checked_add(r.2))
        .filter(|&n| n <= deform::MAX_STEPS);
    if total.is_none() {
        return Err(value_error(format!(
            "runs: at most {} steps in all",
            deform::MAX_STEPS
        )));
    }
    let runs: Vec<deform::advect::Run> = runs
        .into_iter()
        .map(|(t0, h, count)| deform::advect::Run { t0, h, count })
        .collect();
    advect_runs_impl(py, points, &field, &runs, method, progress, every, out)
}

/// The work of [`advect`] and [`advect_runs`]; `out`: the `(n, 3)` float64 array to write
/// the positions into (else a new one).
#[allow(clippy::too_many_arguments)]
fn advect_runs_impl<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    field: &PyField,
    runs: &[deform::advect::Run],
    method: Method,
    progress: Option<Py<PyAny>>,
    every: usize,
    out: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let field = &field.field;
    deform::advect::check_method(field, method)?;
    let x = vec3s("vertices", &points)?;
    deform::finite_rows("vertices", x)?;
    let out = output::<f64, numpy::Ix2>(py, "advect", &[x.len(), 3], out, "out")?;
    let stop = Stop::default();
    let mut ticker = Ticker::every(progress, every, &stop);
    {
        let mut w = writing(&out, "out")?;
        let o: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        o.copy_from_slice(x);
        detach_stoppable(py, &stop, || {
            deform::advect::advect_runs_ticked(field, o, runs, method, every, &mut |d, n| {
                ticker.tick(d, n)
            })
        })?;
    }
    ticker.finish()?;
    Ok(out)
}

type DeformArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyDict>,
);

/// Deform a closed mesh along a field, refining after every step (see `deform::refine`):
/// `(vertices, rest_vertices, faces, vertices after each step, statistics)`. The statistics
/// are a dict: `passes`, `torn` (vertices), `over_threshold` (edges over the threshold),
/// `bounded`, `time_integrate` and `time_refine` (seconds), `slip_vertices` (vertices on a
/// slip surface), `fallback` (vertices at a torn edge's chord midpoint), `flips`,
/// `flip_volume` (their volume change), `collapses`, `moves`, `collapse_volume` (the volume
/// change of the collapses and moves), `bent` and `bend_splits`. `options`: `t0`,
/// `duration`, `steps`, `refine` (`None` only advects), `max_vertices`, `max_passes` and
/// `check` (default true). With `check`, a mesh that is open, not edge-manifold,
/// inconsistently wound or wound inwards is refused first (errors name `mesh`). Ctrl-C stops
/// it between steps; `progress(done, total)` is called after every step when given.
#[pyfunction]
#[pyo3(signature = (vertices, faces, field, options, progress=None))]
pub fn deform_mesh<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    field: PyRef<'py, PyField>,
    options: Options<'py>,
    progress: Option<Py<PyAny>>,
) -> PyResult<DeformArrays<'py>> {
    let t0: f64 = options.get("t0")?;
    let duration: f64 = options.get("duration")?;
    let steps: usize = options.get("steps")?;
    let refine: Option<f64> = options.opt("refine")?;
    let max_vertices: usize = options.get("max_vertices")?;
    let max_passes: usize = options.get("max_passes")?;
    let check: bool = options.get_or("check", true)?;
    let field = &field.field;
    let x = vec3s("mesh", &vertices)?;
    // negative indices become out of range, which the core reports
    let f: Vec<[usize; 3]> = alloc::collect(
        "deform",
        triangles(&faces)?
            .iter()
            .map(|t| t.map(|i| usize::try_from(i).unwrap_or(usize::MAX))),
    )?;
    let opts = refine.map(|ratio| refine::Refinement {
        ratio,
        max_vertices,
        max_passes,
    });
    let stop = Stop::default();
    let mut ticker = Ticker::new(progress, &stop);
    let out = detach_stoppable(py, &stop, || {
        let runs = refine::schedule(field, t0, duration, steps)?;
        refine::deform(field, x, &f, &runs, opts, check, &mut |d, n| {
            ticker.tick(d, n)
        })
    })??;
    ticker.finish()?;
    let d = out.ok_or_else(|| value_error("deform: stopped"))?;
    let faces = alloc::flat("deform", d.faces.iter().map(|f| f.map(|i| i as i64)))?;
    let nf = d.faces.len();
    let counts = alloc::collect("deform", d.step_vertices.iter().map(|&c| c as i64))?;
    let stats = PyDict::new(py);
    stats.set_item("passes", d.passes)?;
    stats.set_item("torn", d.torn)?;
    stats.set_item("over_threshold", d.over_threshold)?;
    stats.set_item("bounded", d.bounded)?;
    stats.set_item("time_integrate", d.time_integrate)?;
    stats.set_item("time_refine", d.time_refine)?;
    stats.set_item("slip_vertices", d.slip_vertices)?;
    stats.set_item("fallback", d.fallback)?;
    stats.set_item("flips", d.flips)?;
    stats.set_item("flip_volume", d.flip_volume)?;
    stats.set_item("collapses", d.collapses)?;
    stats.set_item("moves", d.moves)?;
    stats.set_item("collapse_volume", d.collapse_volume)?;
    stats.set_item("bent", d.bent)?;
    stats.set_item("bend_splits", d.bend_splits)?;
    Ok((
        vec3_array(py, d.vertices)?,
        vec3_array(py, d.rest)?,
        PyArray1::from_vec(py, faces).reshape([nf, 3])?,
        PyArray1::from_vec(py, counts),
        stats,
    ))
}

type StampArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Contact stamper (see `deform::stamp`): a new vertex array and per-frame rows
/// `(dent, time, residual, contact)`. `options`: `start`, `end` (the stamp's path), `radius`,
/// `reach`, `frames` and `iterations`. Ctrl-C stops it between frames, after each of which
/// `progress(done, frames)` is called when given.
#[pyfunction]
#[pyo3(signature = (vertices, faces, options, progress=None))]
pub fn stamp<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    options: Options<'py>,
    progress: Option<Py<PyAny>>,
) -> PyResult<StampArrays<'py>> {
    let start: [f64; 3] = options.get("start")?;
    let end: [f64; 3] = options.get("end")?;
    let radius: f64 = options.get("radius")?;
    let reach: f64 = options.get("reach")?;
    let frames: usize = options.get("frames")?;
    let iterations: usize = options.get("iterations")?;
    let x = vec3s("vertices", &vertices)?;
    // negative indices become out of range, which the stamper reports
    let f: Vec<[usize; 3]> = alloc::collect(
        "stamp",
        triangles(&faces)?
            .iter()
            .map(|t| t.map(|i| usize::try_from(i).unwrap_or(usize::MAX))),
    )?;
    let mut v = alloc::copied("stamp", x)?;
    let stop = Stop::default();
    let mut ticker = Ticker::new(progress, &stop);
    let rep = detach_stoppable(py, &stop, || {
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
    })??;
    ticker.finish()?;
    if rep.len() < frames {
        return Err(value_error("stamp: stopped"));
    }
    let n = rep.len();
    let rows = alloc::flat(
        "stamp",
        rep.iter()
            .map(|r| [r.dent, r.time, r.residual, r.contact as f64]),
    )?;
    Ok((
        vec3_array(py, v)?,
        PyArray1::from_vec(py, rows).reshape([n, 4])?,
    ))
}
