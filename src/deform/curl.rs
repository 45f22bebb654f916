//! Curl tools of any shape (Zheng, thesis Ch. 12, eq. 12.1–12.3, for the free-form tools of
//! §11.2.5–11.2.6): the curl fields of [`super::fields`] with the sphere's distance replaced
//! by the signed distance `d` of an arbitrary shape and its exact gradient `g = ∇d`.
//!
//! With `e = R − |d|`, falloff `φ = e^p` (`p ∈ {2, 3, 4}`) and `φ′ = −p sgn(d) e^{p−1}`,
//! `curl(φB) = φ′ g × B + φ curl B` gives
//!
//! * **translation** `V = −(1/(2R^p)) curl(φ (Y × u))`, `Y = X − C` (`C` the tool's centre),
//!   `curl(Y × u) = −2u`:
//!
//!   `V = (e^{p−1}/R^p) [ e u + (p/2) sgn(d) ((g·u) Y − (g·Y) u) ]`;
//! * **rotation** `V = −(1/(3R^p)) curl(φ B)`, `B = |Y|²Ω − (Ω·Y)Y`, `Y = X − pivot`,
//!   `curl B = 3 Y × Ω`:
//!
//!   `V = (e^{p−1}/(3R^p)) [ p sgn(d) g × B + 3e Ω × Y ]`.
//!
//! Both are curls of potentials that are C¹ where `d` is C¹ (`φ` is C¹ at `|d| = R`), so
//! `div V = 0` exactly for *any* C¹ distance, interpolated or not, as long as `g` is the
//! exact gradient of the `d` used. On the tool surface (`d = 0`, `|g| = 1`) the normal
//! velocity is `u·g` resp. `(Ω × Y)·g`: the material neither enters the tool nor separates
//! from it. With a sphere's distance (`g = Y/|Y|`) these are the fields of
//! [`super::fields::Translation`] and [`super::fields::Rotation`].
//!
//! **Shapes** ([`Distance`]): a ball (the sphere tools), a rod about a spline axis
//! ([`super::rod`]) and a sampled distance (a C² tricubic B-spline, [`super::grid`]; the
//! mesh tools sample a closed mesh's distance onto it).
//!
//! **Motion** ([`CurlTool`]): a translation with velocity `u` or a rotation with angular
//! velocity `Ω` about a pivot; a moving tool carries its shape rigidly (`d` evaluated in the
//! shape's own frame, `X_b = C + Q(t)ᵀ(X − c(t))`, the gradient turned back, `g = Q g_b`),
//! a static one keeps it where it was built (a steady field).

use glam::{DMat3, DVec3};

pub use super::shape::{Distance, Shape};
use super::shape::{ToolShape, falloff_ratio};
use super::{Tool, bounded, falloff as falloff_power, finite3};
use crate::error::{InputError, Result};

/// The falloff factors at distance `d`: `k = e^{p−1}/R^p`, `e = R − |d|` and `p sgn(d)`;
/// `None` outside the support.
#[derive(Debug, Clone, Copy)]
pub struct Falloff {
    pub k: f64,
    pub e: f64,
    pub ps: f64,
}

impl Falloff {
    #[inline(always)]
    pub fn at(d: f64, reach: f64, p: u8) -> Option<Falloff> {
        // k = (e/R)^{p−1}/R: the ratio e/R ∈ (0, 1] keeps R^p from overflowing (or
        // underflowing) at any scale of the tool
        let (qp, e) = falloff_ratio(d, reach, p)?;
        let pf = p as f64;
        Some(Falloff {
            k: qp / reach,
            e,
            ps: if d < 0.0 { -pf } else { pf },
        })
    }

    /// The curl translation `(e^{p−1}/R^p)[e u + (p/2) sgn(d)((g·u)Y − (g·Y)u)]`.
    #[inline(always)]
    pub fn translate(&self, g: DVec3, y: DVec3, u: DVec3) -> DVec3 {
        self.k * (self.e * u + (0.5 * self.ps) * (y * g.dot(u) - u * g.dot(y)))
    }

