//! Strip of type I along a curved axis (Zheng's thesis §11.2.2, "sticking"; naming per
//! erratum A-14): the material inside a tube of radius ρ about an axis curve `γ` flows along
//! the axis, leaves at the head, returns outside the tube and re-enters at the tail.
//!
//! **Axis.** The C¹ piecewise cubic Hermite curve through the samples `x_k` with derivatives
//! `m_k = dγ/dS` at the cumulative chord lengths `S_k` (the Python side passes the clamped C²
//! cubic spline's derivatives, so `γ` is C²). Segment `k`, `λ ∈ [0, 1]`:
//! `γ(λ) = a + bλ + cλ² + dλ³` with `a = x_k`, `b = m_k ΔS_k`,
//! `c = 3(x_{k+1} − x_k) − (2m_k + m_{k+1}) ΔS_k`, `d = 2(x_k − x_{k+1}) + (m_k + m_{k+1}) ΔS_k`.
//!
//! **Field** (the thesis's `p = (1 − D) N·(X − γ(X))`, `q = (1 − D) B·(X − γ(X))` with `(N, B)`
//! a rotation-minimizing frame, `v = ∇p × ∇q`). Write `X = γ(s) + aN(s) + bB(s)` (tube
//! coordinates; `s` the foot point, `(X − γ(s))·T(s) = 0`). For an RMF, `N′ = −(N·T′)T` and
//! `B′ = −(B·T′)T` (no turning about `T`), so `∂X/∂s = (1 − a N·T′ − b B·T′) T`, `∂X/∂a = N`,
//! `∂X/∂b = B`: the coordinates are orthogonal and `∇a = N`, `∇b = B`, `∇a × ∇b = T`. With
//! `p = (1 − D(r)) a`, `q = (1 − D(r)) b`, `r = √(a² + b²)` the distance to the axis,
//!
//! ```text
//! v = ∇p × ∇q = det ∂(p, q)/∂(a, b) · ∇a × ∇b = s₀ (1 − D) (1 − D − r D′) T(s(X))
//! ```
//!
//! (`s₀` the speed). No frame is needed: every RMF of the axis (they differ by a constant
//! turn about `T`) gives this field. It is divergence-free as `∇p × ∇q` of C¹ scalars, or
//! directly: `div(J(r) T) = J′ ∇r·T + J T′·∇s = 0`, since `∇r = (aN + bB)/r ⟂ T` and
//! `∇s = T/(1 − a N·T′ − b B·T′) ∥ T ⟂ T′`. Inside the tube (`r ≤ ρ`) `v = s₀ T`; the flux
//! through every cross-section is `2π ∫ J r dr = π [(1 − D)² r²]₀^{ρ+R_f} = 0` (the return flow).
//!
//! **Caps.** Where the foot point is an end sample `x_e` (`X` beyond the end's normal plane),
//! `p, q` are the same scalars with `X − γ(X) = X − x_e` and the end frame: von Funck's sphere
//! translation about `x_e` with velocity `s₀ T_e` ([`super::cross`]). On the end plane both
//! pieces have the same `p, q` and (because the RMF does not turn about `T`) the same
//! gradients, so `v` is continuous there; a straight axis gives the capsule field exactly.
//!
//! **Where it is valid.** The foot point must be unique within `r < ρ + R_f`: curvature times
//! `ρ + R_f + segment arc length` below 1 (checked here on 16 points per segment; it also makes
//! `(X − γ)·γ′` monotone on every segment within reach, so one bracketed root per segment)
//! and no approach of distant parts of the axis closer than `2(ρ + R_f)` (checked by the
//! Python constructor). The foot point is found by safeguarded Newton on
//! `F(λ) = (X − γ(λ))·γ′(λ)` in each segment whose Bézier hull is within reach and whose end
//! values bracket a root; the nearest candidate wins.

use glam::DVec3;

use super::cross::{blend, translate};
use crate::error::{InputError, Result};
use crate::math::cubic::{Hermite, Power};

/// One axis sample: position, derivative `dγ/dS`, cumulative chord length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSample {
    /// Position `γ` on the axis (world units).
    pub x: DVec3,
    /// Derivative `dγ/dS` (per unit chord length).
    pub m: DVec3,
    /// Cumulative chord length `S`.
    pub s: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    /// `γ(λ)` in power form.
    curve: Power,
    /// Bounding sphere of the Bézier hull.
    centre: DVec3,
    radius: f64,
}

impl Segment {
    #[inline(always)]
    fn at(&self, l: f64) -> (DVec3, DVec3, DVec3) {
        self.curve.at(l)
    }
}

