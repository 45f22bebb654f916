//! Conversions between NumPy arrays and the slices of the core, the option strings and their
//! enums, and [`InputError`] to Python's `ValueError`. The Python package hands in
//! C-contiguous arrays of the right dtype; every check here names the offending argument.

use glam::{DMat3, DQuat, DVec2, DVec3};
use numpy::ndarray::Dimension;
use numpy::{
    Element, PyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray, PyReadonlyArray1,
    PyReadonlyArray2, PyReadonlyArray3, PyReadwriteArray, PyUntypedArrayMethods,
};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use pyo3::exceptions::{
    PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyTypeError, PyValueError,
};
use pyo3::prelude::*;

use super::threads;
use crate::error::{ErrorKind, InputError};
use crate::frames::{Method, Orientation, TangentRule};
use crate::run::alloc;
use crate::{deform, flesh, ph};

/// `ValueError("arg: message")` (`MemoryError("call: out of memory …")` when a buffer sized
/// by the input could not be allocated, `KeyboardInterrupt` for a call stopped by its hook),
/// so `?` works on core results.
impl From<InputError> for PyErr {
    fn from(e: InputError) -> PyErr {
        match e.kind {
            ErrorKind::Invalid => PyValueError::new_err(e.to_string()),
            ErrorKind::OutOfMemory => PyMemoryError::new_err(e.to_string()),
            ErrorKind::Stopped => PyKeyboardInterrupt::new_err(()),
            ErrorKind::Repeated => RepeatedPointsError::new_err(e.to_string()),
        }
    }
}

pyo3::create_exception!(
    spinal._core,
    RepeatedPointsError,
    PyValueError,
    "Consecutive samples that coincide (a ValueError; the Python layer merges them)."
);

/// Fails with `MemoryError` naming `call` unless `bytes` more bytes can be allocated now:
/// a heavy call checks its working memory (estimated from the input sizes) before it starts,
/// so that a refusal of one of its many internal buffers cannot abort the process. The
/// probe is freed at once (large blocks go back to the system).
pub fn ensure_memory(call: &'static str, count: usize, size: usize) -> PyResult<()> {
    let bytes = alloc::product(call, count, size, 1)?;
    alloc::with_capacity::<u8>(call, bytes)
        .map_err(|_| InputError::out_of_memory(call, count, size))?;
    Ok(())
}

/// A request to stop a heavy call, set by the calling thread when a signal handler raised
/// (Ctrl-C) and polled by the work between its blocks (the worker threads never see
/// signals: Python runs its handlers on the main thread only).
#[derive(Default)]
pub struct Stop(AtomicBool);

impl Stop {
    /// Whether the work should stop now.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// How often the calling thread checks for signals while a heavy call runs.
pub const SIGNAL_INTERVAL: Duration = Duration::from_millis(20);

/// Run heavy work with the GIL released inside the rayon pool of the current thread setting
/// ([`super::threads`]); a `KeyboardInterrupt` (or another error of a signal handler) raised
/// while it runs is returned once the work has finished, so no worker outlives the call.
pub fn detach_in_pool<T: Send>(py: Python<'_>, op: impl FnOnce() -> T + Send) -> PyResult<T> {
    detach_stoppable(py, &Stop::default(), op)
}

/// [`detach_in_pool`] for work that polls `stop` between its blocks: the calling thread
/// checks for signals every [`SIGNAL_INTERVAL`] and, when a handler raises, sets `stop`,
/// waits for the work to return and returns the handler's error (its result is dropped).
pub fn detach_stoppable<T: Send>(
    py: Python<'_>,
    stop: &Stop,
    op: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    detach_reporting(py, stop, None, op)
}

/// A count of work that a heavy call adds to as it goes (rows, spines), reported by the
/// calling thread as `progress(done, total)` while it waits ([`detach_reporting`]).
pub struct Report {
    pub done: AtomicUsize,
    pub total: usize,
    pub progress: Py<PyAny>,
}

impl Report {
    /// A report of `total` units to `progress`, or `None` without a callback.
    pub fn new(progress: Option<Py<PyAny>>, total: usize) -> Option<Report> {
        progress.map(|progress| Report {
            done: AtomicUsize::new(0),
            total,
            progress,
        })
    }

    /// The counter that the work adds to, if any.
    pub fn counter(report: &Option<Report>) -> Option<&AtomicUsize> {
        report.as_ref().map(|r| &r.done)
    }

