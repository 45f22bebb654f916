//! Tools moving along a path: a spine `x_0 … x_{n−1}` with its frames `F_k = [r_k s_k t_k]`
//! (the double-reflection RMF of `spinal.frames`), traversed at constant speed in arc length
//! from time `t0` to `t0 + T` (the thesis only says that each tool field is
//! fixed in the tool's object space and moves rigidly with it, Zheng Ch. 11.2).
//!
//! Pose at arc length `σ = L (t − t0)/T` (`S_k` the cumulative chord lengths, `L = S_{n−1}`,
//! `u = L/T`), in segment `k` with `λ = (σ − S_k)/ΔS_k`:
//!
//! * position `o(σ)`: the cubic Hermite through `x_k, x_{k+1}` with end tangents `t_k ΔS_k`,
//!   `t_{k+1} ΔS_k` (C¹ across samples; a straight spine gives exactly `x_k + λ(x_{k+1} − x_k)`),
//!   velocity `ȯ = (u/ΔS_k) do/dλ`;
//! * frame `Q(σ) = F_k Exp(λ Θ_k)`, `Θ_k = Log(F_kᵀ F_{k+1})` (body axis-angle; the
//!   double-reflection transfer is one rotation), so `Q(S_{k+1}) = F_{k+1}` and the world
//!   angular velocity is the constant `ω = u F_k Θ_k / ΔS_k` on the segment (`Exp(λΘ)Θ = Θ`).
//!
//! The field at time `t` is the sum of frozen-parameter divergence-free fields at the pose:
//!
//! * the tool's translation with velocity `ȯ`: the curl tool of [`super::fields::Translation`]
//!   (`push`: a solid sphere pushing the material, normal velocity `ȯ·n` on its surface) or
//!   von Funck's region translation [`super::cross::Sphere`] (`carry`: rigid `v = ȯ` inside the
//!   sphere, so a point inside follows `o(t)`);
//! * optionally the rotation matching the frame's turning, [`super::fields::Rotation`] with
//!   pivot and centre at `o` and `Ω = ω` (together with the translation the tool's full rigid
//!   normal velocity `(ȯ + ω × Y)·n`; zero normal part for a sphere);
//! * optionally a twist about the moving tangent `Q e_z` or a bend about the moving reference
//!   vector `Q e_x` ([`super::fields::Swirl`], ball support of radius `radius + reach`).
//!
//! Each part is divergence-free for frozen parameters, so the sum is divergence-free at every
//! `t`. Outside `[t0, t0 + T]` the tool rests and the field is zero. `Θ_k` is constant per
//! segment, so `ω` and `d²o/dt²` jump at the sample times `t0 + T S_k/L`: RK4 keeps its 4th
//! order only when steps end there (`spinal.advect` splits the integration at those times).

use glam::{DMat3, DVec3};

use super::cross::Sphere;
use super::fields::{Rotation, Swirl, SwirlKind, Translation};
use super::{Tool, falloff, finite, positive, reach_or};
use crate::error::{InputError, Result};
use crate::math::cubic::Hermite;
use crate::math::rotation::{is_rotation, quat_from_mat3, rodrigues};
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

/// The name of the call in out-of-memory errors.
const CALL: &str = "along_path";

/// One spine sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Position of the spine sample (world units).
    pub x: DVec3,
    pub frame: DMat3,
    /// Cumulative chord length.
    pub s: f64,
}

/// A tool moving along a spine (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PathTool {
    pub samples: Vec<Sample>,
    /// Per segment: body axis-angle `Θ_k` and `F_k Θ_k / ΔS_k` (world ω per unit speed).
    theta: Vec<DVec3>,
    omega: Vec<DVec3>,
    /// The times at which the tool passes the samples ([`PathTool::breakpoints`]).
    times: Vec<f64>,
    pub params: PathToolParams,
}

/// The parameters of a [`PathTool`] besides its spine samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathToolParams {
    /// Start time of the motion.
    pub t0: f64,
    /// Duration `T` of the motion (> 0).
    pub duration: f64,
    /// Tool radius.
    pub radius: f64,
    /// Reach of the field beyond the tool.
    pub reach: f64,
    /// Power of the curl tool's blend.
    pub power: u8,
    /// von Funck region translation instead of the pushing curl tool.
    pub carry: bool,
    pub linear: bool,
    /// Add the rotation matching the frame's turning.
    pub rotate: bool,
    /// Twist rate about the moving tangent (0: none).
    pub twist: f64,
    /// Bend rate about the moving reference vector (0: none).
    pub bend: f64,
}

