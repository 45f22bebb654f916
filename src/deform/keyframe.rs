//! Fields following keyframed rigid poses `(t_k, c_k, Q_k)` (the thesis's tools move rigidly
//! with their object space, Zheng Ch. 11.2, §11.2.6; the curl fields are those of Ch. 12).
//! The pose takes a point `C` of the field (by default a shape's centre) to `c(t)` and turns
//! it by `Q(t)` about it.
//!
//! **Pose.** In key interval `k`, `λ = (t − t_k)/Δt_k`:
//!
//! * position: the cubic Hermite segment through `c_k, c_{k+1}` with end slopes `ċ_k Δt_k`,
//!   `ċ_{k+1} Δt_k`, where `ċ_k` is the derivative of the parabola through the keys
//!   `k − 1, k, k + 1` (Bessel's tangent: Catmull–Rom's for uniform times; at the ends the
//!   parabola through the first or last three keys, the chord for two keys). Keys on a line
//!   at constant speed give exactly that motion. `c(t)` is C¹ in time;
//! * orientation: slerp, `Q(λ) = Q_k Exp(λ Θ_k)` with `Θ_k = Log(Q_kᵀ Q_{k+1})` (the short
//!   arc: consecutive quaternions are sign-aligned), world angular velocity
//!   `ω = Q_k Θ_k / Δt_k`, constant in each interval. `Q(t)` is C⁰ in its rate at the keys.
//!
//! **A tool with a shape** ([`Keyframed`]), at time `t`: the curl translation of
//! [`super::curl`] with `u = ċ(t)` and `Y = X − c(t)`, plus (when orientations are given)
//! the curl rotation with `Ω = ω(t)` about `c(t)`, both with the shape's distance at the
//! current pose, `d(C + Qᵀ(X − c))` and its gradient turned back by `Q`. Their normal
//! velocity on the tool surface is the rigid motion's, `(ċ + ω × (X − c))·n`. Zero before
//! the first and after the last key (the tool rests); the key times are breakpoints, and a
//! step's midpoint time `tm` picks the interval (and whether the tool moves) for all its
//! stages.
//!
//! **Any other field** ([`Carried`]): carried whole, `v = Q v₀(C + Qᵀ(X − c), t)`, with the
//! first or last key's pose held outside the keys.

use glam::{DMat3, DQuat, DVec3};

use super::curl::{Falloff, Pose, rotation_bound};
use super::shape::{Distance, Shape, ToolShape};
use super::{Tool, falloff};
use crate::error::{InputError, Result};
use crate::math::cubic::Hermite;
use crate::math::rotation::{ROTATION_TOL, is_rotation, mat3_from_quat, quat_from_mat3};
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

/// Key orientations as the user gives them.
#[derive(Debug, Clone)]
pub enum Orientations {
    /// Rotation matrices.
    Matrices(Vec<DMat3>),
    /// Unit quaternions.
    Quaternions(Vec<DQuat>),
}

/// Validated keys with their interpolation data.
#[derive(Debug, Clone, PartialEq)]
pub struct Keys {
    pub times: Vec<f64>,
    pub positions: Vec<DVec3>,
    /// `dc/dt` at the keys.
    slopes: Vec<DVec3>,
    /// Key frames and the body rotation vector `Θ_k` of each interval.
    turns: Option<(Vec<DMat3>, Vec<DVec3>)>,
}

/// The pose and its rates at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyPose {
    pub pose: Pose,
    /// `ċ`.
    pub v: DVec3,
    /// World angular velocity `ω`.
    pub omega: DVec3,
}

