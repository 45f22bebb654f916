//! The Python binding layer (`spinal._core`): converts NumPy arrays to slices, releases the
//! GIL around the computation and maps [`InputError`] to `ValueError`. It holds no
//! algorithms; the Python package (`python/spinal`) normalises arguments (dtype, layout,
//! shapes) before calling in here, so these functions expect C-contiguous float64 arrays.

use glam::{DMat3, DVec3};
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::error::InputError;
use crate::frames::{self, Analytic, Method, Orientation, Request, TangentRule};
use crate::sweep::{self, Options, Profile, Spine};

type FramesAndAngles<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<f64>>);

fn to_py(e: InputError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn vec3s<'a>(arg: &'static str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<&'a [DVec3]> {
    if a.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{arg}: expected shape (n, 3), got {:?}",
            a.shape()
        )));
    }
    let s = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{arg}: array must be C-contiguous")))?;
    Ok(bytemuck::cast_slice(s))
}

fn parse_method(s: &str) -> PyResult<Method> {
    Ok(match s {
        "double_reflection" => Method::DoubleReflection,
        "projection" => Method::Projection,
        "rotation" => Method::Rotation,
        "frenet" => Method::Frenet,
        "rk4" => Method::Rk4,
        _ => {
            return Err(PyValueError::new_err(format!(
                "method: unknown method {s:?}; expected 'double_reflection', 'projection', \
                 'rotation', 'frenet' or 'rk4'"
            )));
        }
    })
}

fn parse_rule(s: &str) -> PyResult<TangentRule> {
    match s {
        "five_point" => Ok(TangentRule::FivePoint),
        "circle" => Ok(TangentRule::Circle),
        "five_point_uniform" => Ok(TangentRule::FivePointUniform),
        _ => Err(PyValueError::new_err(format!(
            "method: unknown tangent estimate {s:?}; expected 'five_point', 'five_point_uniform' or 'circle'"
        ))),
    }
}

fn orientations(
    vectors: Option<PyReadonlyArray2<'_, f64>>,
    frames: Option<PyReadonlyArray3<'_, f64>>,
) -> PyResult<Vec<Orientation>> {
    let mut out = Vec::new();
    if let Some(v) = vectors {
        for p in vec3s("initial", &v)? {
            out.push(Orientation::Vector(*p));
        }
    }
    if let Some(f) = frames {
        let s = f
            .as_slice()
            .map_err(|_| PyValueError::new_err("frame array must be C-contiguous"))?;
        for a in s.chunks_exact(9) {
            let mut cols = [0.0; 9];
            cols.copy_from_slice(a);
            // row-major (rows of the matrix) -> glam's column-major: transpose
            out.push(Orientation::Frame(
                DMat3::from_cols_array(&cols).transpose(),
            ));
        }
    }
    Ok(out)
}

/// Frames of one or many sampled curves; see `spinal.frames` for the meaning.
#[pyfunction]
#[pyo3(signature = (points, tangents, offsets, method, tangent_rule, tangent_chords, closed,
                    initial_vectors, initial_frames, end_vectors, end_frames, turns))]
#[allow(clippy::too_many_arguments)]
fn frames_sampled<'py>(
    py: Python<'py>,
    points: Option<PyReadonlyArray2<'py, f64>>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    offsets: PyReadonlyArray1<'py, i64>,
    method: &str,
    tangent_rule: &str,
    tangent_chords: bool,
    closed: bool,
    initial_vectors: Option<PyReadonlyArray2<'py, f64>>,
    initial_frames: Option<PyReadonlyArray3<'py, f64>>,
    end_vectors: Option<PyReadonlyArray2<'py, f64>>,
    end_frames: Option<PyReadonlyArray3<'py, f64>>,
    turns: i64,
) -> PyResult<FramesAndAngles<'py>> {
    let method = parse_method(method)?;
    let tangent_rule = parse_rule(tangent_rule)?;
    let pts = points.as_ref().map(|p| vec3s("points", p)).transpose()?;
    let tgs = tangents
        .as_ref()
        .map(|t| vec3s("tangents", t))
        .transpose()?;
    let rows = pts.or(tgs).map(<[DVec3]>::len).unwrap_or(0);
    let offsets = offsets_of(&offsets)?;
    let initial = orientations(initial_vectors, initial_frames)?;
    let end = orientations(end_vectors, end_frames)?;
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
        let buf = rw
            .as_slice_mut()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        py.detach(|| frames::compute_many(&template, &offsets, &initial, &end, buf))
            .map_err(to_py)?
    };
    Ok((out, PyArray1::from_vec(py, angles)))
}

