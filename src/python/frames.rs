//! Frames of sampled and analytic curves and tangent estimates (`spinal.frames`,
//! `spinal.estimate_tangents`); the algorithms are in [`crate::frames`].

use glam::DVec3;
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{
    Report, Stop, detach_reporting, detach_stoppable, empty, ensure_memory, offsets_of,
    orientations, slice_mut, slice_of, value_error, vec3_array, vec3s,
};
use super::options::Options;
use super::out::{output, writing};
use crate::frames::{self, Analytic, Method, Names, Orientation, Request, TangentRule};

/// Bytes a row checked free before a frames call: the output (72) and the working vectors
/// ([`frames::WORKING_BYTES_PER_ROW`], measured).
const PROBE_BYTES_PER_ROW: usize = 72 + frames::WORKING_BYTES_PER_ROW;

pub type FramesAndAngles<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<f64>>);

/// The options shared by the frames calls, read from their `options` dict: `method`,
/// `tangent_rule` (default five-point), `tangent_chords` (default false), `closed`, and the
/// start and end orientations `initial_vectors`, `initial_frames`, `end_vectors`,
/// `end_frames` (each absent or `None` when not given).
struct Shape<'py> {
    method: Method,
    tangent_rule: TangentRule,
    tangent_chords: bool,
    closed: bool,
    initial_vectors: Option<PyReadonlyArray2<'py, f64>>,
    initial_frames: Option<PyReadonlyArray3<'py, f64>>,
    end_vectors: Option<PyReadonlyArray2<'py, f64>>,
    end_frames: Option<PyReadonlyArray3<'py, f64>>,
}

impl<'py> Shape<'py> {
    fn read(o: &Options<'py>) -> PyResult<Shape<'py>> {
        Ok(Shape {
            method: o.get("method")?,
            tangent_rule: o.get_or("tangent_rule", Request::default().tangent_rule)?,
            tangent_chords: o.get_or("tangent_chords", false)?,
            closed: o.get("closed")?,
            initial_vectors: o.opt("initial_vectors")?,
            initial_frames: o.opt("initial_frames")?,
            end_vectors: o.opt("end_vectors")?,
            end_frames: o.opt("end_frames")?,
        })
    }

    /// The start orientations of the curves.
    fn initial(&self) -> PyResult<Vec<Orientation>> {
        orientations(
            "initial",
            self.initial_vectors.as_ref(),
            self.initial_frames.as_ref(),
        )
    }

    /// The end orientations of the curves.
    fn end(&self) -> PyResult<Vec<Orientation>> {
        orientations("end", self.end_vectors.as_ref(), self.end_frames.as_ref())
    }

    /// A request of these settings for sampled `points` and/or `tangents`, turning by
    /// `turns` (no analytic curve, start or end yet), with errors about them naming `names`.
    fn request<'a>(
        &self,
        (points, tangents): Curves<'a>,
        turns: f64,
        names: Names<'a>,
    ) -> Request<'a> {
        Request {
            points,
            tangents,
            analytic: None,
            closed: self.closed,
            method: self.method,
            tangent_chords: self.tangent_chords,
            tangent_rule: self.tangent_rule,
            initial: None,
            end: None,
            turns,
            names,
        }
    }
}

/// Sampled points and/or tangents of curves, back to back.
type Curves<'a> = (Option<&'a [DVec3]>, Option<&'a [DVec3]>);

/// The rows of the `points` and `tangents` arrays (either may be absent) and their count.
fn curves<'a>(
    points: &'a Option<PyReadonlyArray2<'_, f64>>,
    tangents: &'a Option<PyReadonlyArray2<'_, f64>>,
) -> PyResult<(Curves<'a>, usize)> {
    let pts = points.as_ref().map(|p| vec3s("points", p)).transpose()?;
    let tgs = tangents
        .as_ref()
        .map(|t| vec3s("tangents", t))
        .transpose()?;
    Ok(((pts, tgs), pts.or(tgs).map(<[_]>::len).unwrap_or(0)))
}

/// The exact derivatives of an analytic curve at parameters `u` (`d3` read by the torsion
/// method only), named after the user's curve `points`.
fn analytic<'a>(
    u: &'a PyReadonlyArray1<'_, f64>,
    d1: &'a PyReadonlyArray2<'_, f64>,
    d2: &'a PyReadonlyArray2<'_, f64>,
    d3: &'a Option<PyReadonlyArray2<'_, f64>>,
) -> PyResult<Analytic<'a>> {
    Ok(Analytic {
        u: slice_of("u", u)?,
        d1: vec3s("points.d1", d1)?,
        d2: vec3s("points.d2", d2)?,
        d3: match d3 {
            Some(d) => vec3s("points.d3", d)?,
            None => &[],
        },
    })
}

