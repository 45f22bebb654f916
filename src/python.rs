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
use crate::ph;
use crate::quaternion;
use crate::sweep::{self, Options, Profile, Spine};
use rayon::prelude::*;

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

/// The `(F, 3)` index rows of `faces`.
fn triangles<'a>(faces: &'a PyReadonlyArray2<'_, i64>) -> PyResult<&'a [[i64; 3]]> {
    if faces.shape()[1] != 3 {
        return Err(PyValueError::new_err("faces: expected shape (F, 3)"));
    }
    Ok(bytemuck::cast_slice(slice_of("faces", faces)?))
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

fn quats<'a>(arg: &str, a: &'a PyReadonlyArray2<'_, f64>) -> PyResult<&'a [glam::DQuat]> {
    if a.shape()[1] != 4 {
        return Err(PyValueError::new_err(format!(
            "{arg}: expected shape (n, 4), got {:?}",
            a.shape()
        )));
    }
    Ok(bytemuck::cast_slice(slice_of(arg, a)?))
}

fn quat_array<'py>(py: Python<'py>, q: Vec<glam::DQuat>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = q.len();
    PyArray1::from_vec(py, bytemuck::allocation::cast_vec::<glam::DQuat, f64>(q)).reshape([n, 4])
}

/// Quaternions `(x, y, z, w)` of frames; see `spinal.quaternions.to_quaternions`.
#[pyfunction]
fn quat_from_frames<'py>(
    py: Python<'py>,
    frames: PyReadonlyArray3<'py, f64>,
    continuous: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let fr: &[[f64; 9]] = bytemuck::cast_slice(slice_of("frames", &frames)?);
    let q = py
        .detach(|| quaternion::from_frames(fr, continuous))
        .map_err(to_py)?;
    quat_array(py, q)
}

/// Frames of quaternions `(x, y, z, w)`.
#[pyfunction]
fn quat_to_frames<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let qs = quats("quaternions", &q)?;
    let out = empty::<f64, numpy::Ix3>(py, &[qs.len(), 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf: &mut [[f64; 9]] = bytemuck::cast_slice_mut(
            rw.as_slice_mut()
                .map_err(|e| PyValueError::new_err(e.to_string()))?,
        );
        py.detach(|| quaternion::to_frames(qs, buf))
            .map_err(to_py)?;
    }
    Ok(out)
}

/// Sign-continuous copy of quaternions `(x, y, z, w)`.
#[pyfunction]
fn quat_continuous<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut v = quats("q", &q)?.to_vec();
    quaternion::make_continuous(&mut v);
    quat_array(py, v)
}

/// Row-wise slerp of quaternions `(x, y, z, w)`.
#[pyfunction]
fn quat_slerp<'py>(
    py: Python<'py>,
    q0: PyReadonlyArray2<'py, f64>,
    q1: PyReadonlyArray2<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b, us) = (quats("q0", &q0)?, quats("q1", &q1)?, slice_of("u", &u)?);
    if a.len() != b.len() || a.len() != us.len() {
        return Err(PyValueError::new_err(
            "q0, q1 and u must have the same number of rows",
        ));
    }
    let mut out = vec![glam::DQuat::IDENTITY; a.len()];
    py.detach(|| quaternion::slerp_many(a, b, us, &mut out))
        .map_err(to_py)?;
    quat_array(py, out)
}

/// Length of a quaternion curve on S³.
#[pyfunction]
fn quat_path_length(py: Python<'_>, q: PyReadonlyArray2<'_, f64>, closed: bool) -> PyResult<f64> {
    let qs = quats("quaternions", &q)?;
    py.detach(|| quaternion::path_length(qs, closed))
        .map_err(to_py)
}

