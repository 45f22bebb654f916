//! A rod: the tube of radius ρ about a smooth axis curve, as a signed distance for the
//! curl tools of [`super::curl`] (a free-form tool of Zheng's thesis §11.2.5–11.2.6).
//!
//! **Axis.** As for the curved strip of [`super::tube`]: the C¹ piecewise cubic Hermite curve
//! `γ` through the samples `x_k` with derivatives `m_k = dγ/dS` at the cumulative chord
//! lengths `S_k` ([`super::tube::axis_samples`]: the clamped C² cubic spline's derivatives, so `γ` is
//! C²; two samples give a straight segment, a capsule).
//!
//! **Distance.** `d(X) = |X − γ(s*)| − ρ` with `s*` the foot point, `(X − γ(s*))·γ′(s*) = 0`,
//! or the nearer end sample beyond the end planes (spherical caps). Where the foot point is
//! unique the distance is C¹ (C² away from the end planes), and by the envelope theorem its
//! gradient is exactly `∇d = (X − γ(s*))/|X − γ(s*)|` — no derivative of `s*` enters. The
//! foot point is unique within `|X − γ| < ρ + R` when the curvature `κ` satisfies
//! `κ (ρ + R + segment arc length) < 1` (checked here on 16 points per segment; it also makes
//! `(X − γ)·γ′` monotone on each segment within reach, so one bracketed root per segment) and
//! distant parts of the axis stay `2(ρ + R)` apart (checked by [`Rod::from_points`]). It is
//! found by safeguarded Newton (bisection fallback) on each segment whose Bézier hull is
//! within reach and whose end values bracket a root; the nearest candidate wins. On the axis
//! itself (depth ρ, inside the tool) the gradient is undefined and set to zero.

use glam::DVec3;

use super::curl::Distance;
use super::tube::AxisSample;
use crate::error::{InputError, Result};
use crate::math::cubic::{Hermite, Power};

#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    curve: Power,
    /// Bounding sphere of the Bézier hull.
    centre: DVec3,
    radius: f64,
}

/// A rod about a spline axis (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Rod {
    pub samples: Vec<AxisSample>,
    segs: Vec<Segment>,
    pub radius: f64,
    pub reach: f64,
    /// The tool's centre C.
    pub center: DVec3,
    /// A sphere (about `center`) containing every segment's hull.
    bound: f64,
}

impl Rod {
    /// The rod of `spinal.fields.rod` about `points`: the axis of
    /// [`super::tube::axis_samples`], checked like a strip's axis for a tube of
    /// `radius + reach` (curvature and self-approach, [`super::tube::StripAlong::new`]).
    pub fn from_points(
        points: &[DVec3],
        radius: f64,
        reach: Option<f64>,
        center: Option<DVec3>,
    ) -> Result<Rod> {
        let samples = super::tube::axis_samples(points)?;
        let radius = super::positive("radius", radius)?;
        let reach = super::reach_or(reach, radius)?;
        super::tube::StripAlong::new(samples.clone(), 0.0, radius, reach, false)?;
        Rod::new(samples, radius, Some(reach), center)
    }