/// Frames of one or many sampled curves; see `spinal.frames` for the meaning. Errors about
/// the points name `points_arg` (the argument the caller's user passed them as);
/// `progress(done, rows)` is called from the waiting thread as curves are done. `out`: the
/// `(rows, 3, 3)` float64 array to write the frames into (else a new one).
#[pyfunction]
#[pyo3(signature = (points, tangents, offsets, options, progress=None, out=None))]
pub fn frames_sampled<'py>(
    py: Python<'py>,
    points: Option<PyReadonlyArray2<'py, f64>>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    offsets: PyReadonlyArray1<'py, i64>,
    options: Options<'py>,
    progress: Option<Py<PyAny>>,
    out: Option<Bound<'py, PyAny>>,
) -> PyResult<FramesAndAngles<'py>> {
    let shape = Shape::read(&options)?;
    let turns: f64 = options.get("turns")?;
    let points_arg: String = options.get_or("points_arg", "points".to_string())?;
    let (given, rows) = curves(&points, &tangents)?;
    let offsets = offsets_of(&offsets)?;
    let initial = shape.initial()?;
    let end = shape.end()?;
    let names = Names {
        points: &points_arg,
        ..Names::default()
    };
    let template = shape.request(given, turns, names);
    // the output and the working vectors of the frames
    ensure_memory("frames", rows, PROBE_BYTES_PER_ROW)?;
    let out = output::<f64, numpy::Ix3>(py, "frames", &[rows, 3, 3], out, "out")?;
    let angles = {
        let mut rw = writing(&out, "out")?;
        let buf = slice_mut(&mut rw)?;
        let stop = Stop::default();
        let report = Report::new(progress, rows);
        let done = Report::counter(&report);
        detach_reporting(py, &stop, report.as_ref(), || {
            let cancel = || stop.requested();
            frames::compute_many(&template, &offsets, &initial, &end, buf, &cancel, done)
        })??
    };
    Ok((out, PyArray1::from_vec(py, angles)))
}

/// Frames of one analytic curve from exact derivatives at the samples and midpoints. The
/// user passes the curve as `points` (with `u`); `d1`, `d2` (and `d3`, read by the torsion
/// method only) come from its `d1`, `d2`, `d3`.
#[pyfunction]
#[pyo3(signature = (points, u, d1, d2, options, d3=None))]
pub fn frames_analytic<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    d1: PyReadonlyArray2<'py, f64>,
    d2: PyReadonlyArray2<'py, f64>,
    options: Options<'py>,
    d3: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<(Bound<'py, PyArray3<f64>>, f64)> {
    let shape = Shape::read(&options)?;
    let turns: f64 = options.get("turns")?;
    let pts = vec3s("points", &points)?;
    let exact = analytic(&u, &d1, &d2, &d3)?;
    let initial = shape.initial()?;
    let end = shape.end()?;
    let req = Request {
        analytic: Some(exact),
        initial: frames::pick(&initial, 0),
        end: frames::pick(&end, 0),
        // the tangents are the exact derivatives: no estimate
        tangent_chords: false,
        tangent_rule: Request::default().tangent_rule,
        ..shape.request((Some(pts), None), turns, Names::default())
    };
    // the output and the working vectors of the frames' scan
    ensure_memory("frames", pts.len(), PROBE_BYTES_PER_ROW)?;
    let out = empty::<f64, numpy::Ix3>(py, "frames", &[pts.len(), 3, 3])?;
    let angle = {
        let mut rw = out.readwrite();
        let buf = slice_mut(&mut rw)?;
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            frames::compute_into(&req, buf, &|| stop.requested())
        })??
    };
    Ok((out, angle))
}

/// `(into, status)` of [`distinct_rows`].
type MergePlan<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<u8>>);

/// The rows that remain when consecutive repeats are merged
/// ([`frames::validate::distinct_rows`]): for every row the row it is merged into, and each
/// curve's status (0 valid, 1 non-finite, 2 too few distinct samples).
#[pyfunction]
pub fn distinct_rows<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    offsets: PyReadonlyArray1<'py, i64>,
    closed: bool,
) -> PyResult<MergePlan<'py>> {
    let x = vec3s("points", &points)?;
    let offs = offsets_of(&offsets)?;
    let stop = Stop::default();
    let (into, status) = detach_stoppable(py, &stop, || {
        frames::validate::distinct_rows(x, &offs, closed, &|| stop.requested())
    })??;
    let into: Vec<i64> = into.into_iter().map(|r| r as i64).collect();
    let status: Vec<u8> = status.into_iter().map(|s| s as u8).collect();
    Ok((PyArray1::from_vec(py, into), PyArray1::from_vec(py, status)))
}

