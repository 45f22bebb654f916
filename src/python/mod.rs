//! The Python binding layer (`spinal._core`), one thin file per concept: it converts NumPy
//! arrays to slices ([`convert`]), runs the heavy calls with the GIL released in the rayon
//! pool of [`threads`] and maps [`InputError`](crate::InputError) to `ValueError`. It holds
//! no algorithms; the Python package (`python/spinal`) normalises arguments (dtype, layout,
//! shapes) before calling in here, so these functions expect C-contiguous arrays of the
//! right dtype, and the options of a call as one dict ([`options`]). Nothing here imports
//! the package's Python modules ([`coerce`] converts for `Field.__call__`). The core
//! modules never name pyo3 (checked by a test below).

mod coerce;
mod convert;
mod deform;
mod fields;
mod flesh;
mod frames;
mod mesh;
mod options;
mod out;
mod ph;
mod quaternion;
mod sweep;
mod threads;

use pyo3::prelude::*;

#[pymodule(name = "_core")]
fn core_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(frames::frames_sampled, m)?)?;
    m.add_function(wrap_pyfunction!(frames::frames_analytic, m)?)?;
    m.add_function(wrap_pyfunction!(frames::estimate_tangents, m)?)?;
    m.add_function(wrap_pyfunction!(frames::frames_steered, m)?)?;
    m.add_function(wrap_pyfunction!(frames::frames_in_time, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_from_frames, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_spin, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_to_frames, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_continuous, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_slerp, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_slerp_frames, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::camera_inputs, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::camera_level, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::camera_orient, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_path_length, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::quat_transport, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::walk_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(quaternion::walk_mesh_many, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_hermite, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_eval, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_invariants, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_is_ph, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_from_quaternions, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_preimage, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_check_spline, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_frame_setup, m)?)?;
    m.add_function(wrap_pyfunction!(ph::ph_frames, m)?)?;
    m.add_class::<fields::PyField>()?;
    m.add_function(wrap_pyfunction!(fields::field_translation, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_rotation, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_swirl, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_sphere, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_capsule, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_strip, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_torus, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_strip_curve, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_grid, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_grid_coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_path, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_zero, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_grid_curl, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_rod, m)?)?;
    m.add_function(wrap_pyfunction!(fields::field_keyframed, m)?)?;
    m.add_function(wrap_pyfunction!(deform::advect, m)?)?;
    m.add_function(wrap_pyfunction!(deform::advect_runs, m)?)?;
    m.add_class::<deform::DeformStats>()?;
    m.add_function(wrap_pyfunction!(deform::deform_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(deform::stamp, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_volume, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_closed_centroid, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_measure, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_edges, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_self_intersections, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_check_faces, m)?)?;
    m.add_function(wrap_pyfunction!(mesh::mesh_check_finite, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::minimal_rotation, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_bind, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_deform, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_trisurface_bind, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_trisurface_deform, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_trisurface_frames, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_resample, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_surface_bind, m)?)?;
    m.add_function(wrap_pyfunction!(flesh::flesh_surface_deform, m)?)?;
    m.add_function(wrap_pyfunction!(threads::set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(threads::num_threads_setting, m)?)?;
    m.add_function(wrap_pyfunction!(threads::get_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(convert::pool_threads, m)?)?;
    m.add_function(wrap_pyfunction!(frames::distinct_rows, m)?)?;
    m.add(
        "RepeatedPointsError",
        m.py().get_type::<convert::RepeatedPointsError>(),
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    /// Every `.rs` file under `dir`, recursively.
    fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
        let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries {
            let path = entry.expect("directory entry").path();
            if path.is_dir() {
                rust_files(&path, out);
            } else if path.extension().is_some_and(|x| x == "rs") {
                out.push(path);
            }
        }
    }

    /// The core (everything in `src/` outside `src/python/`) never names pyo3 or the numpy
    /// crate, so it builds, tests and benches without Python.
    #[test]
    fn core_never_names_pyo3() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let binding = src.join("python");
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        assert!(files.len() > 10, "found only {files:?}");
        let offenders: Vec<String> = files
            .iter()
            .filter(|p| !p.starts_with(&binding))
            .filter_map(|p| {
                let text = std::fs::read_to_string(p).expect("readable source file");
                let hits: Vec<String> = text
                    .lines()
                    .enumerate()
                    .filter(|(_, l)| l.contains("pyo3") || l.contains("numpy::"))
                    .map(|(i, l)| format!("{}:{}: {}", p.display(), i + 1, l.trim()))
                    .collect();
                (!hits.is_empty()).then(|| hits.join("\n"))
            })
            .collect();
        assert!(
            offenders.is_empty(),
            "the core must not name pyo3 or numpy:: (the binding lives in src/python/):\n{}",
            offenders.join("\n")
        );
    }
}