    /// Jacobian (columns `∂A/∂x_j`) of the translation's potential
    /// `A = −(1/(2R^p)) φ (Y × u)`: `(k/2)[p sgn(d) g_j (Y × u) − e (e_j × u)]`.
    #[inline]
    pub fn translate_potential_jacobian(&self, g: DVec3, y: DVec3, u: DVec3) -> DMat3 {
        let yu = y.cross(u);
        let col =
            |j: usize, ej: DVec3| (0.5 * self.k) * (yu * (self.ps * g[j]) - ej.cross(u) * self.e);
        DMat3::from_cols(col(0, DVec3::X), col(1, DVec3::Y), col(2, DVec3::Z))
    }

    /// Jacobian of the rotation's potential `A = −(1/(3R^p)) φ B`:
    /// `(k/3)[p sgn(d) g_j B − e ∂_j B]`, `∂_j B = 2Y_j Ω − Ω_j Y − (Ω·Y) e_j`.
    #[inline]
    pub fn rotate_potential_jacobian(&self, g: DVec3, y: DVec3, omega: DVec3) -> DMat3 {
        let b = omega * y.length_squared() - y * omega.dot(y);
        let oy = omega.dot(y);
        let col = |j: usize, ej: DVec3| {
            let db = omega * (2.0 * y[j]) - y * omega[j] - ej * oy;
            (self.k / 3.0) * (b * (self.ps * g[j]) - db * self.e)
        };
        DMat3::from_cols(col(0, DVec3::X), col(1, DVec3::Y), col(2, DVec3::Z))
    }

    /// The curl rotation `(e^{p−1}/(3R^p))[p sgn(d) g × B + 3e Ω × Y]`, `B = |Y|²Ω − (Ω·Y)Y`.
    #[inline(always)]
    pub fn rotate(&self, g: DVec3, y: DVec3, omega: DVec3) -> DVec3 {
        let b = omega * y.length_squared() - y * omega.dot(y);
        (self.k / 3.0) * (self.ps * g.cross(b) + (3.0 * self.e) * omega.cross(y))
    }
}

/// Speed bound of a curl translation with speed `u` of a shape: `|g × (Y × u)| ≤ G L |u|` and
/// `e ≤ R` give `|V| ≤ |u| (1 + (p/2) G L / R)`.
pub fn translation_bound(u: f64, shape: &dyn Distance, p: u8) -> f64 {
    u * (1.0 + 0.5 * p as f64 * shape.gradient_bound() * shape.extent() / shape.reach())
}

/// Speed bound of a curl rotation with angular speed `w` about a pivot at `arm` from the
/// centre: `|B| ≤ w L²`, `|Ω × Y| ≤ w L` with `L = arm + extent` give
/// `|V| ≤ w L (1 + p G L/(3R))`.
pub fn rotation_bound(w: f64, arm: f64, shape: &dyn Distance, p: u8) -> f64 {
    let l = arm + shape.extent();
    w * l * (1.0 + p as f64 * shape.gradient_bound() * l / (3.0 * shape.reach()))
}

/// How a [`CurlTool`] moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Translation with velocity `u`.
    Translate(DVec3),
    /// Rotation with angular velocity `Ω` (right-handed, rad/time) about `pivot`.
    Rotate { omega: DVec3, pivot: DVec3 },
}

impl Motion {
    /// The motion of exactly one of `velocity` and `angular_velocity` (`pivot`, default the
    /// centre, only with a rotation), validated (errors name the argument).
    pub fn new(
        velocity: Option<DVec3>,
        angular_velocity: Option<DVec3>,
        pivot: Option<DVec3>,
        center: DVec3,
    ) -> Result<Motion> {
        match (velocity, angular_velocity) {
            (Some(u), None) => {
                if pivot.is_some() {
                    return Err(InputError::new(
                        "pivot",
                        "only applies to a rotation (angular_velocity)",
                    ));
                }
                Ok(Motion::Translate(finite3("velocity", u)?))
            }
            (None, Some(w)) => Ok(Motion::Rotate {
                omega: finite3("angular_velocity", w)?,
                pivot: pivot.map_or(Ok(center), |p| finite3("pivot", p))?,
            }),
            (None, None) => Err(InputError::new(
                "velocity",
                "give velocity (a translation) or angular_velocity (a rotation)",
            )),
            (Some(_), Some(_)) => Err(InputError::new(
                "angular_velocity",
                "give either velocity or angular_velocity, not both (add two fields, or use \
                 fields.keyframed for a combined rigid motion)",
            )),
        }
    }
}

/// The pose of a shape at one time: `X_b = C + Qᵀ(X − c)` (its own frame), `g = Q g_b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Where the shape's centre is.
    pub c: DVec3,
    /// Its orientation relative to the shape as built.
    pub q: DMat3,
}

