//! Quaternions of frames and walkers on triangle meshes (`spinal.quaternions`); the
//! algorithms are in [`crate::quaternion`].

use glam::DQuat;
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArray4, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{
    Stop, detach_stoppable, empty, frames_of, quat_array, quats, slice_mut, slice_of, triangles,
    value_error, vec2s, vec3_of, vec3s,
};
use crate::quaternion::{self, camera, walk};
use crate::run::alloc;

/// Quaternions `(x, y, z, w)` of frames; see `spinal.quaternions.to_quaternions`.
#[pyfunction]
pub fn quat_from_frames<'py>(
    py: Python<'py>,
    frames: PyReadonlyArray3<'py, f64>,
    continuous: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let fr = frames_of("frames", &frames)?;
    let stop = Stop::default();
    let q = detach_stoppable(py, &stop, || {
        quaternion::from_frames(fr, continuous, &|| stop.requested())
    })??;
    quat_array(py, q)
}

/// The twist angle between frames `a` and `b` about their common tangent; see
/// `spinal.quaternions.spin`.
#[pyfunction]
pub fn quat_spin<'py>(
    py: Python<'py>,
    a: PyReadonlyArray3<'py, f64>,
    b: PyReadonlyArray3<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (fa, fb) = (frames_of("a", &a)?, frames_of("b", &b)?);
    // the core checks the frames, then their numbers of rows
    let n = fa.len().max(fb.len());
    let out = empty::<f64, numpy::Ix1>(py, "quaternions.spin", &[n])?;
    {
        let mut rw = out.readwrite();
        let o = slice_mut(&mut rw)?;
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            quaternion::spin::spin_into(fa, fb, o, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// Frames of quaternions `(x, y, z, w)`.
#[pyfunction]
pub fn quat_to_frames<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let qs = quats("quaternions", &q)?;
    let out = empty::<f64, numpy::Ix3>(py, "quaternions.from_quaternions", &[qs.len(), 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf: &mut [[f64; 9]] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            quaternion::to_frames(qs, buf, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// Sign-continuous copy of quaternions `(x, y, z, w)`.
#[pyfunction]
pub fn quat_continuous<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let qs = quats("quaternions", &q)?;
    let stop = Stop::default();
    let v = detach_stoppable(py, &stop, || {
        quaternion::continuous(qs, &|| stop.requested())
    })??;
    quat_array(py, v)
}

/// Row-wise slerp of quaternions `(x, y, z, w)`.
#[pyfunction]
pub fn quat_slerp<'py>(
    py: Python<'py>,
    q0: PyReadonlyArray2<'py, f64>,
    q1: PyReadonlyArray2<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (a, b, us) = (quats("q0", &q0)?, quats("q1", &q1)?, slice_of("u", &u)?);
    if a.len() != b.len() || a.len() != us.len() {
        return Err(value_error(
            "q0, q1 and u must have the same number of rows",
        ));
    }
    let mut out = alloc::filled("slerp", a.len(), DQuat::IDENTITY)?;
    let stop = Stop::default();
    detach_stoppable(py, &stop, || {
        quaternion::slerp_many(a, b, us, &mut out, &|| stop.requested())
    })??;
    quat_array(py, out)
}

/// Key frames interpolated by slerp; see `spinal.quaternions.slerp_frames`.
#[pyfunction]
pub fn quat_slerp_frames<'py>(
    py: Python<'py>,
    frames: PyReadonlyArray3<'py, f64>,
    key_u: PyReadonlyArray1<'py, f64>,
    new_u: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let fr = frames_of("frames", &frames)?;
    let (ku, nu) = (slice_of("key_u", &key_u)?, slice_of("new_u", &new_u)?);
    let out = empty::<f64, numpy::Ix3>(py, "quaternions.slerp_frames", &[nu.len(), 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf: &mut [[f64; 9]] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            quaternion::slerp_frames(fr, ku, nu, buf, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// Length of a quaternion curve on S³.
#[pyfunction]
pub fn quat_path_length(
    py: Python<'_>,
    q: PyReadonlyArray2<'_, f64>,
    closed: bool,
) -> PyResult<f64> {
    let qs = quats("quaternions", &q)?;
    let stop = Stop::default();
    Ok(detach_stoppable(py, &stop, || {
        quaternion::path_length(qs, closed, &|| stop.requested())
    })??)
}

/// Parallel transport as a quaternion recurrence; returns (quaternions, closing angle).
#[pyfunction]
pub fn quat_transport<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    initial: Option<PyReadonlyArray1<'py, f64>>,
    closed: bool,
    turns: f64,
    closing_row: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, f64)> {
    let x = vec3s("points", &points)?;
    let t = tangents
        .as_ref()
        .map(|t| vec3s("tangents", t))
        .transpose()?;
    let r = initial
        .as_ref()
        .map(|r| vec3_of("initial", r, "expected 3 values"))
        .transpose()?;
    let rows = x.len() + usize::from(closed && closing_row);
    let mut out = alloc::filled("quaternion_frames", rows, DQuat::IDENTITY)?;
    let stop = Stop::default();
    let angle = detach_stoppable(py, &stop, || {
        quaternion::transport(x, t, r, closed, turns, &mut out, &|| stop.requested())
    })??;
    Ok((quat_array(py, out)?, angle))
}

/// The checked inputs of a camera path: (unit tangents, unit up, starts vertical, level
/// rows or None); see `spinal.quaternions.camera_frames`.
#[pyfunction]
#[pyo3(signature = (points, tangents, up, bank, closed, level, singular_angle))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn camera_inputs<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    tangents: Option<PyReadonlyArray2<'py, f64>>,
    up: Option<PyReadonlyArray1<'py, f64>>,
    bank: Option<PyReadonlyArray1<'py, f64>>,
    closed: bool,
    level: bool,
    singular_angle: f64,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    bool,
    Option<Bound<'py, PyArray1<bool>>>,
)> {
    let x = vec3s("points", &points)?;
    let t = tangents
        .as_ref()
        .map(|t| vec3s("tangents", t))
        .transpose()?;
    let u = up
        .as_ref()
        .map(|u| vec3_of("up", u, "expected 3 values"))
        .transpose()?;
    let b = bank.as_ref().map(|b| slice_of("bank", b)).transpose()?;
    let mode = if level {
        camera::Mode::Level { singular_angle }
    } else {
        camera::Mode::Transport
    };
    let stop = Stop::default();
    let c = detach_stoppable(py, &stop, || {
        camera::inputs(x, t, u, b, closed, mode, &|| stop.requested())
    })??;
    let n = c.tangents.len();
    // the tangents' own buffer, reinterpreted (no copy)
    let ts: Vec<f64> = bytemuck::allocation::cast_vec(c.tangents);
    Ok((
        PyArray1::from_vec(py, ts).reshape([n, 3])?,
        PyArray1::from_vec(py, c.up.to_array().to_vec()),
        c.vertical,
        c.regular.map(|r| PyArray1::from_vec(py, r)),
    ))
}

/// Level-horizon frames at the `regular` rows (zero elsewhere); see
/// `spinal.quaternions.camera_frames(mode="up")`.
#[pyfunction]
pub fn camera_level<'py>(
    py: Python<'py>,
    tangents: PyReadonlyArray2<'py, f64>,
    up: PyReadonlyArray1<'py, f64>,
    regular: PyReadonlyArray1<'py, bool>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let t = vec3s("tangents", &tangents)?;
    let u = vec3_of("up", &up, "expected 3 values")?;
    let g = slice_of("regular", &regular)?;
    let out = empty::<f64, numpy::Ix3>(py, "quaternions.camera_frames", &[t.len(), 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf: &mut [[f64; 9]] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            camera::level_rows(t, u, g, buf, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// Camera rotations `(right, up, back)` of spinal frames rolled by `bank`; see
/// `spinal.quaternions.camera_frames`.
#[pyfunction]
pub fn camera_orient<'py>(
    py: Python<'py>,
    frames: PyReadonlyArray3<'py, f64>,
    bank: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let fr = frames_of("frames", &frames)?;
    let b = bank.as_ref().map(|b| slice_of("bank", b)).transpose()?;
    let out = empty::<f64, numpy::Ix3>(py, "quaternions.camera_frames", &[fr.len(), 3, 3])?;
    {
        let mut rw = out.readwrite();
        let buf: &mut [[f64; 9]] = bytemuck::cast_slice_mut(slice_mut(&mut rw)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            camera::orient(fr, b, buf, &|| stop.requested())
        })??;
    }
    Ok(out)
}

/// Positions, faces and row-major frames (columns e₁, e₂, e₃) of walker states.
/// `call` names the Python function in `MemoryError`.
fn walker_states(
    call: &'static str,
    states: &[walk::State],
) -> PyResult<(Vec<f64>, Vec<i64>, Vec<f64>)> {
    let mut pts = alloc::with_capacity(call, alloc::product(call, states.len(), 3, 8)?)?;
    pts.extend(states.iter().flat_map(|s| s.point.to_array()));
    let fcs = alloc::collect(call, states.iter().map(|s| s.face as i64))?;
    let mut frs = alloc::with_capacity(call, alloc::product(call, states.len(), 9, 8)?)?;
    frs.extend(
        states
            .iter()
            .flat_map(|s| s.frame.transpose().to_cols_array()),
    );
    Ok((pts, fcs, frs))
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

/// Walk on a triangle mesh; see `spinal.quaternions.walk_mesh`. Returns the states
/// (points, faces, frames, stopped per move) and the crossing path (points, faces, moves).
#[pyfunction]
#[pyo3(signature = (vertices, faces, face, point, direction, moves))]
pub fn walk_mesh<'py>(
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
    let p = vec3_of("point", &point, "expected 3 values")?;
    let d = direction
        .as_ref()
        .map(|d| slice_of("direction", d))
        .transpose()?;
    let mv = vec2s("moves", "(k, 2)", &moves)?;
    let d = match d {
        Some(&[x, y, z]) => Some(glam::DVec3::new(x, y, z)),
        Some(_) => return Err(value_error("direction: expected 3 values")),
        None => None,
    };
    let stop = Stop::default();
    let walk = detach_stoppable(py, &stop, || {
        let w = walk::Walker::new(v, f)?;
        walk::walk_path(&w, face, p, d, mv, &|| stop.requested())
    })??;
    let (states, path) = (&walk.states, &walk.path);
    let k = states.len();
    let (pts, fcs, frs) = walker_states("walk_mesh", states)?;
    let stopped = alloc::collect("walk_mesh", states[1..].iter().map(|s| s.stopped))?;
    let m = path.len();
    let mut pp = alloc::with_capacity("walk_mesh", alloc::product("walk_mesh", m, 3, 8)?)?;
    pp.extend(path.iter().flat_map(|p| p.point.to_array()));
    let pf = alloc::collect("walk_mesh", path.iter().map(|p| p.face as i64))?;
    let pm = alloc::collect("walk_mesh", path.iter().map(|p| p.step as i64))?;
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
    Bound<'py, PyArray4<f64>>,
    Bound<'py, PyArray2<bool>>,
);

/// Many walkers on one mesh; see `spinal.quaternions.walk_mesh_many`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, face, points, directions, moves, k))]
#[allow(clippy::too_many_arguments)]
pub fn walk_mesh_many<'py>(
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
        return Err(value_error(
            "points, directions: one row per walker (as many as face)",
        ));
    }
    let mv = vec2s("moves", "(w·k, 2)", &moves)?;
    let starts: Vec<walk::Start> = alloc::collect(
        "walk_mesh_many",
        (0..fc.len()).map(|i| (fc[i], p[i], d.map(|d| d[i]))),
    )?;
    let stop = Stop::default();
    let states = detach_stoppable(py, &stop, || {
        let w = walk::Walker::new(v, f)?;
        walk::walk_many(&w, &starts, mv, k, &|| stop.requested())
    })??;
    let nw = starts.len();
    let (pts, fcs, frs) = walker_states("walk_mesh_many", &states)?;
    let mut stopped = alloc::with_capacity(
        "walk_mesh_many",
        alloc::product("walk_mesh_many", nw, k, 1)?,
    )?;
    stopped.extend(
        states
            .chunks(k + 1)
            .flat_map(|w| w[1..].iter().map(|s| s.stopped)),
    );
    Ok((
        PyArray1::from_vec(py, pts).reshape([nw, k + 1, 3])?,
        PyArray1::from_vec(py, fcs).reshape([nw, k + 1])?,
        PyArray1::from_vec(py, frs).reshape([nw, k + 1, 3, 3])?,
        PyArray1::from_vec(py, stopped).reshape([nw, k])?,
    ))
}
