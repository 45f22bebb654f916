//! Strip of type I along a curved axis (Zheng's thesis §11.2.2, "sticking"): the material inside a tube of radius ρ about an axis curve `γ` flows along
//! the axis, leaves at the head, returns outside the tube and re-enters at the tail.
//!
//! **Axis.** The C¹ piecewise cubic Hermite curve `γ` through the samples, its foot points
//! and the checks that make them unique: [`super::axis`].
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

use glam::DVec3;

pub use super::axis::{Axis, AxisSample, Foot, axis_samples, clamped_spline_slopes};
use super::shape::{blend, translate};
use crate::error::{InputError, Result};
use crate::run::cancel::Cancel;

/// Strip of type I along a curved axis (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct StripAlong {
    /// The axis (checked for `radius + reach`).
    pub axis: Axis,
    pub speed: f64,
    pub radius: f64,
    pub reach: f64,
    pub linear: bool,
}

impl StripAlong {
    /// The strip about the axis through `samples` (errors name `points` for the axis and
    /// `speed`).
    ///
    /// Polls `cancel` in the axis checks ([`Axis::new`]).
    pub fn new(
        samples: Vec<AxisSample>,
        speed: f64,
        radius: f64,
        reach: f64,
        linear: bool,
        cancel: Cancel<'_>,
    ) -> Result<StripAlong> {
        if !speed.is_finite() {
            return Err(InputError::new(
                "speed",
                format!("strip speed must be finite, got {speed}"),
            ));
        }
        Ok(StripAlong {
            axis: Axis::new(samples, radius + reach, cancel)?,
            speed,
            radius,
            reach,
            linear,
        })
    }
}

impl StripAlong {
    #[inline]
    pub fn eval(&self, x: DVec3) -> DVec3 {
        let foot = self.axis.closest(x, self.radius + self.reach);
        let hit = match foot {
            Some(Foot::Segment(k, l)) => Some((k, l)),
            _ => None,
        };
        let cap = match foot {
            Some(Foot::Cap(e)) => Some(e),
            _ => None,
        };
        if let Some((k, l)) = hit {
            let (g, g1, _) = self.axis.at(k, l);
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
            let p = &self.axis.samples[e];
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
/// `reach` (default `radius`) positive, `speed` finite, then [`StripAlong::new`]'s checks and
/// a finite speed bound.
///
/// Polls `cancel` in the axis checks (see [`Axis::new`]).
pub fn strip_along(
    samples: Vec<AxisSample>,
    radius: f64,
    speed: f64,
    reach: Option<f64>,
    linear: bool,
    cancel: Cancel<'_>,
) -> Result<StripAlong> {
    let radius = super::positive("radius", radius)?;
    let reach = super::reach_or(reach, radius)?;
    let speed = super::finite("speed", speed)?;
    super::bounded(
        "speed",
        StripAlong::new(samples, speed, radius, reach, linear, cancel)?,
    )
}

impl super::Tool for StripAlong {
    fn wants_locality(&self) -> bool {
        true
    }
    #[inline]
    fn velocity(&self, x: DVec3, _t: f64, _tm: f64) -> DVec3 {
        self.eval(x)
    }
    /// The rod about the strip's axis (the same axis, checked for the same
    /// `radius + reach`), for keyframed poses.
    fn shape(&self) -> Option<super::shape::ToolShape> {
        let rod = super::rod::Rod::with_axis(self.axis.clone(), self.radius, self.reach, None);
        Some(super::shape::ToolShape {
            shape: super::shape::Shape::Rod(std::sync::Arc::new(rod)),
            power: None,
        })
    }
    fn max_speed(&self) -> f64 {
        StripAlong::max_speed(self)
    }
    fn length_scale(&self) -> f64 {
        self.reach
    }
}

/// The strip of `spinal.fields.strip_curve` about `points` ([`axis_samples`], then
/// [`strip_along`]'s checks; errors name `points`, `radius`, `speed`, `reach`).
///
/// Polls `cancel` in the axis samples and checks (see [`Axis::new`]).
pub fn strip_curve(
    points: &[DVec3],
    radius: f64,
    speed: f64,
    reach: Option<f64>,
    linear: bool,
    cancel: Cancel<'_>,
) -> Result<StripAlong> {
    let samples = axis_samples(points, cancel)?;
    strip_along(samples, radius, speed, reach, linear, cancel)
}

#[cfg(test)]
mod tests {
    use super::super::axis::tests::arc;
    use super::*;
    use crate::run::cancel;

    #[test]
    fn inside_the_tube_the_flow_is_the_axis_tangent() {
        let s = StripAlong::new(arc(9, 1.0, 1.5), 2.0, 0.1, 0.1, false, &cancel::never).unwrap();
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
        let e =
            StripAlong::new(arc(9, 0.3, 1.5), 1.0, 0.2, 0.2, false, &cancel::never).unwrap_err();
        assert_eq!(e.arg, "points");
        assert!(
            e.msg.starts_with("the axis bends too sharply in segment "),
            "{e}"
        );
        assert!(e.msg.contains("must stay below 1"), "{e}");
    }

    #[test]
    fn an_axis_coming_back_near_itself_is_refused() {
        // 5.5 of 2π rad of a unit circle: the ends are 2 sin(0.39) = 0.76 apart
        let e =
            StripAlong::new(arc(40, 1.0, 5.5), 1.0, 0.2, 0.2, false, &cancel::never).unwrap_err();
        assert_eq!(e.arg, "points");
        assert!(
            e.msg.starts_with("the axis comes within 0.7") && e.msg.contains("(segments 0 and"),
            "{e}"
        );
        // the same arc with a narrower tube is fine
        assert!(StripAlong::new(arc(40, 1.0, 5.5), 1.0, 0.15, 0.15, false, &cancel::never).is_ok());
    }

    #[test]
    fn strip_curve_names_its_arguments() {
        let x: Vec<DVec3> = arc(40, 1.0, 5.5).iter().map(|a| a.x).collect();
        let e = strip_curve(&x, 0.2, 1.0, Some(0.2), false, &cancel::never).unwrap_err();
        assert_eq!(e.arg, "points");
        assert!(e.msg.contains("comes within"), "{e}");
        let ok = strip_curve(&x, 0.1, 1.0, Some(0.1), false, &cancel::never).unwrap();
        assert_eq!(ok.axis.samples.len(), 40);
        assert_eq!(
            strip_curve(&x[..1], 0.1, 1.0, None, false, &cancel::never)
                .unwrap_err()
                .arg,
            "points"
        );
        let mut rep = x.clone();
        rep[3] = rep[2];
        assert!(
            strip_curve(&rep, 0.1, 1.0, None, false, &cancel::never)
                .unwrap_err()
                .msg
                .contains("coincide")
        );
        assert_eq!(
            strip_curve(&x, -0.1, 1.0, None, false, &cancel::never)
                .unwrap_err()
                .arg,
            "radius"
        );
        assert_eq!(
            strip_curve(&x, 0.1, f64::NAN, None, false, &cancel::never)
                .unwrap_err()
                .arg,
            "speed"
        );
    }
}