impl Pose {
    /// The distance and its world gradient at `x` for the shape at this pose.
    #[inline(always)]
    pub fn distance<D: Distance>(&self, shape: &D, x: DVec3) -> Option<(f64, DVec3)> {
        self.distance_as::<D, true>(shape, x)
    }

    /// [`Self::distance`]; with `TURNED` false the orientation is taken as the identity
    /// (the same values for a pose with `q = I`, without the two matrix products).
    #[inline(always)]
    pub fn distance_as<D: Distance, const TURNED: bool>(
        &self,
        shape: &D,
        x: DVec3,
    ) -> Option<(f64, DVec3)> {
        let xb = self.body::<TURNED>(shape.center(), &self.q.transpose(), x);
        if TURNED {
            shape.distance(xb).map(|(d, g)| (d, self.q * g))
        } else {
            shape.distance(xb)
        }
    }

    /// The point `x` in the shape's own frame, `C + Qᵀ(x − c)` (`qt = Qᵀ`); with `TURNED`
    /// false the orientation is taken as the identity.
    #[inline(always)]
    fn body<const TURNED: bool>(&self, center: DVec3, qt: &DMat3, x: DVec3) -> DVec3 {
        if TURNED {
            center + *qt * (x - self.c)
        } else {
            center + (x - self.c)
        }
    }

    /// `out[j] += f(p[j], d, g)` for the lanes where the shape's distance `(d, g)` (the
    /// world gradient) at this pose is defined, with the bits of [`Self::distance_as`] lane
    /// by lane. The orientation is checked for the identity once per batch, and a batch
    /// whose points lie in a box the shape misses ([`Distance::misses`]) adds nothing.
    #[inline(always)]
    pub fn add_lanes<D, F>(&self, shape: &D, p: &[DVec3], out: &mut [DVec3], f: F)
    where
        D: Distance,
        F: Fn(DVec3, f64, DVec3) -> DVec3,
    {
        match (self.q == DMat3::IDENTITY, shape.culls_boxes()) {
            (true, true) => self.add_lanes_as::<D, F, false>(shape, p, out, f),
            (false, true) => self.add_lanes_as::<D, F, true>(shape, p, out, f),
            (true, false) => self.add_points::<D, F, false>(shape, p, out, f),
            (false, false) => self.add_points::<D, F, true>(shape, p, out, f),
        }
    }

    /// [`Self::add_lanes`] point by point, for shapes without a box test.
    #[inline(always)]
    fn add_points<D, F, const TURNED: bool>(&self, shape: &D, p: &[DVec3], out: &mut [DVec3], f: F)
    where
        D: Distance,
        F: Fn(DVec3, f64, DVec3) -> DVec3,
    {
        for (o, x) in out.iter_mut().zip(p) {
            if let Some((d, g)) = self.distance_as::<D, TURNED>(shape, *x) {
                *o += f(*x, d, g);
            }
        }
    }

    #[inline(always)]
    fn add_lanes_as<D, F, const TURNED: bool>(
        &self,
        shape: &D,
        p: &[DVec3],
        out: &mut [DVec3],
        f: F,
    ) where
        D: Distance,
        F: Fn(DVec3, f64, DVec3) -> DVec3,
    {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `lanes_avx2` only needs the processor to support AVX2, checked just
            // above.
            return unsafe { self.lanes_avx2::<D, F, TURNED>(shape, p, out, f) };
        }
        self.lanes::<D, F, TURNED>(shape, p, out, f)
    }

    /// [`Self::lanes`] compiled for AVX2 (the normal planes of a rod's axis four at a
    /// time). Rust never fuses a multiply and an add on its own, so the vector code does
    /// the IEEE operations of the portable one lane by lane: the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn lanes_avx2<D, F, const TURNED: bool>(&self, shape: &D, p: &[DVec3], out: &mut [DVec3], f: F)
    where
        D: Distance,
        F: Fn(DVec3, f64, DVec3) -> DVec3,
    {
        self.lanes::<D, F, TURNED>(shape, p, out, f)
    }

    #[inline(always)]
    fn lanes<D, F, const TURNED: bool>(&self, shape: &D, p: &[DVec3], out: &mut [DVec3], f: F)
    where
        D: Distance,
        F: Fn(DVec3, f64, DVec3) -> DVec3,
    {
        const N: usize = 16;
        let center = shape.center();
        let qt = self.q.transpose();
        for (p, out) in p.chunks(N).zip(out.chunks_mut(N)) {
            let mut xb = [DVec3::ZERO; N];
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for (b, x) in xb.iter_mut().zip(p) {
                *b = self.body::<TURNED>(center, &qt, *x);
                lo = lo.min(*b);
                hi = hi.max(*b);
            }
            if shape.misses(lo, hi) {
                continue;
            }
            for ((o, x), b) in out.iter_mut().zip(p).zip(&xb) {
                if let Some((d, g)) = shape.distance(*b) {
                    *o += f(*x, d, if TURNED { self.q * g } else { g });
                }
            }
        }
    }
}