    fn call(&self, py: Python<'_>, done: usize) -> PyResult<()> {
        self.progress.bind(py).call1((done, self.total)).map(drop)
    }
}

/// The number of rayon workers seen from inside a heavy call (for the tests).
#[pyfunction]
pub fn pool_threads(py: Python<'_>) -> PyResult<usize> {
    detach_in_pool(py, rayon::current_num_threads)
}

/// [`detach_stoppable`] that also calls `report`'s callback from the calling thread, at
/// most every [`SIGNAL_INTERVAL`] while the count moves and once at the end with the final
/// count (the work itself never calls into Python, so reports cost it one atomic add per
/// unit). An error raised by the callback stops the work like Ctrl-C and is returned.
pub fn detach_reporting<T: Send>(
    py: Python<'_>,
    stop: &Stop,
    report: Option<&Report>,
    op: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let (out, shown) = detach_waiting(py, stop, report, op)?;
    if let Some(r) = report {
        let done = r.done.load(Ordering::Relaxed);
        if done != shown || done == 0 {
            r.call(py, done)?;
        }
    }
    Ok(out)
}

/// The work's result, and the count last reported.
fn detach_waiting<T: Send>(
    py: Python<'_>,
    stop: &Stop,
    report: Option<&Report>,
    op: impl FnOnce() -> T + Send,
) -> PyResult<(T, usize)> {
    let pool = threads::current_pool()?;
    if pool.current_thread_index().is_some() {
        // a call from inside the pool (a progress callback): blocking this worker to wait
        // for another could deadlock a pool of one thread, so run here
        return Ok((py.detach(op), 0));
    }
    py.detach(|| {
        let (tx, rx) = mpsc::channel();
        let mut shown = 0;
        pool.in_place_scope(|scope| {
            scope.spawn(move |_| {
                // the receiver outlives the scope, so this send cannot fail
                let _ = tx.send(op());
            });
            loop {
                match rx.recv_timeout(SIGNAL_INTERVAL) {
                    Ok(v) => return Ok((v, shown)),
                    Err(RecvTimeoutError::Timeout) => {
                        let polled = Python::attach(|py| {
                            py.check_signals()?;
                            match report {
                                Some(r) => {
                                    let done = r.done.load(Ordering::Relaxed);
                                    match done != shown {
                                        true => r.call(py, done).map(|()| done),
                                        false => Ok(shown),
                                    }
                                }
                                None => Ok(shown),
                            }
                        });
                        match polled {
                            Ok(done) => shown = done,
                            Err(e) => {
                                stop.0.store(true, Ordering::Relaxed);
                                let _ = rx.recv();
                                return Err(e);
                            }
                        }
                    }
                    // the work panicked; the scope raises the panic again when it ends
                    Err(RecvTimeoutError::Disconnected) => {
                        return Err(PyRuntimeError::new_err("worker thread failed"));
                    }
                }
            }
        })
    })
}

/// Calls back into Python between the steps of a long computation, for the core's
/// `tick(done, total) -> bool`: stops (returns `false`) when the calling thread asked to
/// ([`Stop`], Ctrl-C) and calls `progress(done, total)` after every step when given. A
/// Python error stops the computation and is kept for [`Ticker::finish`].
pub struct Ticker<'a> {
    progress: Option<Py<PyAny>>,
    /// Report progress when `done` is a multiple of this (0 or 1: after every tick).
    every: usize,
    stop: &'a Stop,
    error: Option<PyErr>,
}