impl Keys {
    /// The keys, validated (errors name `times`, `positions`, `orientations`).
    ///
    /// Polls `cancel` between its passes over the keys and fails with [`InputError::stopped`] once
    /// it says stop.
    // Kept whole: one validation of the keys in the order of its error messages, then the
    // Hermite slopes and turns computed in the buffers it checked.
    pub fn new(
        times: &[f64],
        positions: &[DVec3],
        orientations: Option<Orientations>,
        cancel: Cancel<'_>,
    ) -> Result<Keys> {
        let poll = || {
            if cancel() {
                Err(InputError::stopped())
            } else {
                Ok(())
            }
        };
        let n = times.len();
        if n < 2 {
            return Err(InputError::new(
                "times",
                format!("need at least 2 keys, got {n}"),
            ));
        }
        if let Some(i) = times.iter().position(|t| !t.is_finite()) {
            return Err(InputError::new("times", format!("key {i} is not finite")));
        }
        if let Some(i) = times.windows(2).position(|w| !(w[1] > w[0])) {
            return Err(InputError::new(
                "times",
                format!(
                    "must increase strictly: key {} ({}) is not after key {i} ({})",
                    i + 1,
                    times[i + 1],
                    times[i]
                ),
            ));
        }
        if positions.len() != n {
            return Err(InputError::new(
                "positions",
                format!("expected {n} rows (one per key), got {}", positions.len()),
            ));
        }
        poll()?;
        super::finite_rows("positions", positions)?;
        poll()?;
        const CALL: &str = "keyframed";
        let dt = alloc::collect(CALL, times.windows(2).map(|w| w[1] - w[0]))?;
        let delta = alloc::collect(
            CALL,
            positions
                .windows(2)
                .zip(&dt)
                .map(|(w, h)| (w[1] - w[0]) / *h),
        )?;
        poll()?;
        let mut slopes = alloc::with_capacity(CALL, n)?;
        for k in 0..n {
            if k % cancel::BLOCK == 0 {
                poll()?;
            }
            slopes.push(if n == 2 {
                delta[0]
            } else if k == 0 {
                delta[0] + (delta[0] - delta[1]) * (dt[0] / (dt[0] + dt[1]))
            } else if k == n - 1 {
                let (a, b) = (delta[n - 2], delta[n - 3]);
                a + (a - b) * (dt[n - 2] / (dt[n - 3] + dt[n - 2]))
            } else {
                (delta[k - 1] * dt[k] + delta[k] * dt[k - 1]) / (dt[k - 1] + dt[k])
            });
        }
        let turns = match orientations {
            None => None,
            Some(o) => {
                let bad = |m: String| InputError::new("orientations", m);
                let mut q: Vec<DQuat> = match o {
                    Orientations::Matrices(m) => {
                        if let Some(i) = m.iter().position(|f| !is_rotation(f)) {
                            return Err(bad(format!("key {i} is not a rotation matrix")));
                        }
                        alloc::collect(CALL, m.iter().map(quat_from_mat3))?
                    }
                    Orientations::Quaternions(q) => {
                        if let Some(i) = q.iter().position(|q| {
                            !(q.is_finite() && (q.length() - 1.0).abs() < ROTATION_TOL)
                        }) {
                            return Err(bad(format!(
                                "quaternion {i} is not a unit quaternion (x, y, z, w)"
                            )));
                        }
                        alloc::collect(CALL, q.iter().map(|q| q.normalize()))?
                    }
                };
                poll()?;
                if q.len() != n {
                    return Err(bad(format!(
                        "expected {n} orientations (one per key), got {}",
                        q.len()
                    )));
                }
                for k in 1..n {
                    if q[k].dot(q[k - 1]) < 0.0 {
                        q[k] = -q[k];
                    }
                }
                poll()?;
                let frames = alloc::collect(CALL, q.iter().map(|q| mat3_from_quat(*q)))?;
                poll()?;
                let theta = alloc::collect(
                    CALL,
                    q.windows(2).map(|w| {
                        let (axis, angle) = (w[0].conjugate() * w[1]).normalize().to_axis_angle();
                        if angle.is_finite() && angle != 0.0 {
                            axis * angle
                        } else {
                            DVec3::ZERO
                        }
                    }),
                )?;
                Some((frames, theta))
            }
        };
        poll()?;
        Ok(Keys {
            times: alloc::copied(CALL, times)?,
            positions: alloc::copied(CALL, positions)?,
            slopes,
            turns,
        })
    }

    /// The position's Hermite data on interval `k`.
    #[inline]
    fn segment(&self, k: usize) -> Hermite {
        let h = self.times[k + 1] - self.times[k];
        Hermite::new(
            self.positions[k],
            self.positions[k + 1],
            self.slopes[k] * h,
            self.slopes[k + 1] * h,
        )
    }

