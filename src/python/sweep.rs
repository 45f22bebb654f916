//! Sweeps and tubes (`spinal.sweep`); the algorithm is in [`crate::sweep`].

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PySlice;

use super::convert::{
    Report, Stop, detach_reporting, detach_stoppable, empty, ensure_memory, frames_of, offsets_of,
    slice_mut, slice_of, vec2s, vec3s,
};
use super::options::Options as Request;
use super::out::{output, writing};
use crate::sweep::{self, FrameSource, Options, Prepared, Spine};

type MeshArrays<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Option<Bound<'py, PyAny>>,
    Option<Bound<'py, PyAny>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// Sweep a profile along one or many spines; see `spinal.sweep`. `frames`: one per row, or
/// `None` for the rotation-minimising frames of `spinal.frames(points, tangents)` (its
/// defaults; `tangents` optional), computed spine by spine as the sweep goes. Returns
/// vertices, faces,
/// normals (or None), uv (or None), the rows where a miter was folded and the number of
/// faces of every spine (its faces follow those of the spine before it), and for every ring
/// stored after a spine's rings for a corner join (`join`: "round", "bevel" or "miter"),
/// the row of its corner. Coordinates are
/// float32 with `single` (computed in float64, stored rounded), faces int32 with `index32`
/// when the vertex count fits (int64 otherwise). Errors about the scale name `scale_arg`
/// (`spinal.tube` passes its radius as the scale). `scale` may have a single row (the same
/// scale at every sample). `progress(done, rows)` is called from the waiting thread as the
/// spines are swept (rows of the spines done) and once at the end. `turns`: extra turns of
/// a closed spine's computed frames; a half number joins the seam with a half turn (with
/// given frames: they close that way; see `sweep::seam`). `out_vertices`, `out_normals`,
/// `out_uv`: arrays of exactly the shapes and dtype of the results to write them into
/// (else new ones; named `out.vertices` … in errors).
#[pyfunction]
#[pyo3(signature = (points, frames, scale, twist, offsets, profile, options, progress=None))]
#[allow(clippy::too_many_arguments)] // eight from Python, and the GIL token
pub fn sweep_mesh<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    frames: Option<PyReadonlyArray3<'py, f64>>,
    scale: PyReadonlyArray2<'py, f64>,
    twist: Option<PyReadonlyArray1<'py, f64>>,
    offsets: PyReadonlyArray1<'py, i64>,
    profile: PyReadonlyArray2<'py, f64>,
    options: Request<'py>,
    progress: Option<Py<PyAny>>,
) -> PyResult<MeshArrays<'py>> {
    let o = &options;
    let profile_closed: bool = o.get("profile_closed")?;
    let closed: bool = o.get("closed")?;
    let caps: bool = o.get("caps")?;
    let miter_limit: f64 = o.get("miter_limit")?;
    let split_seams: bool = o.get("split_seams")?;
    let scale_arg: String = o.get_or("scale_arg", "scale".to_string())?;
    let single: bool = o.get_or("single", false)?;
    let index32: bool = o.get_or("index32", false)?;
    let normals: bool = o.get_or("normals", true)?;
    let uv: bool = o.get_or("uv", true)?;
    let tangents: Option<PyReadonlyArray2<'py, f64>> = o.opt("tangents")?;
    let join: String = o.get_or("join", "round".to_string())?;
    let turns: f64 = o.get_or("turns", 0.0)?;
    let out_vertices: Option<Bound<'py, PyAny>> = o.opt("out_vertices")?;
    let out_normals: Option<Bound<'py, PyAny>> = o.opt("out_normals")?;
    let out_uv: Option<Bound<'py, PyAny>> = o.opt("out_uv")?;
    let join = match join.as_str() {
        "round" => sweep::Join::Round,
        "bevel" => sweep::Join::Bevel,
        "miter" => sweep::Join::Miter,
        _ => {
            return Err(PyValueError::new_err(format!(
                "join: expected 'round', 'bevel' or 'miter', got {join:?}"
            )));
        }
    };
    let spine = Spine {
        points: vec3s("points", &points)?,
        frames: match &frames {
            Some(f) => frames_of("frames", f)?,
            None => &[],
        },
        scale: vec2s("scale", "(n, 2)", &scale)?,
        twist: match &twist {
            Some(t) => slice_of("twist", t)?,
            None => &[],
        },
    };
    let prof = vec2s("profile", "(m, 2)", &profile)?;
    let offsets = offsets_of(&offsets)?;
    let source = match &frames {
        Some(_) => FrameSource::Given,
        None => {
            let tangents = tangents
                .as_ref()
                .map(|t| vec3s("tangents", t))
                .transpose()?;
            // the frames of the longest spine and the working vectors of their computation
            // (the bytes per row that `spinal.frames` checks for)
            let longest = offsets.windows(2).map(|w| w[1].saturating_sub(w[0])).max();
            ensure_memory("sweep", longest.unwrap_or(0), 256)?;
            FrameSource::Rmf { tangents }
        }
    };
    let opts = Options {
        closed,
        caps,
        miter_limit,
        split_seams,
        join,
        turns,
        scale_name: &scale_arg,
    };
    let stop = Stop::default();
    let prep = detach_stoppable(py, &stop, || {
        let cancel = || stop.requested();
        Prepared::new(spine, &offsets, prof, profile_closed, opts, source, &cancel)
    })?
    // stopped only when a signal handler raised, whose error detach_stoppable returned
    ?;
    // int32 faces only where every index fits
    let index32 = index32 && prep.layout.indices_fit_i32();
    let job = Job {
        prep: &prep,
        normals,
        uv,
        report: Report::new(progress, offsets.last().copied().unwrap_or(0)),
        out: [out_vertices, out_normals, out_uv],
    };
    match (single, index32) {
        (false, false) => job.run::<f64, i64>(py),
        (false, true) => job.run::<f64, i32>(py),
        (true, false) => job.run::<f32, i64>(py),
        (true, true) => job.run::<f32, i32>(py),
    }
}