/// Unit tangents estimated from points: one curve, or many back to back (`offsets`).
#[pyfunction]
#[pyo3(signature = (points, closed, rule, offsets=None))]
pub fn estimate_tangents<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    closed: bool,
    rule: TangentRule,
    offsets: Option<PyReadonlyArray1<'py, i64>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let x = vec3s("points", &points)?;
    // chord lengths, the estimate and its copy into the array
    ensure_memory("estimate_tangents", x.len(), 8 + 24 + 24)?;
    let t = match offsets {
        None => {
            let stop = Stop::default();
            detach_stoppable(py, &stop, || {
                let cancel = || stop.requested();
                frames::tangents::estimate_rows(x, closed, rule, &cancel)
            })??
        }
        Some(o) => {
            let offs = offsets_of(&o)?;
            let stop = Stop::default();
            detach_stoppable(py, &stop, || {
                let cancel = || stop.requested();
                frames::tangents::estimate_many(x, &offs, closed, rule, &cancel)
            })??
        }
    };
    vec3_array(py, t)
}

/// Frames of one or many curves steered by constraints, a guide or the previous time step
/// (`spinal.frames` with `constraints=`, `twist_rule=`, `guide=` or `previous=`). The
/// constraints of all curves come flattened: curve `con_curves[k]`, local row `con_rows[k]`,
/// the vector `con_vectors[k]` or, where `con_is_frame[k]`, the frame `con_frames[k]`. An
/// analytic curve (one) passes `u`, `d1`, `d2` (and `d3`) as in [`frames_analytic`].
#[pyfunction]
#[pyo3(signature = (points, tangents, offsets, options, steering))]
pub fn frames_steered<'py>(
    py: Python<'py>,
    points: Option<PyReadonlyArray2<'py, f64>>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    offsets: PyReadonlyArray1<'py, i64>,
    options: Options<'py>,
    steering: Options<'py>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    use crate::frames::constraints::TwistRule;
    use crate::frames::guide::Guide;
    use crate::frames::steer::{self, Steering};
    use glam::DMat3;

    let shape = Shape::read(&options)?;
    let u: Option<PyReadonlyArray1<'py, f64>> = options.opt("u")?;
    let d1: Option<PyReadonlyArray2<'py, f64>> = options.opt("d1")?;
    let d2: Option<PyReadonlyArray2<'py, f64>> = options.opt("d2")?;
    let d3: Option<PyReadonlyArray2<'py, f64>> = options.opt("d3")?;
    let points_arg: String = options.get_or("points_arg", "points".to_string())?;
    let s = &steering;
    let turns: PyReadonlyArray1<'py, f64> = s.get("turns")?;
    let con_curves: PyReadonlyArray1<'py, i64> = s.get("con_curves")?;
    let con_rows: PyReadonlyArray1<'py, i64> = s.get("con_rows")?;
    let con_vectors: PyReadonlyArray2<'py, f64> = s.get("con_vectors")?;
    let con_frames: PyReadonlyArray3<'py, f64> = s.get("con_frames")?;
    let con_is_frame: PyReadonlyArray1<'py, bool> = s.get("con_is_frame")?;
    let twist_rule: String = s.get("twist_rule")?;
    let guide: Option<PyReadonlyArray2<'py, f64>> = s.opt("guide")?;
    let guide_weight: f64 = s.get("guide_weight")?;
    let guide_tolerance: f64 = s.get("guide_tolerance")?;
    let guide_axis: bool = s.get("guide_axis")?;
    let previous: Option<PyReadonlyArray3<'py, f64>> = s.opt("previous")?;
    let guide_previous: Option<PyReadonlyArray2<'py, f64>> = s.opt("guide_previous")?;
    let previous_weight: f64 = s.get_or("previous_weight", 1.0)?;

    let (given, rows) = curves(&points, &tangents)?;
    let offsets = offsets_of(&offsets)?;
    let curves = offsets.len().saturating_sub(1);
    let initial = shape.initial()?;
    let end = shape.end()?;
    let turns = slice_of("turns", &turns)?;
    let rule = match twist_rule.as_str() {
        "arc_length" => TwistRule::ArcLength,
        "min_angular_speed" => TwistRule::MinAngularSpeed,
        other => {
            return Err(value_error(format!(
                "twist_rule: unknown rule '{other}'; expected 'arc_length' or \
                 'min_angular_speed'"
            )));
        }
    };
    // constraints, grouped by curve
    let cc = slice_of("constraints", &con_curves)?;
    let cr = slice_of("constraints", &con_rows)?;
    let cv = vec3s("constraints", &con_vectors)?;
    let cf = super::convert::frames_of("constraints", &con_frames)?;
    let ck = slice_of("constraints", &con_is_frame)?;
    let k = cc.len();
    if cr.len() != k || cv.len() != k || cf.len() != k || ck.len() != k {
        return Err(value_error("constraints: inconsistent constraint arrays"));
    }
    let orientations: Vec<Orientation> = (0..k)
        .map(|j| match ck[j] {
            true => Orientation::Frame(DMat3::from_cols_array(&cf[j]).transpose()),
            false => Orientation::Vector(cv[j]),
        })
        .collect();
    let per_curve = steer::constraints_by_curve(curves, cc, cr, orientations)?;
    let guide_rows = guide.as_ref().map(|g| vec3s("guide", g)).transpose()?;
    let prev = previous
        .as_ref()
        .map(|p| super::convert::frames_of("previous", p))
        .transpose()?;
    steer::check_lengths(rows, guide_rows.map(<[_]>::len), prev.map(<[_]>::len))?;
    // the previous frames' `r` columns, a second target of the guide's twist solve
    let before = guide_previous
        .as_ref()
        .map(|g| vec3s("previous", g))
        .transpose()?;
    steer::check_lengths(rows, None, before.map(<[_]>::len))?;
    let steering: Vec<Steering> = (0..curves.max(1))
        .map(|c| {
            let (a, b) = (offsets[c.min(curves)], offsets[(c + 1).min(curves)]);
            Steering {
                constraints: &per_curve[c],
                rule,
                turns,
                guide: guide_rows.map(|g| Guide {
                    vectors: if g.len() == 1 { g } else { &g[a..b] },
                    weight: guide_weight,
                    tolerance: guide_tolerance,
                    axis: guide_axis,
                    previous: before.map_or(&[][..], |p| &p[a..b]),
                    previous_weight,
                }),
                previous: prev.map(|p| &p[a..b]),
            }
        })
        .collect();
    let names = Names {
        points: &points_arg,
        ..Names::default()
    };
    let template = shape.request(given, 0.0, names);
    // the output, the rotation-minimising frames, the tangents and the twist solve
    ensure_memory("frames", rows, PROBE_BYTES_PER_ROW)?;
    let out = empty::<f64, numpy::Ix3>(py, "frames", &[rows, 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf = slice_mut(&mut rw)?;
        if let (Some(u), Some(d1), Some(d2)) = (u.as_ref(), d1.as_ref(), d2.as_ref()) {
            let req = Request {
                analytic: Some(analytic(u, d1, d2, &d3)?),
                initial: frames::pick(&initial, 0),
                end: frames::pick(&end, 0),
                ..template
            };
            let st = steering[0];
            let stop = Stop::default();
            detach_stoppable(py, &stop, || {
                steer::compute_steered(&req, &st, buf, &|| stop.requested())
            })??;
        } else {
            let stop = Stop::default();
            detach_stoppable(py, &stop, || {
                let cancel = || stop.requested();
                steer::compute_steered_many(
                    &template, &offsets, &initial, &end, &steering, buf, &cancel,
                )
            })??;
        }
    }
    Ok(out)
}