/// Parallel transport as a quaternion recurrence; returns (quaternions, closing angle).
#[pyfunction]
fn quat_transport<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tangents: PyReadonlyArray2<'py, f64>,
    r0: PyReadonlyArray1<'py, f64>,
    closed: bool,
    turns: i64,
    closing_row: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, f64)> {
    let x = vec3s("points", &points)?;
    let t = vec3s("tangents", &tangents)?;
    let r = slice_of("initial", &r0)?;
    if r.len() != 3 || t.len() != x.len() || t.len() < 2 {
        return Err(PyValueError::new_err(
            "points and tangents must have the same n >= 2 rows and initial 3 values",
        ));
    }
    let r = DVec3::new(r[0], r[1], r[2]);
    let rows = t.len() + usize::from(closed && closing_row);
    let mut out = vec![glam::DQuat::IDENTITY; rows];
    let angle = py
        .detach(|| quaternion::transport(x, t, r, closed, turns, &mut out))
        .map_err(to_py)?;
    Ok((quat_array(py, out)?, angle))
}

type WalkArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// Positions, faces and row-major frames (columns e₁, e₂, e₃) of walker states.
fn walker_states(states: &[quaternion::walk::State]) -> (Vec<f64>, Vec<i64>, Vec<f64>) {
    let pts = states.iter().flat_map(|s| s.point.to_array()).collect();
    let fcs = states.iter().map(|s| s.face as i64).collect();
    let frs = states
        .iter()
        .flat_map(|s| {
            let (a, b, c) = (s.frame.x_axis, s.frame.y_axis, s.frame.z_axis);
            [a.x, b.x, c.x, a.y, b.y, c.y, a.z, b.z, c.z]
        })
        .collect();
    (pts, fcs, frs)
}

/// Walk on a triangle mesh; see `spinal.quaternions.walk_mesh`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, face, point, direction, moves))]
fn walk_mesh<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    face: i64,
    point: PyReadonlyArray1<'py, f64>,
    direction: Option<PyReadonlyArray1<'py, f64>>,
    moves: PyReadonlyArray2<'py, f64>,
) -> PyResult<WalkArrays<'py>> {
    let v = vec3s("vertices", &vertices)?;
    let f = triangles(&faces)?;
    let p = slice_of("point", &point)?;
    if p.len() != 3 {
        return Err(PyValueError::new_err("point: expected 3 values"));
    }
    let d = direction
        .as_ref()
        .map(|d| slice_of("direction", d))
        .transpose()?;
    if moves.shape()[1] != 2 {
        return Err(PyValueError::new_err("moves: expected shape (k, 2)"));
    }
    let mv: &[glam::DVec2] = bytemuck::cast_slice(slice_of("moves", &moves)?);
    let p = DVec3::new(p[0], p[1], p[2]);
    if d.is_some_and(|d| d.len() != 3) {
        return Err(PyValueError::new_err("direction: expected 3 values"));
    }
    let d = d.map(|d| DVec3::new(d[0], d[1], d[2]));
    let (states, path) = py
        .detach(|| {
            let w = quaternion::walk::Walker::new(v, f)?;
            let mut s = w.start(face, p, d)?;
            let mut states = vec![s];
            let mut path = vec![(s.point, s.face, 0usize)];
            let mut crossings = Vec::new();
            for (k, m) in mv.iter().enumerate() {
                crossings.clear();
                s = w.step(s, *m, &mut crossings)?;
                path.extend(crossings.iter().map(|&(q, g)| (q, g, k + 1)));
                path.push((s.point, s.face, k + 1));
                states.push(s);
            }
            Ok::<_, crate::error::InputError>((states, path))
        })
        .map_err(to_py)?;
    let k = states.len();
    let (pts, fcs, frs) = walker_states(&states);
    let stopped: Vec<bool> = states[1..].iter().map(|s| s.stopped).collect();
    let m = path.len();
    let pp: Vec<f64> = path.iter().flat_map(|p| p.0.to_array()).collect();
    let pf: Vec<i64> = path.iter().map(|p| p.1 as i64).collect();
    let pm: Vec<i64> = path.iter().map(|p| p.2 as i64).collect();
    Ok((
        PyArray1::from_vec(py, pts).reshape([k, 3])?,
        PyArray1::from_vec(py, fcs),
        PyArray1::from_vec(py, frs).reshape([k, 3, 3])?,
        PyArray1::from_vec(py, stopped),
        PyArray1::from_vec(py, pp).reshape([m, 3])?,
        PyArray1::from_vec(py, pf),
        PyArray1::from_vec(py, pm),
    ))
}