/// The pose at time `t`: position, velocity, world angular velocity, frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Position (world units).
    pub o: DVec3,
    /// Velocity (world units per unit time).
    pub v: DVec3,
    pub omega: DVec3,
    pub frame: DMat3,
}

impl PathTool {
    /// Build from samples (positions and orthonormal right-handed frames, strictly increasing
    /// arc length `s`, at least 2) and the parameters. The per-segment buffers are allocated
    /// fallibly (the out-of-memory error names `along_path`).
    ///
    /// Polls `cancel` every [`cancel::BLOCK`] samples and fails with [`InputError::stopped`] once
    /// it says stop.
    pub fn new(
        samples: Vec<Sample>,
        params: PathToolParams,
        cancel: Cancel<'_>,
    ) -> Result<PathTool> {
        let poll = |i: usize| match i % cancel::BLOCK == 0 && cancel() {
            true => Err(InputError::stopped()),
            false => Ok(()),
        };
        let duration = params.duration;
        let bad = |m: String| InputError::new("field", m);
        if samples.len() < 2 {
            return Err(bad("a path needs at least 2 samples".into()));
        }
        if !(duration > 0.0 && duration.is_finite()) {
            return Err(bad(format!(
                "path duration must be positive, got {duration}"
            )));
        }
        for (i, p) in samples.iter().enumerate() {
            poll(i)?;
            if !is_rotation(&p.frame) {
                return Err(bad(format!("path frame {i} is not a rotation matrix")));
            }
        }
        let mut theta = alloc::with_capacity(CALL, samples.len() - 1)?;
        let mut omega = alloc::with_capacity(CALL, samples.len() - 1)?;
        for (k, w) in samples.windows(2).enumerate() {
            poll(k)?;
            let ds = w[1].s - w[0].s;
            if !(ds > 0.0) {
                return Err(bad(format!(
                    "path arc length must increase strictly (segment {k})"
                )));
            }
            let rel = quat_from_mat3(&(w[0].frame.transpose() * w[1].frame));
            let rel = if rel.w < 0.0 { -rel } else { rel };
            let (axis, angle) = rel.to_axis_angle();
            let th = if angle.is_finite() && angle != 0.0 {
                axis * angle
            } else {
                DVec3::ZERO
            };
            theta.push(th);
            omega.push(w[0].frame * th / ds);
        }
        let (s0, l) = (samples[0].s, samples[samples.len() - 1].s - samples[0].s);
        let times = alloc::collect(
            CALL,
            samples
                .iter()
                .map(|p| params.t0 + params.duration * (p.s - s0) / l),
        )?;
        Ok(PathTool {
            samples,
            theta,
            omega,
            times,
            params,
        })
    }

    /// The position's Hermite data on the segment from `a` to `b` (end tangents `t ΔS`).
    #[inline]
    fn segment(a: &Sample, b: &Sample) -> Hermite {
        let ds = b.s - a.s;
        Hermite::new(a.x, b.x, a.frame.z_axis * ds, b.frame.z_axis * ds)
    }

    /// Total arc length.
    pub fn length(&self) -> f64 {
        self.samples[self.samples.len() - 1].s - self.samples[0].s
    }

    /// The pose at time `t` (`None` while the tool rests, outside `[t0, t0 + T]`).
    pub fn pose(&self, t: f64) -> Option<Pose> {
        self.pose_in(t, t)
    }