/// Strip of type I along a curved axis (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct StripAlong {
    pub samples: Vec<AxisSample>,
    segs: Vec<Segment>,
    /// A sphere containing every segment's hull.
    centre: DVec3,
    bound: f64,
    pub speed: f64,
    pub radius: f64,
    pub reach: f64,
    pub linear: bool,
}

impl StripAlong {
    pub fn new(
        samples: Vec<AxisSample>,
        speed: f64,
        radius: f64,
        reach: f64,
        linear: bool,
    ) -> Result<StripAlong> {
        let bad = |m: String| InputError::new("field", m);
        if samples.len() < 2 {
            return Err(bad("a strip axis needs at least 2 samples".into()));
        }
        if !speed.is_finite() {
            return Err(bad(format!("strip speed must be finite, got {speed}")));
        }
        for (i, p) in samples.iter().enumerate() {
            if !(p.m.length() > 0.0) {
                return Err(bad(format!("strip axis derivative {i} is zero")));
            }
        }
        let outer = radius + reach;
        let mut segs = Vec::with_capacity(samples.len() - 1);
        for (k, w) in samples.windows(2).enumerate() {
            let ds = w[1].s - w[0].s;
            if !(ds > 0.0) {
                return Err(bad(format!(
                    "strip axis arc length must increase strictly (segment {k})"
                )));
            }
            let x0 = w[0].x;
            let data = Hermite::new(x0, w[1].x, w[0].m * ds, w[1].m * ds);
            let hull = data.bezier().b;
            let centre = 0.25 * (hull[0] + hull[1] + hull[2] + hull[3]);
            let radius = hull
                .iter()
                .map(|p| (*p - centre).length())
                .fold(0.0, f64::max);
            let seg = Segment {
                curve: data.power(),
                centre,
                radius,
            };
            // curvature-like bound |γ″|/|γ′|² and the arc length, on 16 sub-intervals
            let mut kmax: f64 = 0.0;
            let mut arc = 0.0;
            let mut prev = x0;
            for i in 0..=16 {
                let l = i as f64 / 16.0;
                let (g, g1, g2) = seg.at(l);
                let s2 = g1.length_squared();
                if !(s2 > 0.0) {
                    return Err(bad(format!("strip axis has a cusp in segment {k}")));
                }
                kmax = kmax.max(g2.length() / s2);
                arc += (g - prev).length();
                prev = g;
            }
            if !(kmax * (outer + 1.01 * arc) < 1.0) {
                return Err(bad(format!(
                    "strip axis bends too sharply in segment {k}: curvature {kmax:.4} times \
                     radius + reach + segment length ({:.4}) must stay below 1",
                    outer + 1.01 * arc
                )));
            }
            segs.push(seg);
        }
        let lo = segs
            .iter()
            .fold(DVec3::INFINITY, |m, g| m.min(g.centre - g.radius));
        let hi = segs
            .iter()
            .fold(DVec3::NEG_INFINITY, |m, g| m.max(g.centre + g.radius));
        let centre = 0.5 * (lo + hi);
        let bound = segs
            .iter()
            .map(|g| (g.centre - centre).length() + g.radius)
            .fold(0.0, f64::max);
        Ok(StripAlong {
            samples,
            segs,
            centre,
            bound,
            speed,
            radius,
            reach,
            linear,
        })
    }