type WalksArrays<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, numpy::PyArray4<f64>>,
    Bound<'py, PyArray2<bool>>,
);

/// Many walkers on one mesh; see `spinal.quaternions.walk_mesh_many`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, face, points, directions, moves, k))]
#[allow(clippy::too_many_arguments)]
fn walk_mesh_many<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    face: PyReadonlyArray1<'py, i64>,
    points: PyReadonlyArray2<'py, f64>,
    directions: Option<PyReadonlyArray2<'py, f64>>,
    moves: PyReadonlyArray2<'py, f64>,
    k: usize,
) -> PyResult<WalksArrays<'py>> {
    let v = vec3s("vertices", &vertices)?;
    let f = triangles(&faces)?;
    let fc = slice_of("face", &face)?;
    let p = vec3s("points", &points)?;
    let d = directions
        .as_ref()
        .map(|d| vec3s("directions", d))
        .transpose()?;
    if p.len() != fc.len() || d.is_some_and(|d| d.len() != fc.len()) {
        return Err(PyValueError::new_err(
            "points, directions: one row per walker (as many as face)",
        ));
    }
    if moves.shape()[1] != 2 {
        return Err(PyValueError::new_err("moves: expected shape (w·k, 2)"));
    }
    let mv: &[glam::DVec2] = bytemuck::cast_slice(slice_of("moves", &moves)?);
    let starts: Vec<quaternion::walk::Start> = (0..fc.len())
        .map(|i| (fc[i], p[i], d.map(|d| d[i])))
        .collect();
    let states = py
        .detach(|| {
            let w = quaternion::walk::Walker::new(v, f)?;
            quaternion::walk::walk_many(&w, &starts, mv, k)
        })
        .map_err(to_py)?;
    let nw = starts.len();
    let (pts, fcs, frs) = walker_states(&states);
    let stopped: Vec<bool> = states
        .chunks(k + 1)
        .flat_map(|w| w[1..].iter().map(|s| s.stopped))
        .collect();
    Ok((
        PyArray1::from_vec(py, pts).reshape([nw, k + 1, 3])?,
        PyArray1::from_vec(py, fcs).reshape([nw, k + 1])?,
        PyArray1::from_vec(py, frs).reshape([nw, k + 1, 3, 3])?,
        PyArray1::from_vec(py, stopped).reshape([nw, k])?,
    ))
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
        "split" => M::Split,
        _ => {
            return Err(PyValueError::new_err(format!(
                "method: unknown method {method:?}; expected 'rk4', 'euler' or 'split'"
            )));
        }
    };
    let field = field_of(&rows)?;
    if m == M::Split && !field.has_potential() {
        return Err(PyValueError::new_err(
            "method: 'split' needs curl potentials; only fields.translation tools have one",
        ));
    }
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

type FleshBinding<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray2<f64>>);
type FleshPose<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>);

fn flesh_spine<'py>(
    arg: &'static str,
    points: &PyReadonlyArray2<'py, f64>,
    frames: &PyReadonlyArray3<'py, f64>,
) -> PyResult<crate::flesh::Spine> {
    let pts = vec3s(arg, points)?;
    let fr = slice_of(arg, frames)?;
    crate::flesh::Spine::new(arg, pts, fr).map_err(to_py)
}