    /// The pose at time `t` of an integration step whose interior contains `tm`: `tm` decides
    /// whether the tool moves and on which spine segment, so that the stages of a step that
    /// ends at a sample time (or at `t0`, `t0 + T`) all see the same smooth piece (the pose
    /// polynomials are evaluated at `t`, slightly outside the segment if `t` is its end).
    pub fn pose_in(&self, t: f64, tm: f64) -> Option<Pose> {
        let taum = (tm - self.params.t0) / self.params.duration;
        if !(0.0..=1.0).contains(&taum) {
            return None;
        }
        let s0 = self.samples[0].s;
        let l = self.length();
        let sigma = s0 + (t - self.params.t0) / self.params.duration * l;
        let sigma_m = s0 + taum * l;
        let u = l / self.params.duration;
        let n = self.samples.len();
        let k = self
            .samples
            .partition_point(|p| p.s <= sigma_m)
            .saturating_sub(1)
            .min(n - 2);
        let (a, b) = (&self.samples[k], &self.samples[k + 1]);
        let ds = b.s - a.s;
        let lam = (sigma - a.s) / ds;
        let curve = Self::segment(a, b);
        let (o, dodl) = (curve.value(lam), curve.slope(lam));
        let th = self.theta[k];
        let ang = th.length();
        let frame = if ang > 0.0 {
            let ax = th / ang;
            let e = |v: DVec3| a.frame * rodrigues(v, ax, lam * ang);
            DMat3::from_cols(e(DVec3::X), e(DVec3::Y), e(DVec3::Z))
        } else {
            a.frame
        };
        Some(Pose {
            o,
            v: dodl * (u / ds),
            omega: self.omega[k] * u,
            frame,
        })
    }

    /// The velocity at `x`, time `t`, within a step containing `tm` (see [`Self::pose_in`]).
    #[inline]
    pub fn eval(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        match self.pose_in(t, tm) {
            Some(p) => self.eval_at(x, &p),
            None => DVec3::ZERO,
        }
    }

    /// The velocity at `x` for the tool at pose `p` (the pose is shared by all points at one
    /// time, so batches compute it once).
    #[inline]
    pub fn eval_at(&self, x: DVec3, p: &Pose) -> DVec3 {
        let outer = self.params.radius + self.params.reach;
        if (x - p.o).length_squared() >= outer * outer {
            return DVec3::ZERO;
        }
        let mut v = if self.params.carry {
            Sphere {
                center: p.o,
                velocity: p.v,
                radius: self.params.radius,
                reach: self.params.reach,
                linear: self.params.linear,
                moving: false,
            }
            .eval(x, 0.0)
        } else {
            Translation {
                center: p.o,
                velocity: p.v,
                radius: self.params.radius,
                reach: self.params.reach,
                power: self.params.power,
                moving: false,
            }
            .eval(x, 0.0)
        };
        if self.params.rotate {
            v += Rotation {
                center: p.o,
                pivot: p.o,
                omega: p.omega,
                radius: self.params.radius,
                reach: self.params.reach,
                power: self.params.power,
            }
            .eval(x, 0.0);
        }
        if self.params.twist != 0.0 {
            v += self.swirl(p, SwirlKind::Twist).eval(x);
        }
        if self.params.bend != 0.0 {
            v += self.swirl(p, SwirlKind::Bend).eval(x);
        }
        v
    }

    fn swirl(&self, p: &Pose, kind: SwirlKind) -> Swirl {
        let (axis, rate) = match kind {
            SwirlKind::Twist => (p.frame.z_axis, self.params.twist),
            SwirlKind::Bend => (p.frame.x_axis, self.params.bend),
        };
        Swirl {
            pivot: p.o,
            axis,
            rate,
            reach: self.params.radius + self.params.reach,
            kind,
            curl_form: false,
        }
    }

    /// A bound of `|v|`: the parts' bounds at the largest tool speed and turning rate
    /// (sampled at 17 points per segment, ×1.05), polling `cancel` every [`cancel::BLOCK`]
    /// segments (`None` once it says stop).
    pub fn max_speed(&self, cancel: Cancel<'_>) -> Option<f64> {
        let u = self.length() / self.params.duration;
        let mut vmax: f64 = 0.0;
        for (k, w) in self.samples.windows(2).enumerate() {
            if k % cancel::BLOCK == 0 && cancel() {
                return None;
            }
            let ds = w[1].s - w[0].s;
            let curve = Self::segment(&w[0], &w[1]);
            for i in 0..=16 {
                let d = curve.slope(i as f64 / 16.0);
                vmax = vmax.max(d.length() / ds);
            }
        }
        let vel = DVec3::X * (u * vmax * 1.05);
        let mut m = if self.params.carry {
            Sphere {
                center: DVec3::ZERO,
                velocity: vel,
                radius: self.params.radius,
                reach: self.params.reach,
                linear: self.params.linear,
                moving: false,
            }
            .max_speed()
        } else {
            Translation {
                center: DVec3::ZERO,
                velocity: vel,
                radius: self.params.radius,
                reach: self.params.reach,
                power: self.params.power,
                moving: false,
            }
            .max_speed()
        };
        if self.params.rotate {
            let w = self.omega.iter().map(|w| w.length()).fold(0.0, f64::max) * u;
            m += Rotation {
                center: DVec3::ZERO,
                pivot: DVec3::ZERO,
                omega: DVec3::X * w,
                radius: self.params.radius,
                reach: self.params.reach,
                power: self.params.power,
            }
            .max_speed();
        }
        let pose = Pose {
            o: DVec3::ZERO,
            v: DVec3::ZERO,
            omega: DVec3::ZERO,
            frame: DMat3::IDENTITY,
        };
        if self.params.twist != 0.0 {
            m += self.swirl(&pose, SwirlKind::Twist).max_speed();
        }
        if self.params.bend != 0.0 {
            m += self.swirl(&pose, SwirlKind::Bend).max_speed();
        }
        Some(m)
    }

