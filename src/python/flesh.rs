//! Skinning on a spine or a spine surface (`spinal.SpineBinding`, `spinal.SurfaceBinding`);
//! the algorithms are in [`crate::flesh`].

use glam::DVec3;
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
};
use pyo3::prelude::*;

use super::convert::{Stop, detach_stoppable, empty, slice_mut, slice_of, vec3_array, vec3s};
use super::options::Options;
use crate::error::Result;
use crate::flesh::{self, Solution, surface, trisurf};
use crate::run::alloc;
use crate::run::cancel::Cancel;

type FleshBinding<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray2<f64>>);
type SurfaceFleshBinding<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray2<f64>>, i32);
type FleshPose<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<u8>>);
type Resampled<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// The points `(n, 3)` and frames `(n, 3, 3)` of a spine, both named `arg`.
fn spine_arrays<'a>(
    arg: &'static str,
    points: &'a PyReadonlyArray2<'_, f64>,
    frames: &'a PyReadonlyArray3<'_, f64>,
) -> PyResult<(&'a [DVec3], &'a [f64])> {
    Ok((vec3s(arg, points)?, slice_of(arg, frames)?))
}

/// Register vertices on a rest spine; see `spinal.SpineBinding`.
#[pyfunction]
#[pyo3(signature = (rest_points, rest_frames, vertices, closed=false))]
pub fn flesh_bind<'py>(
    py: Python<'py>,
    rest_points: PyReadonlyArray2<'py, f64>,
    rest_frames: PyReadonlyArray3<'py, f64>,
    vertices: PyReadonlyArray2<'py, f64>,
    closed: bool,
) -> PyResult<FleshBinding<'py>> {
    let (pts, fr) = spine_arrays("rest_spine", &rest_points, &rest_frames)?;
    let v = vec3s("vertices", &vertices)?;
    let stop = Stop::default();
    let b = detach_stoppable(py, &stop, || {
        let cancel = || stop.requested();
        let rest = flesh::SpineModel::new("rest_spine", pts, fr, closed, &cancel)?;
        flesh::bind(&rest, v, &cancel)
    })??;
    let nv = b.edge.len();
    let coords = PyArray1::from_vec(py, b.coords).reshape([nv, flesh::COORDS])?;
    Ok((PyArray1::from_vec(py, b.edge), coords))
}

/// Deform registered vertices onto a posed spine; see `spinal.SpineBinding.deform`.
/// `options`: `solution`, `twist` (per-vertex angles, `None` for none), `closed` (default
/// false), `blend` (the weight of `solution="blend"`, refused with the other solutions) and
/// `planar` (default false: the shape lies in the spine's plane, where every corrected
/// solution is the planar quadratic, the normal solution).
#[pyfunction]
pub fn flesh_deform<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    posed_frames: PyReadonlyArray3<'py, f64>,
    edge: PyReadonlyArray1<'py, i64>,
    coords: PyReadonlyArray2<'py, f64>,
    options: Options<'py>,
) -> PyResult<FleshPose<'py>> {
    let solution: Solution = options.get("solution")?;
    let twist: Option<PyReadonlyArray1<'py, f64>> = options.opt("twist")?;
    let closed: bool = options.get_or("closed", false)?;
    let blend: Option<f64> = options.opt("blend")?;
    let planar: bool = options.get_or("planar", false)?;
    let mut solution = solution.with_blend(blend)?;
    if planar && solution != Solution::None {
        solution = Solution::Normal;
    }
    let (pts, fr) = spine_arrays("posed_spine", &posed_points, &posed_frames)?;
    let edge = slice_of("edge", &edge)?;
    let coords = slice_of("coords", &coords)?;
    let tw: &[f64] = match &twist {
        Some(t) => slice_of("twist", t)?,
        None => &[],
    };
    posed(
        py,
        "SpineBinding.deform",
        "flesh",
        edge.len(),
        |buf, flags, cancel| {
            let posed = flesh::SpineModel::new("posed_spine", pts, fr, closed, cancel)?;
            flesh::deform(&posed, edge, coords, solution, tw, buf, flags, cancel)
        },
    )
}

