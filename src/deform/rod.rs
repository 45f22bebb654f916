//! A rod: the tube of radius ρ about a smooth axis curve, as a signed distance for the
//! curl tools of [`super::curl`] (a free-form tool of Zheng's thesis §11.2.5–11.2.6).
//!
//! **Axis.** As for the curved strip of [`super::tube`]: the C¹ piecewise cubic Hermite curve
//! `γ` through the samples `x_k` with derivatives `m_k = dγ/dS` at the cumulative chord
//! lengths `S_k` ([`super::axis::axis_samples`]: the clamped C² cubic spline's derivatives, so `γ` is
//! C²; two samples give a straight segment, a capsule).
//!
//! **Distance.** `d(X) = |X − γ(s*)| − ρ` with `s*` the foot point, `(X − γ(s*))·γ′(s*) = 0`,
//! or the nearer end sample beyond the end planes (spherical caps). Where the foot point is
//! unique the distance is C¹ (C² away from the end planes), and by the envelope theorem its
//! gradient is exactly `∇d = (X − γ(s*))/|X − γ(s*)|` — no derivative of `s*` enters. The
//! foot point is unique within `|X − γ| < ρ + R` when the curvature `κ` satisfies
//! `κ (ρ + R + segment arc length) < 1` and distant parts of the axis stay `2(ρ + R)` apart;
//! both are checked, and the foot point found, by the strip's [`Axis`]. On the axis
//! itself (depth ρ, inside the tool) the gradient is undefined and set to zero.

use glam::DVec3;

use super::axis::{Axis, AxisSample};
use super::shape::{Distance, radial};
use crate::error::{InputError, Result};
use crate::run::cancel::Cancel;

/// A rod about a spline axis (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Rod {
    /// The axis, checked for `radius + reach` ([`Axis::new`]).
    pub axis: Axis,
    pub radius: f64,
    pub reach: f64,
    /// The tool's centre C.
    pub center: DVec3,
    /// A sphere about `center` containing every segment's hull.
    bound: f64,
}

impl Rod {
    /// The rod of `spinal.fields.rod` about `points` ([`super::axis::axis_samples`]).
    ///
    /// Polls `cancel` in the axis set-up and checks (see [`Axis::new`]); fails with
    /// [`InputError::stopped`] once it says stop.
    pub fn from_points(
        points: &[DVec3],
        radius: f64,
        reach: Option<f64>,
        center: Option<DVec3>,
        cancel: Cancel<'_>,
    ) -> Result<Rod> {
        let samples = super::axis::axis_samples(points, cancel)?;
        Rod::new(samples, radius, reach, center, cancel)
    }

    /// The rod, validated: `radius` and `reach` (default `radius`) positive, finite `center`
    /// (default: the centroid of the sample polyline, segments weighted by their length), an
    /// axis whose foot points are unique within `radius + reach` ([`Axis::new`]; errors name
    /// `points`).
    ///
    /// Polls `cancel` in the axis checks ([`Axis::new`]).
    pub fn new(
        samples: Vec<AxisSample>,
        radius: f64,
        reach: Option<f64>,
        center: Option<DVec3>,
        cancel: Cancel<'_>,
    ) -> Result<Rod> {
        let radius = super::positive("radius", radius)?;
        let reach = super::reach_or(reach, radius)?;
        if let Some(i) = samples
            .iter()
            .position(|p| !(p.x.is_finite() && p.m.is_finite() && p.s.is_finite()))
        {
            return Err(InputError::new(
                "points",
                format!("row {i} is not finite (NaN or inf)"),
            ));
        }
        let axis = Axis::new(samples, radius + reach, cancel)?;
        let center = center.map(|c| super::finite3("center", c)).transpose()?;
        Ok(Rod::with_axis(axis, radius, reach, center))
    }

    /// The rod about an axis already checked for `radius + reach` ([`Axis::new`]), `center`
    /// finite or, when not given, the centroid of the sample polyline (segments weighted by
    /// their length).
    pub fn with_axis(axis: Axis, radius: f64, reach: f64, center: Option<DVec3>) -> Rod {
        let center = match center {
            Some(c) => c,
            None => {
                let (mut m, mut l) = (DVec3::ZERO, 0.0);
                for w in axis.samples.windows(2) {
                    let len = (w[1].x - w[0].x).length();
                    m += 0.5 * (w[0].x + w[1].x) * len;
                    l += len;
                }
                if l > 0.0 { m / l } else { axis.samples[0].x }
            }
        };
        let bound = axis.extent_about(center);
        Rod {
            axis,
            radius,
            reach,
            center,
            bound,
        }
    }

    /// The nearest axis point within `ρ + R` of `x`, if any.
    #[inline(always)]
    pub fn closest(&self, x: DVec3) -> Option<DVec3> {
        self.axis
            .closest_point(x, self.radius + self.reach)
            .map(|(_, p)| p)
    }
}

impl Distance for Rod {
    #[inline(always)]
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let c = self.closest(x)?;
        let y = x - c;
        Some(radial(y, y.length(), self.radius))
    }
    fn reach(&self) -> f64 {
        self.reach
    }
    fn center(&self) -> DVec3 {
        self.center
    }
    fn extent(&self) -> f64 {
        self.bound + self.radius + self.reach
    }
    fn wants_locality(&self) -> bool {
        true
    }
    #[inline(always)]
    fn misses(&self, lo: DVec3, hi: DVec3) -> bool {
        !self.axis.may_reach(lo, hi, self.radius + self.reach)
    }
    fn culls_boxes(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;

    #[test]
    fn a_straight_rod_is_a_capsule() {
        let a = DVec3::new(0.1, 0.2, -0.3);
        let b = DVec3::new(0.9, -0.4, 0.5);
        let t = (b - a).normalize();
        let s = (b - a).length();
        let samples = vec![
            AxisSample { x: a, m: t, s: 0.0 },
            AxisSample { x: b, m: t, s },
        ];
        let rod = Rod::new(samples, 0.2, Some(0.3), None, &cancel::never).unwrap();
        assert!((rod.center - 0.5 * (a + b)).length() < 1e-15);
        for i in 0..300 {
            let q = i as f64 * 0.37;
            let x = 0.5 * (a + b) + DVec3::new(q.sin(), (1.7 * q).cos(), (0.3 * q).sin()) * 0.9;
            let l = ((x - a).dot(b - a) / (s * s)).clamp(0.0, 1.0);
            let foot = a + (b - a) * l;
            let d = (x - foot).length() - 0.2;
            match rod.distance(x) {
                Some((dd, g)) => {
                    assert!((dd - d).abs() < 1e-12, "{dd} {d}");
                    assert!((g - (x - foot).normalize()).length() < 1e-12);
                }
                None => assert!(d >= 0.3 - 1e-12),
            }
        }
    }
}