    /// Times at which the tool passes a spine sample (its start and end included).
    pub fn breakpoints(&self) -> &[f64] {
        &self.times
    }
}

/// What a path tool does besides translating (`kind` of `spinal.fields.along_path`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathKind {
    /// Only the translation along the spine.
    Translate,
    /// Also turn the material with the frames.
    Rotate,
    /// Also twist about the moving tangent.
    Twist,
    /// Also bend about the moving reference vector.
    Bend,
}

/// The arguments of `spinal.fields.along_path`, as the user gives them.
#[derive(Debug, Clone, Copy)]
pub struct PathArgs<'a> {
    /// Spine samples `(n, 3)`.
    pub points: &'a [DVec3],
    /// Rotation-minimising frames at the samples, columns `(r, s, t)`.
    pub frames: &'a [DMat3],
    /// Tool radius ρ.
    pub radius: f64,
    /// Time to travel the whole spine.
    pub duration: f64,
    /// What the tool does besides translating.
    pub kind: PathKind,
    /// von Funck's region translation ("carry") instead of the curl tool ("push").
    pub carry: bool,
    /// Twist or bend rate for `kind` twist or bend.
    pub rate: f64,
    /// Start time.
    pub t0: f64,
    /// Reach beyond the tool (default `radius`).
    pub reach: Option<f64>,
    /// Falloff power of the curl parts.
    pub power: i64,
    /// Linear region function for `carry`.
    pub linear: bool,
}

impl PathTool {
    /// The tool of `spinal.fields.along_path`, validated (errors name its arguments): at least
    /// 2 finite samples with no repeated consecutive point, one rotation per sample.
    ///
    /// Polls `cancel` between and inside its passes over the samples and fails with
    /// [`InputError::stopped`] once it says stop.
    pub fn from_args(a: PathArgs<'_>, cancel: Cancel<'_>) -> Result<PathTool> {
        let poll = |i: usize| match i % cancel::BLOCK == 0 && cancel() {
            true => Err(InputError::stopped()),
            false => Ok(()),
        };
        let x = a.points;
        if x.len() < 2 {
            return Err(InputError::new(
                "points",
                format!("need at least 2 samples, got {}", x.len()),
            ));
        }
        if let Some(i) = x.iter().position(|p| !p.is_finite()) {
            return Err(InputError::new(
                "points",
                format!("row {i} is not finite (NaN or inf)"),
            ));
        }
        if a.frames.len() != x.len() {
            return Err(InputError::new(
                "frames",
                format!(
                    "expected shape ({}, 3, 3), got {} frames",
                    x.len(),
                    a.frames.len()
                ),
            ));
        }
        poll(0)?;
        if let Some(i) = a.frames.iter().position(|f| !is_rotation(f)) {
            return Err(InputError::new(
                "frames",
                format!("frame {i} is not a rotation matrix"),
            ));
        }
        let mut s = 0.0;
        let mut samples = alloc::with_capacity(CALL, x.len())?;
        for (i, (p, f)) in x.iter().zip(a.frames).enumerate() {
            poll(i)?;
            if i > 0 {
                let chord = p.distance(x[i - 1]);
                if !(chord > 0.0) {
                    return Err(InputError::new(
                        "points",
                        format!("consecutive samples {} and {i} coincide", i - 1),
                    ));
                }
                s += chord;
            }
            samples.push(Sample {
                x: *p,
                frame: *f,
                s,
            });
        }
        let radius = positive("radius", a.radius)?;
        let params = PathToolParams {
            t0: finite("t0", a.t0)?,
            duration: positive("duration", a.duration)?,
            radius,
            reach: reach_or(a.reach, radius)?,
            power: falloff(a.power)?,
            carry: a.carry,
            linear: a.linear,
            rotate: a.kind == PathKind::Rotate,
            twist: if a.kind == PathKind::Twist {
                finite("rate", a.rate)?
            } else {
                0.0
            },
            bend: if a.kind == PathKind::Bend {
                finite("rate", a.rate)?
            } else {
                0.0
            },
        };
        let tool = PathTool::new(samples, params, cancel)?;
        let speed = tool.max_speed(cancel).ok_or_else(InputError::stopped)?;
        if !speed.is_finite() {
            return Err(InputError::new(
                "duration",
                format!("is too small: the tool's speed bound is {speed}"),
            ));
        }
        Ok(tool)
    }
}

