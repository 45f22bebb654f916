//! Cross-product fields `v = ∇p × ∇q` (von Funck, Theisel & Seidel 2006; Zheng's thesis
//! Ch. 11), divergence-free by the identity `div(∇p × ∇q) = 0` for any C² scalars p, q.
//!
//! Region function (von Funck et al. 2006): `D = b(σ)`, `σ = clamp(d/R_f, 0, 1)`, with `d` the
//! signed distance to the tool and `R_f` the reach; von Funck's C¹ blend `b = 4σ³ − 3σ⁴`
//! (`b′ = 12σ²(1 − σ)`), or Zheng's linear `b = σ` (C⁰). `D = 0` inside the tool, `v = 0`
//! where `d ≥ R_f`.
//!
//! * **Translation of a region** (§11.1, §11.2.1, and the exact distance-field extension of
//!   von Funck et al. 2006): `p = (1 − D) N·Y`, `q = (1 − D) B·Y`, `N × B = u/|u|`, `Y = X − c`.
//!   Because `N(B·Y) − B(N·Y) = Y × (N × B)`, the field does not depend on the choice of
//!   `N, B` and is linear in the velocity `u`:
//!
//!   `v = (1 − D)² u + (1 − D) D′ [ (n·u) Y − (n·Y) u ]`,  `n = ∇d`,
//!
//!   rigid (`v = u`) inside the tool, normal velocity `(1 − D)²(u·n)`. This holds for **any**
//!   C¹ distance `d` with its exact gradient: a sphere ([`Sphere`], von Funck with
//!   `r_i = ρ`, `r_o = ρ + R_f`) or a capsule ([`Capsule`], the free-form extension; also
//!   Zheng's strip of type I on a straight axis when `u` is along the axis, where
//!   `∇(N·(X − γ)) = N` exactly).
//! * **Strip of type II**, flow across a straight strip (§11.2.3, S increasing along the
//!   axis t, type II): `p = s σ(X)` (arc-length parameter of the closest axis point, clamped),
//!   `q = (1 − D) U·(X − a)`, `U = m̂ × t`; `v = s [(1 − D) m̂ − D′ (U·(X − a)) t × n]`
//!   between the end planes, 0 beyond them (a tangential jump: the flux is continuous).
//! * **Torus** moving along its axis k (§11.2.4): the two half-torus fields of the thesis sum
//!   to the field of the multivalued `p = s R_t θ`, whose gradient `s R_t e_θ/ρ_ax` is single
//!   valued; `q = −(1 − D)(ρ_ax − R_t)`:
//!
//!   `v = s (R_t/ρ_ax) [ (1 − D) k + D′ (ρ_ax − R_t) e_θ × n ]`.

use crate::run::cancel;
use glam::DVec3;

use super::shape::{Ball, Ring, Shape, ToolShape, blend, moved, speed_factor, translate};
use super::{Field, Tool, bounded, finite, finite3, positive, reach_or, unit};
use crate::error::{InputError, Result};

/// Sphere tool of radius ρ translating with velocity u (von Funck's region translation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    pub center: DVec3,
    pub velocity: DVec3,
    pub radius: f64,
    pub reach: f64,
    pub linear: bool,
    pub moving: bool,
}

impl Sphere {
    /// The tool of `spinal.fields.sphere`, validated; `reach` defaults to `radius`.
    pub fn new(
        center: DVec3,
        radius: f64,
        velocity: DVec3,
        reach: Option<f64>,
        linear: bool,
        moving: bool,
    ) -> Result<Sphere> {
        let radius = positive("radius", radius)?;
        bounded(
            "velocity",
            Sphere {
                center: finite3("center", center)?,
                velocity: finite3("velocity", velocity)?,
                radius,
                reach: reach_or(reach, radius)?,
                linear,
                moving,
            },
        )
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        let c = moved(self.center, self.velocity, self.moving, t);
        let y = x - c;
        let r2 = y.length_squared();
        let outer = self.radius + self.reach;
        if !(r2 < outer * outer) {
            return DVec3::ZERO;
        }
        if r2 <= self.radius * self.radius {
            return self.velocity;
        }
        let r = r2.sqrt();
        let d = r - self.radius;
        translate(d, y * (1.0 / r), y, self.velocity, self.reach, self.linear)
    }