/// Frames of one analytic curve from exact derivatives at the samples and midpoints.
#[pyfunction]
#[pyo3(signature = (points, u, d1, d2, method, closed, initial_vectors, initial_frames,
                    end_vectors, end_frames, turns))]
#[allow(clippy::too_many_arguments)]
fn frames_analytic<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    d1: PyReadonlyArray2<'py, f64>,
    d2: PyReadonlyArray2<'py, f64>,
    method: &str,
    closed: bool,
    initial_vectors: Option<PyReadonlyArray2<'py, f64>>,
    initial_frames: Option<PyReadonlyArray3<'py, f64>>,
    end_vectors: Option<PyReadonlyArray2<'py, f64>>,
    end_frames: Option<PyReadonlyArray3<'py, f64>>,
    turns: i64,
) -> PyResult<(Bound<'py, PyArray3<f64>>, f64)> {
    let method = parse_method(method)?;
    let pts = vec3s("points", &points)?;
    let us = u
        .as_slice()
        .map_err(|_| PyValueError::new_err("u: must be contiguous"))?;
    let d1s = vec3s("points", &d1)?;
    let d2s = vec3s("points", &d2)?;
    let initial = orientations(initial_vectors, initial_frames)?;
    let end = orientations(end_vectors, end_frames)?;
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
        let buf = rw
            .as_slice_mut()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        py.detach(|| frames::compute_into(&req, buf))
            .map_err(to_py)?
    };
    Ok((out, angle))
}

/// Unit tangents estimated from points (one curve).
#[pyfunction]
fn estimate_tangents<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    closed: bool,
    rule: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rule = parse_rule(rule)?;
    let x = vec3s("points", &points)?;
    let t = py
        .detach(|| frames::tangents::estimate_rows(x, closed, rule))
        .map_err(to_py)?;
    let flat: Vec<f64> = bytemuck::cast_slice(&t).to_vec();
    PyArray1::from_vec(py, flat).reshape([t.len(), 3])
}

fn offsets_of(offsets: &PyReadonlyArray1<'_, i64>) -> PyResult<Vec<usize>> {
    offsets
        .as_slice()
        .map_err(|_| PyValueError::new_err("offsets must be contiguous"))?
        .iter()
        .map(|&o| usize::try_from(o))
        .collect::<Result<_, _>>()
        .map_err(|_| PyValueError::new_err("lengths: must be non-negative"))
}

fn slice_of<'a, T: numpy::Element>(
    arg: &str,
    a: &'a numpy::PyReadonlyArray<'_, T, impl numpy::ndarray::Dimension>,
) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("{arg}: array must be C-contiguous")))
}

type MeshArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
);

/// Sweep a profile along one or many spines; see `spinal.sweep`.
#[pyfunction]
#[pyo3(signature = (points, frames, scale, twist, offsets, profile, profile_closed, closed, caps,
                    miter_limit, split_seams))]
#[allow(clippy::too_many_arguments)]
fn sweep_mesh<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    frames: PyReadonlyArray3<'py, f64>,
    scale: PyReadonlyArray2<'py, f64>,
    twist: Option<PyReadonlyArray1<'py, f64>>,
    offsets: PyReadonlyArray1<'py, i64>,
    profile: PyReadonlyArray2<'py, f64>,
    profile_closed: bool,
    closed: bool,
    caps: bool,
    miter_limit: f64,
    split_seams: bool,
) -> PyResult<MeshArrays<'py>> {
    let pts = vec3s("points", &points)?;
    let fr: &[[f64; 9]] = bytemuck::cast_slice(slice_of("frames", &frames)?);
    let sc: &[glam::DVec2] = bytemuck::cast_slice(slice_of("scale", &scale)?);
    let tw: &[f64] = match &twist {
        Some(t) => slice_of("twist", t)?,
        None => &[],
    };
    let prof: &[glam::DVec2] = bytemuck::cast_slice(slice_of("profile", &profile)?);
    let offsets = offsets_of(&offsets)?;
    let opts = Options {
        closed,
        caps,
        miter_limit,
        split_seams,
    };
    let spine = Spine {
        points: pts,
        frames: fr,
        scale: sc,
        twist: tw,
    };
    let (p, lay) = py
        .detach(|| {
            let p = Profile::new(prof, profile_closed)?;
            let lay = sweep::layout(&spine, &offsets, &p, &opts)?;
            Ok((p, lay))
        })
        .map_err(to_py)?;
    let (nv, nf) = (lay.vertices, lay.faces);
    let v = empty::<f64, numpy::Ix2>(py, &[nv, 3])?;
    let n = empty::<f64, numpy::Ix2>(py, &[nv, 3])?;
    let uv = empty::<f64, numpy::Ix2>(py, &[nv, 2])?;
    let f = empty::<i64, numpy::Ix2>(py, &[nf, 3])?;
    let folds = {
        let (mut wv, mut wn, mut wu, mut wf) =
            (v.readwrite(), n.readwrite(), uv.readwrite(), f.readwrite());
        let out = sweep::MeshMut {
            vertices: bytemuck::cast_slice_mut(slice_mut(&mut wv)?),
            faces: bytemuck::cast_slice_mut(slice_mut(&mut wf)?),
            normals: bytemuck::cast_slice_mut(slice_mut(&mut wn)?),
            uv: bytemuck::cast_slice_mut(slice_mut(&mut wu)?),
        };
        py.detach(|| sweep::sweep_into(&spine, &offsets, &p, &opts, &lay, out))
    };
    let folds: Vec<i64> = folds.iter().map(|&i| i as i64).collect();
    Ok((v, f, n, uv, PyArray1::from_vec(py, folds)))
}

