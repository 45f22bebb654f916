//! Fleshing: spine-driven deformation with local volume preservation (Wei Zhuo, PhD thesis,
//! Georgia Tech 2014, and Zhuo & Rossignac, CGF 2013; see docs/references.md).
//!
//! A vertex `P0` is registered on the rest spine by its cross-section (Assumption I, §1.2):
//! parameter `(k, a)` on edge `k` and offset `d0 ⊥ t0(k, a)` in the interpolated RMF. After the
//! spine moves, the vertex is rebuilt from the posed spine at the same `(k, a)` with a
//! corrected offset — unbend (rest curvature), transfer (RMF to RMF, optional twist, stretch),
//! bend (posed curvature) (§4.2.1, §5.2.1) — so that `det ∂P1/∂P0 = 1`.
//!
//! **Discrete spine model** ([`spine`]). Between samples `k` and `k + 1` the position `C(a)`
//! is the cubic Hermite interpolant of the two samples with end slopes `h_k t_k`, `h_k t_{k+1}`
//! (`h_k` the chord length, `t_j` the sample unit tangents), and the unit tangent is a
//! normalised cubic Hermite interpolation of the sample tangents whose slopes match the
//! sample curvature vectors; the cross-section at `(k, a)` is the plane through `C(a)`
//! normal to `t(a)`. In the coordinates
//! `(a, α, β)` of that foliation the volume element is exactly `σ(a) (1 − d·κ(a)) da dα dβ`
//! with `σ = E_k·t(a)` and `κ = (dt/da)/σ` (the spine's speed and curvature vector in this
//! model), so the thesis' stretchable formulas with `λ = σ1/σ0` make the discrete map exactly
//! volume preserving inside every edge slab for any sampling, not only in the limit. The
//! curvature is continuous across samples, so is the map (up to the O(h³) jump of the speed
//! ratio); points beyond the end planes use the straight extension of the end (κ = 0).
//!
//! **Loops** (`closed`): the spine is given with its first sample and frame repeated at the
//! end, so the closing edge is an edge like the others; the sample curvature at the seam is
//! the central difference across it, and there are no ends to extend. The frames are the
//! RMF with its closing angle spread linearly in arc length (Wang et al. §6.3), so the
//! sections meet across the seam.
//!
//! **The posed frames** are an input: the unbend–transfer–bend map carries the offset's
//! coordinates from the rest frame to whatever frame the posed spine gets, so the roll of
//! the posed spine about its tangent (which Zhuo 2014 leaves open; a best fit cannot recover
//! it for a straight spine) can come from the caller — a rigid motion's frames give a rigid
//! result, a rig's frames roll the shape — without changing the volume element.
//!
//! Registration (bind) starts from the edge of the vertex before and climbs a hierarchy of
//! boxes over the edges ([`crate::math::chain`]: `O(log n)` box tests per vertex whose
//! section is near the one before; results do not depend on where the search starts);
//! deformation is
//! `O(V + n)`, per vertex independent and run in parallel with rayon.

pub mod bind;
pub mod blend;
pub mod pose;
pub mod section;
pub mod solve;
pub mod spine;
pub mod surface;
pub mod trisurf;

pub use bind::{Binding, COORDS, bind};
pub use pose::deform;
pub use solve::Solution;
pub use spine::SpineModel;

/// Below this `1 − κ1 x'` the binormal solution is clamped (a choice of ours: the thesis gives
/// no policy past the limit).
pub const BINORMAL_MIN_FACTOR: f64 = 1e-3;
/// Curvatures below this (1/length units) are treated as straight: the step is the identity.
pub const TINY_CURVATURE: f64 = 1e-300;

/// Flag bits reported per vertex.
pub const CLAMPED_BEND: u8 = 1;
pub const CLAMPED_UNBEND: u8 = 2;

/// The normal offset after a bend by the curvature `κ` (Eq. 15 in its stable form,
/// `x1 = 2x_t/(1 + √(1 − 2κ x_t))`, of the stretched offset `x_t`), clamped at the focal
/// point `1/κ` with [`CLAMPED_BEND`] set in `flags` where no fold-free root exists. Shared by
/// the normal solution ([`solve`]) and the blend's normal stage ([`blend`]).
#[inline(always)]
fn bent_normal(kk: f64, xt: f64, flags: &mut u8) -> f64 {
    let disc = 1.0 - 2.0 * kk * xt;
    if disc < 0.0 {
        *flags |= CLAMPED_BEND;
        1.0 / kk
    } else {
        2.0 * xt / (1.0 + disc.sqrt())
    }
}

/// Refuse vertices that are not finite, or that leave the range of `f64` once brought to the
/// units of a rest model (`to_model`) far smaller than 1; errors name `vertices` and say
/// which model (`"spine"` or `"surface"`).
fn check_vertices(
    vertices: &[glam::DVec3],
    to_model: crate::math::scale::Pow2,
    model: &str,
) -> crate::error::Result<()> {
    use crate::error::InputError;
    use rayon::prelude::*;
    if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(InputError::new(
            "vertices",
            format!("row {i} is not finite"),
        ));
    }
    if to_model.exp() > 0 {
        // a model far smaller than 1: a vertex far from it may leave the range once scaled
        if let Some(i) = vertices
            .par_iter()
            .position_first(|v| !to_model.of3(*v).is_finite())
        {
            return Err(InputError::new(
                "vertices",
                format!(
                    "row {i} is out of range: its distance from the rest {model}, in units of \
                     the {model}'s size, exceeds float64"
                ),
            ));
        }
    }
    Ok(())
}