/// The deformed vertices `(n, 3)` and their clamp flags, written by `deform(vertices, flags,
/// cancel)` with the GIL released; `call` and `label` name the call in a memory error.
fn posed<'py>(
    py: Python<'py>,
    call: &'static str,
    label: &'static str,
    n: usize,
    deform: impl FnOnce(&mut [DVec3], &mut [u8], Cancel<'_>) -> crate::error::Result<()> + Send,
) -> PyResult<FleshPose<'py>> {
    let out = empty::<f64, numpy::Ix2>(py, call, &[n, 3])?;
    let mut flags = alloc::filled(label, n, 0u8)?;
    {
        let mut w = out.readwrite();
        let buf: &mut [DVec3] = bytemuck::cast_slice_mut(slice_mut(&mut w)?);
        let stop = Stop::default();
        detach_stoppable(py, &stop, || deform(buf, &mut flags, &|| stop.requested()))??;
    }
    Ok((out, PyArray1::from_vec(py, flags)))
}

/// The settings of a surface deform, read from its `options`: `rest_exp` (the exponent of
/// the rest surface's normalisation, from the bind), `corrected` (the offset solution) and
/// `directions` (`None`, or the offset directions that replace the surface's normals with
/// the name of the argument they came from).
struct SurfacePose<'py> {
    rest_exp: i32,
    corrected: bool,
    directions: Option<(String, PyReadonlyArray2<'py, f64>)>,
}

impl<'py> SurfacePose<'py> {
    fn read(o: &Options<'py>) -> PyResult<SurfacePose<'py>> {
        Ok(SurfacePose {
            rest_exp: o.get("rest_exp")?,
            corrected: o.get("corrected")?,
            directions: o.opt("directions")?,
        })
    }

    /// Convert the posed surface's points, the offset directions, each vertex's cell or
    /// face (`at`, with its argument name) and coordinates, then run
    /// `deform(points, directions, at, coords, (vertices, flags, cancel))` into [`posed`].
    fn run(
        self,
        py: Python<'py>,
        posed_points: &PyReadonlyArray2<'py, f64>,
        (at_arg, at): (&'static str, &PyReadonlyArray1<'py, i64>),
        coords: &PyReadonlyArray2<'py, f64>,
        deform: impl FnOnce(&[DVec3], Directions<'_>, &[i64], &[f64], Written<'_>) -> Result<()> + Send,
    ) -> PyResult<FleshPose<'py>> {
        let pts = vec3s("posed_surface", posed_points)?;
        let dirs = directions_of(&self.directions)?;
        let at = slice_of(at_arg, at)?;
        let coords = slice_of("coords", coords)?;
        posed(
            py,
            "SurfaceBinding.deform",
            "flesh_surface",
            at.len(),
            |buf, flags, cancel| deform(pts, dirs, at, coords, (buf, flags, cancel)),
        )
    }
}

/// Offset directions named after the argument they came from.
type Directions<'a> = Option<(&'static str, &'a [DVec3])>;

/// What a deform writes: the vertices, their clamp flags, and the stop poll.
type Written<'a> = (&'a mut [DVec3], &'a mut [u8], Cancel<'a>);

/// The offset directions that replace a posed surface's normals, named after the argument
/// they came from (`posed_up`, else `posed_frames`).
fn directions_of<'a>(
    directions: &'a Option<(String, PyReadonlyArray2<'_, f64>)>,
) -> PyResult<Directions<'a>> {
    let Some((name, d)) = directions else {
        return Ok(None);
    };
    let arg = if name == "posed_up" {
        "posed_up"
    } else {
        "posed_frames"
    };
    Ok(Some((arg, vec3s(arg, d)?)))
}