impl<'a> Ticker<'a> {
    pub fn new(progress: Option<Py<PyAny>>, stop: &'a Stop) -> Ticker<'a> {
        Ticker::every(progress, 0, stop)
    }

    /// A ticker that reports progress only at multiples of `every` steps (and at the end).
    pub fn every(progress: Option<Py<PyAny>>, every: usize, stop: &'a Stop) -> Ticker<'a> {
        Ticker {
            progress,
            every,
            stop,
            error: None,
        }
    }

    /// Continue (true) or stop (false) after `done` of `total` steps.
    pub fn tick(&mut self, done: usize, total: usize) -> bool {
        if self.stop.requested() {
            return false;
        }
        let Some(p) = &self.progress else {
            return true;
        };
        if !(self.every <= 1 || done % self.every == 0 || done == total) {
            return true;
        }
        match Python::attach(|py| p.bind(py).call1((done, total)).map(drop)) {
            Ok(()) => true,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    /// The Python error that stopped the computation, if any.
    pub fn finish(self) -> PyResult<()> {
        self.error.map_or(Ok(()), Err)
    }
}

/// A `ValueError` with the given message.
pub fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// The data of a C-contiguous array.
pub fn slice_of<'a, T: Element>(
    arg: &str,
    a: &'a PyReadonlyArray<'_, T, impl Dimension>,
) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| value_error(format!("{arg}: array must be C-contiguous")))
}

/// The rows of an `(n, 3)` array as vectors.
pub fn vec3s<'a>(arg: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<&'a [DVec3]> {
    if a.shape()[1] != 3 {
        return Err(value_error(format!(
            "{arg}: expected shape (n, 3), got {:?}",
            a.shape()
        )));
    }
    Ok(bytemuck::cast_slice(slice_of(arg, a)?))
}

/// The rows of an `(n, 2)` array as 2-vectors; `shape` is the expected shape in the message.
pub fn vec2s<'a>(
    arg: &str,
    shape: &str,
    a: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<&'a [DVec2]> {
    if a.shape()[1] != 2 {
        return Err(value_error(format!("{arg}: expected shape {shape}")));
    }
    Ok(bytemuck::cast_slice(slice_of(arg, a)?))
}

/// One vector of exactly 3 values; `msg` says so when it has another length.
pub fn vec3_of(arg: &str, a: &PyReadonlyArray1<'_, f64>, msg: &str) -> PyResult<DVec3> {
    match slice_of(arg, a)? {
        &[x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(value_error(format!("{arg}: {msg}"))),
    }
}

/// The rows of a `(k, 3, 3)` array of frames (row-major, as NumPy sees them).
pub fn frames_of<'a>(arg: &str, a: &'a PyReadonlyArray3<'_, f64>) -> PyResult<&'a [[f64; 9]]> {
    if a.shape()[1..] != [3, 3] {
        return Err(value_error(format!(
            "{arg}: expected shape (n, 3, 3), got {:?}",
            a.shape()
        )));
    }
    Ok(bytemuck::cast_slice(slice_of(arg, a)?))
}

/// The `(F, 3)` index rows of `faces`.
pub fn triangles<'a>(faces: &'a PyReadonlyArray2<'_, i64>) -> PyResult<&'a [[i64; 3]]> {
    if faces.shape()[1] != 3 {
        return Err(value_error("faces: expected shape (F, 3)"));
    }
    Ok(bytemuck::cast_slice(slice_of("faces", faces)?))
}

/// The rows of an `(n, 4)` array as quaternions `(x, y, z, w)`.
pub fn quats<'a>(arg: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<&'a [DQuat]> {
    if a.shape()[1] != 4 {
        return Err(value_error(format!(
            "{arg}: expected shape (n, 4), got {:?}",
            a.shape()
        )));
    }
    Ok(bytemuck::cast_slice(slice_of(arg, a)?))
}

/// Curve offsets (`offsets[c] .. offsets[c + 1]` are the rows of curve `c`).
pub fn offsets_of(offsets: &PyReadonlyArray1<'_, i64>) -> PyResult<Vec<usize>> {
    slice_of("offsets", offsets)?
        .iter()
        .map(|&o| usize::try_from(o))
        .collect::<Result<_, _>>()
        .map_err(|_| value_error("offsets: must be non-negative"))
}

/// Start or end orientations of curves: reference vectors `(k, 3)` and/or frames
/// `(k, 3, 3)` (row-major with columns `r, s, t`); `arg` is `"initial"` or `"end"`.
pub fn orientations(
    arg: &str,
    vectors: Option<&PyReadonlyArray2<'_, f64>>,
    frames: Option<&PyReadonlyArray3<'_, f64>>,
) -> PyResult<Vec<Orientation>> {
    let mut out = Vec::new();
    if let Some(v) = vectors {
        out.extend(vec3s(arg, v)?.iter().map(|p| Orientation::Vector(*p)));
    }
    if let Some(f) = frames {
        let s = slice_of(arg, f)?;
        // row-major (rows of the matrix) -> glam's column-major: transpose
        out.extend(s.chunks_exact(9).map(|a| {
            let mut cols = [0.0; 9];
            cols.copy_from_slice(a);
            Orientation::Frame(DMat3::from_cols_array(&cols).transpose())
        }));
    }
    Ok(out)
}

/// PH cubics from control points `(m, 4, 3)`.
pub fn cubics_of(call: &'static str, a: &PyReadonlyArray3<'_, f64>) -> PyResult<Vec<ph::Cubic>> {
    Ok(cubics_from(
        call,
        cubic_points(a)?,
        &crate::run::cancel::never,
    )?)
}

/// The control points of `(m, 4, 3)` cubics, four rows per cubic (see [`cubics_from`]).
pub fn cubic_points<'a>(a: &'a PyReadonlyArray3<'_, f64>) -> PyResult<&'a [DVec3]> {
    let sh = a.shape();
    if sh[1] != 4 || sh[2] != 3 {
        return Err(value_error(format!(
            "control_points: expected shape (m, 4, 3), got {sh:?}"
        )));
    }
    Ok(bytemuck::cast_slice(slice_of("control_points", a)?))
}

/// The cubics of [`cubic_points`] (allocated fallibly, naming `call`), polling `cancel` every
/// [`crate::run::cancel::BLOCK`] cubics; needs no Python, so a heavy call makes them with the GIL
/// released.
pub fn cubics_from(
    call: &'static str,
    flat: &[DVec3],
    cancel: crate::run::cancel::Cancel<'_>,
) -> crate::error::Result<Vec<ph::Cubic>> {
    let mut out = alloc::with_capacity(call, flat.len() / 4)?;
    for block in flat.chunks(4 * crate::run::cancel::BLOCK) {
        if cancel() {
            return Err(crate::error::InputError::stopped());
        }
        out.extend(
            block
                .chunks_exact(4)
                .map(|c| ph::Cubic::new([c[0], c[1], c[2], c[3]])),
        );
    }
    Ok(out)
}

/// `numpy.empty(shape, dtype)`: NumPy's allocator reuses freed heap memory for small arrays
/// and asks for transparent huge pages for large ones, and nothing is zeroed, so an output
/// that is written once costs about what NumPy's own write floor costs. Every caller writes
/// every element before the array reaches Python.
/// A refused allocation is a `MemoryError` naming `call` and NumPy's reason (the size and
/// shape).
pub fn empty<'py, T: Element, D: Dimension>(
    py: Python<'py>,
    call: &'static str,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let np = py.import("numpy")?;
    let tuple = pyo3::types::PyTuple::new(py, shape)?;
    let a = match np.getattr("empty")?.call1((tuple, numpy::dtype::<T>(py))) {
        Ok(a) => a,
        Err(e) if e.is_instance_of::<PyMemoryError>(py) => {
            return Err(PyMemoryError::new_err(format!(
                "{call}: out of memory for an output array: {}",
                e.value(py)
            )));
        }
        Err(e) => return Err(e),
    };
    Ok(a.cast_into::<PyArray<T, D>>()?)
}

