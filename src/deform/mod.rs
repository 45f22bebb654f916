//! Volume-preserving deformation by divergence-free vector fields.
//!
//! A [`Field`] is a sum of tools, each a divergence-free velocity field `v(X, t)` behind the
//! [`Tool`] trait: the curl fields of Zheng's thesis Ch. 12 ([`fields`]: translation,
//! rotation, twist, bend), the cross-product fields `∇p × ∇q` of Ch. 11 / von Funck et al.
//! 2006 ([`cross`]: sphere, capsule, torus, strips), a strip along a curved axis ([`tube`]), a
//! free-form tool from a signed-distance grid ([`grid`]) and tools moving along a path
//! ([`path`]). Sums keep `div v = 0`. Every tool is validated and built once by its
//! constructor, whose errors name the Python argument. Vertices are carried along the flow
//! `dX/dt = v(X, t)` by [`advect`] (RK4, explicit Euler for comparison, a volume-exact
//! splitting), path lines in parallel; [`refine`] carries a closed mesh and refines it while it
//! integrates; [`stamp`] is the contact stamper.
//!
//! The tools share their vocabulary from [`shape`] (signed distances, the region function);
//! the shape a tool reports for keyframing is a [`Shape`] of this module, and the axis curve
//! of the strip along a curve and of the rod is [`axis`].

pub mod advect;
pub mod axis;
pub mod cross;
pub mod curl;
pub mod fields;
pub mod grid;
pub mod keyframe;
pub mod path;
pub mod refine;
pub mod rod;
pub mod shape;
pub mod slip;
pub mod stamp;
pub mod steps;
pub mod tube;

use std::ops::Range;
use std::sync::Arc;

use glam::{DMat3, DVec3};

use crate::error::{InputError, Result};
pub use cross::{Capsule, Sphere, StripAcross, Torus};
pub use fields::{Rotation, Swirl, SwirlKind, Translation};
use grid::GridTool;
use rod::Rod;
use shape::{Ball, Distance, Ring};

/// A tool's shape, for tools that can be posed by keys ([`keyframe`]).
#[derive(Debug, Clone)]
pub enum Shape {
    Ball(Ball),
    Rod(Arc<Rod>),
    Grid(Arc<GridTool>),
    Ring(Ring),
}

impl Shape {
    /// The shape's centre `C`.
    pub fn center(&self) -> DVec3 {
        match self {
            Shape::Ball(b) => b.center(),
            Shape::Rod(r) => r.center(),
            Shape::Grid(g) => Distance::center(&**g),
            Shape::Ring(r) => r.center(),
        }
    }
}

impl From<Ring> for Shape {
    fn from(r: Ring) -> Shape {
        Shape::Ring(r)
    }
}

impl From<Ball> for Shape {
    fn from(b: Ball) -> Shape {
        Shape::Ball(b)
    }
}

impl From<Arc<Rod>> for Shape {
    fn from(r: Arc<Rod>) -> Shape {
        Shape::Rod(r)
    }
}

impl From<Arc<GridTool>> for Shape {
    fn from(g: Arc<GridTool>) -> Shape {
        Shape::Grid(g)
    }
}

/// The shape of a built tool and its falloff power (`None` for tools that are not curl
/// fields: the keyframed tool then needs one).
#[derive(Debug, Clone)]
pub struct ToolShape {
    pub shape: Shape,
    pub power: Option<u8>,
}

/// A divergence-free velocity field of one tool.
///
/// The batch methods have default bodies that the compiler instantiates for every tool type,
/// so a field of one tool runs an RK4 loop with the tool's evaluation inlined (one virtual
/// call per batch of path lines, none per evaluation).
pub trait Tool: Send + Sync + std::fmt::Debug {
    /// `v(x, t)` within an integration step whose stages all share the midpoint time `tm`
    /// (only tools moving along a path use `tm`: it picks the smooth piece of their motion).
    fn velocity(&self, x: DVec3, t: f64, tm: f64) -> DVec3;

