//! Projection method (Klok 1986; TOG §2.1): the reference vector is projected along the
//! chord `d = x_{i+1} − x_i` onto the normal plane at `x_{i+1}` and normalised,
//! `p = r_i − (r_i·t_{i+1})/(d·t_{i+1}) d`, `r_{i+1} = p/|p|`.
//!
//! The projection is not an isometry of the normal plane, so the result depends on the
//! initial vector; 2nd-order accurate. Defined when `d·t_{i+1} ≠ 0` (checked by the caller).
//!
//! Klok's polygon variant (Klok 1986; Zheng's thesis §2.3) needs no tangents: the plane at
//! an interior vertex contains the bisector of the angle between the two segments there
//! and is ⟂ to their plane, so its normal, taken as the frame's tangent, is the sum of the
//! two unit segment directions, `t_i ∝ d̂_{i−1} + d̂_i`; at an open end it is the end
//! segment's direction ([`bisector_tangents`]). The same projection along each segment then
//! carries `r` from plane to plane. Each step moves `r` along `d_i`, so a component of `r`
//! normal to a planar polygon is kept exactly: on a planar polygon the frames do not twist.

use glam::DVec3;

use super::transport::Step;

#[inline(always)]
pub fn projection_step(d: DVec3, t1: DVec3, r: DVec3) -> DVec3 {
    let dt = d.dot(t1);
    let mut p = r - (r.dot(t1) / dt) * d;
    // where `r` nearly lies along `d` the difference cancels and keeps a rounding error of
    // `ε|r|` along `t1` on a short `p`: once more along `d` (a no-op in exact arithmetic), so
    // the frame stays orthonormal to rounding
    let res = p.dot(t1);
    if res * res > 1e-24 * p.length_squared() {
        p -= (res / dt) * d;
    }
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

/// The normals of Klok's bisector planes at the vertices `x` (see the module notes), or the
/// first vertex where the two segments turn back on each other (`d̂_{i−1} + d̂_i = 0`). The
/// vertices must be distinct in turn (checked by the caller).
pub fn bisector_tangents(x: &[DVec3], closed: bool) -> Result<Vec<DVec3>, usize> {
    let n = x.len();
    let unit = |i: usize| (x[(i + 1) % n] - x[i]).normalize();
    (0..n)
        .map(|i| {
            let (before, after) = match (i, closed) {
                (0, false) => (DVec3::ZERO, unit(0)),
                (i, false) if i + 1 == n => (unit(i - 1), DVec3::ZERO),
                (i, _) => (unit((i + n - 1) % n), unit(i)),
            };
            let s = before + after;
            let l = s.length();
            if l > 1e-12 { Ok(s / l) } else { Err(i) }
        })
        .collect()
}