    /// The rod, validated: `radius` and `reach` (default `radius`) positive, finite `center`
    /// (default: the centroid of the sample polyline, segments weighted by their length), a
    /// smooth axis that does not bend too sharply for `radius + reach` (errors name `points`).
    pub fn new(
        samples: Vec<AxisSample>,
        radius: f64,
        reach: Option<f64>,
        center: Option<DVec3>,
    ) -> Result<Rod> {
        let radius = super::positive("radius", radius)?;
        let reach = super::reach_or(reach, radius)?;
        let bad = |m: String| InputError::new("points", m);
        if samples.len() < 2 {
            return Err(bad(format!(
                "need at least 2 samples, got {}",
                samples.len()
            )));
        }
        for (i, p) in samples.iter().enumerate() {
            if !(p.x.is_finite() && p.m.is_finite() && p.s.is_finite()) {
                return Err(bad(format!("row {i} is not finite (NaN or inf)")));
            }
            if !(p.m.length() > 0.0) {
                return Err(bad(format!("the axis derivative at sample {i} is zero")));
            }
        }
        let center = match center {
            Some(c) => super::finite3("center", c)?,
            None => {
                let (mut m, mut l) = (DVec3::ZERO, 0.0);
                for w in samples.windows(2) {
                    let len = (w[1].x - w[0].x).length();
                    m += 0.5 * (w[0].x + w[1].x) * len;
                    l += len;
                }
                if l > 0.0 { m / l } else { samples[0].x }
            }
        };
        let outer = radius + reach;
        let mut segs = Vec::with_capacity(samples.len() - 1);
        for (k, w) in samples.windows(2).enumerate() {
            let ds = w[1].s - w[0].s;
            if !(ds > 0.0) {
                return Err(bad(format!(
                    "consecutive samples {k} and {} coincide",
                    k + 1
                )));
            }
            let data = Hermite::new(w[0].x, w[1].x, w[0].m * ds, w[1].m * ds);
            let hull = data.bezier().b;
            let centre = 0.25 * (hull[0] + hull[1] + hull[2] + hull[3]);
            let rad = hull
                .iter()
                .map(|p| (*p - centre).length())
                .fold(0.0, f64::max);
            let curve = data.power();
            let (mut kmax, mut arc, mut prev) = (0.0f64, 0.0, w[0].x);
            for i in 0..=16 {
                let (g, g1, g2) = curve.at(i as f64 / 16.0);
                let s2 = g1.length_squared();
                if !(s2 > 0.0) {
                    return Err(bad(format!("the axis has a cusp in segment {k}")));
                }
                kmax = kmax.max(g2.length() / s2);
                arc += (g - prev).length();
                prev = g;
            }
            if !(kmax * (outer + 1.01 * arc) < 1.0) {
                return Err(bad(format!(
                    "the axis bends too sharply in segment {k}: curvature {kmax:.4} × (radius \
                     + reach + segment length) = {:.4} must stay below 1",
                    kmax * (outer + 1.01 * arc)
                )));
            }
            segs.push(Segment {
                curve,
                centre,
                radius: rad,
            });
        }
        let bound = segs
            .iter()
            .map(|g| (g.centre - center).length() + g.radius)
            .fold(0.0, f64::max);
        Ok(Rod {
            samples,
            segs,
            radius,
            reach,
            center,
            bound,
        })
    }

    /// The root of `F(λ) = (X − γ)·γ′` in `[0, 1]`, given `F(0) ≥ 0 > F(1)`.
    #[inline]
    fn foot(seg: &Segment, x: DVec3, f0: f64, f1: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut l = (f0 / (f0 - f1)).clamp(0.0, 1.0);
        for _ in 0..64 {
            let (g, g1, g2) = seg.curve.at(l);
            let w = x - g;
            let f = w.dot(g1);
            if f == 0.0 {
                break;
            }
            if f > 0.0 {
                lo = l;
            } else {
                hi = l;
            }
            let df = w.dot(g2) - g1.length_squared();
            let newton = l - f / df;
            if df < 0.0 && newton >= lo && newton <= hi {
                let step = (newton - l).abs();
                l = newton;
                // quadratic convergence: after a step ≤ 1e-9 the error is O(1e-18)
                if !(step > 1e-9) {
                    break;
                }
            } else {
                l = 0.5 * (lo + hi);
                if !(hi - lo > 1e-16) {
                    break;
                }
            }
        }
        l
    }

    /// The nearest axis point within `ρ + R` of `x`, if any.
    #[inline]
    pub fn closest(&self, x: DVec3) -> Option<DVec3> {
        let outer = self.radius + self.reach;
        let lim = self.bound + outer;
        if !((x - self.center).length_squared() < lim * lim) {
            return None;
        }
        let n = self.samples.len();
        let mut best = outer * outer;
        let mut hit = None;
        for (k, seg) in self.segs.iter().enumerate() {
            let lim = seg.radius + outer;
            if (x - seg.centre).length_squared() >= lim * lim {
                continue;
            }
            let (p0, p1) = (&self.samples[k], &self.samples[k + 1]);
            let f0 = (x - p0.x).dot(p0.m);
            let f1 = (x - p1.x).dot(p1.m);
            let mut take = |p: DVec3| {
                let r2 = (x - p).length_squared();
                if r2 < best {
                    best = r2;
                    hit = Some(p);
                }
            };
            if k == 0 && f0 < 0.0 {
                take(p0.x);
            }
            if k == n - 2 && f1 >= 0.0 {
                take(p1.x);
            }
            if f0 >= 0.0 && f1 < 0.0 {
                take(seg.curve.value(Self::foot(seg, x, f0, f1)));
            }
        }
        hit
    }
}

impl Distance for Rod {
    #[inline]
    fn distance(&self, x: DVec3) -> Option<(f64, DVec3)> {
        let c = self.closest(x)?;
        let y = x - c;
        let r = y.length();
        let g = if r > 0.0 { y * (1.0 / r) } else { DVec3::ZERO };
        Some((r - self.radius, g))
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
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let rod = Rod::new(samples, 0.2, Some(0.3), None).unwrap();
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
