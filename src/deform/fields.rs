//! Curl fields `V = c · curl(φ(d) B(Y))` (Zheng, thesis Ch. 12, eq. 12.1–12.6), with the sign
//! and scale of the printed fields corrected as derived below.
//!
//! Notation: `Y = X − pivot`, `d` the signed distance to the tool (negative inside), `n = ∇d`,
//! `R` the reach (the field vanishes where `|d| ≥ R`), falloff `φ = (R − |d|)^p`, `p ∈ {2,3,4}`
//! (`p = 2` is the thesis; the field is only C⁰ at `|d| = R`, `p = 4` makes it C²). Using
//! `curl(φB) = φ′ n × B + φ curl B` and `φ′ = −p sgn(d) (R − |d|)^{p−1}`:
//!
//! * **translation** (eq. 12.1–12.2): `B = Y × i`, `curl B = −2i`. The printed field flows
//!   *into* the front of the tool with a speed-independent magnitude; the corrected
//!   field is `V = −(1/(2R^p)) curl(φ (Y × u))`, linear in the tool velocity `u`:
//!
//!   `V = (e^{p−1}/R^p) [ e u + (p/2) sgn(d) ((n·u) Y − (n·Y) u) ]`,  `e = R − |d|`,
//!
//!   whose normal component on the tool surface is exactly `u·n` (no penetration);
//! * **rotation** (eq. 12.3): `B = (Y × Ω) × Y = |Y|²Ω − (Ω·Y)Y`, `curl B = 3 Y × Ω`;
//!   corrected `V = −(1/(3R^p)) curl(φ B)`:
//!
//!   `V = (e^{p−1}/(3R^p)) [ p sgn(d) n × B + 3 e Ω × Y ]`,
//!
//!   whose normal component on the tool surface is `(Ω × Y)·n` (a rigidly turning tool);
//! * **twist, bend** (eq. 12.4–12.6, printed without falloff and turning clockwise):
//!   swirls `v = h(z, r) a × Y` (`z = a·Y`, `r = |Y|`), divergence-free because
//!   `∇h ∈ span(a, Y) ⟂ a × Y`. With `q = r/R` and support `r < R`:
//!   - rate form (default): twist `h = κ z (1 − q)²`, bend `h = β r² (1 − q)²`;
//!   - curl form (the thesis's potential with the falloff inside): twist
//!     `−(κ/(4R²)) curl((R − r)² z B)` `= κ z (1 − q)(1 − 3q/2) a × Y`, bend
//!     `−(β/(5R²)) curl((R − r)² r² B)` `= β r² (1 − q)(1 − 7q/5) a × Y` (counter-rotates
//!     near the edge of the support).
//!
//! The tools here are spheres (`d = |X − c| − ρ`); a translation tool moves with its velocity
//! (`c(t) = c₀ + u t`) unless it is static, a rotation tool orbits the pivot when its centre
//! is off the pivot. Swirls are exact rotations on every sphere `r = const` (`z, r` are
//! invariants), which gives the closed-form flows used by the tests.

use glam::{DMat3, DVec3};

use super::shape::{falloff_ratio, moved, outside_shell};
use super::{Tool, bounded, falloff as falloff_power, finite, finite3, positive, reach_or, unit};
use crate::error::Result;
use crate::math::rotation::rodrigues;

/// The falloff of a ball of radius `ρ` at `Y` from its centre: `(|Y|, d, ((R − |d|)/R)^(p−1),
/// e)` with `d = |Y| − ρ`, `e = R − |d|`; `None` outside the support `|d| < R` (the shell is
/// tested first, without a square root).
#[inline(always)]
fn ball_falloff(y: DVec3, rho: f64, reach: f64, p: u8) -> Option<(f64, f64, f64, f64)> {
    let r2 = y.length_squared();
    if outside_shell(r2, rho, reach) {
        return None;
    }
    let r = r2.sqrt();
    let d = r - rho;
    let (ep, e) = falloff_ratio(d, reach, p)?;
    Some((r, d, ep, e))
}

/// Sphere tool translating with velocity `u` (curl field, eq. 12.1–12.2 corrected).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Translation {
    pub center: DVec3,
    pub velocity: DVec3,
    pub radius: f64,
    pub reach: f64,
    pub power: u8,
    /// The tool centre moves, `c(t) = center + velocity · t`; else the field is steady.
    pub moving: bool,
}