    /// The pose at time `t` of a step whose midpoint time is `tm` (`None` while the tool
    /// rests: `tm` before the first or after the last key).
    pub fn pose_in(&self, t: f64, tm: f64) -> Option<KeyPose> {
        let n = self.times.len();
        if !(tm >= self.times[0] && tm <= self.times[n - 1]) {
            return None;
        }
        let k = self
            .times
            .partition_point(|s| *s <= tm)
            .saturating_sub(1)
            .min(n - 2);
        let h = self.times[k + 1] - self.times[k];
        let lam = (t - self.times[k]) / h;
        let seg = self.segment(k);
        let (c, v) = (seg.value(lam), seg.slope(lam) / h);
        let (q, omega) = match &self.turns {
            None => (DMat3::IDENTITY, DVec3::ZERO),
            Some((frames, theta)) => {
                let th = theta[k];
                let ang = th.length();
                let q = if ang > 0.0 {
                    frames[k] * DMat3::from_axis_angle(th / ang, lam * ang)
                } else {
                    frames[k]
                };
                (q, frames[k] * th / h)
            }
        };
        Some(KeyPose {
            pose: Pose { c, q },
            v,
            omega,
        })
    }

    /// The pose at time `t` of a step whose midpoint time is `tm`, held at the first or last
    /// key's outside the keys (`ċ = ω = 0` there).
    pub fn pose_held(&self, t: f64, tm: f64) -> Pose {
        if let Some(p) = self.pose_in(t, tm) {
            return p.pose;
        }
        let k = if tm < self.times[0] {
            0
        } else {
            self.times.len() - 1
        };
        Pose {
            c: self.positions[k],
            q: self.turns.as_ref().map_or(DMat3::IDENTITY, |(f, _)| f[k]),
        }
    }

    /// The largest `|ċ|` (17 samples per interval, × 1.05) and `|ω|`, polling `cancel` every
    /// [`cancel::BLOCK`] intervals (`None` once it says stop).
    pub fn rates(&self, cancel: Cancel<'_>) -> Option<(f64, f64)> {
        let mut v: f64 = 0.0;
        for k in 0..self.times.len() - 1 {
            if k % cancel::BLOCK == 0 && cancel() {
                return None;
            }
            let seg = self.segment(k);
            let h = self.times[k + 1] - self.times[k];
            for i in 0..=16 {
                v = v.max(seg.slope(i as f64 / 16.0).length() / h);
            }
        }
        let w = match &self.turns {
            None => 0.0,
            Some((_, theta)) => theta
                .iter()
                .zip(self.times.windows(2))
                .map(|(th, t)| th.length() / (t[1] - t[0]))
                .fold(0.0, f64::max),
        };
        Some((1.05 * v, w))
    }
}

/// A shape following keys (see the module docs).
#[derive(Debug, Clone)]
pub struct Keyframed<D> {
    pub shape: D,
    pub keys: Keys,
    pub power: u8,
    /// `C − C_shape`: the point `C` taken to the key positions, from the shape's centre
    /// (zero unless the caller names another `C`).
    offset: DVec3,
}

impl<D: Distance> Keyframed<D> {
    /// The tool, validated: a finite speed bound (errors name `times`); `center` is the point
    /// `C` of the shape taken to the key positions (default the shape's centre).
    ///
    /// Polls `cancel` in the speed bound and fails with [`InputError::stopped`] once it says stop.
    pub fn new(
        shape: D,
        keys: Keys,
        power: u8,
        center: Option<DVec3>,
        cancel: Cancel<'_>,
    ) -> Result<Keyframed<D>> {
        let (v, w) = keys.rates(cancel).ok_or_else(InputError::stopped)?;
        let offset = center.map_or(DVec3::ZERO, |c| c - shape.center());
        let tool = Keyframed {
            shape,
            keys,
            power,
            offset,
        };
        let s = tool.speed_bound(v, w);
        if !s.is_finite() {
            return Err(InputError::new(
                "times",
                format!("keys too close in time: the tool's speed bound is {s}"),
            ));
        }
        Ok(tool)
    }

