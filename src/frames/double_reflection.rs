//! Double reflection (Wang, Jüttler, Zheng & Liu, "Computation of Rotation Minimizing
//! Frames", ACM TOG 27(1), 2008, §4 and Table I; Zheng's thesis Table 5.1).
//!
//! From sample `i` to `i+1` the reference vector is reflected twice:
//!
//! 1. in the bisecting plane of `x_i` and `x_{i+1}`: `R₁ = I − 2 v₁v₁ᵀ/(v₁·v₁)`,
//!    `v₁ = x_{i+1} − x_i`, giving `rᴸ = R₁ r_i` and `tᴸ = R₁ t_i`;
//! 2. in the plane that maps `tᴸ` onto `t_{i+1}`: `R₂ = I − 2 v₂v₂ᵀ/(v₂·v₂)`,
//!    `v₂ = t_{i+1} − tᴸ`, giving `r_{i+1} = R₂ rᴸ`.
//!
//! The composite `R₂R₁` is a rotation taking `t_i` to `t_{i+1}` that depends only on the
//! curve data. It is the exact rotation-minimising transport of the unique sphere (or plane)
//! through `x_i`, `x_{i+1}` tangent to `t_i`, `t_{i+1}`: exact on spherical and planar
//! curves and straight lines, 4th-order accurate in general (one-step error
//! `|K| h⁵/720`, `K = 2κ₁²τ₀ + κ₀²τ₀³ + κ₁κ₀τ₁ − κ₂κ₀τ₀`). Cost: 2 divisions, no square root.
//!
//! Well defined when `v₁ ≠ 0` and `v₁·(t_i + t_{i+1}) > 0`, since `v₂·v₂ ≥ (v̂₁·(t_i + t_{i+1}))²`;
//! the caller checks both before transporting (see `validate`).
//!
//! In the tangents-only variant (TOG §6.2) `v₁` is replaced by a 4th-order quadrature of
//! `∫ t`, see [`super::tangents::tangent_chord`].

use glam::DVec3;

use super::tangents::tangent_chord;
use super::transport::Step;

/// One double-reflection step: carries `r` (⟂ `t0`) across the chord `v1` to the normal
/// plane of `t1`. `t0`, `t1` must be unit vectors.
///
/// Written as `r′ = r − (v₁·r) a − (v₂·r) b` with `a = k₁(v₁ − k₂(v₂·v₁) v₂)`, `b = k₂v₂`
/// (`kᵢ = 2/vᵢ·vᵢ`): `a` and `b` depend on the curve only, so along a curve the chain of
/// dependent operations from `r_i` to `r_{i+1}` is two independent dot products and two
/// multiply-subtracts (half that of reflecting twice in turn), and the processor computes
/// the next steps' `a`, `b` meanwhile.
#[inline(always)]
pub fn dr_step(v1: DVec3, t0: DVec3, t1: DVec3, r: DVec3) -> DVec3 {
    dr_step_with(v1, v1.dot(v1), t0, t1, r)
}

/// [`dr_step`] with `v1·v1` already at hand (the same value, bit for bit).
#[inline(always)]
pub fn dr_step_with(v1: DVec3, v1v1: f64, t0: DVec3, t1: DVec3, r: DVec3) -> DVec3 {
    let k1 = 2.0 / v1v1;
    let tl = t0 - (k1 * v1.dot(t0)) * v1;
    let v2 = t1 - tl;
    let k2 = 2.0 / v2.dot(v2);
    let a = k1 * (v1 - (k2 * v2.dot(v1)) * v2);
    let b = k2 * v2;
    r - v1.dot(r) * a - v2.dot(r) * b
}

/// Double reflection over a sampled curve (points may be empty in tangents-only mode).
pub struct DoubleReflection<'a> {
    /// Sample points `x_i` (empty in tangents-only mode).
    pub x: &'a [DVec3],
    /// Unit tangents `t_i` at the samples.
    pub t: &'a [DVec3],
    /// The samples form a loop (the segment from the last to the first is included).
    pub closed: bool,
    /// Chords from the 4th-order quadrature of the tangents instead of `x_{i+1} − x_i`.
    pub tangent_chords: bool,
}

impl DoubleReflection<'_> {
    #[inline(always)]
    pub fn chord(&self, i: usize) -> DVec3 {
        if self.tangent_chords {
            tangent_chord(self.t, i, self.closed)
        } else {
            let j = if i + 1 == self.t.len() { 0 } else { i + 1 };
            self.x[j] - self.x[i]
        }
    }

    /// Transport from sample `i+1` back to sample `i` (the exact inverse step: DR is
    /// symmetric, TOG §4.4).
    #[inline]
    pub fn step_back(&self, i: usize, r: DVec3) -> DVec3 {
        let j = if i + 1 == self.t.len() { 0 } else { i + 1 };
        dr_step(-self.chord(i), self.t[j], self.t[i], r)
    }
}

impl Step for DoubleReflection<'_> {
    #[inline(always)]
    fn step(&self, i: usize, r: DVec3) -> DVec3 {
        let j = if i + 1 == self.t.len() { 0 } else { i + 1 };
        dr_step(self.chord(i), self.t[i], self.t[j], r)
    }
    fn is_rotation(&self) -> bool {
        true
    }
}