impl Translation {
    /// The tool of `spinal.fields.translation`, validated (errors name its arguments);
    /// `reach` defaults to `radius`.
    pub fn new(
        center: DVec3,
        radius: f64,
        velocity: DVec3,
        reach: Option<f64>,
        power: i64,
        moving: bool,
    ) -> Result<Translation> {
        let radius = positive("radius", radius)?;
        let tool = Translation {
            center: finite3("center", center)?,
            velocity: finite3("velocity", velocity)?,
            radius,
            reach: reach_or(reach, radius)?,
            power: falloff_power(power)?,
            moving,
        };
        bounded("velocity", tool)
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        let c = moved(self.center, self.velocity, self.moving, t);
        let y = x - c;
        let Some((r, d, ep, e)) = ball_falloff(y, self.radius, self.reach, self.power) else {
            return DVec3::ZERO;
        };
        let u = self.velocity;
        let k = ep / self.reach; // e^{p−1}/R^p
        if !(r > 0.0) {
            return u * (k * e);
        }
        let n = y * (1.0 / r);
        let sg = if d < 0.0 { -1.0 } else { 1.0 };
        let half_p = 0.5 * self.power as f64;
        k * (e * u + (half_p * sg) * (y * n.dot(u) - u * r))
    }

    /// Jacobian `DA` (columns `∂A/∂x_j`) of the potential `A = −(1/(2R^p)) φ(d) (Y × u)` with
    /// `curl A = V` (the corrected eq. 12.2), for the splitting scheme:
    /// `∂A/∂x_j = −(1/(2R^p)) [φ′ n_j (Y × u) + φ e_j × u]`, `φ′ = −p sgn(d) e^{p−1}`.
    #[inline]
    pub fn potential_jacobian(&self, x: DVec3, t: f64) -> glam::DMat3 {
        let c = moved(self.center, self.velocity, self.moving, t);
        let y = x - c;
        let r = y.length();
        let d = r - self.radius;
        let Some((ep, e)) = falloff_ratio(d, self.reach, self.power) else {
            return glam::DMat3::ZERO;
        };
        let k = -0.5 / self.reach; // with ep = (e/R)^{p−1}: −1/(2R^p) · R^{p−1}
        let u = self.velocity;
        let phi = ep * e;
        let sg = if d < 0.0 { -1.0 } else { 1.0 };
        let dphi_n = if r > 0.0 {
            y * (-(self.power as f64) * sg * ep / r)
        } else {
            DVec3::ZERO
        };
        let yu = y.cross(u);
        let col = |j: usize, ej: DVec3| k * (yu * dphi_n[j] + phi * ej.cross(u));
        glam::DMat3::from_cols(col(0, DVec3::X), col(1, DVec3::Y), col(2, DVec3::Z))
    }

    /// Upper bound of |V| outside the tool: `|u| (1 + (p/2) ρ/R)` (reached on the surface).
    pub fn max_speed(&self) -> f64 {
        self.velocity.length() * (1.0 + 0.5 * self.power as f64 * self.radius / self.reach)
    }
}

impl Tool for Translation {
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, _tm: f64) -> DVec3 {
        self.eval(x, t)
    }
    fn max_speed(&self) -> f64 {
        Translation::max_speed(self)
    }
    /// The ball's own motion: `|u|` when it moves, else 0.
    fn support_speed(&self) -> f64 {
        if self.moving {
            self.velocity.length()
        } else {
            0.0
        }
    }
    fn length_scale(&self) -> f64 {
        self.reach
    }
    fn potential_jacobian(&self, x: DVec3, t: f64) -> Option<DMat3> {
        Some(Translation::potential_jacobian(self, x, t))
    }
    fn shape(&self) -> Option<super::shape::ToolShape> {
        Some(ball_shape(self.center, self.radius, self.reach, self.power))
    }
    fn rigid_velocity(&self) -> DVec3 {
        if self.moving {
            self.velocity
        } else {
            DVec3::ZERO
        }
    }
    fn slip_surface(&self, x: DVec3, t: f64) -> Option<(f64, DVec3)> {
        let c = moved(self.center, self.velocity, self.moving, t);
        let y = x - c;
        let r = y.length();
        (r > 0.0).then(|| (r - self.radius, y / r))
    }
}