/// The data of a freshly allocated output array, for writing.
pub fn slice_mut<'a, T: Element, D: Dimension>(
    a: &'a mut PyReadwriteArray<'_, T, D>,
) -> PyResult<&'a mut [T]> {
    a.as_slice_mut().map_err(|e| value_error(e.to_string()))
}

/// Flat data as an `(m, len / m)` array (`(0, 0)` when `m = 0`).
pub fn rows_of<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    m: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let width = data.len().checked_div(m).unwrap_or(0);
    PyArray1::from_vec(py, data).reshape([m, width])
}

/// Vectors as an `(n, 3)` array.
pub fn vec3_array<'py>(py: Python<'py>, v: Vec<DVec3>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = v.len();
    PyArray1::from_vec(py, bytemuck::allocation::cast_vec::<DVec3, f64>(v)).reshape([n, 3])
}

/// Quaternions `(x, y, z, w)` as an `(n, 4)` array.
pub fn quat_array<'py>(py: Python<'py>, q: Vec<DQuat>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = q.len();
    PyArray1::from_vec(py, bytemuck::allocation::cast_vec::<DQuat, f64>(q)).reshape([n, 4])
}

/// Read a real number (not a bool, not a string): `"{arg}: expected a real number, got T"`
/// otherwise. The value is not checked here.
pub fn real(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<f64> {
    let ty = || {
        obj.get_type()
            .name()
            .map_or_else(|_| "?".to_string(), |n| n.to_string())
    };
    if obj.is_instance_of::<pyo3::types::PyBool>() || obj.is_instance_of::<pyo3::types::PyString>()
    {
        return Err(PyTypeError::new_err(format!(
            "{arg}: expected a real number, got {}",
            ty()
        )));
    }
    obj.extract::<f64>()
        .map_err(|_| PyTypeError::new_err(format!("{arg}: expected a real number, got {}", ty())))
}

/// Read a string option: `"{arg}: unknown {what} 'x'; expected 'a', 'b' or 'c'"` when it is
/// not one of `choices` (listed in that order).
pub fn choice<T: Copy>(
    obj: Borrowed<'_, '_, PyAny>,
    arg: &str,
    what: &str,
    choices: &[(&str, T)],
) -> PyResult<T> {
    let names: Vec<String> = choices.iter().map(|(n, _)| format!("'{n}'")).collect();
    let list = match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.join(""),
    };
    let Ok(s) = obj.extract::<&str>() else {
        let ty = obj
            .get_type()
            .name()
            .map_or_else(|_| "?".to_string(), |n| n.to_string());
        return Err(PyTypeError::new_err(format!(
            "{arg}: expected a string, {list}, got {ty}"
        )));
    };
    if let Some(&(_, v)) = choices.iter().find(|(name, _)| *name == s) {
        return Ok(v);
    }
    Err(value_error(format!(
        "{arg}: unknown {what} {s:?}; expected {list}"
    )))
}