/// `numpy.empty(shape, dtype)`: NumPy's allocator reuses freed heap memory for small arrays
/// and asks for transparent huge pages for large ones, and nothing is zeroed, so an output
/// that is written once costs about what NumPy's own write floor costs. Every caller writes
/// every element before the array reaches Python.
fn empty<'py, T: numpy::Element, D: numpy::ndarray::Dimension>(
    py: Python<'py>,
    shape: &[usize],
) -> PyResult<Bound<'py, numpy::PyArray<T, D>>> {
    let np = py.import("numpy")?;
    let shape = pyo3::types::PyTuple::new(py, shape)?;
    let a = np.getattr("empty")?.call1((shape, numpy::dtype::<T>(py)))?;
    Ok(a.cast_into::<numpy::PyArray<T, D>>()?)
}

fn slice_mut<'a, T: numpy::Element>(
    a: &'a mut numpy::PyReadwriteArray<'_, T, numpy::Ix2>,
) -> PyResult<&'a mut [T]> {
    a.as_slice_mut()
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

// ---- deformation (issue 4) -------------------------------------------------------------

fn field_of(rows: &PyReadonlyArray2<'_, f64>) -> PyResult<crate::deform::Field> {
    if rows.shape()[1] != crate::deform::ROW {
        return Err(PyValueError::new_err(format!(
            "field: expected element rows of shape (k, {}), got {:?}",
            crate::deform::ROW,
            rows.shape()
        )));
    }
    crate::deform::Field::parse(slice_of("field", rows)?).map_err(to_py)
}

/// Velocities of a field at points; see `spinal.fields`.
#[pyfunction]
fn field_eval<'py>(
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
        py.detach(|| crate::deform::advect::eval_into(&field, x, t, o));
    }
    Ok(out)
}

/// `(max_speed, length_scale, default steps for duration)` of a field.
#[pyfunction]
fn field_info(rows: PyReadonlyArray2<'_, f64>, duration: f64) -> PyResult<(f64, f64, usize)> {
    let field = field_of(&rows)?;
    Ok((
        field.max_speed(),
        field.length_scale(),
        field.default_steps(duration),
    ))
}

/// Advect points: `steps` steps of size `h` from `t0`; a new array.
#[pyfunction]
fn advect<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    rows: PyReadonlyArray2<'py, f64>,
    t0: f64,
    h: f64,
    steps: usize,
    method: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    use crate::deform::advect::{Method as M, advect_in_place};
    let m = match method {
        "rk4" => M::Rk4,
        "euler" => M::Euler,
        _ => {
            return Err(PyValueError::new_err(format!(
                "method: unknown method {method:?}; expected 'rk4' or 'euler'"
            )));
        }
    };
    let field = field_of(&rows)?;
    let x = vec3s("vertices", &points)?;
    let out = empty::<f64, numpy::Ix2>(py, &[x.len(), 3])?;
    {
        let mut w = out.readwrite();
        let o: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        o.copy_from_slice(x);
        py.detach(|| advect_in_place(&field, o, t0, h, steps, m));
    }
    Ok(out)
}

#[pymodule(name = "_core")]
fn core_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(frames_sampled, m)?)?;
    m.add_function(wrap_pyfunction!(frames_analytic, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_tangents, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(field_eval, m)?)?;
    m.add_function(wrap_pyfunction!(field_info, m)?)?;
    m.add_function(wrap_pyfunction!(advect, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