impl Tool for PathTool {
    #[inline]
    fn velocity(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        self.eval(x, t, tm)
    }
    fn max_speed(&self) -> f64 {
        // never stopped (a stopped bound would be no bound)
        PathTool::max_speed(self, &cancel::never).unwrap_or(f64::INFINITY)
    }
    fn length_scale(&self) -> f64 {
        self.params.reach
    }
    fn breakpoints(&self) -> &[f64] {
        PathTool::breakpoints(self)
    }
    /// The centre stays within `1.5 ΔS_k` of the samples of its segment (a Hermite segment
    /// with tangents of length `ΔS_k` leaves the chord's end by at most `(1 + 8/27) ΔS_k`),
    /// and the field within `radius + reach` of the centre.
    fn support_radius(&self, about: DVec3) -> Option<f64> {
        let near = self
            .samples
            .iter()
            .map(|p| (p.x - about).length())
            .fold(0.0, f64::max);
        let ds = self
            .samples
            .windows(2)
            .map(|w| w[1].s - w[0].s)
            .fold(0.0, f64::max);
        Some(near + 1.5 * ds + self.params.radius + self.params.reach)
    }
    /// The pose once per batch, then the frozen-pose field at every point.
    #[inline]
    fn add_lanes(&self, p: &[DVec3], t: f64, tm: f64, out: &mut [DVec3]) {
        if let Some(pose) = self.pose_in(t, tm) {
            for (o, x) in out.iter_mut().zip(p) {
                *o += self.eval_at(*x, &pose);
            }
        }
    }
    #[inline]
    fn rk4_lanes(&self, x: &mut [DVec3], t0: f64, h: f64, steps: std::ops::Range<usize>) {
        super::advect::rk4_by_batches(self, x, t0, h, steps);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_interpolates_samples_and_frames() {
        // quarter circle of radius 1 in the xy-plane, frames (r = normal, s = z, t = tangent)
        let n = 9;
        let samples: Vec<Sample> = (0..n)
            .map(|i| {
                let a = std::f64::consts::FRAC_PI_2 * i as f64 / (n - 1) as f64;
                let x = DVec3::new(a.cos(), a.sin(), 0.0);
                let t = DVec3::new(-a.sin(), a.cos(), 0.0);
                let r = -x;
                Sample {
                    x,
                    frame: DMat3::from_cols(r, t.cross(r), t),
                    s: 2.0 * (std::f64::consts::FRAC_PI_4 / (n - 1) as f64).sin() * i as f64,
                }
            })
            .collect();
        let params = PathToolParams {
            t0: 0.5,
            duration: 2.0,
            radius: 0.1,
            reach: 0.1,
            power: 2,
            carry: false,
            linear: false,
            rotate: true,
            twist: 0.0,
            bend: 0.0,
        };
        let tool = PathTool::new(samples.clone(), params, &cancel::never).unwrap();
        for (i, s) in samples.iter().enumerate() {
            let t = 0.5 + 2.0 * s.s / tool.length();
            let p = tool.pose(t).unwrap();
            assert!((p.o - s.x).length() < 1e-14, "sample {i}");
            assert!((p.frame - s.frame).abs_diff_eq(DMat3::ZERO, 1e-12));
        }
        assert!(tool.pose(0.49).is_none() && tool.pose(2.51).is_none());
        // ω: about +z at speed u / radius (the chord/arc ratio aside)
        let p = tool.pose(1.0).unwrap();
        let u = tool.length() / 2.0;
        assert!(
            (p.omega - DVec3::Z * u * (std::f64::consts::FRAC_PI_2 / tool.length())).length()
                < 1e-12
        );
    }
}