/// Frames of a curve moving in time, `(T, n, 3)` points (and tangents) flattened to
/// `(T·n, 3)`: each step's RMF, turned to be closest to the step before. `progress(done,
/// steps)` is called from the waiting thread as the steps' frames are computed.
#[pyfunction]
#[pyo3(signature = (points, tangents, steps, options, previous, progress=None))]
pub fn frames_in_time<'py>(
    py: Python<'py>,
    points: Option<PyReadonlyArray2<'py, f64>>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    steps: usize,
    options: Options<'py>,
    previous: Option<PyReadonlyArray3<'py, f64>>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let shape = Shape::read(&options)?;
    let turns: f64 = options.get("turns")?;
    let (given, total) = curves(&points, &tangents)?;
    if steps == 0 || total % steps != 0 {
        return Err(value_error(
            "points: expected shape (T, n, 3) with T ≥ 1 time steps",
        ));
    }
    let rows = total / steps;
    let initial = shape.initial()?;
    let prev = previous
        .as_ref()
        .map(|p| super::convert::frames_of("previous", p))
        .transpose()?;
    let names = Names {
        points: "points_t",
        tangents: "tangents_t",
    };
    let template = shape.request(given, turns, names);
    // the output and every step's working vectors (the steps run in parallel, but each holds
    // its rows' share only)
    ensure_memory("frames", total, PROBE_BYTES_PER_ROW)?;
    let out = empty::<f64, numpy::Ix3>(py, "frames_in_time", &[total, 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf = slice_mut(&mut rw)?;
        let stop = Stop::default();
        let report = Report::new(progress, steps);
        let done = Report::counter(&report);
        detach_reporting(py, &stop, report.as_ref(), || {
            frames::time::frames_in_time(
                &template,
                steps,
                rows,
                frames::pick(&initial, 0),
                prev,
                buf,
                &|| stop.requested(),
                done,
            )
        })??;
    }
    Ok(out)
}