/// Sphere tool turning with angular velocity `Ω` about `pivot` (eq. 12.3 corrected).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    pub center: DVec3,
    pub pivot: DVec3,
    /// `ω a`, right-handed.
    pub omega: DVec3,
    pub radius: f64,
    pub reach: f64,
    pub power: u8,
}

impl Rotation {
    /// The tool of `spinal.fields.rotation`, validated; `pivot` defaults to `center`,
    /// `reach` to `radius`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        center: DVec3,
        radius: f64,
        axis: DVec3,
        angular_speed: f64,
        pivot: Option<DVec3>,
        reach: Option<f64>,
        power: i64,
    ) -> Result<Rotation> {
        let center = finite3("center", center)?;
        let radius = positive("radius", radius)?;
        let tool = Rotation {
            center,
            pivot: pivot.map_or(Ok(center), |p| finite3("pivot", p))?,
            omega: unit("axis", axis)? * finite("angular_speed", angular_speed)?,
            radius,
            reach: reach_or(reach, radius)?,
            power: falloff_power(power)?,
        };
        bounded("angular_speed", tool)
    }

    /// The tool's centre at time `t` (orbiting the pivot when off it).
    #[inline]
    pub fn center_at(&self, t: f64) -> DVec3 {
        let w = self.omega.length();
        let arm = self.center - self.pivot;
        if w > 0.0 && arm != DVec3::ZERO && t != 0.0 {
            self.pivot + rodrigues(arm, self.omega / w, w * t)
        } else {
            self.center
        }
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        let yc = x - self.center_at(t);
        let Some((rc, d, ep, e)) = ball_falloff(yc, self.radius, self.reach, self.power) else {
            return DVec3::ZERO;
        };
        let y = x - self.pivot;
        let k = ep / (3.0 * self.reach); // e^{p−1}/(3R^p)
        let swirl = self.omega.cross(y) * (3.0 * e);
        if !(rc > 0.0) {
            return k * swirl;
        }
        let n = yc * (1.0 / rc);
        let b = self.omega * y.length_squared() - y * self.omega.dot(y);
        let sg = if d < 0.0 { -1.0 } else { 1.0 };
        k * ((self.power as f64 * sg) * n.cross(b) + swirl)
    }

    /// `ω L (1 + p L/(3R))` with `L = |c − o| + ρ + R` the reach of the support about the pivot.
    pub fn max_speed(&self) -> f64 {
        let l = (self.center - self.pivot).length() + self.radius + self.reach;
        self.omega.length() * l * (1.0 + self.power as f64 * l / (3.0 * self.reach))
    }
}

impl Tool for Rotation {
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, _tm: f64) -> DVec3 {
        self.eval(x, t)
    }
    fn slip_surface(&self, x: DVec3, t: f64) -> Option<(f64, DVec3)> {
        let y = x - self.center_at(t);
        let r = y.length();
        (r > 0.0).then(|| (r - self.radius, y / r))
    }
    fn max_speed(&self) -> f64 {
        Rotation::max_speed(self)
    }
    /// The ball's centre orbiting the pivot: `ω |c − o|` (a ball turning about its centre
    /// stays where it is).
    fn support_speed(&self) -> f64 {
        self.omega.length() * (self.center - self.pivot).length()
    }
    fn length_scale(&self) -> f64 {
        self.reach
    }
    fn shape(&self) -> Option<super::shape::ToolShape> {
        Some(ball_shape(self.center, self.radius, self.reach, self.power))
    }
}

/// The ball of a sphere tool (at its position at t = 0) for keyframed poses.
fn ball_shape(center: DVec3, radius: f64, reach: f64, power: u8) -> super::shape::ToolShape {
    super::shape::ToolShape {
        shape: super::shape::Shape::Ball(super::shape::Ball {
            center,
            radius,
            reach,
        }),
        power: Some(power),
    }
}

/// Which swirl.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwirlKind {
    Twist,
    Bend,
}

/// Twist or bend about `axis` through `pivot`, support the ball `r < reach` (eq. 12.5, 12.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Swirl {
    pub pivot: DVec3,
    /// Unit axis.
    pub axis: DVec3,
    /// κ (rad per length per time) for a twist, β (rad per length² per time) for a bend.
    pub rate: f64,
    pub reach: f64,
    pub kind: SwirlKind,
    /// The thesis's curl form (falloff inside the potential) instead of the rate form.
    pub curl_form: bool,
}