/// Register vertices on a rest spine; see `spinal.SpineBinding`.
#[pyfunction]
fn flesh_bind<'py>(
    py: Python<'py>,
    rest_points: PyReadonlyArray2<'py, f64>,
    rest_frames: PyReadonlyArray3<'py, f64>,
    vertices: PyReadonlyArray2<'py, f64>,
) -> PyResult<FleshBinding<'py>> {
    let rest = flesh_spine("rest_spine", &rest_points, &rest_frames)?;
    let v = vec3s("vertices", &vertices)?;
    let b = py.detach(|| crate::flesh::bind(&rest, v)).map_err(to_py)?;
    let nv = b.edge.len();
    let coords = PyArray1::from_vec(py, b.coords).reshape([nv, crate::flesh::COORDS])?;
    Ok((PyArray1::from_vec(py, b.edge), coords))
}

/// Deform registered vertices onto a posed spine; see `spinal.SpineBinding.deform`.
#[pyfunction]
#[pyo3(signature = (posed_points, posed_frames, edge, coords, solution, twist))]
fn flesh_deform<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    posed_frames: PyReadonlyArray3<'py, f64>,
    edge: PyReadonlyArray1<'py, i64>,
    coords: PyReadonlyArray2<'py, f64>,
    solution: &str,
    twist: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<FleshPose<'py>> {
    use crate::flesh::Solution;
    let sol = match solution {
        "none" => Solution::None,
        "normal" => Solution::Normal,
        "binormal" => Solution::Binormal,
        "radial" => Solution::Radial,
        _ => {
            return Err(PyValueError::new_err(format!(
                "solution: unknown value {solution:?}; expected 'none', 'normal', 'binormal' or 'radial'"
            )));
        }
    };
    let posed = flesh_spine("posed_spine", &posed_points, &posed_frames)?;
    let edge = slice_of("edge", &edge)?;
    let coords = slice_of("coords", &coords)?;
    let tw: &[f64] = match &twist {
        Some(t) => slice_of("twist", t)?,
        None => &[],
    };
    let nv = edge.len();
    let out = empty::<f64, numpy::Ix2>(py, &[nv, 3])?;
    let mut flags = vec![0u8; nv];
    {
        let mut w = out.readwrite();
        let buf: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        py.detach(|| crate::flesh::deform(&posed, edge, coords, sol, tw, buf, &mut flags))
            .map_err(to_py)?;
    }
    Ok((out, PyArray1::from_vec(py, flags)))
}

/// Compass-walk resampling of a posed spine; see `spinal.SpineBinding.posed_spine`.
#[pyfunction]
fn flesh_resample<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    chords: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let pts = vec3s("posed_spine", &posed_points)?;
    let ch = slice_of("chords", &chords)?;
    if pts.len() < 2 || ch.iter().any(|h| !(h.is_finite() && *h > 0.0)) {
        return Err(PyValueError::new_err(
            "posed_spine: need at least 2 points and positive chords",
        ));
    }
    let out = py.detach(|| crate::flesh::spine::compass_walk(pts, ch));
    let n = out.len();
    let flat: Vec<f64> = bytemuck::cast_slice(&out).to_vec();
    PyArray1::from_vec(py, flat).reshape([n, 3])
}

/// Register vertices on a rest spine surface (grid `nu × nv`); see `spinal.SurfaceBinding`.
#[pyfunction]
fn flesh_surface_bind<'py>(
    py: Python<'py>,
    rest_points: PyReadonlyArray2<'py, f64>,
    nu: usize,
    nv: usize,
    vertices: PyReadonlyArray2<'py, f64>,
) -> PyResult<FleshBinding<'py>> {
    let pts = vec3s("rest_surface", &rest_points)?;
    let v = vec3s("vertices", &vertices)?;
    let (cell, coords) = py
        .detach(|| {
            let rest = crate::flesh::surface::Surface::new("rest_surface", pts, nu, nv)?;
            crate::flesh::surface::bind_surface(&rest, v)
        })
        .map_err(to_py)?;
    let n = cell.len();
    let coords =
        PyArray1::from_vec(py, coords).reshape([n, crate::flesh::surface::SURFACE_COORDS])?;
    Ok((PyArray1::from_vec(py, cell), coords))
}

