//! Sweeps and tubes (`spinal.sweep`); the algorithm is in [`crate::sweep`].

use glam::{DVec2, DVec3};
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{empty, frames_of, offsets_of, renamed, slice_mut, slice_of, vec2s, vec3s};
use crate::math::scale;
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
    // A spine or profile far from unit size is swept divided by powers of two (exact):
    // spine points by 2^k (its size), the profile by 2^j (its largest coordinate) and the
    // scale multiplied by 2^(k + j), so x + M(scale ⊙ profile) is the swept surface times 2^k;
    // the vertices and arc lengths are multiplied back after. The normals and fold tests
    // multiply lengths and would overflow otherwise.
    let finite = pts.iter().all(|p| p.is_finite())
        && prof.iter().all(|p| p.is_finite())
        && sc.iter().all(|v| v.x > 0.0 && v.y > 0.0 && v.is_finite());
    let k = finite
        .then(|| {
            let (lo, hi) = crate::frames::geometry::bounds(pts);
            scale::curve_exponent(lo, hi)
        })
        .flatten();
    let pmax = prof
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs().max_element()));
    let j = if finite && pmax > 0.0 {
        let e = scale::exponent(pmax);
        if e.abs() > scale::SAFE_EXP { e } else { 0 }
    } else {
        0
    };
    let (pts_k, prof_k, sc_k);
    let (pts, prof, sc) = if k.is_none() && j == 0 {
        (pts, prof, sc)
    } else {
        let k = k.unwrap_or(0);
        let mul2 = |v: &DVec2, e: i32| DVec2::new(scale::ldexp(v.x, e), scale::ldexp(v.y, e));
        pts_k = scale::scaled(pts, k);
        prof_k = prof.iter().map(|v| mul2(v, -j)).collect::<Vec<_>>();
        sc_k = sc.iter().map(|v| mul2(v, k + j)).collect::<Vec<_>>();
        (&pts_k[..], &prof_k[..], &sc_k[..])
    };
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
            Ok::<_, crate::InputError>((p, lay))
        })
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
        let folds = py.detach(|| sweep::sweep_into(&spine, &offsets, &p, &opts, &lay, out));
        if let Some(k) = k {
            for v in slice_mut(&mut wv)?.iter_mut() {
                *v = scale::ldexp(*v, -k);
            }
            for u in slice_mut(&mut wu)?.iter_mut().step_by(2) {
                *u = scale::ldexp(*u, -k);
            }
        }
        let verts: &[DVec3] = bytemuck::cast_slice(&*slice_mut(&mut wv)?);
        py.detach(|| sweep::check_finite(verts))
            .map_err(|e| renamed(e, "scale", scale_arg))?;
        folds
    };
    let folds: Vec<i64> = folds.iter().map(|&i| i as i64).collect();
    Ok((v, f, n, uv, PyArray1::from_vec(py, folds)))
}
