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

use glam::DVec3;

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