    /// Exact maximum for a sphere: `|v| = |u| max((1 − D)², |(1 − D)² − (1 − D)D′ r|)`
    /// (the extremes over the angle between Y and u), sampled over r.
    pub fn max_speed(&self) -> f64 {
        let n = 2048;
        let mut m: f64 = 1.0;
        for i in 0..=n {
            let d = self.reach * i as f64 / n as f64;
            let (b, db) = blend(d, self.reach, self.linear);
            let g = 1.0 - b;
            m = m.max((g * g - g * db * (self.radius + d)).abs());
        }
        m * self.velocity.length()
    }
}

/// Capsule tool (segment a–b, radius ρ) translating with velocity u: the exact
/// distance-field extension of the region translation, `Y = X − (a + b)/2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// First end of the capsule's axis segment (world units).
    pub a: DVec3,
    /// Second end of the capsule's axis segment (world units).
    pub b: DVec3,
    pub velocity: DVec3,
    pub radius: f64,
    pub reach: f64,
    pub linear: bool,
    pub moving: bool,
    ab: DVec3,
    inv_len2: f64,
}

/// Closest point on the segment `a + λ ab`, λ ∈ [0, 1].
#[inline(always)]
fn closest(x: DVec3, a: DVec3, ab: DVec3, inv_len2: f64) -> (DVec3, f64) {
    let lam = ((x - a).dot(ab) * inv_len2).clamp(0.0, 1.0);
    (a + ab * lam, lam)
}

impl Capsule {
    /// The tool of `spinal.fields.capsule` (segment `start`–`end`), validated; `reach`
    /// defaults to `radius`.
    pub fn new(
        start: DVec3,
        end: DVec3,
        radius: f64,
        velocity: DVec3,
        reach: Option<f64>,
        linear: bool,
        moving: bool,
    ) -> Result<Capsule> {
        let (a, b) = (finite3("start", start)?, finite3("end", end)?);
        let radius = positive("radius", radius)?;
        let ab = b - a;
        let l2 = ab.length_squared();
        bounded(
            "velocity",
            Capsule {
                a,
                b,
                velocity: finite3("velocity", velocity)?,
                radius,
                reach: reach_or(reach, radius)?,
                linear,
                moving,
                ab,
                inv_len2: if l2 > 0.0 { 1.0 / l2 } else { 0.0 },
            },
        )
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        let a = moved(self.a, self.velocity, self.moving, t);
        let (p, _) = closest(x, a, self.ab, self.inv_len2);
        let w = x - p;
        let r = w.length();
        if !(r > 0.0) {
            return self.velocity;
        }
        let y = x - (a + 0.5 * self.ab);
        translate(
            r - self.radius,
            w * (1.0 / r),
            y,
            self.velocity,
            self.reach,
            self.linear,
        )
    }

    pub fn max_speed(&self) -> f64 {
        let half = 0.5 * self.ab.length();
        let (rho, rf) = (self.radius, self.reach);
        self.velocity.length() * speed_factor(rf, self.linear, |d| half + rho + d)
    }
}

/// Torus (centre c, unit axis k, major R_t, minor r_t) moving along k with speed s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torus {
    pub center: DVec3,
    pub axis: DVec3,
    pub speed: f64,
    pub major: f64,
    pub minor: f64,
    pub reach: f64,
    pub linear: bool,
    pub moving: bool,
}