/// A checked sweep, to be written into arrays of a chosen precision.
struct Job<'a, 'py> {
    prep: &'a Prepared<'a>,
    normals: bool,
    uv: bool,
    /// The spine rows swept, reported to the caller's `progress(done, total)`.
    report: Option<Report>,
    /// The caller's arrays for the vertices, normals and uv, where given.
    out: [Option<Bound<'py, PyAny>>; 3],
}

impl<'py> Job<'_, 'py> {
    fn run<R, I>(&self, py: Python<'py>) -> PyResult<MeshArrays<'py>>
    where
        R: sweep::Real + numpy::Element + bytemuck::Pod,
        I: sweep::Index + numpy::Element + bytemuck::Pod,
    {
        let (nv, nf) = (self.prep.layout.vertices, self.prep.layout.faces);
        let [ov, on, ou] = self.out.clone();
        let v = output::<R, numpy::Ix2>(py, "sweep", &[nv, 3], ov, "out.vertices")?;
        let f = empty::<I, numpy::Ix2>(py, "sweep", &[nf, 3])?;
        let n = match self.normals {
            true => Some(output::<R, numpy::Ix2>(
                py,
                "sweep",
                &[nv, 3],
                on,
                "out.normals",
            )?),
            false => None,
        };
        let uv = match self.uv {
            true => Some(output::<R, numpy::Ix2>(
                py,
                "sweep",
                &[nv, 2],
                ou,
                "out.uv",
            )?),
            false => None,
        };
        let folds = {
            let (mut wv, mut wf) = (writing(&v, "out.vertices")?, f.readwrite());
            let mut wn = n.as_ref().map(|a| writing(a, "out.normals")).transpose()?;
            let mut wu = uv.as_ref().map(|a| writing(a, "out.uv")).transpose()?;
            let out = sweep::MeshMut::<R, I> {
                vertices: bytemuck::cast_slice_mut(slice_mut(&mut wv)?),
                faces: bytemuck::cast_slice_mut(slice_mut(&mut wf)?),
                normals: match wn.as_mut() {
                    Some(w) => Some(bytemuck::cast_slice_mut(slice_mut(w)?)),
                    None => None,
                },
                uv: match wu.as_mut() {
                    Some(w) => Some(bytemuck::cast_slice_mut(slice_mut(w)?)),
                    None => None,
                },
            };
            let stop = Stop::default();
            let done = Report::counter(&self.report);
            detach_reporting(py, &stop, self.report.as_ref(), || {
                self.prep.write_into(out, &|| stop.requested(), done)
            })??
        };
        let written = folds;
        let as_i64 = |a: &[usize]| a.iter().map(|&i| i as i64).collect::<Vec<i64>>();
        let mut f = f.into_any();
        if written.faces < nf {
            // the faces the joins' welds flattened are left out: a view of the ones kept
            f = f.get_item(PySlice::new(py, 0, written.faces as isize, 1))?;
        }
        Ok((
            v.into_any(),
            f,
            n.map(Bound::into_any),
            uv.map(Bound::into_any),
            PyArray1::from_vec(py, as_i64(&written.folds)),
            PyArray1::from_vec(py, as_i64(&written.faces_per_spine)),
            PyArray1::from_vec(py, as_i64(&written.join_rows)),
        ))
    }
}