    /// The root of `F(λ) = (X − γ)·γ′` in `[0, 1]`, given `F(0) ≥ 0 > F(1)`.
    #[inline]
    fn foot(seg: &Segment, x: DVec3, f0: f64, f1: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut l = (f0 / (f0 - f1)).clamp(0.0, 1.0);
        for _ in 0..64 {
            let (g, g1, g2) = seg.at(l);
            let w = x - g;
            let f = w.dot(g1);
            if f == 0.0 {
                break;
            }
            if f >= 0.0 {
                lo = l;
            } else {
                hi = l;
            }
            let df = w.dot(g2) - g1.length_squared();
            let newton = l - f / df;
            if df < 0.0 && newton >= lo && newton <= hi {
                let step = (newton - l).abs();
                l = newton;
                // quadratic convergence: after a Newton step δ ≤ 1e-9 the error is O(δ²)
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

    #[inline]
    pub fn eval(&self, x: DVec3) -> DVec3 {
        let outer = self.radius + self.reach;
        let o2 = outer * outer;
        let n = self.samples.len();
        let lim = self.bound + outer;
        if !((x - self.centre).length_squared() < lim * lim) {
            return DVec3::ZERO;
        }
        // the nearest candidate within reach: a foot point (segment, λ) or an end cap
        let mut best = o2;
        let mut hit: Option<(usize, f64)> = None;
        let mut cap: Option<usize> = None;
        for (k, seg) in self.segs.iter().enumerate() {
            let lim = seg.radius + outer;
            if (x - seg.centre).length_squared() >= lim * lim {
                continue;
            }
            let (p0, p1) = (&self.samples[k], &self.samples[k + 1]);
            let f0 = (x - p0.x).dot(p0.m);
            let f1 = (x - p1.x).dot(p1.m);
            if k == 0 && f0 < 0.0 {
                let r2 = (x - p0.x).length_squared();
                if r2 < best {
                    best = r2;
                    hit = None;
                    cap = Some(0);
                }
            }
            if k == n - 2 && f1 >= 0.0 {
                let r2 = (x - p1.x).length_squared();
                if r2 < best {
                    best = r2;
                    hit = None;
                    cap = Some(n - 1);
                }
            }
            if f0 >= 0.0 && f1 < 0.0 {
                let l = Self::foot(seg, x, f0, f1);
                let r2 = (x - seg.at(l).0).length_squared();
                if r2 < best {
                    best = r2;
                    hit = Some((k, l));
                    cap = None;
                }
            }
        }
        if let Some((k, l)) = hit {
            let (g, g1, _) = self.segs[k].at(l);
            let t = g1 * (1.0 / g1.length());
            let r = (x - g).length();
            let d = r - self.radius;
            if !(d > 0.0) {
                return t * self.speed;
            }
            let (b, db) = blend(d, self.reach, self.linear);
            let g = 1.0 - b;
            return t * (self.speed * g * (g - db * r));
        }
        if let Some(e) = cap {
            let p = &self.samples[e];
            let y = x - p.x;
            let r = y.length();
            let u = p.m * (self.speed / p.m.length());
            if !(r > 0.0) {
                return u;
            }
            return translate(
                r - self.radius,
                y * (1.0 / r),
                y,
                u,
                self.reach,
                self.linear,
            );
        }
        DVec3::ZERO
    }

    /// `|s₀| max_r |(1 − D)(1 − D − r D′)|` (the sphere's bound, which also covers the caps).
    pub fn max_speed(&self) -> f64 {
        super::cross::Sphere {
            center: DVec3::ZERO,
            velocity: DVec3::X * self.speed,
            radius: self.radius,
            reach: self.reach,
            linear: self.linear,
            moving: false,
        }
        .max_speed()
    }
}

/// The strip of `spinal.fields.strip_curve` from its axis samples (positions, derivatives
/// `dγ/dS` of the clamped C² spline, cumulative chord lengths), validated: `radius` and
/// `reach` (default `radius`) positive, `speed` finite, then [`StripAlong::new`]'s checks.
pub fn strip_along(
    samples: Vec<AxisSample>,
    radius: f64,
    speed: f64,
    reach: Option<f64>,
    linear: bool,
) -> Result<StripAlong> {
    let radius = super::positive("radius", radius)?;
    let reach = super::reach_or(reach, radius)?;
    let speed = super::finite("speed", speed)?;
    StripAlong::new(samples, speed, radius, reach, linear)
}

impl super::Tool for StripAlong {
    #[inline]
    fn velocity(&self, x: DVec3, _t: f64, _tm: f64) -> DVec3 {
        self.eval(x)
    }
    fn max_speed(&self) -> f64 {
        StripAlong::max_speed(self)
    }
    fn length_scale(&self) -> f64 {
        self.reach
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(n: usize, r: f64, a: f64) -> Vec<AxisSample> {
        (0..n)
            .map(|i| {
                let th = a * i as f64 / (n - 1) as f64;
                AxisSample {
                    x: DVec3::new(r * th.cos(), r * th.sin(), 0.0),
                    m: DVec3::new(-th.sin(), th.cos(), 0.0),
                    s: r * th,
                }
            })
            .collect()
    }

    #[test]
    fn inside_the_tube_the_flow_is_the_axis_tangent() {
        let s = StripAlong::new(arc(9, 1.0, 1.5), 2.0, 0.1, 0.1, false).unwrap();
        for th in [0.2f64, 0.7, 1.1] {
            let x = DVec3::new(1.05 * th.cos(), 1.05 * th.sin(), 0.03);
            let v = s.eval(x);
            let t = DVec3::new(-th.sin(), th.cos(), 0.0);
            // the Hermite arc is within O(h⁴) of the circle
            assert!((v - 2.0 * t).length() < 1e-4, "{v}");
            assert!((v.length() - 2.0).abs() < 1e-14);
        }
        assert_eq!(s.eval(DVec3::new(0.0, 0.0, 0.0)), DVec3::ZERO);
    }

    #[test]
    fn sharp_bends_are_refused() {
        assert!(StripAlong::new(arc(9, 0.3, 1.5), 1.0, 0.2, 0.2, false).is_err());
    }
}