/// Deform vertices registered on a spine surface; see `spinal.SurfaceBinding.deform`.
#[pyfunction]
fn flesh_surface_deform<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    nu: usize,
    nv: usize,
    cell: PyReadonlyArray1<'py, i64>,
    coords: PyReadonlyArray2<'py, f64>,
    corrected: bool,
) -> PyResult<FleshPose<'py>> {
    let pts = vec3s("posed_surface", &posed_points)?;
    let cell = slice_of("cell", &cell)?;
    let coords = slice_of("coords", &coords)?;
    let n = cell.len();
    let out = empty::<f64, numpy::Ix2>(py, &[n, 3])?;
    let mut flags = vec![0u8; n];
    {
        let mut w = out.readwrite();
        let buf: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        py.detach(|| {
            let posed = crate::flesh::surface::Surface::new("posed_surface", pts, nu, nv)?;
            crate::flesh::surface::deform_surface(&posed, cell, coords, corrected, buf, &mut flags)
        })
        .map_err(to_py)?;
    }
    Ok((out, PyArray1::from_vec(py, flags)))
}

type StampArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Contact stamper (see `deform::stamp`): a new vertex array and per-frame rows
/// `(dent, time, residual, contact)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn stamp<'py>(
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
    let f = triangles(&faces)?;
    let f: Vec<[usize; 3]> = f
        .iter()
        .map(|t| t.map(|i| usize::try_from(i).unwrap_or(usize::MAX)))
        .collect();
    let mut v = x.to_vec();
    let rep = py
        .detach(|| {
            crate::deform::stamp::stamp(
                &mut v,
                &f,
                DVec3::from(start),
                DVec3::from(end),
                radius,
                reach,
                frames,
                iterations,
            )
        })
        .map_err(to_py)?;
    let n = rep.len();
    let rows: Vec<f64> = rep
        .iter()
        .flat_map(|r| [r.dent, r.time, r.residual, r.contact as f64])
        .collect();
    let flat: Vec<f64> = v.iter().flat_map(|p| p.to_array()).collect();
    Ok((
        PyArray1::from_vec(py, flat).reshape([v.len(), 3])?,
        PyArray1::from_vec(py, rows).reshape([n, 4])?,
    ))
}