    /// The shape's own pose for the key pose `p` (which takes `C` to `c`): its centre at
    /// `c − Q (C − C_shape)`.
    #[inline(always)]
    fn shape_pose(&self, p: &Pose) -> Pose {
        if self.offset == DVec3::ZERO {
            *p
        } else {
            Pose {
                c: p.c - p.q * self.offset,
                q: p.q,
            }
        }
    }

    /// The velocity at `x` for the tool at pose `p`.
    #[inline(always)]
    pub fn eval_at(&self, x: DVec3, p: &KeyPose) -> DVec3 {
        match self.shape_pose(&p.pose).distance(&self.shape, x) {
            Some((d, g)) => self.eval_with(x, p, d, g),
            None => DVec3::ZERO,
        }
    }

    /// The velocity at `x` given the shape's distance `d` and world gradient `g` there.
    #[inline(always)]
    fn eval_with(&self, x: DVec3, p: &KeyPose, d: f64, g: DVec3) -> DVec3 {
        let Some(f) = Falloff::at(d, self.shape.reach(), self.power) else {
            return DVec3::ZERO;
        };
        let y = x - p.pose.c;
        let v = f.translate(g, y, p.v);
        if self.keys.turns.is_some() {
            v + f.rotate(g, y, p.omega)
        } else {
            v
        }
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        match self.keys.pose_in(t, tm) {
            Some(p) => self.eval_at(x, &p),
            None => DVec3::ZERO,
        }
    }

    /// The curl bounds with `|Y| = |X − c|` at most the shape's extent plus `|C − C_shape|`.
    pub fn max_speed(&self) -> f64 {
        // never stopped (a stopped bound would be no bound)
        let rates = self.keys.rates(&cancel::never);
        rates.map_or(f64::INFINITY, |(v, w)| self.speed_bound(v, w))
    }

    /// The speed bound for the key rates `(|ċ|, |ω|)` ([`Keys::rates`]).
    fn speed_bound(&self, v: f64, w: f64) -> f64 {
        let arm = self.offset.length();
        let s = &self.shape;
        v * (1.0 + 0.5 * self.power as f64 * s.gradient_bound() * (s.extent() + arm) / s.reach())
            + rotation_bound(w, arm, s, self.power)
    }
}

/// The keyframed tool of a built field (see [`Carried`] for the rule): a field of one tool
/// with a shape moves that shape (`power` (2, 3 or 4) overrides the tool's falloff power; a
/// tool without one, not a curl field, defaults to 2; `center` the point `C` taken to the
/// keys, default the shape's centre); any other field is carried rigidly about `center`
/// (default the tool's natural centre; required for sums), and `power` is refused.
///
/// Polls `cancel` in the speed bound (see [`Keyframed::new`]).
pub fn keyframed(
    field: &super::Field,
    keys: Keys,
    power: Option<i64>,
    center: Option<DVec3>,
    cancel: Cancel<'_>,
) -> Result<super::Field> {
    let center = center.map(|c| super::finite3("center", c)).transpose()?;
    let shape = match field.tools.as_slice() {
        [one] => one.shape(),
        _ => None,
    };
    let Some(shape) = shape else {
        if power.is_some() {
            return Err(InputError::new(
                "falloff_power",
                "only applies to a tool with a shape (a field carried rigidly keeps its own \
                 falloff)",
            ));
        }
        let c = match (center, field.tools.as_slice()) {
            (Some(c), _) => c,
            (None, [one]) => one.natural_center().ok_or_else(|| {
                InputError::new(
                    "center",
                    "required: this tool has no shape and no natural centre (give the point \
                     C of the field that the keys move)",
                )
            })?,
            (None, _) => {
                return Err(InputError::new(
                    "center",
                    format!(
                        "required for a sum of {} tools (give the point C of the field that \
                         the keys move)",
                        field.tools.len()
                    ),
                ));
            }
        };
        return Ok(super::Field::single(Carried::new(
            field.clone(),
            keys,
            c,
            cancel,
        )?));
    };
    let p = match (power, shape.power) {
        (Some(p), _) => falloff(p)?,
        (None, Some(p)) => p,
        (None, None) => 2,
    };
    Ok(match shape.shape {
        Shape::Ball(b) => super::Field::single(Keyframed::new(b, keys, p, center, cancel)?),
        Shape::Rod(r) => super::Field::single(Keyframed::new(r, keys, p, center, cancel)?),
        Shape::Grid(g) => super::Field::single(Keyframed::new(g, keys, p, center, cancel)?),
        Shape::Ring(r) => super::Field::single(Keyframed::new(r, keys, p, center, cancel)?),
    })
}