impl Torus {
    /// The tool of `spinal.fields.torus`, validated; `reach` defaults to `minor`, and
    /// `minor + reach < major` keeps the field away from the axis.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        center: DVec3,
        axis: DVec3,
        major: f64,
        minor: f64,
        speed: f64,
        reach: Option<f64>,
        linear: bool,
        moving: bool,
    ) -> Result<Torus> {
        let (major, minor) = (positive("major", major)?, positive("minor", minor)?);
        let reach = reach_or(reach, minor)?;
        if !(minor + reach < major) {
            return Err(InputError::new(
                "minor",
                format!(
                    "minor + reach ({}) must be below major ({major}) so that the field stays \
                     away from the axis",
                    minor + reach
                ),
            ));
        }
        bounded(
            "speed",
            Torus {
                center: finite3("center", center)?,
                axis: unit("axis", axis)?,
                speed: finite("speed", speed)?,
                major,
                minor,
                reach,
                linear,
                moving,
            },
        )
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        let k = self.axis;
        let c = if self.moving {
            self.center + k * (self.speed * t)
        } else {
            self.center
        };
        let y = x - c;
        let z = k.dot(y);
        let yp = y - k * z;
        let rho = yp.length();
        let dr = rho - self.major;
        let dist = (dr * dr + z * z).sqrt();
        let d = dist - self.minor;
        if !(d < self.reach) || !(rho > 0.0) {
            return DVec3::ZERO;
        }
        let (b, db) = blend(d, self.reach, self.linear);
        let scale = self.speed * self.major / rho;
        let mut v = k * (1.0 - b);
        if db > 0.0 {
            let e_rho = yp * (1.0 / rho);
            let n = (e_rho * dr + k * z) * (1.0 / dist);
            v += k.cross(e_rho).cross(n) * (db * dr);
        }
        v * scale
    }

    pub fn max_speed(&self) -> f64 {
        let inner = self.major - self.minor - self.reach;
        let f = speed_factor(self.reach, self.linear, |d| self.minor + d);
        self.speed.abs() * self.major / inner * f
    }
}

/// Straight strip (segment a–b, radius ρ) pushing sideways with velocity m ⟂ (b − a).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripAcross {
    /// First end of the strip's axis segment (world units).
    pub a: DVec3,
    /// Second end of the strip's axis segment (world units).
    pub b: DVec3,
    pub velocity: DVec3,
    pub radius: f64,
    pub reach: f64,
    pub linear: bool,
    ab: DVec3,
    inv_len2: f64,
    tangent: DVec3,
    side: DVec3,
}

impl StripAcross {
    /// The sideways strip of `spinal.fields.strip(kind="across")`, validated.
    pub fn new(
        start: DVec3,
        end: DVec3,
        radius: f64,
        velocity: DVec3,
        reach: Option<f64>,
        linear: bool,
    ) -> Result<StripAcross> {
        let (a, b) = (finite3("start", start)?, finite3("end", end)?);
        let velocity = finite3("velocity", velocity)?;
        let radius = positive("radius", radius)?;
        let reach = reach_or(reach, radius)?;
        let t = strip_axis(a, b)?;
        let ab = b - a;
        let l = ab.length();
        let s = velocity.length();
        if (velocity.dot(t)).abs() > 1e-9 * s {
            return Err(InputError::new(
                "velocity",
                "must be perpendicular to the strip axis for kind='across'",
            ));
        }
        let side = if s > 0.0 {
            (velocity / s).cross(t)
        } else {
            DVec3::ZERO
        };
        bounded(
            "velocity",
            StripAcross {
                a,
                b,
                velocity,
                radius,
                reach,
                linear,
                ab,
                inv_len2: 1.0 / (l * l),
                tangent: t,
                side,
            },
        )
    }

    #[inline]
    pub fn eval(&self, x: DVec3) -> DVec3 {
        let (p, lam) = closest(x, self.a, self.ab, self.inv_len2);
        if !(lam > 0.0 && lam < 1.0) {
            return DVec3::ZERO;
        }
        let w = x - p;
        let r = w.length();
        let d = r - self.radius;
        if !(d < self.reach) {
            return DVec3::ZERO;
        }
        let (b, db) = blend(d, self.reach, self.linear);
        let mut v = self.velocity * (1.0 - b);
        if db > 0.0 {
            let n = w * (1.0 / r);
            let s = self.velocity.length();
            v -= self.tangent.cross(n) * (s * db * self.side.dot(x - self.a));
        }
        v
    }

    pub fn max_speed(&self) -> f64 {
        let rho = self.radius;
        self.velocity.length() * speed_factor(self.reach, self.linear, |d| rho + d)
    }
}

