//! spinal — moving frames, sweeps and volume-preserving deformations along 3D curves.
//!
//! The crate is split in two layers:
//!
//! * plain Rust modules that know nothing of Python: [`frames`] (moving frames of sampled
//!   and analytic curves), [`sweep`] (sweeps and tubes), [`quaternion`] (quaternions of
//!   frames, walkers on triangle meshes), [`ph`] (Pythagorean-hodograph cubics), [`deform`]
//!   (volume-preserving deformation by divergence-free fields, advection, the contact
//!   stamper), [`flesh`] (spine-driven deformation with local volume preservation, on a
//!   spine or a spine surface), [`math`] (the shared kernels: cubics, rotations, mesh
//!   measures), [`run`] (the stop hook of long calls and fallible allocation) and
//!   [`error`]. They work on `glam::DVec3` slices and
//!   flat `f64` output buffers and return [`error::InputError`] for bad input, never
//!   panicking on user data;
//! * the binding folder `src/python/` (module `python`, compiled into the `spinal._core`
//!   extension): one thin file per concept that converts NumPy arrays and option strings,
//!   releases the GIL around the heavy calls and maps errors to Python exceptions. It holds
//!   no algorithms, and only it names the Python crates (a test checks the rest of `src/`).
//!
//! Frame layout everywhere: frame `i` occupies `out[9 i .. 9 i + 9]` in row-major order of
//! the 3×3 matrix whose **columns** are `(r, s, t)`, i.e. `[r.x, s.x, t.x, r.y, s.y, t.y,
//! r.z, s.z, t.z]`, which is what NumPy sees as an `(n, 3, 3)` C-ordered array.

// `!(a > b)` is used on purpose: it is also true when a value is NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod deform;
pub mod error;
pub mod flesh;
pub mod frames;
pub mod math;
pub mod mesh;
pub mod ph;
mod python;
pub mod quaternion;
pub mod run;
pub mod sweep;

pub use error::InputError;
