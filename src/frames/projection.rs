//! Projection method (Klok 1986; TOG §2.1): the reference vector is projected along the
//! chord `d = x_{i+1} − x_i` onto the normal plane at `x_{i+1}` and normalised,
//! `p = r_i − (r_i·t_{i+1})/(d·t_{i+1}) d`, `r_{i+1} = p/|p|`.
//!
//! The projection is not an isometry of the normal plane, so the result depends on the
//! initial vector; 2nd-order accurate. Defined when `d·t_{i+1} ≠ 0` (checked by the caller).

use glam::DVec3;

use super::transport::Step;

#[inline(always)]
pub fn projection_step(d: DVec3, t1: DVec3, r: DVec3) -> DVec3 {
    let p = r - (r.dot(t1) / d.dot(t1)) * d;
    // p = 0 would need r ∥ d ⟂ t1 as well as r ⟂ t0: excluded by the chord check; keep r
    // finite anyway.
    p.try_normalize().unwrap_or(r)
}

pub struct Projection<'a> {
    /// Sample points `x_i` (the chords `x_{i+1} − x_i` are the projection directions).
    pub x: &'a [DVec3],
    /// Unit tangents `t_i` at the samples.
    pub t: &'a [DVec3],
}

impl Step for Projection<'_> {
    #[inline(always)]
    fn step(&self, i: usize, r: DVec3) -> DVec3 {
        let j = if i + 1 == self.t.len() { 0 } else { i + 1 };
        projection_step(self.x[j] - self.x[i], self.t[j], r)
    }
    fn is_rotation(&self) -> bool {
        false
    }
}