/// A whole field carried rigidly by keyframed poses: with the pose `(c(t), Q(t))` of the keys
/// (held at the first or last key outside them),
///
/// `v(X, t) = Q v₀(C + Qᵀ(X − c), t)`,
///
/// the field `v₀` seen in the frame that takes its point `C` to `c` and turns it by `Q`.
/// A rigid change of coordinates keeps `div v = 0` (the Jacobian `Q J₀ Qᵀ` has `J₀`'s
/// trace); no rigid velocity is added (the field's action moves, the material is not
/// dragged along). `v₀` keeps its own clock, so its breakpoints stay where they are and the
/// field's are those and the key times.
#[derive(Debug, Clone)]
pub struct Carried {
    pub field: super::Field,
    pub keys: Keys,
    pub center: DVec3,
    breaks: Vec<f64>,
    speed: f64,
}

impl Carried {
    /// The carried field, validated: a finite speed bound (errors name `times`).
    ///
    /// Polls `cancel` in the speed bound and fails with [`InputError::stopped`] once it says stop.
    pub fn new(
        field: super::Field,
        keys: Keys,
        center: DVec3,
        cancel: Cancel<'_>,
    ) -> Result<Carried> {
        const CALL: &str = "keyframed";
        let own = field.breakpoints(CALL)?;
        let mut breaks = alloc::with_capacity(CALL, own.len() + keys.times.len())?;
        breaks.extend_from_slice(&own);
        breaks.extend_from_slice(&keys.times);
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        // the step rule's speed: the field's own plus the speed at which the pose moves its
        // pattern past the material, |ċ| + |ω| E with E the support's radius about C (|ċ|
        // alone where the support is unbounded)
        let (v, w) = keys.rates(cancel).ok_or_else(InputError::stopped)?;
        let reach = field.support_radius(center);
        if let Some(e) = reach.filter(|e| v.is_finite() && w.is_finite() && !(w * e).is_finite()) {
            return Err(InputError::new(
                "center",
                format!(
                    "too far from the field's support ({e:e} away) for the keys' turning \
                     rate {w:e}: the speed bound is out of floating-point range"
                ),
            ));
        }
        let pattern = v + reach.map_or(0.0, |e| w * e);
        let speed = field.max_speed() + pattern;
        if !speed.is_finite() {
            return Err(InputError::new(
                "times",
                format!("keys too close in time: the field's speed bound is {speed}"),
            ));
        }
        Ok(Carried {
            field,
            keys,
            center,
            breaks,
            speed,
        })
    }

    /// `C + Qᵀ(x − c)`.
    #[inline(always)]
    fn body(&self, p: &Pose, x: DVec3) -> DVec3 {
        self.center + p.q.transpose() * (x - p.c)
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        let p = self.keys.pose_held(t, tm);
        p.q * self.field.eval_in(self.body(&p, x), t, tm)
    }
}

impl Tool for Carried {
    fn wants_locality(&self) -> bool {
        self.field.tools.iter().any(|e| e.wants_locality())
    }
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        self.eval(x, t, tm)
    }
    fn max_speed(&self) -> f64 {
        self.speed
    }
    fn length_scale(&self) -> f64 {
        self.field.length_scale()
    }
    fn breakpoints(&self) -> &[f64] {
        &self.breaks
    }
    /// The field's slip surfaces in the carried frame (the pose of the first or last key
    /// outside the keys).
    fn slip_surface(&self, x: DVec3, t: f64) -> Option<(f64, DVec3)> {
        let p = self.keys.pose_held(t, t);
        self.field
            .slip_surface(self.body(&p, x), t)
            .map(|(d, g)| (d, p.q * g))
    }
    /// The pose once per batch, the points into the field's frame, the field's own batch
    /// evaluation, the velocities turned back.
    #[inline]
    fn add_lanes(&self, p: &[DVec3], t: f64, tm: f64, out: &mut [DVec3]) {
        const N: usize = super::advect::LANES;
        let pose = self.keys.pose_held(t, tm);
        for (p, out) in p.chunks(N).zip(out.chunks_mut(N)) {
            let n = p.len();
            let mut xb = [DVec3::ZERO; N];
            let mut vb = [DVec3::ZERO; N];
            for (b, x) in xb.iter_mut().zip(p) {
                *b = self.body(&pose, *x);
            }
            for e in &self.field.tools {
                e.add_lanes(&xb[..n], t, tm, &mut vb[..n]);
            }
            for (o, v) in out.iter_mut().zip(&vb) {
                *o += pose.q * *v;
            }
        }
    }
    #[inline]
    fn rk4_lanes(&self, x: &mut [DVec3], t0: f64, h: f64, steps: std::ops::Range<usize>) {
        super::advect::rk4_by_batches(self, x, t0, h, steps);
    }
}

