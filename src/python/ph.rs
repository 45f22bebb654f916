//! PH cubics (`spinal.ph`): control points arrive as C-contiguous `(m, 4, 3)` float64
//! arrays, outputs leave as rows that the Python layer reshapes; the algorithms are in
//! [`crate::ph`].

use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{
    Stop, cubic_points, cubics_from, cubics_of, detach_stoppable, empty, quats, rows_of, slice_mut,
    slice_of, vec3_of, vec3s,
};
use super::frames::FramesAndAngles;
use crate::ph::{self, frame::Mode};
use crate::run::alloc;

type HermiteArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// G¹ Hermite interpolation, one row per data set: `(candidates (m, 24), counts (m,),
/// reasons (m,))`; with `all = False` the first row without a solution raises.
#[pyfunction]
#[pyo3(signature = (p0, t0, p1, t1, all, batch))]
pub fn ph_hermite<'py>(
    py: Python<'py>,
    p0: PyReadonlyArray2<'py, f64>,
    t0: PyReadonlyArray2<'py, f64>,
    p1: PyReadonlyArray2<'py, f64>,
    t1: PyReadonlyArray2<'py, f64>,
    all: bool,
    batch: bool,
) -> PyResult<HermiteArrays<'py>> {
    let (p0, t0) = (vec3s("p0", &p0)?, vec3s("t0", &t0)?);
    let (p1, t1) = (vec3s("p1", &p1)?, vec3s("t1", &t1)?);
    let stop = Stop::default();
    let rows = detach_stoppable(py, &stop, || {
        let cancel = || stop.requested();
        ph::hermite::hermite_rows(p0, t0, p1, t1, all, batch, &cancel)
    })??;
    Ok((
        rows_of(py, rows.candidates, p0.len())?,
        PyArray1::from_vec(py, rows.counts),
        PyArray1::from_vec(py, rows.codes),
    ))
}

/// Points or derivatives (order 0..3, with respect to the local v) at global parameters
/// `s = segment + v`.
#[pyfunction]
pub fn ph_eval<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    s: PyReadonlyArray1<'py, f64>,
    derivative: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cubics = cubics_of("PHSpline.evaluate", &control_points)?;
    let s = slice_of("s", &s)?;
    let out = empty::<f64, numpy::Ix2>(py, "PHSpline.evaluate", &[s.len(), 3])?;
    {
        let mut rw = out.readwrite();
        let o: &mut [glam::DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            ph::eval_into(&cubics, s, derivative, o, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// `[L1, L2, L3, cθ, sθ, Δ, a, b, c, k, κ/τ, σ_min, κ_max]` per cubic.
#[pyfunction]
pub fn ph_invariants<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let points = cubic_points(&control_points)?;
    let stop = Stop::default();
    let rows = detach_stoppable(py, &stop, || {
        let cubics = cubics_from("ph.invariants", points, &|| stop.requested())?;
        ph::check::invariant_rows(&cubics, &|| stop.requested())
    })??;
    let out = alloc::flat("ph.invariants", rows.iter().map(|v| v.row()))?;
    let m = rows.len();
    PyArray1::from_vec(py, out).reshape([m, 13])
}

/// Control-polygon PH test per cubic.
#[pyfunction]
pub fn ph_is_ph<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    tol: f64,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let points = cubic_points(&control_points)?;
    let stop = Stop::default();
    let out = detach_stoppable(py, &stop, || {
        let cubics = cubics_from("ph.is_ph", points, &|| stop.requested())?;
        ph::check::is_ph_rows(&cubics, tol, &|| stop.requested())
    })??;
    Ok(PyArray1::from_vec(py, out))
}

/// The checks of a G¹ PH spline (`ph::check::check_spline`): raises ValueError or returns
/// None.
#[pyfunction]
pub fn ph_check_spline(
    control_points: PyReadonlyArray3<'_, f64>,
    knots: PyReadonlyArray1<'_, f64>,
    single: bool,
) -> PyResult<()> {
    let cubics = cubics_of("PHSpline", &control_points)?;
    let knots = slice_of("knots", &knots)?;
    Ok(ph::check::check_spline(&cubics, knots, single)?)
}

/// Control points `(m, 12)` from quaternion preimages `(m, 4)` (scalar first, or
/// `(x, y, z, w)`) and one start or one per row.
#[pyfunction]
pub fn ph_from_quaternions<'py>(
    py: Python<'py>,
    a0: PyReadonlyArray2<'py, f64>,
    a1: PyReadonlyArray2<'py, f64>,
    start: PyReadonlyArray2<'py, f64>,
    scalar_first: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q0: &[ph::Quat] = bytemuck::cast_slice(quats("A0", &a0)?);
    let q1: &[ph::Quat] = bytemuck::cast_slice(quats("A1", &a1)?);
    let st = vec3s("start", &start)?;
    let out = empty::<f64, numpy::Ix2>(py, "ph.from_quaternions", &[q0.len(), 12])?;
    {
        let mut rw = out.readwrite();
        let o: &mut [[f64; 12]] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            let cancel = || stop.requested();
            ph::from_quaternion_rows_into(q0, q1, st, scalar_first, o, &cancel)
        })??;
    }
    Ok(out)
}