/// The unit axis of a strip from `a` to `b`.
fn strip_axis(a: DVec3, b: DVec3) -> Result<DVec3> {
    let l = (b - a).length();
    if l > 0.0 && l.is_finite() {
        Ok((b - a) / l)
    } else {
        Err(InputError::new("end", "must differ from start"))
    }
}

/// The straight strip of `spinal.fields.strip`: `across = false` (type I, the material slides
/// along the strip: a static [`Capsule`], `velocity` parallel to the axis) or `true` (type
/// II, [`StripAcross`], `velocity` perpendicular to it).
pub fn strip(
    start: DVec3,
    end: DVec3,
    radius: f64,
    velocity: DVec3,
    across: bool,
    reach: Option<f64>,
    linear: bool,
) -> Result<Field> {
    if across {
        return Ok(Field::single(StripAcross::new(
            start, end, radius, velocity, reach, linear,
        )?));
    }
    let (a, b) = (finite3("start", start)?, finite3("end", end)?);
    let u = finite3("velocity", velocity)?;
    let t = strip_axis(a, b)?;
    let s = u.length();
    if (u.dot(t).abs() - s).abs() > 1e-9 * s {
        return Err(InputError::new(
            "velocity",
            "must be parallel to the strip axis for kind='along'",
        ));
    }
    Ok(Field::single(Capsule::new(
        a, b, radius, u, reach, linear, false,
    )?))
}

/// The shape a keyframed pose moves ([`super::keyframe`]): a segment's rod (two points, a
/// capsule) or, for a degenerate segment, its ball; no falloff power of its own.
fn segment_shape(a: DVec3, b: DVec3, radius: f64, reach: f64) -> Option<ToolShape> {
    let shape = if a == b {
        Shape::Ball(Ball {
            center: a,
            radius,
            reach,
        })
    } else {
        let rod = super::rod::Rod::from_points(&[a, b], radius, Some(reach), None, &cancel::never)
            .ok()?;
        Shape::Rod(std::sync::Arc::new(rod))
    };
    Some(ToolShape { shape, power: None })
}

/// `impl Tool` for a tool with `eval(x, t)` and `max_speed()` whose length scale is `reach`,
/// whether it asks for a spatial order of the path lines ([`Tool::wants_locality`]) and its
/// shape for keyframed poses.
macro_rules! tool {
    ($t:ty, |$s:ident, $x:ident, $time:ident| $eval:expr, $local:expr, |$me:ident| $shape:expr) => {
        impl Tool for $t {
            fn wants_locality(&self) -> bool {
                $local
            }
            #[inline]
            fn velocity(&self, $x: DVec3, $time: f64, _tm: f64) -> DVec3 {
                let $s = self;
                $eval
            }
            fn max_speed(&self) -> f64 {
                <$t>::max_speed(self)
            }
            fn length_scale(&self) -> f64 {
                self.reach
            }
            fn shape(&self) -> Option<ToolShape> {
                let $me = self;
                $shape
            }
        }
    };
}

// the sphere's evaluation branches three ways (inside the tool, the blend shell, outside):
// on points in no spatial order (10⁶ random points in a ball, a third in the shell) the
// branches mispredict about 1.7 times per RK4 step, 0.3 in Morton order (callgrind's branch
// simulation), which more than pays for the sort
tool!(Sphere, |s, x, t| s.eval(x, t), true, |s| Some(ToolShape {
    shape: Shape::Ball(Ball {
        center: s.center,
        radius: s.radius,
        reach: s.reach,
    }),
    power: None,
}));
tool!(Capsule, |s, x, t| s.eval(x, t), false, |s| segment_shape(
    s.a, s.b, s.radius, s.reach
));
tool!(Torus, |s, x, t| s.eval(x, t), false, |s| Some(ToolShape {
    shape: Shape::Ring(Ring {
        center: s.center,
        axis: s.axis,
        major: s.major,
        minor: s.minor,
        reach: s.reach,
    }),
    power: None,
}));
tool!(StripAcross, |s, x, _t| s.eval(x), false, |s| segment_shape(
    s.a, s.b, s.radius, s.reach
));