#[pymodule(name = "_core")]
fn core_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(frames_sampled, m)?)?;
    m.add_function(wrap_pyfunction!(frames_analytic, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_tangents, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(quat_from_frames, m)?)?;
    m.add_function(wrap_pyfunction!(quat_to_frames, m)?)?;
    m.add_function(wrap_pyfunction!(quat_continuous, m)?)?;
    m.add_function(wrap_pyfunction!(quat_slerp, m)?)?;
    m.add_function(wrap_pyfunction!(quat_path_length, m)?)?;
    m.add_function(wrap_pyfunction!(quat_transport, m)?)?;
    m.add_function(wrap_pyfunction!(walk_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(walk_mesh_many, m)?)?;
    m.add_function(wrap_pyfunction!(ph_hermite, m)?)?;
    m.add_function(wrap_pyfunction!(ph_eval, m)?)?;
    m.add_function(wrap_pyfunction!(ph_invariants, m)?)?;
    m.add_function(wrap_pyfunction!(ph_is_ph, m)?)?;
    m.add_function(wrap_pyfunction!(ph_from_quaternions, m)?)?;
    m.add_function(wrap_pyfunction!(ph_preimage, m)?)?;
    m.add_function(wrap_pyfunction!(ph_frame_setup, m)?)?;
    m.add_function(wrap_pyfunction!(ph_frames, m)?)?;
    m.add_function(wrap_pyfunction!(field_eval, m)?)?;
    m.add_function(wrap_pyfunction!(field_info, m)?)?;
    m.add_function(wrap_pyfunction!(advect, m)?)?;
    m.add_function(wrap_pyfunction!(stamp, m)?)?;
    m.add_function(wrap_pyfunction!(flesh_bind, m)?)?;
    m.add_function(wrap_pyfunction!(flesh_deform, m)?)?;
    m.add_function(wrap_pyfunction!(flesh_resample, m)?)?;
    m.add_function(wrap_pyfunction!(flesh_surface_bind, m)?)?;
    m.add_function(wrap_pyfunction!(flesh_surface_deform, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// PH cubics (spinal.ph). Control points arrive as C-contiguous (m, 4, 3) float64 arrays,
// outputs leave as flat rows that the Python layer reshapes.

fn cubics_of(a: &PyReadonlyArray3<'_, f64>) -> PyResult<Vec<ph::Cubic>> {
    let sh = a.shape();
    if sh[1] != 4 || sh[2] != 3 {
        return Err(PyValueError::new_err(format!(
            "control_points: expected shape (m, 4, 3), got {sh:?}"
        )));
    }
    let flat: &[DVec3] = bytemuck::cast_slice(slice_of("control_points", a)?);
    Ok(flat
        .chunks_exact(4)
        .map(|c| ph::Cubic::new([c[0], c[1], c[2], c[3]]))
        .collect())
}

fn rows_of<'py>(py: Python<'py>, data: Vec<f64>, m: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let width = data.len().checked_div(m).unwrap_or(0);
    PyArray1::from_vec(py, data).reshape([m, width])
}

/// G¹ Hermite interpolation, one row per data set: `(candidates (m, 24), counts (m,),
/// reasons (m,))`; with `all = False` the first row without a solution raises.
#[pyfunction]
#[pyo3(signature = (p0, t0, p1, t1, all, batch))]
#[allow(clippy::type_complexity)]
fn ph_hermite<'py>(
    py: Python<'py>,
    p0: PyReadonlyArray2<'py, f64>,
    t0: PyReadonlyArray2<'py, f64>,
    p1: PyReadonlyArray2<'py, f64>,
    t1: PyReadonlyArray2<'py, f64>,
    all: bool,
    batch: bool,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
)> {
    let (p0, t0) = (vec3s("p0", &p0)?, vec3s("t0", &t0)?);
    let (p1, t1) = (vec3s("p1", &p1)?, vec3s("t1", &t1)?);
    let m = p0.len();
    if t0.len() != m || p1.len() != m || t1.len() != m {
        return Err(PyValueError::new_err(
            "p0, t0, p1, t1: must have the same number of rows",
        ));
    }
    let (cands, counts, codes) = py
        .detach(|| -> Result<_, InputError> {
            let mut cands = vec![0.0; m * 24];
            let mut counts = vec![0i64; m];
            let mut codes = vec![0i64; m];
            for i in 0..m {
                let at = |arg: &'static str, msg: &str| {
                    let msg = if batch {
                        format!("row {i}: {msg}")
                    } else {
                        msg.to_string()
                    };
                    InputError::new(arg, msg)
                };
                for (arg, v) in [("p0", p0[i]), ("t0", t0[i]), ("p1", p1[i]), ("t1", t1[i])] {
                    if !v.is_finite() {
                        return Err(at(arg, "contains non-finite values"));
                    }
                }
                for (arg, v) in [("t0", t0[i]), ("t1", t1[i])] {
                    if !(v.length() > 0.0) {
                        return Err(at(arg, "zero tangent vector"));
                    }
                }
                if p0[i] == p1[i] {
                    return Err(at("p1", "equals p0 (no segment to interpolate)"));
                }
                let sol = ph::hermite::hermite(p0[i], t0[i].normalize(), p1[i], t1[i].normalize());
                if let Some(r) = sol.reason {
                    if !all {
                        return Err(at("p0, t0, p1, t1", r.message()));
                    }
                    codes[i] = r.code();
                }
                counts[i] = sol.cubics.len() as i64;
                for (j, c) in sol.cubics.iter().enumerate() {
                    let o = i * 24 + j * 12;
                    let f: &[f64] = bytemuck::cast_slice(&c.b);
                    cands[o..o + 12].copy_from_slice(f);
                }
            }
            Ok((cands, counts, codes))
        })
        .map_err(to_py)?;
    Ok((
        rows_of(py, cands, m)?,
        PyArray1::from_vec(py, counts),
        PyArray1::from_vec(py, codes),
    ))
}

fn locate(m: usize, s: f64) -> (usize, f64) {
    let seg = (s.floor().max(0.0) as usize).min(m - 1);
    (seg, s - seg as f64)
}

fn params_of<'a>(m: usize, s: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    let s = slice_of("s", s)?;
    if m == 0 {
        return Err(PyValueError::new_err("control_points: no segments"));
    }
    if s.iter()
        .any(|x| !(x.is_finite() && *x >= 0.0 && *x <= m as f64))
    {
        return Err(PyValueError::new_err(format!(
            "s: values must be finite and within [0, {m}]"
        )));
    }
    Ok(s)
}