/// What a surface binding returns: each vertex's cell or face, its coordinates
/// `(n, SURFACE_COORDS)` and the exponent of the rest surface's normalisation.
fn surface_binding(
    py: Python<'_>,
    (at, coords, exp): (Vec<i64>, Vec<f64>, i32),
) -> PyResult<SurfaceFleshBinding<'_>> {
    let n = at.len();
    let coords = PyArray1::from_vec(py, coords).reshape([n, surface::SURFACE_COORDS])?;
    Ok((PyArray1::from_vec(py, at), coords, exp))
}

/// Compass-walk resampling of a posed spine; see `spinal.SpineBinding.posed_spine`. Returns
/// the points and their positions `k + u` on the input polyline.
#[pyfunction]
pub fn flesh_resample<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    chords: PyReadonlyArray1<'py, f64>,
) -> PyResult<Resampled<'py>> {
    let pts = vec3s("posed_spine", &posed_points)?;
    let ch = slice_of("chords", &chords)?;
    let stop = Stop::default();
    let (out, at) = detach_stoppable(py, &stop, || {
        flesh::spine::compass_walk_located(pts, ch, &|| stop.requested())
    })??;
    Ok((vec3_array(py, out)?, PyArray1::from_vec(py, at)))
}

/// The rotation matrix by the smallest angle taking unit `t0` to unit `t1` (a half turn for
/// opposite vectors).
#[pyfunction]
pub fn minimal_rotation<'py>(
    py: Python<'py>,
    t0: [f64; 3],
    t1: [f64; 3],
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let m = crate::math::rotation::minimal_rotation_matrix(t0.into(), t1.into());
    // glam is column-major; NumPy's rows are the matrix rows
    let rows = m.transpose().to_cols_array().to_vec();
    numpy::PyArray1::from_vec(py, rows).reshape([3, 3])
}

/// Register vertices on a rest spine surface (grid `nu × nv`); see `spinal.SurfaceBinding`.
/// Also returns the exponent of the rest surface's normalisation (the units of some of the
/// coordinates), which [`flesh_surface_deform`] takes back.
#[pyfunction]
pub fn flesh_surface_bind<'py>(
    py: Python<'py>,
    rest_points: PyReadonlyArray2<'py, f64>,
    nu: usize,
    nv: usize,
    vertices: PyReadonlyArray2<'py, f64>,
) -> PyResult<SurfaceFleshBinding<'py>> {
    let pts = vec3s("rest_surface", &rest_points)?;
    let v = vec3s("vertices", &vertices)?;
    let stop = Stop::default();
    let bound = detach_stoppable(py, &stop, || {
        let rest = surface::Surface::new("rest_surface", pts, nu, nv)?;
        let (cell, coords) = surface::bind_surface(&rest, v, &|| stop.requested())?;
        Ok::<_, crate::error::InputError>((cell, coords, rest.scale.exp()))
    })??;
    surface_binding(py, bound)
}

/// Deform vertices registered on a spine surface; see `spinal.SurfaceBinding.deform`.
/// `options` as in [`SurfacePose`], the directions one per sample, row-major.
#[pyfunction]
pub fn flesh_surface_deform<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    nu: usize,
    nv: usize,
    cell: PyReadonlyArray1<'py, i64>,
    coords: PyReadonlyArray2<'py, f64>,
    options: Options<'py>,
) -> PyResult<FleshPose<'py>> {
    let pose = SurfacePose::read(&options)?;
    let (rest_exp, corrected) = (pose.rest_exp, pose.corrected);
    pose.run(
        py,
        &posed_points,
        ("cell", &cell),
        &coords,
        |pts, dirs, at, c, out| {
            let posed = match dirs {
                Some((arg, d)) => {
                    surface::Surface::with_directions("posed_surface", pts, nu, nv, arg, d)?
                }
                None => surface::Surface::new("posed_surface", pts, nu, nv)?,
            };
            let (buf, flags, cancel) = out;
            surface::deform_surface(&posed, rest_exp, at, c, corrected, buf, flags, cancel)
        },
    )
}