    /// An upper bound (or a sampled estimate with margin) of `|v|`, length/time.
    fn max_speed(&self) -> f64;

    /// The length over which the field changes: the reach (curl fields, swirls) or the width
    /// of the blend region (cross-product fields).
    fn length_scale(&self) -> f64;

    /// Times at which the velocity is only continuous in time (a path tool's samples).
    fn breakpoints(&self) -> &[f64] {
        &[]
    }

    /// Jacobian (columns `∂A/∂x_j`) of a curl potential `A` with `curl A = v`, for the
    /// splitting scheme; `None` for tools without one.
    fn potential_jacobian(&self, _x: DVec3, _t: f64) -> Option<DMat3> {
        None
    }

    /// A bound of the speed at which the region where the tool acts moves (its support
    /// swept by its motion): 0 for a tool at rest. The measured step rule
    /// ([`steps::measured_steps`]) takes at least `8 |T| w / ℓ` steps with this `w`, so no
    /// point can miss the tool between two samples of time. The default, [`Tool::max_speed`],
    /// keeps the a priori rule for tools that do not say.
    fn support_speed(&self) -> f64 {
        self.max_speed()
    }

    /// The velocity with which the whole tool translates (its field is steady in a frame
    /// moving with it); zero for tools at rest or with other motions.
    fn rigid_velocity(&self) -> DVec3 {
        DVec3::ZERO
    }

    /// For a tool whose tangential velocity jumps across a surface (the curl tools: across
    /// their own surface `d = 0`), the signed distance to that surface and its gradient at
    /// `x`, time `t`; `None` for tools whose velocity is continuous.
    fn slip_surface(&self, _x: DVec3, _t: f64) -> Option<(f64, DVec3)> {
        None
    }

    /// Whether an evaluation reads a large table at a place that depends on the point (a
    /// distance grid, a spline's segments), or branches on where the point lies (inside the
    /// tool, in the blend region, outside it): then path lines are integrated in a spatial
    /// order, so that neighbouring lanes share cache lines and take the same branches
    /// ([`advect::advect_ticked`]).
    fn wants_locality(&self) -> bool {
        false
    }

    /// The tool's shape (its signed distance, centre and reach) for tools that a
    /// [`keyframe::Keyframed`] tool can pose; `None` for the others.
    fn shape(&self) -> Option<ToolShape> {
        None
    }

    /// The point a keyframed carry of a shape-less tool takes to the key positions when the
    /// caller names none ([`keyframe::Carried`]): a swirl's centre; `None` for tools
    /// without a natural centre.
    fn natural_center(&self) -> Option<DVec3> {
        None
    }

    /// The radius of a ball about `about` outside which the velocity is zero at every time,
    /// where one is known (a swirl, a path tool); `None` otherwise (a moving tool's support
    /// travels without bound).
    fn support_radius(&self, _about: DVec3) -> Option<f64> {
        None
    }

    /// `out[j] += v(p[j], t)` for a batch of points.
    #[inline]
    fn add_lanes(&self, p: &[DVec3], t: f64, tm: f64, out: &mut [DVec3]) {
        for (o, x) in out.iter_mut().zip(p) {
            *o += self.velocity(*x, t, tm);
        }
    }

    /// RK4 on a batch of path lines in lock-step, steps `j ∈ steps` at `t0 + h·j`, for a
    /// field of this tool alone.
    #[inline]
    fn rk4_lanes(&self, x: &mut [DVec3], t0: f64, h: f64, steps: Range<usize>) {
        advect::rk4_batch(|p, t, tm| self.velocity(p, t, tm), x, t0, h, steps);
    }

    /// RK4 on the path lines of one task (any number; by batches of lock-step lanes),
    /// steps `j ∈ steps`, for a field of this tool alone: where a tool prepares per time
    /// (a pose), it can do so once for all the batches.
    #[inline]
    fn rk4_chunk(&self, x: &mut [DVec3], t0: f64, h: f64, steps: Range<usize>) {
        advect::rk4_chunk_by_batches(self, x, t0, h, steps);
    }
}