impl<D: Distance + Clone + Into<Shape>> Tool for Keyframed<D> {
    fn wants_locality(&self) -> bool {
        self.shape.wants_locality()
    }
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        self.eval(x, t, tm)
    }
    fn max_speed(&self) -> f64 {
        Keyframed::max_speed(self)
    }
    fn length_scale(&self) -> f64 {
        self.shape.reach()
    }
    fn breakpoints(&self) -> &[f64] {
        &self.keys.times
    }
    fn shape(&self) -> Option<ToolShape> {
        Some(ToolShape {
            shape: self.shape.clone().into(),
            power: Some(self.power),
        })
    }
    /// The shape's own surface at its pose at `t` (its tangential velocity jumps there; the
    /// pose of the first or last key outside the keys, where the tool rests).
    fn slip_surface(&self, x: DVec3, t: f64) -> Option<(f64, DVec3)> {
        let ts = &self.keys.times;
        let t = t.clamp(ts[0], ts[ts.len() - 1]);
        let p = self.keys.pose_in(t, t)?.pose;
        self.shape_pose(&p).distance(&self.shape, x)
    }
    /// The pose once per batch, then the frozen-pose field at every point.
    #[inline]
    fn add_lanes(&self, p: &[DVec3], t: f64, tm: f64, out: &mut [DVec3]) {
        if let Some(pose) = self.keys.pose_in(t, tm) {
            self.shape_pose(&pose.pose)
                .add_lanes(&self.shape, p, out, |x, d, g| {
                    self.eval_with(x, &pose, d, g)
                });
        }
    }
    #[inline]
    fn rk4_lanes(&self, x: &mut [DVec3], t0: f64, h: f64, steps: std::ops::Range<usize>) {
        super::advect::rk4_by_batches(self, x, t0, h, steps);
    }
    /// The poses of the steps' three stage times once for all the batches of the chunk (by
    /// runs of [`POSE_STEPS`] steps), then the batches.
    fn rk4_chunk(&self, x: &mut [DVec3], t0: f64, h: f64, steps: std::ops::Range<usize>) {
        use super::advect::{LANES, rk4_lanes_staged, stage_times};
        let mut first = steps.start;
        while first < steps.end {
            let part = first..steps.end.min(first + POSE_STEPS);
            let mut poses = [[None; 3]; POSE_STEPS];
            for (p, j) in poses.iter_mut().zip(part.clone()) {
                let (ts, tm) = stage_times(t0, h, j);
                *p = ts.map(|t| self.keys.pose_in(t, tm));
            }
            for b in x.chunks_mut(LANES) {
                rk4_lanes_staged(
                    |p, j, stage, _t, _tm, out| {
                        if let Some(pose) = &poses[j - part.start][STAGE_POSE[stage]] {
                            let at = self.shape_pose(&pose.pose);
                            at.add_lanes(&self.shape, p, out, |x, d, g| {
                                self.eval_with(x, pose, d, g)
                            });
                        }
                    },
                    b,
                    t0,
                    h,
                    part.clone(),
                );
            }
            first = part.end;
        }
    }
}

/// Steps whose poses [`Keyframed`]'s `rk4_chunk` keeps at a time.
const POSE_STEPS: usize = 32;