impl Swirl {
    /// The swirl of `spinal.fields.twist` / `bend`, validated (`radius` is its support).
    pub fn new(
        center: DVec3,
        axis: DVec3,
        rate: f64,
        radius: f64,
        kind: SwirlKind,
        curl_form: bool,
    ) -> Result<Swirl> {
        let tool = Swirl {
            pivot: finite3("center", center)?,
            axis: unit("axis", axis)?,
            rate: finite("rate", rate)?,
            reach: positive("radius", radius)?,
            kind,
            curl_form,
        };
        bounded("rate", tool)
    }

    /// Angular speed `h` (rad per time, right-handed about the axis) at `z = a·Y`, `r = |Y|`.
    #[inline]
    pub fn angular(&self, z: f64, r: f64) -> f64 {
        let q = r / self.reach;
        if !(q < 1.0) {
            return 0.0;
        }
        let w = if self.curl_form {
            (1.0 - q)
                * match self.kind {
                    SwirlKind::Twist => 1.0 - 1.5 * q,
                    SwirlKind::Bend => 1.0 - 1.4 * q,
                }
        } else {
            (1.0 - q) * (1.0 - q)
        };
        let g = match self.kind {
            SwirlKind::Twist => z,
            SwirlKind::Bend => r * r,
        };
        self.rate * g * w
    }

    #[inline]
    pub fn eval(&self, x: DVec3) -> DVec3 {
        let y = x - self.pivot;
        let r2 = y.length_squared();
        if !(r2 < self.reach * self.reach) {
            return DVec3::ZERO;
        }
        let r = r2.sqrt();
        let h = self.angular(self.axis.dot(y), r);
        if h == 0.0 {
            return DVec3::ZERO;
        }
        h * self.axis.cross(y)
    }

    /// max over the ball of `|h| r` (sampled on 4097 radii; `|z| ≤ r`).
    pub fn max_speed(&self) -> f64 {
        let n = 4096;
        let mut m: f64 = 0.0;
        for i in 0..=n {
            let r = self.reach * i as f64 / n as f64;
            m = m.max((self.angular(r, r) * r).abs());
        }
        m
    }
}

impl Tool for Swirl {
    #[inline]
    fn velocity(&self, x: DVec3, _t: f64, _tm: f64) -> DVec3 {
        self.eval(x)
    }
    fn max_speed(&self) -> f64 {
        Swirl::max_speed(self)
    }
    /// A swirl stays where it is.
    fn support_speed(&self) -> f64 {
        0.0
    }
    fn length_scale(&self) -> f64 {
        self.reach
    }
    fn natural_center(&self) -> Option<DVec3> {
        Some(self.pivot)
    }
    fn support_radius(&self, about: DVec3) -> Option<f64> {
        Some((self.pivot - about).length() + self.reach)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn div(f: impl Fn(DVec3) -> DVec3, x: DVec3) -> f64 {
        let h = 1e-6;
        let mut s = 0.0;
        for k in 0..3 {
            let mut e = DVec3::ZERO;
            e[k] = h;
            s += (f(x + e)[k] - f(x - e)[k]) / (2.0 * h);
        }
        s
    }

    #[test]
    fn translation_normal_velocity_and_divergence() {
        for p in [2u8, 3, 4] {
            let tr = Translation {
                center: DVec3::ZERO,
                velocity: DVec3::new(0.3, -1.0, 0.5),
                radius: 0.4,
                reach: 0.3,
                power: p,
                moving: false,
            };
            let n = DVec3::new(1.0, 2.0, -0.5).normalize();
            let v = tr.eval(n * (0.4 + 1e-12), 0.0);
            assert!((v.dot(n) - tr.velocity.dot(n)).abs() < 1e-9);
            let x = DVec3::new(0.3, 0.35, -0.1);
            assert!(div(|x| tr.eval(x, 0.0), x).abs() < 1e-7);
        }
    }

    #[test]
    fn swirl_speed_bounds() {
        let s = Swirl {
            pivot: DVec3::ZERO,
            axis: DVec3::Z,
            rate: 4.0,
            reach: 2.0,
            kind: SwirlKind::Twist,
            curl_form: false,
        };
        // κ R² / 16
        assert!((s.max_speed() - 4.0 * 4.0 / 16.0).abs() < 1e-6);
        let b = Swirl {
            kind: SwirlKind::Bend,
            ..s
        };
        assert!((b.max_speed() - 0.03456 * 4.0 * 8.0).abs() < 1e-6);
    }
}
