//! Sweeps and tubes (`spinal.sweep`); the algorithm is in [`crate::sweep`].

use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{
    Stop, detach_in_pool, detach_stoppable, empty, frames_of, offsets_of, renamed, slice_mut,
    slice_of, vec2s, vec3s,
};
use crate::sweep::{self, Options, Profile, Spine};

type MeshArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
);

/// Sweep a profile along one or many spines; see `spinal.sweep`. Returns vertices, faces,
/// normals, uv and the rows where a miter was folded. Errors about the scale name
/// `scale_arg` (`spinal.tube` passes its radius as the scale).
#[pyfunction]
#[pyo3(signature = (points, frames, scale, twist, offsets, profile, profile_closed, closed, caps,
                    miter_limit, split_seams, scale_arg="scale"))]
#[allow(clippy::too_many_arguments)]
pub fn sweep_mesh<'py>(
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
    scale_arg: &str,
) -> PyResult<MeshArrays<'py>> {
    let pts = vec3s("points", &points)?;
    let fr = frames_of("frames", &frames)?;
    let sc = vec2s("scale", "(n, 2)", &scale)?;
    let tw: &[f64] = match &twist {
        Some(t) => slice_of("twist", t)?,
        None => &[],
    };
    let prof = vec2s("profile", "(m, 2)", &profile)?;
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
    let (p, lay) = detach_in_pool(py, || {
        let p = Profile::new(prof, profile_closed)?;
        let lay = sweep::layout(&spine, &offsets, &p, &opts)?;
        Ok::<_, crate::InputError>((p, lay))
    })?
    .map_err(|e| renamed(e, "scale", scale_arg))?;
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
        let stop = Stop::default();
        detach_stoppable(py, &stop, || {
            let cancel = || stop.requested();
            sweep::sweep_into_cancellable(&spine, &offsets, &p, &opts, &lay, out, &cancel)
        })?
    };
    let folds: Vec<i64> = folds.iter().map(|&i| i as i64).collect();
    Ok((v, f, n, uv, PyArray1::from_vec(py, folds)))
}