/// Points or derivatives (order 0..3, with respect to the local v) at global parameters
/// `s = segment + v`.
#[pyfunction]
fn ph_eval<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    s: PyReadonlyArray1<'py, f64>,
    derivative: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cubics = cubics_of(&control_points)?;
    let s = params_of(cubics.len(), &s)?;
    if derivative > 3 {
        return Err(PyValueError::new_err("derivative: must be 0, 1, 2 or 3"));
    }
    let out: Vec<f64> = py.detach(|| {
        s.par_iter()
            .flat_map_iter(|&x| {
                let (i, v) = locate(cubics.len(), x);
                cubics[i].derivative(derivative, v).to_array()
            })
            .collect()
    });
    rows_of(py, out, s.len())
}

/// `[L1, L2, L3, cθ, sθ, Δ, a, b, c, k, κ/τ, σ_min, κ_max]` per cubic.
#[pyfunction]
fn ph_invariants<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cubics = cubics_of(&control_points)?;
    let mut out = Vec::with_capacity(cubics.len() * 13);
    for c in &cubics {
        let v = c.invariants();
        out.extend_from_slice(&[
            v.l[0],
            v.l[1],
            v.l[2],
            v.ctheta,
            v.stheta,
            v.delta,
            v.a,
            v.b,
            v.c,
            v.k,
            v.kappa_over_tau,
            v.sigma_min,
            v.kappa_max,
        ]);
    }
    let m = cubics.len();
    PyArray1::from_vec(py, out).reshape([m, 13])
}

/// Control-polygon PH test per cubic.
#[pyfunction]
fn ph_is_ph<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    tol: f64,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let cubics = cubics_of(&control_points)?;
    let out: Vec<bool> = cubics.iter().map(|c| c.is_ph(tol)).collect();
    Ok(PyArray1::from_vec(py, out))
}

/// Control points `(m, 12)` from quaternion preimages `(m, 4)` (scalar first) and starts.
#[pyfunction]
fn ph_from_quaternions<'py>(
    py: Python<'py>,
    a0: PyReadonlyArray2<'py, f64>,
    a1: PyReadonlyArray2<'py, f64>,
    start: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let q0: &[[f64; 4]] = bytemuck::cast_slice(slice_of("A0", &a0)?);
    let q1: &[[f64; 4]] = bytemuck::cast_slice(slice_of("A1", &a1)?);
    let st = vec3s("start", &start)?;
    let m = q0.len();
    if q1.len() != m || st.len() != m {
        return Err(PyValueError::new_err(
            "A0, A1, start: must have the same number of rows",
        ));
    }
    let mut out = Vec::with_capacity(m * 12);
    for i in 0..m {
        let c = ph::Cubic::from_quaternions(q0[i], q1[i], st[i]);
        out.extend_from_slice(bytemuck::cast_slice(&c.b));
    }
    rows_of(py, out, m)
}