/// A curl tool of any shape: translation or rotation (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct CurlTool<D> {
    pub shape: D,
    pub motion: Motion,
    pub power: u8,
    /// The shape moves with the tool; else the field is steady.
    pub moving: bool,
}

impl<D: Distance + Clone + Into<Shape>> CurlTool<D> {
    /// The tool, validated (errors name the Python argument).
    pub fn new(shape: D, motion: Motion, power: i64, moving: bool) -> Result<CurlTool<D>> {
        let arg = match motion {
            Motion::Translate(_) => "velocity",
            Motion::Rotate { .. } => "angular_velocity",
        };
        bounded(
            arg,
            CurlTool {
                shape,
                motion,
                power: falloff_power(power)?,
                moving,
            },
        )
    }

    /// The shape's pose at time `t`.
    #[inline]
    pub fn pose(&self, t: f64) -> Pose {
        let c0 = self.shape.center();
        if !self.moving || t == 0.0 {
            return Pose {
                c: c0,
                q: DMat3::IDENTITY,
            };
        }
        match self.motion {
            Motion::Translate(u) => Pose {
                c: c0 + u * t,
                q: DMat3::IDENTITY,
            },
            Motion::Rotate { omega, pivot } => {
                let w = omega.length();
                if !(w > 0.0) {
                    return Pose {
                        c: c0,
                        q: DMat3::IDENTITY,
                    };
                }
                let q = DMat3::from_axis_angle(omega / w, w * t);
                Pose {
                    c: pivot + q * (c0 - pivot),
                    q,
                }
            }
        }
    }

    /// The velocity at `x` with the shape at `pose`.
    #[inline(always)]
    pub fn eval_at(&self, x: DVec3, pose: &Pose) -> DVec3 {
        match pose.distance(&self.shape, x) {
            Some((d, g)) => self.eval_with(x, pose, d, g),
            None => DVec3::ZERO,
        }
    }

    /// The velocity at `x` given the shape's distance `d` and world gradient `g` there.
    #[inline(always)]
    fn eval_with(&self, x: DVec3, pose: &Pose, d: f64, g: DVec3) -> DVec3 {
        let Some(f) = Falloff::at(d, self.shape.reach(), self.power) else {
            return DVec3::ZERO;
        };
        match self.motion {
            Motion::Translate(u) => f.translate(g, x - pose.c, u),
            // the pivot stays fixed (a shape off the pivot orbits it)
            Motion::Rotate { omega, pivot } => f.rotate(g, x - pivot, omega),
        }
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        self.eval_at(x, &self.pose(t))
    }

    /// Jacobian of the curl potential at `x`, time `t` (zero outside the support).
    pub fn potential_jacobian(&self, x: DVec3, t: f64) -> DMat3 {
        let pose = self.pose(t);
        let Some((d, g)) = pose.distance(&self.shape, x) else {
            return DMat3::ZERO;
        };
        let Some(f) = Falloff::at(d, self.shape.reach(), self.power) else {
            return DMat3::ZERO;
        };
        match self.motion {
            Motion::Translate(u) => f.translate_potential_jacobian(g, x - pose.c, u),
            Motion::Rotate { omega, pivot } => f.rotate_potential_jacobian(g, x - pivot, omega),
        }
    }

    pub fn max_speed(&self) -> f64 {
        match self.motion {
            Motion::Translate(u) => translation_bound(u.length(), &self.shape, self.power),
            Motion::Rotate { omega, pivot } => rotation_bound(
                omega.length(),
                (self.shape.center() - pivot).length(),
                &self.shape,
                self.power,
            ),
        }
    }
}

