//! Velocity fields, advection and the contact stamper (`spinal.fields`, `spinal.deform`);
//! the algorithms are in [`crate::deform`].

use glam::DVec3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

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

/// Declares a frozen record class of the core from one list of its fields, each copied from
/// the same field of a core struct: read-only attributes, `repr`, `==` and pickling (by
/// rebuilding from the `dict` of its fields, `_asdict()`).
macro_rules! record {
    ($(#[$doc:meta])* $name:ident from $source:ty {
        $($(#[$fdoc:meta])* $field:ident: $ty:ty,)+
    }) => {
        $(#[$doc])*
        #[pyclass(frozen, eq, module = "spinal._core")]
        #[derive(Clone, PartialEq)]
        pub struct $name {
            $($(#[$fdoc])* #[pyo3(get)] pub $field: $ty,)+
        }

        impl From<&$source> for $name {
            fn from(s: &$source) -> $name {
                $name { $($field: s.$field,)+ }
            }
        }

        #[pymethods]
        impl $name {
            /// The record of the `dict` of its fields (as `_asdict()` gives them).
            #[new]
            fn new(fields: Options<'_>) -> PyResult<$name> {
                Ok($name { $($field: fields.get(stringify!($field))?,)+ })
            }

            /// The fields as a `dict`, in order.
            fn _asdict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let d = PyDict::new(py);
                $(d.set_item(stringify!($field), self.$field)?;)+
                Ok(d)
            }

            fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
                let fields = [$(format!(
                    "{}={}",
                    stringify!($field),
                    self.$field.into_pyobject(py)?.repr()?
                )),+];
                Ok(format!("{}({})", stringify!($name), fields.join(", ")))
            }

            /// Pickle support: rebuilt from `_asdict()`.
            fn __reduce__<'py>(
                slf: &Bound<'py, Self>,
            ) -> PyResult<(Bound<'py, PyType>, (Bound<'py, PyDict>,))> {
                Ok((slf.get_type(), (slf.get()._asdict(slf.py())?,)))
            }
        }
    };
}

record!(
    /// What [`deform_mesh`] did besides moving the vertices (`spinal.DeformReport` is built
    /// from it and the volumes).
    DeformStats from refine::Deformed {
        /// Refinement passes that split at least one edge.
        passes: usize,
        /// New vertices of edges that the slip at a curl tool's surface tore apart.
        torn: usize,
        /// Edges over the threshold at the end (0 when the refinement converged).
        over_threshold: usize,
        /// Whether `max_vertices` or `max_passes` stopped the refinement with edges still
        /// too long or bent.
        bounded: bool,
        /// Wall time of the integration of the mesh's vertices, seconds.
        time_integrate: f64,
        /// Wall time of the refinement, seconds.
        time_refine: f64,
        /// Vertices on a slip surface at the end.
        slip_vertices: usize,
        /// New vertices placed at a torn edge's chord midpoint.
        fallback: usize,
        /// Edges flipped along slip surfaces.
        flips: usize,
        /// The change of the volume by the flips.
        flip_volume: f64,
        /// Edges collapsed along slip surfaces after the integration.
        collapses: usize,
        /// Vertices of slivers moved on a slip surface after the collapses.
        moves: usize,
        /// The change of the volume by the collapses and moves.
        collapse_volume: f64,
        /// Edges still bent by the flow at the end.
        bent: usize,
        /// Vertices added by the bending splits.
        bend_splits: usize,
    }
);

type DeformArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<i64>>,
    DeformStats,
);

/// Deform a closed mesh along a field, refining after every step (see `deform::refine`):
/// `(vertices, rest_vertices, faces, vertices after each step, statistics)`, the statistics
/// a [`DeformStats`]. `options`: `t0`,
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
    let stats = DeformStats::from(&d);
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