/// `x` if every component is finite.
pub(crate) fn finite3(arg: &'static str, x: DVec3) -> Result<DVec3> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(InputError::new(
            arg,
            format!("must be finite, got {:?}", x.to_array()),
        ))
    }
}

/// `x` if finite.
pub fn finite(arg: &'static str, x: f64) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(InputError::new(arg, format!("must be finite, got {x}")))
    }
}

/// Every point finite (the message names the first row that is not).
pub fn finite_rows(arg: &'static str, x: &[DVec3]) -> Result<()> {
    match x.iter().position(|p| !p.is_finite()) {
        Some(i) => Err(InputError::new(
            arg,
            format!("row {i} is not finite (NaN or inf)"),
        )),
        None => Ok(()),
    }
}

/// `x` if positive and finite.
pub(crate) fn positive(arg: &'static str, x: f64) -> Result<f64> {
    if x > 0.0 && x.is_finite() {
        Ok(x)
    } else {
        Err(InputError::new(
            arg,
            format!("must be positive and finite, got {x}"),
        ))
    }
}

/// `x` (positive) or, when not given, `default`.
pub(crate) fn reach_or(reach: Option<f64>, default: f64) -> Result<f64> {
    reach.map_or(Ok(default), |r| positive("reach", r))
}

/// The unit vector along `a`.
pub(crate) fn unit(arg: &'static str, a: DVec3) -> Result<DVec3> {
    let l = a.length();
    if l > 0.0 && l.is_finite() {
        Ok(a / l)
    } else {
        Err(InputError::new(arg, "must be a non-zero finite vector"))
    }
}

/// The falloff power `p ∈ {2, 3, 4}` of the curl tools.
pub(crate) fn falloff(p: i64) -> Result<u8> {
    match p {
        2..=4 => Ok(p as u8),
        _ => Err(InputError::new(
            "falloff_power",
            format!("must be 2, 3 or 4, got {p}"),
        )),
    }
}

/// `tool` if its speed bound is finite: a velocity so large that the bound overflows would
/// make every step rule meaningless.
pub(crate) fn bounded<T: Tool>(arg: &'static str, tool: T) -> Result<T> {
    let s = tool.max_speed();
    if s.is_finite() {
        Ok(tool)
    } else {
        Err(InputError::new(
            arg,
            format!("is too large: the field's speed bound is {s} (out of floating-point range)"),
        ))
    }
}

/// A sum of tools (an empty sum is the zero field). Cloning shares the tools.
#[derive(Debug, Clone, Default)]
pub struct Field {
    /// The tools whose velocities add up.
    pub tools: Vec<Arc<dyn Tool>>,
}

/// Steps for which the default step rule or an explicit count is refused.
pub const MAX_STEPS: usize = 100_000_000;

impl Field {
    /// The field of one tool.
    pub fn single(tool: impl Tool + 'static) -> Field {
        Field {
            tools: vec![Arc::new(tool)],
        }
    }

    /// The sum of two fields.
    pub fn plus(&self, other: &Field) -> Field {
        // one pointer per tool, each tool already built
        Field {
            tools: self.tools.iter().chain(&other.tools).cloned().collect(),
        }
    }

    #[inline]
    pub fn eval(&self, x: DVec3, t: f64) -> DVec3 {
        self.eval_in(x, t, t)
    }

    /// [`Self::eval`] for a stage of an integration step whose midpoint time is `tm`.
    #[inline]
    pub fn eval_in(&self, x: DVec3, t: f64, tm: f64) -> DVec3 {
        self.tools
            .iter()
            .fold(DVec3::ZERO, |s, e| s + e.velocity(x, t, tm))
    }

    /// The common velocity of the tools if they all move with the same one (a frame in which
    /// the field is steady), else zero.
    pub fn frame_velocity(&self) -> DVec3 {
        let mut w = None;
        for e in &self.tools {
            let u = e.rigid_velocity();
            match w {
                None => w = Some(u),
                Some(v) if v != u => return DVec3::ZERO,
                _ => {}
            }
        }
        w.unwrap_or(DVec3::ZERO)
    }

