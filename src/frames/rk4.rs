//! Classical Runge–Kutta (RK4) integration of the rotation-minimising-frame ODE on an
//! analytic curve (TOG §2.3; Zheng's thesis §2.5, §3.3).
//!
//! With `x′`, `x″` the derivatives with respect to the curve parameter `u`,
//! `r′(u) = ω(u) × r`, `ω = x′ × x″ / |x′|²` (the Darboux vector of the RMF, `κ b` per unit
//! arc length). One step from `u_i` to `u_{i+1}` uses `ω` at `u_i`, at the midpoint and at
//! `u_{i+1}` (2m + 1 curve evaluations for m steps). RK4 does not keep `r ⟂ t`, so after
//! every step `r` is projected onto the normal plane of `t_{i+1}` and normalised (the
//! better-behaved form, a choice of ours: the paper gives no formulas, and its Table III
//! matches an unprojected variant, which has the same order). Global error O(h⁴).
//!
//! [`Rk4Phi`] is that unprojected variant, the form Wang et al.'s Table III measures: RK4 on
//! `r′ = −(r·t′) t` (their Eq. 7, equal to the ω-form only while `r ⟂ t`), with
//! `t′ = (x″ − (t·x″) t)/|x′|`, the state never projected. Its error is about 1.5× that of
//! the projected ω-form, same order. The φ-form is linear in `r`, so the state at row `i` is
//! `Φ_i r_0` for the product `Φ_i` of the step matrices; the step carries two such states
//! (the images of a basis of the first normal plane) and maps `r_i` to `r_{i+1}` through
//! them, so the frame written at each row is the state's normal part, normalised, while the
//! state itself keeps its drift out of the normal plane.

use glam::DVec3;

use super::geometry::any_perpendicular;
use super::transport::Step;

pub struct Rk4<'a> {
    /// Parameter values `u_0 < … < u_m`.
    pub u: &'a [f64],
    /// `ω` at `u_0, (u_0+u_1)/2, u_1, …, u_m` (2m + 1 entries).
    pub omega: &'a [DVec3],
    /// Unit tangents at the samples (`n` unique samples; index mod n).
    pub t: &'a [DVec3],
}

/// `ω = x′ × x″ / |x′|²`.
#[inline]
pub fn omega(d1: DVec3, d2: DVec3) -> DVec3 {
    d1.cross(d2) / d1.length_squared()
}

impl Step for Rk4<'_> {
    fn step(&self, i: usize, r: DVec3) -> DVec3 {
        let h = self.u[i + 1] - self.u[i];
        let (w0, wm, w1) = (
            self.omega[2 * i],
            self.omega[2 * i + 1],
            self.omega[2 * i + 2],
        );
        let k1 = w0.cross(r);
        let k2 = wm.cross(r + 0.5 * h * k1);
        let k3 = wm.cross(r + 0.5 * h * k2);
        let k4 = w1.cross(r + h * k3);
        let r1 = r + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        let j = if i + 1 == self.t.len() { 0 } else { i + 1 };
        let t1 = self.t[j];
        (r1 - r1.dot(t1) * t1).try_normalize().unwrap_or(r)
    }
    fn is_rotation(&self) -> bool {
        false
    }
}

/// The unit tangent `t = x′/|x′|` and its rate `t′ = (x″ − (t·x″) t)/|x′|`.
#[inline]
pub fn tangent_rate(d1: DVec3, d2: DVec3) -> (DVec3, DVec3) {
    let l = d1.length();
    let t = d1 / l;
    (t, (d2 - t.dot(d2) * t) / l)
}

/// One unprojected RK4 step of `f′ = −(f·t′) t` over `h`, from `(t, t′)` at the start, the
/// midpoint and the end.
#[inline]
fn phi_step(h: f64, a: (DVec3, DVec3), m: (DVec3, DVec3), b: (DVec3, DVec3), f: DVec3) -> DVec3 {
    let rate = |(t, dt): (DVec3, DVec3), v: DVec3| -v.dot(dt) * t;
    let k1 = rate(a, f);
    let k2 = rate(m, f + 0.5 * h * k1);
    let k3 = rate(m, f + 0.5 * h * k2);
    let k4 = rate(b, f + h * k3);
    f + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
}

/// RK4 on the φ-form without projection (see the module notes).
pub struct Rk4Phi<'a> {
    /// Unit tangents at the samples (`n` unique samples; index mod n).
    pub t: &'a [DVec3],
    /// The unprojected states at `u_0 … u_m` started from `e` and `t_0 × e` at `u_0`.
    basis: Vec<(DVec3, DVec3)>,
}

impl<'a> Rk4Phi<'a> {
    /// Integrate the two basis states over the parameters `u` with the derivatives `d1`,
    /// `d2` at `u_0, (u_0+u_1)/2, u_1, …` (2m + 1 rows).
    pub fn new(u: &[f64], d1: &[DVec3], d2: &[DVec3], t: &'a [DVec3]) -> Self {
        let at = |k: usize| tangent_rate(d1[k], d2[k]);
        let e = any_perpendicular(t[0]);
        let mut cur = (e, t[0].cross(e));
        let mut basis = Vec::with_capacity(u.len());
        basis.push(cur);
        for i in 0..u.len() - 1 {
            let h = u[i + 1] - u[i];
            let (a, m, b) = (at(2 * i), at(2 * i + 1), at(2 * i + 2));
            cur = (phi_step(h, a, m, b, cur.0), phi_step(h, a, m, b, cur.1));
            basis.push(cur);
        }
        Rk4Phi { t, basis }
    }
}

impl Step for Rk4Phi<'_> {
    fn step(&self, i: usize, r: DVec3) -> DVec3 {
        let n = self.t.len();
        let (t0, t1) = (self.t[i % n], self.t[(i + 1) % n]);
        let ((a0, b0), (a1, b1)) = (self.basis[i], self.basis[i + 1]);
        // r = α a + β b in the normal plane of t0 (a, b the normal parts of the states)
        let (pa, pb) = (a0 - a0.dot(t0) * t0, b0 - b0.dot(t0) * t0);
        let den = pa.cross(pb).dot(t0);
        let (alpha, beta) = (r.cross(pb).dot(t0) / den, pa.cross(r).dot(t0) / den);
        let f = alpha * a1 + beta * b1;
        (f - f.dot(t1) * t1).try_normalize().unwrap_or(r)
    }
    fn is_rotation(&self) -> bool {
        false
    }
}