/// The pose of each RK4 stage among a step's three stage times.
const STAGE_POSE: [usize; 4] = [0, 1, 1, 2];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_on_a_line_at_constant_speed_move_linearly() {
        let u = DVec3::new(0.3, -0.2, 0.1);
        let times = [0.0, 0.5, 1.5, 2.0];
        let pos: Vec<DVec3> = times.iter().map(|t| DVec3::ONE + u * *t).collect();
        let keys = Keys::new(&times, &pos, None, &cancel::never).unwrap();
        for t in [0.1, 0.7, 1.9] {
            let p = keys.pose_in(t, t).unwrap();
            assert!((p.pose.c - (DVec3::ONE + u * t)).length() < 1e-15);
            assert!((p.v - u).length() < 1e-15);
        }
        assert!(keys.pose_in(2.1, 2.1).is_none());
        assert_eq!(
            Keys::new(&[0.0, 0.0], &pos[..2], None, &cancel::never)
                .unwrap_err()
                .arg,
            "times"
        );
    }

    /// A batch of lanes (the pose once, a box the rod misses skipped) has the bits of the
    /// points one at a time, turned or not.
    #[test]
    fn lanes_have_the_bits_of_single_points() {
        use super::super::rod::Rod;
        use std::sync::Arc;
        let axis: Vec<DVec3> = (0..13)
            .map(|i| {
                let a = -0.6 + 0.1 * i as f64;
                DVec3::new(a.sin(), 0.15 * (2.0 * a).sin(), a.cos())
            })
            .collect();
        let rod = Arc::new(Rod::from_points(&axis, 0.3, Some(0.3), None, &cancel::never).unwrap());
        let times: [f64; 4] = [0.0, 0.1, 0.2, 0.3];
        let pos: Vec<DVec3> = times
            .iter()
            .map(|t| rod.center + DVec3::new(0.3 * (4.0 * t).sin(), 0.0, -t))
            .collect();
        let turn: Vec<DQuat> = times
            .iter()
            .map(|t| DQuat::from_rotation_y(1.5 * t))
            .collect();
        for o in [None, Some(Orientations::Quaternions(turn))] {
            let keys = Keys::new(&times, &pos, o, &cancel::never).unwrap();
            let tool = Keyframed::new(rod.clone(), keys, 2, None, &cancel::never).unwrap();
            let (mut moved, mut skipped) = (0, 0);
            for b in 0..400 {
                let q = b as f64 * 0.37;
                let c = DVec3::new(q.sin(), 0.6 * (1.3 * q).cos(), 0.9 * (0.7 * q).sin());
                let p: Vec<DVec3> = (0..16)
                    .map(|j| {
                        let a = q + j as f64;
                        c + 0.05 * DVec3::new(a.cos(), (1.7 * a).sin(), (2.3 * a).cos())
                    })
                    .collect();
                let t = 0.05 + 0.2 * (b % 7) as f64 / 7.0;
                let mut out = vec![DVec3::ZERO; 16];
                Tool::add_lanes(&tool, &p, t, t, &mut out);
                for (x, v) in p.iter().zip(&out) {
                    let one = tool.eval(*x, t, t);
                    assert_eq!(
                        v.to_array().map(f64::to_bits),
                        one.to_array().map(f64::to_bits)
                    );
                    moved += (one != DVec3::ZERO) as usize;
                }
                skipped += out.iter().all(|v| *v == DVec3::ZERO) as usize;
            }
            assert!(moved > 500 && skipped > 40, "{moved} {skipped}");
        }
    }

    #[test]
    fn slerp_turns_at_a_constant_rate() {
        let ax = DVec3::new(1.0, 2.0, -0.5).normalize();
        let times = [0.0, 1.0, 2.0];
        let q: Vec<DQuat> = times
            .iter()
            .map(|t| DQuat::from_axis_angle(ax, 0.8 * t))
            .collect();
        let keys = Keys::new(
            &times,
            &[DVec3::ZERO; 3],
            Some(Orientations::Quaternions(q)),
            &cancel::never,
        )
        .unwrap();
        let p = keys.pose_in(1.3, 1.3).unwrap();
        assert!((p.omega - ax * 0.8).length() < 1e-14);
        assert!((p.pose.q - DMat3::from_axis_angle(ax, 0.8 * 1.3)).abs_diff_eq(DMat3::ZERO, 1e-14));
    }
}