    /// Whether every tool has a curl potential for the splitting scheme.
    pub fn has_potential(&self) -> bool {
        self.tools
            .iter()
            .all(|e| e.potential_jacobian(DVec3::ZERO, 0.0).is_some())
    }

    /// Jacobian of the summed curl potentials (columns `∂A/∂x_j`); zero for tools without
    /// one (see [`Self::has_potential`]).
    #[inline]
    pub fn potential_jacobian(&self, x: DVec3, t: f64) -> DMat3 {
        self.tools.iter().fold(DMat3::ZERO, |s, e| {
            s + e.potential_jacobian(x, t).unwrap_or(DMat3::ZERO)
        })
    }

    /// The nearest slip surface of the tools at `x` ([`Tool::slip_surface`]): the signed
    /// distance and its gradient of the tool with the smallest `|d|`.
    pub fn slip_surface(&self, x: DVec3, t: f64) -> Option<(f64, DVec3)> {
        self.tools
            .iter()
            .filter_map(|e| e.slip_surface(x, t))
            .min_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
    }

    /// The largest [`Tool::support_radius`] of the tools about `about` (`None` if a tool
    /// has none; 0 for the zero field).
    pub fn support_radius(&self, about: DVec3) -> Option<f64> {
        self.tools
            .iter()
            .try_fold(0.0, |m: f64, e| e.support_radius(about).map(|r| m.max(r)))
    }

    /// Sum of the tools' [`Tool::support_speed`]s.
    pub fn support_speed(&self) -> f64 {
        self.tools.iter().map(|e| e.support_speed()).sum()
    }

    /// Sum of the tools' speed bounds.
    pub fn max_speed(&self) -> f64 {
        self.tools.iter().map(|e| e.max_speed()).sum()
    }

    /// Sorted times at which a tool's velocity is only continuous in time, allocated
    /// fallibly (the out-of-memory error names `what`, the calling function).
    pub fn breakpoints(&self, what: &'static str) -> Result<Vec<f64>> {
        let n = self.tools.iter().map(|e| e.breakpoints().len()).sum();
        let mut b = crate::run::alloc::with_capacity(what, n)?;
        for e in &self.tools {
            b.extend_from_slice(e.breakpoints());
        }
        b.sort_by(f64::total_cmp);
        b.dedup();
        Ok(b)
    }

    /// Smallest length scale of the tools (∞ for the zero field).
    pub fn length_scale(&self) -> f64 {
        self.tools
            .iter()
            .map(|e| e.length_scale())
            .fold(f64::INFINITY, f64::min)
    }

    /// `⌈8 |duration| max_speed / length_scale⌉` (NaN for the zero field over no time): the
    /// steps of [`Self::default_steps`] before its floor of 4 and its cap.
    pub fn step_bound(&self, duration: f64) -> f64 {
        (duration.abs() * 8.0 * self.max_speed() / self.length_scale()).ceil()
    }

    /// The a priori step rule (the default for `steps=None` without points, see
    /// [`steps::measured_steps`] for the rule measured on them): a step moves a point by at most 1/8 of the field's
    /// length scale, `h = ℓ / (8 v_max)`, and never fewer than 4 steps. More than
    /// [`MAX_STEPS`] is refused (the caller must then choose the steps).
    pub fn default_steps(&self, duration: f64) -> Result<usize> {
        let v = self.max_speed();
        let l = self.length_scale();
        let n = self.step_bound(duration);
        if !(n <= MAX_STEPS as f64) {
            return Err(InputError::new(
                "steps",
                format!(
                    "the default step rule needs {n:.3e} steps (|duration| {:e} · 8 · max_speed \
                     {v:e} / length_scale {l:e}), more than {MAX_STEPS}; pass steps= explicitly",
                    duration.abs()
                ),
            ));
        }
        Ok(if n > 4.0 { n as usize } else { 4 })
    }
}