impl<D: Distance + Clone + Into<Shape>> Tool for CurlTool<D> {
    fn wants_locality(&self) -> bool {
        self.shape.wants_locality()
    }
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, _tm: f64) -> DVec3 {
        self.eval(x, t)
    }
    fn max_speed(&self) -> f64 {
        CurlTool::max_speed(self)
    }
    fn length_scale(&self) -> f64 {
        self.shape.reach()
    }
    fn potential_jacobian(&self, x: DVec3, t: f64) -> Option<DMat3> {
        Some(CurlTool::potential_jacobian(self, x, t))
    }
    /// The shape's own motion: `|u|` for a moving translation, `|Ω| (arm + extent)` for a
    /// moving rotation (the farthest point of the support); 0 for a steady field.
    fn support_speed(&self) -> f64 {
        if !self.moving {
            return 0.0;
        }
        match self.motion {
            Motion::Translate(u) => u.length(),
            Motion::Rotate { omega, pivot } => {
                omega.length() * ((self.shape.center() - pivot).length() + self.shape.extent())
            }
        }
    }
    fn rigid_velocity(&self) -> DVec3 {
        match self.motion {
            Motion::Translate(u) if self.moving => u,
            _ => DVec3::ZERO,
        }
    }
    fn shape(&self) -> Option<ToolShape> {
        Some(ToolShape {
            shape: self.shape.clone().into(),
            power: Some(self.power),
        })
    }
    /// The tool's own surface (its tangential velocity jumps there), within the reach.
    fn slip_surface(&self, x: DVec3, t: f64) -> Option<(f64, DVec3)> {
        self.pose(t).distance(&self.shape, x)
    }
    /// The pose once per batch.
    #[inline]
    fn add_lanes(&self, p: &[DVec3], t: f64, _tm: f64, out: &mut [DVec3]) {
        let pose = self.pose(t);
        pose.add_lanes(&self.shape, p, out, |x, d, g| {
            self.eval_with(x, &pose, d, g)
        });
    }
    #[inline]
    fn rk4_lanes(&self, x: &mut [DVec3], t0: f64, h: f64, steps: std::ops::Range<usize>) {
        super::advect::rk4_by_batches(self, x, t0, h, steps);
    }
}

#[cfg(test)]
mod tests {
    use crate::run::cancel;
    use std::sync::Arc;

    use super::super::Field;
    use super::super::fields::{Rotation, Translation};
    use super::super::rod::Rod;
    use super::super::shape::{Ball, Ring};
    use super::*;

    fn div(f: impl Fn(DVec3) -> DVec3, x: DVec3) -> f64 {
        let h = 1e-6;
        (0..3)
            .map(|k| {
                let mut e = DVec3::ZERO;
                e[k] = h;
                (f(x + e)[k] - f(x - e)[k]) / (2.0 * h)
            })
            .sum()
    }

    #[test]
    fn a_ball_gives_the_sphere_tools() {
        let c = DVec3::new(0.1, -0.2, 0.3);
        let ball = Ball {
            center: c,
            radius: 0.4,
            reach: 0.3,
        };
        let u = DVec3::new(0.3, -1.0, 0.5);
        for p in [2, 3, 4] {
            let tr = Translation::new(c, 0.4, u, Some(0.3), p, true).unwrap();
            let ct = CurlTool::new(ball, Motion::Translate(u), p, true).unwrap();
            let om = DVec3::new(0.2, 0.5, -1.0);
            let pivot = c + DVec3::new(0.5, 0.1, -0.2);
            let ro = Rotation::new(c, 0.4, om, om.length(), Some(pivot), Some(0.3), p).unwrap();
            let cr = CurlTool::new(ball, Motion::Rotate { omega: om, pivot }, p, true).unwrap();
            for i in 0..200 {
                let a = i as f64 * 0.7;
                let x = c + DVec3::new(a.sin(), (1.3 * a).cos(), (0.7 * a).sin()) * 0.6;
                for t in [0.0, 0.3] {
                    assert!((tr.eval(x, t) - ct.eval(x, t)).length() < 1e-14);
                    assert!((ro.eval(x, t) - cr.eval(x, t)).length() < 1e-13);
                }
                if (x - c).length() > 0.45 && (x - c).length() < 0.65 {
                    assert!(div(|x| ct.eval(x, 0.1), x).abs() < 1e-7);
                    assert!(div(|x| cr.eval(x, 0.1), x).abs() < 1e-6);
                }
            }
        }
    }

