//! Shared maths kernels, each written once and used by the frame, sweep, deformation,
//! fleshing and PH modules.
//!
//! * [`cubic`]: the cubic segment on a local parameter `λ ∈ [0, 1]` in its three forms:
//!   Hermite data `(p₀, p₁, d₀, d₁)` ([`cubic::Hermite`], with the basis functions
//!   [`cubic::basis`]), power form ([`cubic::Power`], Horner evaluation of the value and the
//!   first three derivatives) and Bézier form ([`cubic::Bezier`], de Casteljau and Bernstein
//!   derivatives), with the conversions between them.
//! * [`rotation`]: the minimal rotation taking one unit vector to another (vector and
//!   quaternion forms), Rodrigues' rotation about an axis, the signed angle about an axis,
//!   3×3 rotation matrix ↔ unit quaternion (Shepperd's method), and the test whether a
//!   matrix is a rotation.
//! * [`scale`]: normalisation by a power of two (curves) or the largest component
//!   (vectors, quaternions) before squaring, so results do not depend on the units.
//! * [`mesh`]: signed volume of a closed triangle mesh and its undirected edges (for
//!   manifold checks and adjacency).
//! * [`bvh`]: a bounding-volume hierarchy over boxes, with overlap and nearest-first
//!   queries (face pairs of the self-intersection test, the faces of a rest surface
//!   mesh in registration).
//! * [`chain`]: a hierarchy of boxes over the consecutive items of a chain, searched
//!   nearest first from a start item (the rest spine's edges in registration).
//! * [`predicates`]: exact orientation tests in the plane and in space (Shewchuk's
//!   orient2d and orient3d: a floating-point filter, then exact expansions), for the profile
//!   triangulation and the self-intersection test of meshes.

pub mod bvh;
pub mod chain;
pub mod cubic;
pub mod mesh;
pub mod predicates;
pub mod rotation;
pub mod scale;

#[cfg(test)]
mod proptests;