/// Register vertices on a rest spine surface given as a triangle mesh (`faces` (F, 3));
/// see `spinal.SurfaceBinding`. Returns the face and coordinates of every vertex and the
/// exponent of the rest surface's normalisation, which [`flesh_trisurface_deform`] takes back.
#[pyfunction]
pub fn flesh_trisurface_bind<'py>(
    py: Python<'py>,
    rest_points: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    vertices: PyReadonlyArray2<'py, f64>,
) -> PyResult<SurfaceFleshBinding<'py>> {
    let pts = vec3s("rest_surface", &rest_points)?;
    let fs = slice_of("rest_surface", &faces)?;
    let v = vec3s("vertices", &vertices)?;
    let stop = Stop::default();
    let bound = detach_stoppable(py, &stop, || {
        let rest = trisurf::TriSurface::new("rest_surface", pts, fs)?;
        let (face, coords) = trisurf::bind_trisurface(&rest, v, &|| stop.requested())?;
        Ok::<_, crate::error::InputError>((face, coords, rest.scale.exp()))
    })??;
    surface_binding(py, bound)
}

/// Orthonormal frames `(n, 3, 3)`, columns `(e1, e2, normal)`, at the vertices of a
/// triangle-mesh spine surface; see `spinal.SurfaceBinding.rest_frames`.
#[pyfunction]
pub fn flesh_trisurface_frames<'py>(
    py: Python<'py>,
    rest_points: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
) -> PyResult<Bound<'py, numpy::PyArray3<f64>>> {
    let pts = vec3s("rest_surface", &rest_points)?;
    let fs = slice_of("rest_surface", &faces)?;
    let n = pts.len();
    let frames = py.detach(|| {
        let rest = trisurf::TriSurface::new("rest_surface", pts, fs)?;
        rest.frames("SurfaceBinding")
    })?;
    // row-major (vertex, row, column): column c of vertex i is frames[i][c]
    let mut flat = alloc::filled("SurfaceBinding", 9 * n, 0.0)?;
    for (out, f) in flat.chunks_exact_mut(9).zip(&frames) {
        for r in 0..3 {
            for c in 0..3 {
                out[3 * r + c] = f[c][r];
            }
        }
    }
    PyArray1::from_vec(py, flat).reshape([n, 3, 3])
}

/// Deform vertices registered on a triangle-mesh spine surface; see
/// `spinal.SurfaceBinding.deform`. `options` as in [`SurfacePose`], the directions one per
/// vertex.
#[pyfunction]
pub fn flesh_trisurface_deform<'py>(
    py: Python<'py>,
    posed_points: PyReadonlyArray2<'py, f64>,
    faces: PyReadonlyArray2<'py, i64>,
    face: PyReadonlyArray1<'py, i64>,
    coords: PyReadonlyArray2<'py, f64>,
    options: Options<'py>,
) -> PyResult<FleshPose<'py>> {
    let pose = SurfacePose::read(&options)?;
    let (rest_exp, corrected) = (pose.rest_exp, pose.corrected);
    let fs = slice_of("posed_surface", &faces)?;
    pose.run(
        py,
        &posed_points,
        ("face", &face),
        &coords,
        |pts, dirs, at, c, out| {
            let posed = match dirs {
                Some((arg, d)) => {
                    trisurf::TriSurface::with_directions("posed_surface", pts, fs, arg, d)?
                }
                None => trisurf::TriSurface::new("posed_surface", pts, fs)?,
            };
            let (buf, flags, cancel) = out;
            trisurf::deform_trisurface(&posed, rest_exp, at, c, corrected, buf, flags, cancel)
        },
    )
}