/// Quaternion preimages `(m, 9)`: `A0` (4), `A1` (4), residual, the quaternions scalar first
/// or `(x, y, z, w)`; a residual above `tol` times the polygon length raises (`batch`:
/// naming the cubic).
#[pyfunction]
pub fn ph_preimage<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    tol: f64,
    batch: bool,
    scalar_first: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    use rayon::prelude::*;
    let points = cubic_points(&control_points)?;
    let stop = Stop::default();
    let rows = detach_stoppable(py, &stop, || {
        let cubics = cubics_from("ph.preimage", points, &|| stop.requested())?;
        let mut rows = ph::preimage_rows(&cubics, tol, batch, &|| stop.requested())?;
        if !scalar_first {
            rows.par_iter_mut().with_min_len(1 << 12).for_each(|r| {
                r[0..4].rotate_left(1);
                r[4..8].rotate_left(1);
            });
        }
        Ok::<_, crate::error::InputError>(rows)
    })??;
    let m = rows.len();
    rows_of(py, bytemuck::allocation::cast_vec(rows), m)
}

/// How the RMF starts: a reference vector `initial` or the angle `omega_start`.
fn start_of(
    initial: Option<PyReadonlyArray1<'_, f64>>,
    omega_start: f64,
) -> PyResult<ph::frame::Start> {
    Ok(match initial {
        Some(v) => ph::frame::Start::Vector(vec3_of("initial", &v, "expected 3 components")?),
        None => ph::frame::Start::Angle(omega_start),
    })
}

/// Per-segment frame data `(m, 34)`, one row of `ph::frame::Segment::to_row` per cubic.
#[pyfunction]
#[pyo3(signature = (control_points, initial, omega_start, phi))]
pub fn ph_frame_setup<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    omega_start: f64,
    phi: Option<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cubics = cubics_of("angle_fit", &control_points)?;
    let start = start_of(initial, omega_start)?;
    let stop = Stop::default();
    let segs = detach_stoppable(py, &stop, || {
        ph::frame::setup(&cubics, start, phi, &|| stop.requested())
    })??;
    let out = alloc::flat("angle_fit", segs.iter().map(|s| s.to_row()))?;
    rows_of(py, out, segs.len())
}

/// Frames `(n, 3, 3)` (columns r, s, t) and their angles from the principal normal at
/// global parameters `s`; `mode` is "frenet", "exact" or "rational".
#[pyfunction]
#[pyo3(signature = (control_points, s, mode, initial, omega_start, phi))]
pub fn ph_frames<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    s: PyReadonlyArray1<'py, f64>,
    mode: Mode,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    omega_start: f64,
    phi: Option<f64>,
) -> PyResult<FramesAndAngles<'py>> {
    let cubics = cubics_of("PHSpline.rmf", &control_points)?;
    let s = slice_of("s", &s)?;
    let start = start_of(initial, omega_start)?;
    let n = s.len();
    let out = empty::<f64, numpy::Ix3>(py, "PHSpline frames", &[n, 3, 3])?;
    let angles = empty::<f64, numpy::Ix1>(py, "PHSpline frames", &[n])?;
    {
        let mut rw = out.readwrite();
        let frames: &mut [[f64; 9]] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let mut ra = angles.readwrite();
        let a = slice_mut(&mut ra)?;
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            ph::frame::frames_at(&cubics, s, start, phi, mode, frames, a, &|| {
                stop.requested()
            })
        })??;
    }
    Ok((out, angles))
}
