//! The Frenet frame turned by the integral of the torsion (Wang, Jüttler, Zheng & Liu,
//! ACM TOG 27(1), 2008, §2.3 and §3.2 Eq. 3; Zheng's thesis §2.4, Eq. 3.1).
//!
//! The Frenet frame turns about `t` at the rate `τ` per unit arc length relative to the
//! rotation-minimising frame (its Darboux vector is `κ b + τ t`, the RMF's `κ b`), so the
//! RMF is `r = cos θ N + sin θ B` with `θ(u) = θ₀ − ∫_{u₀}^{u} τ |x′| dv`,
//! `τ = det(x′, x″, x‴)/|x′ × x″|²`. The integral is taken by Simpson's rule on each
//! segment from the exact derivatives at its ends and midpoint, so the frames are the exact
//! Frenet frames turned by a 4th-order angle: exact on a circular helix (constant `τ |x′|`),
//! O(h⁴) in general. Defined only where the curvature does not vanish; near an inflection
//! `τ` is unbounded and the Frenet frame flips, so the caller refuses such curves (a
//! reference method, not a robust one).

use glam::DVec3;

use super::transport::Step;
use crate::math::rotation::{rotate_about, signed_angle};

/// `τ |x′| = det(x′, x″, x‴) |x′| / |x′ × x″|²`, the Frenet frame's turn per unit parameter.
#[inline]
pub fn torsion_rate(d1: DVec3, d2: DVec3, d3: DVec3) -> f64 {
    let c = d1.cross(d2);
    c.dot(d3) * d1.length() / c.length_squared()
}

/// The unit principal normal `N` from `x′`, `x″` (the caller checks `x′ × x″ ≠ 0`).
#[inline]
pub fn principal_normal(d1: DVec3, d2: DVec3) -> DVec3 {
    d1.cross(d2).cross(d1).normalize()
}

/// The Frenet frames turned by the torsion integral.
pub struct Torsion<'a> {
    /// Unit tangents at the samples (`n` unique samples; index mod n).
    pub t: &'a [DVec3],
    /// Principal normals at the samples (index mod n).
    pub normal: Vec<DVec3>,
    /// `∫ τ |x′| du` over each segment (Simpson).
    pub turn: Vec<f64>,
}

impl<'a> Torsion<'a> {
    /// From the parameters `u` and the derivatives at `u_0, (u_0+u_1)/2, u_1, …` (2m + 1
    /// rows); `n` unique samples.
    pub fn new(u: &[f64], d1: &[DVec3], d2: &[DVec3], d3: &[DVec3], t: &'a [DVec3]) -> Self {
        let rate = |k: usize| torsion_rate(d1[k], d2[k], d3[k]);
        let turn = (0..u.len() - 1)
            .map(|i| {
                (u[i + 1] - u[i]) / 6.0 * (rate(2 * i) + 4.0 * rate(2 * i + 1) + rate(2 * i + 2))
            })
            .collect();
        let normal = (0..t.len())
            .map(|i| principal_normal(d1[2 * i], d2[2 * i]))
            .collect();
        Torsion { t, normal, turn }
    }
}

impl Step for Torsion<'_> {
    fn step(&self, i: usize, r: DVec3) -> DVec3 {
        let n = self.t.len();
        let j = (i + 1) % n;
        let theta = signed_angle(self.normal[i], r, self.t[i]) - self.turn[i];
        rotate_about(self.normal[j], self.t[j], theta)
    }
    fn is_rotation(&self) -> bool {
        false
    }
}