/// Quaternion preimages `(m, 9)`: `A0` (4, scalar first), `A1` (4), residual.
#[pyfunction]
fn ph_preimage<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cubics = cubics_of(&control_points)?;
    let mut out = Vec::with_capacity(cubics.len() * 9);
    for (i, c) in cubics.iter().enumerate() {
        let (q0, q1, res) = c.preimage().ok_or_else(|| {
            PyValueError::new_err(format!(
                "control_points: cubic {i} has a control-polygon leg of zero length (not a PH cubic)"
            ))
        })?;
        out.extend_from_slice(&q0);
        out.extend_from_slice(&q1);
        out.push(res);
    }
    rows_of(py, out, cubics.len())
}

fn ph_start(
    initial: Option<PyReadonlyArray1<'_, f64>>,
    omega_start: f64,
) -> PyResult<ph::frame::Start> {
    Ok(match initial {
        Some(v) => {
            let v = slice_of("initial", &v)?;
            if v.len() != 3 {
                return Err(PyValueError::new_err("initial: expected 3 components"));
            }
            ph::frame::Start::Vector(DVec3::new(v[0], v[1], v[2]))
        }
        None => ph::frame::Start::Angle(omega_start),
    })
}

/// Per-segment frame data `(m, 25)` (see `ph::frame::Segment::to_row`).
#[pyfunction]
#[pyo3(signature = (control_points, initial, omega_start, phi))]
fn ph_frame_setup<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    omega_start: f64,
    phi: Option<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cubics = cubics_of(&control_points)?;
    let start = ph_start(initial, omega_start)?;
    let segs = py
        .detach(|| ph::frame::setup(&cubics, start, phi))
        .map_err(to_py)?;
    let out: Vec<f64> = segs.iter().flat_map(|s| s.to_row()).collect();
    rows_of(py, out, segs.len())
}

/// Frames `(n, 3, 3)` (columns r, s, t) and their angles from the principal normal at
/// global parameters `s`; `mode` is "frenet", "exact" or "rational".
#[pyfunction]
#[pyo3(signature = (control_points, s, mode, initial, omega_start, phi))]
fn ph_frames<'py>(
    py: Python<'py>,
    control_points: PyReadonlyArray3<'py, f64>,
    s: PyReadonlyArray1<'py, f64>,
    mode: &str,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    omega_start: f64,
    phi: Option<f64>,
) -> PyResult<FramesAndAngles<'py>> {
    let mode = match mode {
        "frenet" => ph::frame::Mode::Frenet,
        "exact" => ph::frame::Mode::Exact,
        "rational" => ph::frame::Mode::Rational,
        _ => {
            return Err(PyValueError::new_err(format!(
                "mode: unknown frame {mode:?}; expected 'frenet', 'exact' or 'rational'"
            )));
        }
    };
    let cubics = cubics_of(&control_points)?;
    let s = params_of(cubics.len(), &s)?;
    let start = ph_start(initial, omega_start)?;
    let n = s.len();
    let out = empty::<f64, numpy::Ix3>(py, &[n, 3, 3])?;
    let angles = empty::<f64, numpy::Ix1>(py, &[n])?;
    {
        let mut rw = out.readwrite();
        let buf = rw
            .as_slice_mut()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let mut ra = angles.readwrite();
        let abuf = ra
            .as_slice_mut()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        py.detach(|| -> Result<(), InputError> {
            let segs = ph::frame::setup(&cubics, start, phi)?;
            buf.par_chunks_mut(9)
                .zip(abuf.par_iter_mut())
                .zip(s.par_iter())
                .for_each(|((f, a), &x)| {
                    let (i, v) = locate(cubics.len(), x);
                    let (m, om) = ph::frame::frame_at(&cubics[i], &segs[i], v, mode);
                    // glam is column-major; the NumPy frame is row-major with columns r, s, t
                    f.copy_from_slice(&m.transpose().to_cols_array());
                    *a = om;
                });
            Ok(())
        })
        .map_err(to_py)?;
    }
    Ok((out, angles))
}