    /// `curl A` from the potential's Jacobian (columns `∂A/∂x_j`).
    fn curl_of(j: DMat3) -> DVec3 {
        DVec3::new(
            j.col(1).z - j.col(2).y,
            j.col(2).x - j.col(0).z,
            j.col(0).y - j.col(1).x,
        )
    }

    #[test]
    fn the_potential_jacobian_has_the_velocity_as_curl_and_matches_differences() {
        let axis: Vec<DVec3> = (0..7)
            .map(|i| {
                let a = i as f64 * 0.15 - 0.45;
                DVec3::new(a.sin(), 0.2 * (2.0 * a).sin(), a.cos())
            })
            .collect();
        let rod = Arc::new(Rod::from_points(&axis, 0.15, Some(0.3), None, &cancel::never).unwrap());
        let om = DVec3::new(0.3, -1.0, 0.5);
        for (motion, p) in [
            (Motion::Translate(DVec3::new(0.2, 0.1, -1.0)), 2),
            (Motion::Translate(DVec3::new(0.2, 0.1, -1.0)), 4),
            (
                Motion::Rotate {
                    omega: om,
                    pivot: DVec3::new(0.1, 0.0, 0.8),
                },
                3,
            ),
        ] {
            let tool = CurlTool::new(rod.clone(), motion, p, true).unwrap();
            let mut inside = 0;
            for i in 0..300 {
                let a = i as f64 * 0.77;
                let x = DVec3::new(
                    a.sin() * 0.8,
                    (1.3 * a).cos() * 0.4,
                    0.9 + 0.3 * (0.7 * a).sin(),
                );
                let t = 0.1;
                let jac = tool.potential_jacobian(x, t);
                let v = tool.eval(x, t);
                assert!(
                    (curl_of(jac) - v).length() <= 1e-12 * (1.0 + v.length()),
                    "{x}"
                );
                if v.length() > 0.0 {
                    inside += 1;
                }
            }
            assert!(inside > 30, "{inside}");
        }
        assert!(
            Field::single(CurlTool::new(rod, Motion::Translate(DVec3::Z), 2, true).unwrap())
                .has_potential()
        );
    }

    /// The torus distance's gradient is the central difference of its distance, and it is
    /// the distance to the core circle minus the tube radius.
    #[test]
    fn a_ring_has_the_exact_gradient_of_its_distance() {
        let axis = DVec3::new(0.3, -0.4, 0.8).normalize();
        let ring = Ring {
            center: DVec3::new(0.1, -0.2, 0.3),
            axis,
            major: 0.6,
            minor: 0.12,
            reach: 0.15,
        };
        let e1 = axis.any_orthonormal_vector();
        let e2 = axis.cross(e1);
        let mut seen = 0;
        for i in 0..400 {
            let a = i as f64 * 0.37;
            let x = ring.center
                + DVec3::new(0.8 * a.sin(), 0.8 * (1.3 * a).cos(), 0.3 * (0.7 * a).sin());
            let Some((d, g)) = ring.distance(x) else {
                continue;
            };
            seen += 1;
            let y = x - ring.center;
            let (u, v, z) = (y.dot(e1), y.dot(e2), y.dot(axis));
            let core = (u.hypot(v) - 0.6).hypot(z);
            assert!((d - (core - 0.12)).abs() < 1e-14);
            let h = 1e-6;
            for k in 0..3 {
                let mut e = DVec3::ZERO;
                e[k] = h;
                let fd =
                    (ring.distance(x + e).unwrap().0 - ring.distance(x - e).unwrap().0) / (2.0 * h);
                assert!((fd - g[k]).abs() < 1e-8, "{fd} {}", g[k]);
            }
        }
        assert!(seen > 40, "{seen}");
    }

    #[test]
    fn motion_needs_exactly_one_velocity() {
        let z = DVec3::ZERO;
        assert_eq!(
            Motion::new(None, None, None, z).unwrap_err().arg,
            "velocity"
        );
        assert_eq!(
            Motion::new(Some(z), Some(z), None, z).unwrap_err().arg,
            "angular_velocity"
        );
        assert_eq!(
            Motion::new(Some(z), None, Some(z), z).unwrap_err().arg,
            "pivot"
        );
    }
}
