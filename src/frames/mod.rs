//! Moving frames along sampled and analytic curves.
//!
//! A frame is `U = (r, s, t)`: `t` the unit tangent, `r` the reference vector (⟂ t) and
//! `s = t × r`, so the matrix with columns `(r, s, t)` is a rotation. Methods:
//!
//! | method | module | order | notes |
//! |---|---|---|---|
//! | double reflection | [`double_reflection`] | 4 | exact on lines, planes and spheres |
//! | rotation (Bloomenthal, discrete parallel transport) | [`rotation`] | 2 | |
//! | projection (Klok) | [`projection`] | 2 | depends on the initial vector |
//! | bisector planes (Klok's polygon variant) | [`projection`] | 2 (1 at the ends) | points only; its own tangents |
//! | RK4 on the RMF ODE | [`rk4`] | 4 | analytic curves (needs x′, x″) |
//! | RK4, unprojected φ-form (Wang et al.'s Table III) | [`rk4`] | 4 | analytic curves; for comparisons |
//! | Frenet | [`frenet`] | exact where κ ≠ 0 | continuous fill at κ ≈ 0 |
//! | Frenet turned by −∫τ ds | [`torsion`] | 4 (exact on helices) | analytic curves (needs x‴), κ ≠ 0 |
//!
//! Boundary conditions (closed curves, a prescribed end vector) add a twist linear in arc
//! length ([`transport`]). [`steer`] turns the RMF about its tangents to meet constraints at
//! any rows ([`constraints`], twist by arc length or by curvature), to follow a guide
//! ([`guide`]) or to stay close to the previous time step ([`time`]).
//!
//! What a caller asks for ([`Request`], [`Method`], [`Orientation`]) is in `request.rs`, the
//! input checks in `check.rs`. The driver [`compute_into`] (`dispatch.rs`) validates the
//! input, estimates the tangents when they are not given ([`tangents`]), picks the initial
//! vector and writes the frames into a caller-provided buffer; [`compute_many`] maps it over
//! a bundle of curves in parallel.

pub mod constraints;
pub mod double_reflection;
pub mod end_cone;
pub mod frenet;
pub mod fused;
pub mod geometry;
pub mod guide;
pub mod lanes;
pub mod projection;
pub mod rk4;
pub mod rotation;
pub mod steer;
pub mod tangent_lanes;
pub mod tangents;
pub mod time;
pub mod torsion;
pub mod transport;
pub mod validate;

mod carry;
mod check;
mod dispatch;
mod request;
#[cfg(test)]
mod tests;

pub(crate) use dispatch::{bundle_slices, rmf_parts};
pub use dispatch::{compute_general, compute_into, compute_many};
pub(crate) use request::resolve;
pub use request::{
    Analytic, FRAME_TANGENT_TOL, Method, Names, Orientation, Request, STRAIGHT_TOL,
    WORKING_BYTES_PER_ROW, pick,
};
pub use tangents::TangentRule;