/// `FromPyObject` for an option string read by [`choice`]: `option_string!(Type, "arg",
/// "what", [("name", value), …])`.
macro_rules! option_string {
    ($ty:ty, $arg:literal, $what:literal, [$(($name:literal, $value:expr)),+ $(,)?]) => {
        impl ::pyo3::FromPyObject<'_, '_> for $ty {
            type Error = ::pyo3::PyErr;

            fn extract(obj: ::pyo3::Borrowed<'_, '_, ::pyo3::PyAny>) -> ::pyo3::PyResult<Self> {
                $crate::python::convert::choice(obj, $arg, $what, &[$(($name, $value)),+])
            }
        }
    };
}
pub(crate) use option_string;

option_string!(
    Method,
    "method",
    "method",
    [
        ("double_reflection", Method::DoubleReflection),
        ("projection", Method::Projection),
        ("rotation", Method::Rotation),
        ("frenet", Method::Frenet),
        ("rk4", Method::Rk4),
        ("rk4_phi", Method::Rk4Phi),
        ("torsion", Method::Torsion),
        ("bisector", Method::Bisector),
    ]
);

impl FromPyObject<'_, '_> for TangentRule {
    type Error = PyErr;

    fn extract(obj: Borrowed<'_, '_, PyAny>) -> PyResult<Self> {
        // the default, the five-point rule with bounded ends, is named apart in the message
        if obj
            .extract::<&str>()
            .is_ok_and(|s| s == "five_point_bounded")
        {
            return Ok(TangentRule::FivePointBounded);
        }
        choice(
            obj,
            "method",
            "tangent estimate",
            &[
                ("five_point", TangentRule::FivePoint),
                ("five_point_uniform", TangentRule::FivePointUniform),
                ("circle", TangentRule::Circle),
            ],
        )
        .map_err(|e| {
            if e.is_instance_of::<pyo3::exceptions::PyValueError>(obj.py()) {
                value_error(format!(
                    "{}, or 'five_point_bounded' (the default: 'five_point' with bounded ends)",
                    e.value(obj.py())
                ))
            } else {
                e
            }
        })
    }
}

option_string!(
    ph::frame::Mode,
    "mode",
    "frame",
    [
        ("frenet", ph::frame::Mode::Frenet),
        ("exact", ph::frame::Mode::Exact),
        ("rational", ph::frame::Mode::Rational),
    ]
);

option_string!(
    deform::advect::Method,
    "method",
    "method",
    [
        ("rk4", deform::advect::Method::Rk4),
        ("euler", deform::advect::Method::Euler),
        ("split", deform::advect::Method::Split),
    ]
);

option_string!(
    flesh::Solution,
    "solution",
    "value",
    [
        ("none", flesh::Solution::None),
        ("normal", flesh::Solution::Normal),
        ("binormal", flesh::Solution::Binormal),
        ("radial", flesh::Solution::Radial),
        // the weight is set from the `blend` option (Solution::with_blend)
        ("blend", flesh::Solution::Blend(f64::NAN)),
    ]
);
