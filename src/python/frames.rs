//! Frames of sampled and analytic curves and tangent estimates (`spinal.frames`,
//! `spinal.estimate_tangents`); the algorithms are in [`crate::frames`].

use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{
    Stop, detach_in_pool, detach_stoppable, empty, ensure_memory, offsets_of, orientations,
    renamed, slice_mut, slice_of, vec3_array, vec3s,
};
use crate::frames::{self, Analytic, Method, Request, TangentRule};

pub type FramesAndAngles<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<f64>>);

/// Frames of one or many sampled curves; see `spinal.frames` for the meaning. Errors about
/// the points name `points_arg` (the argument the caller's user passed them as).
#[pyfunction]
#[pyo3(signature = (points, tangents, offsets, method, tangent_rule, tangent_chords, closed,
                    initial_vectors, initial_frames, end_vectors, end_frames, turns,
                    points_arg="points"))]
#[allow(clippy::too_many_arguments)]
pub fn frames_sampled<'py>(
    py: Python<'py>,
    points: Option<PyReadonlyArray2<'py, f64>>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    offsets: PyReadonlyArray1<'py, i64>,
    method: Method,
    tangent_rule: TangentRule,
    tangent_chords: bool,
    closed: bool,
    initial_vectors: Option<PyReadonlyArray2<'py, f64>>,
    initial_frames: Option<PyReadonlyArray3<'py, f64>>,
    end_vectors: Option<PyReadonlyArray2<'py, f64>>,
    end_frames: Option<PyReadonlyArray3<'py, f64>>,
    turns: i64,
    points_arg: &str,
) -> PyResult<FramesAndAngles<'py>> {
    let pts = points.as_ref().map(|p| vec3s("points", p)).transpose()?;
    let tgs = tangents
        .as_ref()
        .map(|t| vec3s("tangents", t))
        .transpose()?;
    let rows = pts.or(tgs).map(<[_]>::len).unwrap_or(0);
    let offsets = offsets_of(&offsets)?;
    let initial = orientations("initial", initial_vectors, initial_frames)?;
    let end = orientations("end", end_vectors, end_frames)?;
    let template = Request {
        points: pts,
        tangents: tgs,
        analytic: None,
        closed,
        method,
        tangent_chords,
        tangent_rule,
        initial: None,
        end: None,
        turns,
    };
    let out = empty::<f64, numpy::Ix3>(py, &[rows, 3, 3])?;
    let angles = {
        let mut rw = out.readwrite();
        let buf = slice_mut(&mut rw)?;
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            let cancel = || stop.requested();
            frames::compute_many_cancellable(&template, &offsets, &initial, &end, buf, &cancel)
        })?
        .map_err(|e| renamed(e, "points", points_arg))?
    };
    Ok((out, PyArray1::from_vec(py, angles)))
}

/// Frames of one analytic curve from exact derivatives at the samples and midpoints. The
/// user passes the curve as `points` (with `u`); `d1`, `d2` come from its `d1`, `d2`.
#[pyfunction]
#[pyo3(signature = (points, u, d1, d2, method, closed, initial_vectors, initial_frames,
                    end_vectors, end_frames, turns))]
#[allow(clippy::too_many_arguments)]
pub fn frames_analytic<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    d1: PyReadonlyArray2<'py, f64>,
    d2: PyReadonlyArray2<'py, f64>,
    method: Method,
    closed: bool,
    initial_vectors: Option<PyReadonlyArray2<'py, f64>>,
    initial_frames: Option<PyReadonlyArray3<'py, f64>>,
    end_vectors: Option<PyReadonlyArray2<'py, f64>>,
    end_frames: Option<PyReadonlyArray3<'py, f64>>,
    turns: i64,
) -> PyResult<(Bound<'py, PyArray3<f64>>, f64)> {
    let pts = vec3s("points", &points)?;
    let us = slice_of("u", &u)?;
    let d1s = vec3s("points.d1", &d1)?;
    let d2s = vec3s("points.d2", &d2)?;
    let initial = orientations("initial", initial_vectors, initial_frames)?;
    let end = orientations("end", end_vectors, end_frames)?;
    let req = Request {
        points: Some(pts),
        analytic: Some(Analytic {
            u: us,
            d1: d1s,
            d2: d2s,
        }),
        closed,
        method,
        initial: frames::pick(&initial, 0),
        end: frames::pick(&end, 0),
        turns,
        ..Request::default()
    };
    let out = empty::<f64, numpy::Ix3>(py, &[pts.len(), 3, 3])?;
    let angle = {
        let mut rw = out.readwrite();
        let buf = slice_mut(&mut rw)?;
        detach_in_pool(py, || frames::compute_into(&req, buf))??
    };
    Ok((out, angle))
}

/// Unit tangents estimated from points (one curve).
#[pyfunction]
pub fn estimate_tangents<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    closed: bool,
    rule: TangentRule,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let x = vec3s("points", &points)?;
    // chord lengths, the estimate and its copy into the array
    ensure_memory("estimate_tangents", x.len(), 8 + 24 + 24)?;
    let t = detach_in_pool(py, || frames::tangents::estimate_rows(x, closed, rule))??;
    vec3_array(py, t)
}
