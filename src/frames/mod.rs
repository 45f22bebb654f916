//! Moving frames along sampled and analytic curves.
//!
//! A frame is `U = (r, s, t)`: `t` the unit tangent, `r` the reference vector (⟂ t) and
//! `s = t × r`, so the matrix with columns `(r, s, t)` is a rotation. Methods:
//!
//! | method | module | order | notes |
//! |---|---|---|---|
//! | double reflection | [`double_reflection`] | 4 | exact on lines, planes and spheres |
//! | rotation (Bloomenthal, discrete parallel transport) | [`rotation`] | 2 | |
//! | projection (Klok) | [`projection`] | 2 | depends on the initial vector |
//! | RK4 on the RMF ODE | [`rk4`] | 4 | analytic curves (needs x′, x″) |
//! | Frenet | [`frenet`] | exact where κ ≠ 0 | continuous fill at κ ≈ 0 |
//!
//! Boundary conditions (closed curves, a prescribed end vector) add a twist linear in arc
//! length ([`transport`]). [`steer`] turns the RMF about its tangents to meet constraints at
//! any rows ([`constraints`], twist by arc length or by curvature), to follow a guide
//! ([`guide`]) or to stay close to the previous time step ([`time`]). The driver [`compute_into`] validates the input, estimates the
//! tangents when they are not given ([`tangents`]), picks the initial vector and writes the
//! frames into a caller-provided buffer; [`compute_many`] maps it over a bundle of curves in
//! parallel.

pub mod constraints;
pub mod double_reflection;
pub mod frenet;
pub mod fused;
pub mod geometry;
pub mod guide;
pub mod lanes;
pub mod projection;
pub mod rk4;
pub mod rotation;
pub mod steer;
pub mod tangents;
pub mod time;
pub mod transport;
pub mod validate;

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::error::{InputError, Result};
use double_reflection::DoubleReflection;
use geometry::{any_perpendicular, rotate_about, scale_and_diagonal, signed_angle};
pub use tangents::TangentRule;
use transport::{Step, Twist, transport_into_cancellable};

/// Frame method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    DoubleReflection,
    Projection,
    Rotation,
    Frenet,
    Rk4,
}

/// A prescribed orientation: a reference vector (projected onto the normal plane) or a
/// whole frame (a rotation matrix with columns `r, s, t`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    Vector(DVec3),
    Frame(DMat3),
}

/// Exact derivatives of an analytic curve at `u_0, (u_0+u_1)/2, u_1, …, u_m` (2m + 1 rows).
#[derive(Debug, Clone, Copy)]
pub struct Analytic<'a> {
    /// Parameter values `u_0 < … < u_m` of the samples.
    pub u: &'a [f64],
    /// First derivative `x′(u)` at the samples and midpoints (2m + 1 rows).
    pub d1: &'a [DVec3],
    /// Second derivative `x″(u)` at the samples and midpoints (2m + 1 rows).
    pub d2: &'a [DVec3],
}

/// Everything one frame computation needs. Arrays have one row per input sample.
#[derive(Debug, Clone, Copy)]
pub struct Request<'a> {
    pub points: Option<&'a [DVec3]>,
    pub tangents: Option<&'a [DVec3]>,
    pub analytic: Option<Analytic<'a>>,
    pub closed: bool,
    pub method: Method,
    /// Tangents-only double reflection: chords from a quadrature of the tangents.
    pub tangent_chords: bool,
    pub tangent_rule: TangentRule,
    pub initial: Option<Orientation>,
    pub end: Option<Orientation>,
    pub turns: i64,
}

impl Default for Request<'_> {
    fn default() -> Self {
        Request {
            points: None,
            tangents: None,
            analytic: None,
            closed: false,
            method: Method::DoubleReflection,
            tangent_chords: false,
            tangent_rule: TangentRule::FivePointBounded,
            initial: None,
            end: None,
            turns: 0,
        }
    }
}

/// Bytes a row that a frames call may hold at once besides its output (9 × 8 = 72 bytes a
/// row): the per-row working vectors of this module and of [`steer`], [`guide`],
/// [`constraints`], [`frenet`] and [`time`] are allocated infallibly within this bound, which
/// the bindings check is free before the call (`ensure_memory` of
/// `72 + WORKING_BYTES_PER_ROW` bytes a row, output included).
///
/// Measured: the peak resident memory of the compiled call alone, output included (VmHWM
/// reset through `/proc/self/clear_refs` just before it, less the resident set then), per
/// row, for 4·10⁶ and 10⁷ rows (`benchmarks/memory_frames.py`): an open curve 72 (the fused
/// scan keeps nothing per row; bundles too), a closed curve or given tangents 104, Frenet
/// 168–172 (address space 160–173), an analytic curve 112 (RK4 152–160), frames in time 104
/// (Frenet 157–167), `quaternion_frames` 136; steered: `previous` 136, constraints 144, the
/// minimum-angular-speed rule 152, a guide 192 (closed 208–216, analytic 200), a guide with
/// constraints on a closed curve 224, the most. `72 + 216 = 288` bytes a row is 29 % over it.
pub const WORKING_BYTES_PER_ROW: usize = 216;

/// Curvature below this (times the curve's bounding-box diagonal) counts as straight.
pub const STRAIGHT_TOL: f64 = 1e-9;
/// Largest accepted angle between a prescribed frame's third column and the tangent.
pub const FRAME_TANGENT_TOL: f64 = 1e-3;

pub(crate) fn resolve(o: &Orientation, t: DVec3, row: usize, arg: &'static str) -> Result<DVec3> {
    match *o {
        Orientation::Vector(v) => {
            if !v.is_finite() {
                return Err(InputError::new(arg, "contains a non-finite value"));
            }
            // a unit vector first, so that huge or tiny vectors neither overflow nor vanish
            let v = crate::math::scale::normalize(v).unwrap_or(DVec3::ZERO);
            let p = v - v.dot(t) * t;
            let l = p.length();
            if l == 0.0 || l <= 1e-8 {
                return Err(InputError::new(
                    arg,
                    format!(
                        "the vector is zero or parallel to the tangent at row {row}; it \
                         must have a component in the normal plane"
                    ),
                ));
            }
            Ok(p / l)
        }
        Orientation::Frame(m) => {
            if !m.is_finite() {
                return Err(InputError::new(arg, "contains a non-finite value"));
            }
            if !crate::math::rotation::is_rotation(&m) {
                return Err(InputError::new(
                    arg,
                    "is not a rotation matrix: its columns (r, s, t) must be orthonormal \
                     and right-handed (det = +1)",
                ));
            }
            let ang = m.z_axis.angle_between(t);
            if ang > FRAME_TANGENT_TOL {
                return Err(InputError::new(
                    arg,
                    format!(
                        "its third column (the frame's tangent) differs from the curve's \
                         tangent at row {row} by {ang:.3e} rad; pass a frame with t = \
                         tangent, or just a reference vector"
                    ),
                ));
            }
            resolve(&Orientation::Vector(m.x_axis), t, row, arg)
        }
    }
}

/// Where the principal normal comes from.
enum Curvature<'a> {
    /// Exact derivatives at the samples (every other row of the analytic arrays).
    Analytic(&'a [DVec3], &'a [DVec3], f64),
    /// The circle through neighbouring samples; (points, round-off level, bbox diagonal).
    Points(&'a [DVec3], f64, f64),
    /// Differences of consecutive unit tangents (tangents-only input).
    Tangents,
}

impl Curvature<'_> {
    /// Unit principal normal at sample `i`, or None where the curve is straight there
    /// (`κ·diag ≤ STRAIGHT_TOL`, or the curvature is below round-off).
    fn normal(&self, t: &[DVec3], i: usize, closed: bool) -> Option<DVec3> {
        let ti = t[i];
        match *self {
            Curvature::Analytic(d1, d2, diag) => {
                let (v, a) = (d1[2 * i], d2[2 * i]);
                let perp = a - a.dot(ti) * ti;
                let l = perp.length();
                let kappa = l / v.length_squared();
                (l > 64.0 * f64::EPSILON * a.length() && kappa * diag > STRAIGHT_TOL)
                    .then(|| perp / l)
            }
            Curvature::Points(x, noise, diag) => tangents::circle_normal(x, ti, i, closed, noise)
                .and_then(|(nrm, kappa)| (kappa * diag > STRAIGHT_TOL).then_some(nrm)),
            Curvature::Tangents => {
                let n = t.len();
                let (p, q) = if closed {
                    (t[(i + n - 1) % n], t[(i + 1) % n])
                } else {
                    (t[i.saturating_sub(1)], t[(i + 1).min(n - 1)])
                };
                let a = q - p;
                let perp = a - a.dot(ti) * ti;
                let l = perp.length();
                (l > 1e-10).then(|| perp / l)
            }
        }
    }
}

/// `tangents` must have one row per point.
fn rows_match(points: &[DVec3], tangents: &[DVec3]) -> Result<()> {
    if points.len() == tangents.len() {
        return Ok(());
    }
    Err(InputError::new(
        "tangents",
        format!(
            "shape ({}, 3) does not match points ({}, 3): one tangent per point",
            tangents.len(),
            points.len()
        ),
    ))
}

/// The checks of a bundle request (per-curve `initial`/`end` counts, points against tangents,
/// the offsets, the output size) and the output cut into one `9 × rows` slice per curve.
pub(crate) fn bundle_slices<'o>(
    template: &Request,
    offsets: &[usize],
    initial: &[Orientation],
    end: &[Orientation],
    out: &'o mut [f64],
) -> Result<Vec<&'o mut [f64]>> {
    let curves = offsets.len().saturating_sub(1);
    for (arg, v) in [("initial", initial.len()), ("end", end.len())] {
        if v > 1 && v != curves {
            return Err(InputError::new(
                arg,
                format!("expected one entry per curve ({curves}), got {v}"),
            ));
        }
    }
    let total = template
        .points
        .map(<[DVec3]>::len)
        .or(template.tangents.map(<[DVec3]>::len))
        .unwrap_or(0);
    if let (Some(p), Some(t)) = (template.points, template.tangents) {
        rows_match(p, t)?;
    }
    validate::offsets(offsets, total)?;
    if out.len() != 9 * total {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    let mut slices = Vec::with_capacity(curves);
    let mut rest = out;
    for w in offsets.windows(2) {
        let (head, tail) = rest.split_at_mut(9 * (w[1] - w[0]));
        slices.push(head);
        rest = tail;
    }
    Ok(slices)
}

/// Compute the frames of one curve into `out` (`9 × rows` values, row-major `(rows, 3, 3)`).
///
/// Returns the raw end angle of the boundary condition (the closing angle for a closed
/// curve, the angle from the transported frame to `end` otherwise; 0 without a condition),
/// before `2π·turns` is added.
///
/// A curve whose size is far from 1 is first divided by a power of two (exact; see
/// [`crate::math::scale`]), so the frames and the angle do not depend on its units.
pub fn compute_into(req: &Request, out: &mut [f64]) -> Result<f64> {
    compute_into_cancellable(req, out, &crate::cancel::never)
}

/// [`compute_into`] that polls `cancel` before every chunk of the fused scan and returns at
/// once (with `out` incomplete) when it says stop (see [`crate::cancel`]).
///
/// Memory: the per-row working vectors of this module (tangents, chords, segment lengths,
/// normals, ω) take less than [`WORKING_BYTES_PER_ROW`], which the binding's
/// `ensure_memory` probe checks before the call, so they are allocated infallibly; the
/// normalised copy of the input is allocated fallibly.
pub fn compute_into_cancellable(
    req: &Request,
    out: &mut [f64],
    cancel: crate::cancel::Cancel<'_>,
) -> Result<f64> {
    if req.turns != 0 && !req.closed && req.end.is_none() && req.method != Method::Frenet {
        return Err(InputError::new(
            "turns",
            "applies to a closed curve (closed=True) or with a prescribed end; an open curve \
             without end has no twist to add turns to",
        ));
    }
    let owned = normalised(req)?;
    let req = match &owned {
        Some(o) => &o.request(req),
        None => req,
    };
    if cancel() {
        return Ok(0.0);
    }
    match fused::try_open_points(req, out, cancel) {
        Some(angle) => Ok(angle),
        None if cancel() => Ok(0.0),
        None => compute_general_cancellable(req, out, cancel),
    }
}

/// The points (and exact derivatives) of a request divided by the curve's power-of-two
/// scale, or `None` when its size needs no normalisation.
struct Normalised {
    points: Vec<DVec3>,
    d1: Vec<DVec3>,
    d2: Vec<DVec3>,
}

fn normalised(req: &Request) -> Result<Option<Normalised>> {
    let Some(p) = req.points else {
        return Ok(None);
    };
    let (lo, hi) = geometry::bounds(p);
    let Some(k) = crate::math::scale::curve_exponent(lo, hi) else {
        return Ok(None);
    };
    let scaled = |v: &[DVec3]| crate::math::scale::try_scaled("frames", v, k);
    Ok(Some(Normalised {
        points: scaled(p)?,
        d1: req.analytic.map_or(Ok(Vec::new()), |a| scaled(a.d1))?,
        d2: req.analytic.map_or(Ok(Vec::new()), |a| scaled(a.d2))?,
    }))
}

impl Normalised {
    fn request<'a>(&'a self, req: &Request<'a>) -> Request<'a> {
        Request {
            points: Some(&self.points),
            analytic: req.analytic.map(|a| Analytic {
                u: a.u,
                d1: &self.d1,
                d2: &self.d2,
            }),
            ..*req
        }
    }
}

/// [`compute_into`] without the fused fast path: one pass per stage, and the only place
/// that reports input errors.
///
/// The stages, in the order their errors are reported: the shapes and values of the input
/// (`check_input`), the distinct samples of a closed curve (`distinct_samples`), the chord
/// lengths, the unit tangents (`unit_tangents`), the segments against the tangents
/// (`check_segments`); then the frames, Frenet (`frenet_frames`) or transported with the
/// boundary condition (`transport_frames`).
pub fn compute_general(req: &Request, out: &mut [f64]) -> Result<f64> {
    compute_general_cancellable(req, out, &crate::cancel::never)
}

/// [`compute_general`] that polls `cancel` between its stages and inside the long ones (the
/// tangent estimate, the search for a defined normal, the transport and the Frenet fill) and
/// returns at once (with `out` incomplete) when it says stop (see [`crate::cancel`]).
pub fn compute_general_cancellable(
    req: &Request,
    out: &mut [f64],
    cancel: crate::cancel::Cancel<'_>,
) -> Result<f64> {
    let rows = check_input(req, out)?;
    let n = distinct_samples(req, rows)?;
    let closed = req.closed;
    let x: &[DVec3] = req.points.map(|p| &p[..n]).unwrap_or(&[]);
    if cancel() {
        return Ok(0.0);
    }
    let chords = if x.is_empty() {
        Vec::new()
    } else {
        validate::chords_cancellable(x, closed, cancel)?
    };
    if cancel() {
        return Ok(0.0);
    }
    let t = unit_tangents(req, x, &chords, n, cancel)?;
    // a cancelled estimate is incomplete: nothing below may read it
    if cancel() {
        return Ok(0.0);
    }
    let dr = DoubleReflection {
        x,
        t: &t,
        closed,
        tangent_chords: req.tangent_chords,
    };
    check_segments(req, &dr)?;
    if cancel() {
        return Ok(0.0);
    }
    let seg = segment_lengths(req, x, n, chords);
    let curvature = curvature_source(req, x, n);
    if cancel() {
        return Ok(0.0);
    }
    if req.method == Method::Frenet {
        return frenet_frames(req, &dr, &seg, &curvature, out, cancel);
    }
    let ctx = Ctx {
        req,
        t: &t,
        seg: &seg,
        curvature: &curvature,
        closed,
    };
    transport_frames(&ctx, &dr, out, cancel)
}

/// The shapes and values of the input, and the options that fit together; returns the
/// number of rows.
fn check_input(req: &Request, out: &[f64]) -> Result<usize> {
    let rows = check_shapes(req, out)?;
    if let Some(a) = req.analytic {
        check_analytic(&a, rows)?;
    }
    check_options(req)?;
    Ok(rows)
}

/// Row counts of the sample arrays and the output buffer, and finite samples.
fn check_shapes(req: &Request, out: &[f64]) -> Result<usize> {
    let rows = match (req.points, req.tangents) {
        (Some(p), _) => p.len(),
        (None, Some(t)) => t.len(),
        (None, None) => return Err(InputError::new("points", "points or tangents are required")),
    };
    if let (Some(p), Some(t)) = (req.points, req.tangents) {
        rows_match(p, t)?;
    }
    if rows < 2 {
        return Err(InputError::new(
            if req.analytic.is_some() {
                "u"
            } else if req.points.is_some() {
                "points"
            } else {
                "tangents"
            },
            format!("need at least 2 samples, got {rows}"),
        ));
    }
    if out.len() != 9 * rows {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    if let Some(p) = req.points {
        validate::finite("points", p)?;
    }
    if let Some(t) = req.tangents {
        validate::finite("tangents", t)?;
    }
    Ok(rows)
}

/// The analytic samples: `rows` parameter values increasing strictly, `2·rows − 1` finite
/// derivatives of each order.
fn check_analytic(a: &Analytic, rows: usize) -> Result<()> {
    if a.u.len() != rows || a.d1.len() != 2 * rows - 1 || a.d2.len() != 2 * rows - 1 {
        return Err(InputError::new(
            "u",
            "analytic samples have inconsistent lengths",
        ));
    }
    validate::finite_scalars("u", a.u)?;
    validate::finite("points", a.d1)?;
    validate::finite("points", a.d2)?;
    if let Some(i) = a.u.windows(2).position(|w| !(w[1] > w[0])) {
        return Err(InputError::new(
            "u",
            format!(
                "parameter values must increase strictly (index {i} to {})",
                i + 1
            ),
        ));
    }
    Ok(())
}

/// The method, the tangents-only chords, the input they need and the end condition.
fn check_options(req: &Request) -> Result<()> {
    if req.method == Method::Rk4 && req.analytic.is_none() {
        return Err(InputError::new(
            "method",
            "'rk4' integrates the RMF ODE and needs an analytic curve (x′ and x″): pass a \
             spinal.curves object with u=..., e.g. frames(spinal.curves.Helix(), u=200, \
             method='rk4')",
        ));
    }
    if req.tangent_chords && req.method != Method::DoubleReflection && req.method != Method::Frenet
    {
        return Err(InputError::new(
            "reflection",
            "'tangents' (tangents-only chords) applies to method='double_reflection' only",
        ));
    }
    if req.points.is_none() && !req.tangent_chords {
        return Err(InputError::new(
            "points",
            "points are required for this method",
        ));
    }
    if req.closed && req.end.is_some() {
        return Err(InputError::new(
            "end",
            "cannot be combined with closed=True (a closed curve's end is its start)",
        ));
    }
    Ok(())
}

/// The number of distinct samples: a closed curve drops a repeated first sample at the end.
fn distinct_samples(req: &Request, rows: usize) -> Result<usize> {
    if !req.closed {
        return Ok(rows);
    }
    let repeat = match (req.points, req.tangents) {
        (Some(p), _) => validate::coincide(p[rows - 1], p[0]),
        (None, Some(t)) => validate::coincide(t[rows - 1], t[0]),
        _ => false,
    };
    let mut n = rows;
    if repeat {
        n = rows - 1;
    } else if req.analytic.is_some() {
        return Err(InputError::new(
            "u",
            "closed=True on an analytic curve needs u to span whole periods \
             (x(u_last) = x(u_first))",
        ));
    }
    if n < 3 {
        return Err(InputError::new(
            "points",
            format!("a closed curve needs at least 3 distinct points, got {n}"),
        ));
    }
    Ok(n)
}

/// Unit tangents of the `n` distinct samples: the analytic derivative, the given tangents or
/// the estimate from the points `x` (with their `chords`).
fn unit_tangents(
    req: &Request,
    x: &[DVec3],
    chords: &[f64],
    n: usize,
    cancel: crate::cancel::Cancel<'_>,
) -> Result<Vec<DVec3>> {
    let t: Vec<DVec3> = if let Some(a) = req.analytic {
        if let Some(j) = a.d1.par_iter().position_first(|d| !(d.length() > 0.0)) {
            return Err(InputError::new(
                "points",
                format!(
                    "the curve's derivative vanishes at u = {} (a singular point); frames \
                     need a regular curve",
                    if j % 2 == 0 {
                        a.u[j / 2]
                    } else {
                        0.5 * (a.u[j / 2] + a.u[j / 2 + 1])
                    }
                ),
            ));
        }
        let mut t: Vec<DVec3> = (0..n).map(|i| a.d1[2 * i]).collect();
        tangents::normalize_all(&mut t).map_err(|i| {
            InputError::new("points", format!("cannot normalise the tangent at row {i}"))
        })?;
        t
    } else if let Some(tg) = req.tangents {
        let mut t = tg[..n].to_vec();
        tangents::normalize_all(&mut t).map_err(|i| {
            InputError::new(
                "tangents",
                format!("zero-length (or too small to normalise) tangent at row {i}"),
            )
        })?;
        t
    } else {
        tangents::estimate_cancellable(x, chords, req.closed, req.tangent_rule, cancel)?
    };
    if req.tangent_chords && n < 4 {
        return Err(InputError::new(
            "tangents",
            format!("tangents-only double reflection needs at least 4 samples, got {n}"),
        ));
    }
    Ok(t)
}

/// Every segment must run along its tangents; the projection method also needs each chord
/// to cross the next normal plane.
fn check_segments(req: &Request, dr: &DoubleReflection) -> Result<()> {
    let (t, closed) = (dr.t, dr.closed);
    let n = t.len();
    if req.method != Method::Rk4 {
        let what = if req.tangent_chords {
            "tangents"
        } else {
            "points"
        };
        validate::aligned(t, closed, |i| dr.chord(i), what)?;
    }
    if req.method == Method::Projection {
        let m = if closed { n } else { n - 1 };
        if let Some(i) = (0..m).into_par_iter().position_first(|i| {
            let d = dr.chord(i);
            !(d.dot(t[(i + 1) % n]) > 1e-9 * d.length())
        }) {
            return Err(InputError::new(
                "points",
                format!(
                    "the projection method needs each chord to cross the next normal plane; \
                     the segment from row {i} lies in it; sample more densely"
                ),
            ));
        }
    }
    Ok(())
}

/// Segment lengths for the twist distribution: Simpson's rule on the analytic speed, the
/// chords of the points, or 1 per segment for tangents alone.
fn segment_lengths(req: &Request, x: &[DVec3], n: usize, chords: Vec<f64>) -> Vec<f64> {
    let m = if req.closed { n } else { n - 1 };
    if let Some(a) = req.analytic {
        (0..m)
            .into_par_iter()
            .map(|i| {
                let h = a.u[i + 1] - a.u[i];
                h / 6.0
                    * (a.d1[2 * i].length()
                        + 4.0 * a.d1[2 * i + 1].length()
                        + a.d1[2 * i + 2].length())
            })
            .collect()
    } else if !x.is_empty() {
        chords
    } else {
        vec![1.0; m]
    }
}

/// Where the principal normal comes from (see [`Curvature`]).
fn curvature_source<'a>(req: &Request<'a>, x: &'a [DVec3], n: usize) -> Curvature<'a> {
    if let Some(a) = req.analytic {
        Curvature::Analytic(
            a.d1,
            a.d2,
            scale_and_diagonal(&req.points.unwrap_or(&[])[..n]).1,
        )
    } else if !x.is_empty() {
        let (scale, diag) = scale_and_diagonal(x);
        Curvature::Points(x, 64.0 * f64::EPSILON * scale, diag)
    } else {
        Curvature::Tangents
    }
}

/// The Frenet frames (no boundary condition applies); a curve straight everywhere gets the
/// transported frame instead.
fn frenet_frames(
    req: &Request,
    dr: &DoubleReflection,
    seg: &[f64],
    curvature: &Curvature,
    out: &mut [f64],
    cancel: crate::cancel::Cancel<'_>,
) -> Result<f64> {
    if req.initial.is_some() || req.end.is_some() || req.turns != 0 {
        return Err(InputError::new(
            if req.initial.is_some() {
                "initial"
            } else if req.end.is_some() {
                "end"
            } else {
                "turns"
            },
            "is not used by method='frenet': the Frenet frame is fixed by the curve",
        ));
    }
    let (t, closed) = (dr.t, dr.closed);
    // a cancelled pass leaves the remaining normals undefined (the caller discards them)
    let normals: Vec<Option<DVec3>> = (0..t.len())
        .into_par_iter()
        .map(|i| {
            if cancel() {
                return None;
            }
            curvature.normal(t, i, closed)
        })
        .collect();
    if cancel() {
        return Ok(0.0);
    }
    if normals.iter().any(Option::is_some) {
        frenet::frenet_into_cancellable(dr, &normals, seg, closed, out, cancel);
        return Ok(0.0);
    }
    transport_into_cancellable(
        dr,
        t,
        seg,
        closed,
        any_perpendicular(t[0]),
        Twist::None,
        out,
        cancel,
    );
    Ok(0.0)
}

/// The frames of a transport method, with the boundary condition of the request.
fn transport_frames(
    ctx: &Ctx,
    dr: &DoubleReflection,
    out: &mut [f64],
    cancel: crate::cancel::Cancel<'_>,
) -> Result<f64> {
    let (req, t) = (ctx.req, ctx.t);
    match req.method {
        Method::DoubleReflection => ctx.run(dr, out, cancel),
        Method::Rotation => ctx.run(&rotation::Rotation { t }, out, cancel),
        Method::Projection => ctx.run(&projection::Projection { x: dr.x, t }, out, cancel),
        Method::Rk4 => {
            let a = req
                .analytic
                .ok_or_else(|| InputError::new("method", "rk4"))?;
            let omega: Vec<DVec3> =
                a.d1.par_iter()
                    .zip(a.d2.par_iter())
                    .map(|(d1, d2)| rk4::omega(*d1, *d2))
                    .collect();
            ctx.run(
                &rk4::Rk4 {
                    u: a.u,
                    omega: &omega,
                    t,
                },
                out,
                cancel,
            )
        }
        Method::Frenet => unreachable!("frenet_frames handles it"),
    }
}

/// What the transport of one curve needs besides the step (static dispatch on the step type
/// keeps the per-sample loop inlined).
struct Ctx<'a> {
    req: &'a Request<'a>,
    t: &'a [DVec3],
    seg: &'a [f64],
    curvature: &'a Curvature<'a>,
    closed: bool,
}

impl Ctx<'_> {
    fn run<S: Step>(
        &self,
        step: &S,
        out: &mut [f64],
        cancel: crate::cancel::Cancel<'_>,
    ) -> Result<f64> {
        let (req, t, closed) = (self.req, self.t, self.closed);
        let n = t.len();
        let curvature = self.curvature;
        let r0 = match &req.initial {
            Some(o) => resolve(o, t[0], 0, "initial")?,
            None => {
                // a cancelled search stops at once and finds the first row (discarded)
                let found = (0..n).into_par_iter().find_map_first(|i| {
                    if cancel() {
                        return Some((0, t[0]));
                    }
                    curvature.normal(t, i, closed).map(|v| (i, v))
                });
                if cancel() {
                    return Ok(0.0);
                }
                let p = any_perpendicular(t[0]);
                match found {
                    None => p,
                    Some((k, nk)) => {
                        let mut r = p;
                        for i in 0..k {
                            r = step.step(i, r);
                        }
                        rotate_about(p, t[0], signed_angle(r, nk, t[k]))
                    }
                }
            }
        };
        let twist = if closed {
            Twist::Closed { turns: req.turns }
        } else if let Some(o) = &req.end {
            Twist::End {
                target: resolve(o, t[n - 1], n - 1, "end")?,
                turns: req.turns,
            }
        } else {
            Twist::None
        };
        Ok(transport_into_cancellable(
            step, t, self.seg, closed, r0, twist, out, cancel,
        ))
    }
}

/// What the steering modules ([`steer`]) need besides the frames: the number of distinct
/// samples, the segment lengths of the twist distribution and the RMF's closing angle.
pub(crate) struct RmfParts {
    pub n: usize,
    pub seg: Vec<f64>,
    pub closing: f64,
}

/// The plain rotation-minimising frames of `req` (its `end` and `turns` ignored; a closed
/// curve's frames are transported once round without the closing twist, so frame `n − 1`
/// carried across the closing segment differs from frame 0 by the closing angle), written
/// into `out`, with the [`RmfParts`].
pub(crate) fn rmf_parts(
    req: &Request,
    out: &mut [f64],
    cancel: crate::cancel::Cancel<'_>,
) -> Result<RmfParts> {
    let base = Request {
        end: None,
        turns: 0,
        ..*req
    };
    let closing = compute_into_cancellable(&base, out, cancel)?;
    if cancel() {
        // the caller polls `cancel` too and discards everything
        return Ok(RmfParts {
            n: 0,
            seg: Vec::new(),
            closing,
        });
    }
    let rows = out.len() / 9;
    let n = distinct_samples(req, rows)?;
    let x: &[DVec3] = req.points.map(|p| &p[..n]).unwrap_or(&[]);
    let chords = if x.is_empty() {
        Vec::new()
    } else {
        validate::chords(x, req.closed)?
    };
    let seg = segment_lengths(req, x, n, chords);
    if req.closed && closing != 0.0 {
        // undo the closing twist `closing · s / L` that compute_into spread along the loop
        let length: f64 = seg.iter().sum();
        let mut arc = 0.0;
        for (i, f) in out.chunks_exact_mut(9).take(n).enumerate() {
            let (sin, cos) = (-closing * arc / length).sin_cos();
            for row in 0..3 {
                let (r, s) = (f[3 * row], f[3 * row + 1]);
                f[3 * row] = cos * r + sin * s;
                f[3 * row + 1] = cos * s - sin * r;
            }
            arc += seg[i];
        }
    }
    Ok(RmfParts { n, seg, closing })
}

/// Per-curve orientations of a bundle: none, one shared by all curves, or one per curve.
pub fn pick<T: Copy>(v: &[T], c: usize) -> Option<T> {
    match v.len() {
        0 => None,
        1 => Some(v[0]),
        _ => v.get(c).copied(),
    }
}

/// Frames of many curves stored back to back (`offsets[c]..offsets[c+1]` are the rows of
/// curve `c`), computed in parallel. `initial`/`end` hold 0, 1 or one entry per curve.
/// Returns the raw end angle of every curve.
pub fn compute_many(
    template: &Request,
    offsets: &[usize],
    initial: &[Orientation],
    end: &[Orientation],
    out: &mut [f64],
) -> Result<Vec<f64>> {
    compute_many_cancellable(template, offsets, initial, end, out, &crate::cancel::never)
}

/// [`compute_many`] that polls `cancel` before each curve (see [`crate::cancel`]).
pub fn compute_many_cancellable(
    template: &Request,
    offsets: &[usize],
    initial: &[Orientation],
    end: &[Orientation],
    out: &mut [f64],
    cancel: crate::cancel::Cancel<'_>,
) -> Result<Vec<f64>> {
    let curves = offsets.len().saturating_sub(1);
    let slices = bundle_slices(template, offsets, initial, end, out)?;
    let results: Vec<Result<f64>> = slices
        .into_par_iter()
        .enumerate()
        .map(|(c, buf)| {
            if cancel() {
                return Ok(0.0);
            }
            let (a, b) = (offsets[c], offsets[c + 1]);
            let req = Request {
                points: template.points.map(|p| &p[a..b]),
                tangents: template.tangents.map(|t| &t[a..b]),
                analytic: None,
                initial: pick(initial, c),
                end: pick(end, c),
                ..*template
            };
            compute_into_cancellable(&req, buf, cancel).map_err(|e| {
                if curves > 1 {
                    e.context(&format!("curve {c} (rows {a} to {})", b.max(1) - 1))
                } else {
                    e
                }
            })
        })
        .collect();
    results.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    /// Column `k` (0: r, 1: s, 2: t) of frame `i` of a row-major frames buffer.
    fn col(out: &[f64], i: usize, k: usize) -> DVec3 {
        DVec3::new(out[9 * i + k], out[9 * i + 3 + k], out[9 * i + 6 + k])
    }

    /// An angle brought into `[−π, π)`.
    fn wrap(a: f64) -> f64 {
        (a + PI).rem_euclid(TAU) - PI
    }

    fn frames(req: &Request) -> Result<(Vec<f64>, f64)> {
        let rows = req.points.or(req.tangents).map_or(0, <[DVec3]>::len);
        let mut out = vec![0.0; 9 * rows];
        let angle = compute_into(req, &mut out)?;
        Ok((out, angle))
    }

    /// Every frame orthonormal and right-handed (`s = t × r`) to `tol`.
    fn assert_rotations(out: &[f64], tol: f64) {
        for i in 0..out.len() / 9 {
            let (r, s, t) = (col(out, i, 0), col(out, i, 1), col(out, i, 2));
            let worst = [
                r.length() - 1.0,
                s.length() - 1.0,
                t.length() - 1.0,
                r.dot(s),
                r.dot(t),
                s.dot(t),
                r.cross(s).dot(t) - 1.0,
                (t.cross(r) - s).length(),
            ]
            .iter()
            .fold(0.0_f64, |a, v| a.max(v.abs()));
            assert!(worst < tol, "frame {i} is off a rotation by {worst:e}");
        }
    }

    /// The helix `x(u) = (a cos u, a sin u, b u)`: speed `c = √(a² + b²)`, torsion `b/c²`,
    /// principal normal `N = (−cos u, −sin u, 0)`.
    struct Helix {
        a: f64,
        b: f64,
    }

    impl Helix {
        fn x(&self, u: f64) -> DVec3 {
            DVec3::new(self.a * u.cos(), self.a * u.sin(), self.b * u)
        }
        fn d1(&self, u: f64) -> DVec3 {
            DVec3::new(-self.a * u.sin(), self.a * u.cos(), self.b)
        }
        fn d2(&self, u: f64) -> DVec3 {
            DVec3::new(-self.a * u.cos(), -self.a * u.sin(), 0.0)
        }
        fn normal(&self, u: f64) -> DVec3 {
            DVec3::new(-u.cos(), -u.sin(), 0.0)
        }
        /// Rate `dθ/du` of the RMF against the Frenet frame. With `r = cos θ N + sin θ B`
        /// and the Frenet–Serret formulas, `r′ = −sin θ (θ′ + τ) N + cos θ (θ′ + τ) B − κ cos θ T`
        /// (per arc length), which is along `T` (rotation minimising) iff `θ′ = −τ`; per unit
        /// of `u` that is `−τ c = −b/c`.
        fn rate(&self) -> f64 {
            -self.b / self.a.hypot(self.b)
        }
    }

    /// The largest error of the frames of `n` helix samples over two turns: of the angle
    /// between `r` and the principal normal against the closed form, and of `t` against the
    /// unit tangent. `given`: exact tangents are passed; `analytic`: exact derivatives.
    fn helix_errors(method: Method, given: bool, analytic: bool, n: usize) -> (f64, f64) {
        let h = Helix { a: 1.0, b: 0.5 };
        let span = 4.0 * PI;
        let u: Vec<f64> = (0..n).map(|i| span * i as f64 / (n - 1) as f64).collect();
        let half: Vec<f64> = (0..2 * n - 1)
            .map(|i| span * i as f64 / (2 * n - 2) as f64)
            .collect();
        let x: Vec<DVec3> = u.iter().map(|&u| h.x(u)).collect();
        let t: Vec<DVec3> = u.iter().map(|&u| h.d1(u)).collect();
        let d1: Vec<DVec3> = half.iter().map(|&u| h.d1(u)).collect();
        let d2: Vec<DVec3> = half.iter().map(|&u| h.d2(u)).collect();
        let req = Request {
            points: Some(&x),
            tangents: given.then_some(&t[..]),
            analytic: analytic.then_some(Analytic {
                u: &u,
                d1: &d1,
                d2: &d2,
            }),
            method,
            ..Default::default()
        };
        let (out, _) = frames(&req).expect("a regular helix");
        assert_rotations(&out, 1e-12);
        let theta = |i: usize| signed_angle(h.normal(u[i]), col(&out, i, 0), col(&out, i, 2));
        let theta0 = theta(0);
        let (mut angle, mut tangent) = (0.0_f64, 0.0_f64);
        for i in 0..n {
            let want = theta0 + h.rate() * u[i];
            angle = angle.max(wrap(theta(i) - want).abs());
            tangent = tangent.max((col(&out, i, 2) - t[i].normalize()).length());
        }
        (angle, tangent)
    }

    /// The RMF of a helix turns against its Frenet frame at the constant rate `−b/c` per
    /// unit of `u`; every method approaches it at its order (the error falls by about `2^p`
    /// when the spacing halves).
    #[test]
    fn helix_rmf_matches_the_closed_form_at_the_method_order() {
        for (method, given, analytic, order, n) in [
            (Method::DoubleReflection, true, false, 4, 40),
            (Method::DoubleReflection, false, false, 4, 40),
            (Method::Rotation, true, false, 2, 40),
            (Method::Rotation, false, false, 2, 40),
            (Method::Projection, true, false, 2, 40),
            (Method::Rk4, false, true, 4, 40),
        ] {
            let (e1, t1) = helix_errors(method, given, analytic, n);
            let (e2, t2) = helix_errors(method, given, analytic, 2 * n - 1);
            let (e3, _) = helix_errors(method, given, analytic, 4 * n - 3);
            let what = format!("{method:?}, given {given}: errors {e1:e} {e2:e} {e3:e}");
            // halving the spacing divides the error by 2^p (a margin of half an order)
            let least = 2f64.powf(order as f64 - 0.5);
            assert!(e1 < 0.1 && e1 / e2 > least && e2 / e3 > least, "{what}");
            if given || analytic {
                assert!(t1 < 1e-15 && t2 < 1e-15, "{what}: t is the unit tangent");
            } else {
                // five-point tangents: 4th order
                assert!(
                    t1 / t2 > 2f64.powf(3.5),
                    "{what}: tangent errors {t1:e} {t2:e}"
                );
            }
        }
    }

    /// The Frenet method's `r` is the principal normal, to the order of the circle through
    /// three samples it is estimated from: 2 for the centred circle inside, 1 at the ends.
    #[test]
    fn frenet_frame_follows_the_principal_normal() {
        let h = Helix { a: 1.0, b: 0.5 };
        let err = |n: usize| {
            let u: Vec<f64> = (0..n)
                .map(|i| 4.0 * PI * i as f64 / (n - 1) as f64)
                .collect();
            let x: Vec<DVec3> = u.iter().map(|&u| h.x(u)).collect();
            let (out, _) = frames(&Request {
                points: Some(&x),
                method: Method::Frenet,
                ..Default::default()
            })
            .expect("a regular helix");
            assert_rotations(&out, 1e-12);
            let at = |i: usize| (col(&out, i, 0) - h.normal(u[i])).length();
            let inside = (1..n - 1).map(at).fold(0.0, f64::max);
            (inside, at(0).max(at(n - 1)))
        };
        let ((e1, f1), (e2, f2)) = (err(100), err(199));
        assert!(
            e1 < 0.01 && e1 / e2 > 2f64.powf(1.5),
            "inside: {e1:e} {e2:e}"
        );
        assert!(f1 < 0.1 && f1 / f2 > 2f64.powf(0.5), "ends: {f1:e} {f2:e}");
    }

    /// An uneven, non-planar open curve.
    fn wiggle(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let u = 0.05 * (i as f64 + 0.3 * (1.7 * i as f64).sin());
                DVec3::new(
                    3.0 * u.cos(),
                    2.0 * u.sin(),
                    0.4 * u + 0.2 * (3.0 * u).sin(),
                )
            })
            .collect()
    }

    /// A trefoil knot sampled unevenly (no repeated end point).
    fn trefoil(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let u = TAU * (i as f64 + 0.2 * (3.0 * TAU * i as f64 / n as f64).sin()) / n as f64;
                let r = 2.0 + (3.0 * u).cos();
                DVec3::new(r * (2.0 * u).cos(), r * (2.0 * u).sin(), (3.0 * u).sin())
            })
            .collect()
    }

    /// All methods, with and without given tangents: rotations whose `t` is the unit tangent.
    #[test]
    fn frames_are_rotations_with_t_the_unit_tangent() {
        let x = wiggle(300);
        let t: Vec<DVec3> = (0..x.len())
            .map(|i| {
                let u = 0.05 * (i as f64 + 0.3 * (1.7 * i as f64).sin());
                DVec3::new(-3.0 * u.sin(), 2.0 * u.cos(), 0.4 + 0.6 * (3.0 * u).cos()) * 7.0
            })
            .collect();
        for method in [
            Method::DoubleReflection,
            Method::Rotation,
            Method::Projection,
            Method::Frenet,
        ] {
            for (closed, x) in [(false, x.clone()), (true, trefoil(257))] {
                let (out, _) = frames(&Request {
                    points: Some(&x),
                    method,
                    closed,
                    ..Default::default()
                })
                .expect("valid curve");
                assert_rotations(&out, 1e-12);
                let est = tangents::estimate_rows(&x, closed, TangentRule::FivePointBounded)
                    .expect("regular curve");
                for (i, e) in est.iter().enumerate() {
                    assert!(
                        (col(&out, i, 2) - *e).length() < 1e-15,
                        "{method:?} row {i}"
                    );
                }
            }
            let (out, _) = frames(&Request {
                points: Some(&x),
                tangents: Some(&t),
                method,
                ..Default::default()
            })
            .expect("valid curve");
            assert_rotations(&out, 1e-12);
            for (i, ti) in t.iter().enumerate() {
                assert!((col(&out, i, 2) - ti.normalize()).length() < 1e-15);
            }
        }
    }

    /// Carry frame `i`'s `r` one step and measure the angle to frame `i + 1`'s (mod n).
    fn step_angles<S: Step>(step: &S, out: &[f64], n: usize, closed: bool) -> Vec<f64> {
        let m = if closed { n } else { n - 1 };
        (0..m)
            .map(|i| {
                let j = (i + 1) % n;
                let carried = step.step(i, col(out, i, 0));
                signed_angle(carried, col(out, j, 0), col(out, j, 2))
            })
            .collect()
    }

    /// A closed curve's frames meet at the seam: the frames turn away from the transported
    /// ones by the closing twist spread linearly in arc length, and after the closing
    /// segment they are back at frame 0; a repeated end point gets frame 0's copy.
    #[test]
    fn closed_curve_frames_meet_at_the_seam() {
        let n = 400;
        let x = trefoil(n);
        let h: Vec<f64> = (0..n).map(|i| (x[(i + 1) % n] - x[i]).length()).collect();
        let length: f64 = h.iter().sum();
        for method in [Method::DoubleReflection, Method::Rotation] {
            for turns in [0, 1, -2] {
                let (out, raw) = frames(&Request {
                    points: Some(&x),
                    closed: true,
                    method,
                    turns,
                    ..Default::default()
                })
                .expect("a closed curve");
                assert!(raw.abs() <= PI && raw.abs() > 1e-3, "{raw}");
                let t: Vec<DVec3> = (0..n).map(|i| col(&out, i, 2)).collect();
                let angles = if method == Method::Rotation {
                    step_angles(&rotation::Rotation { t: &t }, &out, n, true)
                } else {
                    let dr = DoubleReflection {
                        x: &x,
                        t: &t,
                        closed: true,
                        tangent_chords: false,
                    };
                    step_angles(&dr, &out, n, true)
                };
                let total = raw + TAU * turns as f64;
                for (i, a) in angles.iter().enumerate() {
                    let want = wrap(total * h[i] / length);
                    assert!(
                        (a - want).abs() < 1e-10,
                        "{method:?} step {i}: {a} vs {want}"
                    );
                }
                // with the repeated end point: the same frames and a copy of frame 0
                let mut y = x.clone();
                y.push(x[0]);
                let (again, raw2) = frames(&Request {
                    points: Some(&y),
                    closed: true,
                    method,
                    turns,
                    ..Default::default()
                })
                .expect("a closed curve");
                assert_eq!(raw.to_bits(), raw2.to_bits());
                assert_eq!(&again[..9 * n], &out[..]);
                assert_eq!(&again[9 * n..], &out[..9]);
            }
        }
        // a plane curve closes without a twist (double reflection is exact on planes)
        let circle: Vec<DVec3> = (0..50)
            .map(|i| {
                let u = TAU * (i as f64 + 0.3 * (i as f64).sin()) / 50.0;
                DVec3::new(u.cos(), u.sin(), 0.0)
            })
            .collect();
        let (_, raw) = frames(&Request {
            points: Some(&circle),
            closed: true,
            ..Default::default()
        })
        .expect("a circle");
        assert!(raw.abs() < 1e-12, "closing angle of a circle: {raw}");
    }

    /// With `initial` and `end` the first and last `r` are the given vectors projected onto
    /// the normal planes, and the twist in between is linear in arc length.
    #[test]
    fn open_curve_meets_initial_and_end() {
        let x = wiggle(200);
        let n = x.len();
        let h: Vec<f64> = (0..n - 1).map(|i| (x[i + 1] - x[i]).length()).collect();
        let length: f64 = h.iter().sum();
        let (v0, v1) = (DVec3::new(0.3, -1.0, 2.0), DVec3::new(1.0, 0.5, -0.2));
        for turns in [0, 3] {
            let (out, raw) = frames(&Request {
                points: Some(&x),
                initial: Some(Orientation::Vector(v0)),
                end: Some(Orientation::Vector(v1)),
                turns,
                ..Default::default()
            })
            .expect("valid curve");
            let proj = |v: DVec3, t: DVec3| (v - v.dot(t) * t).normalize();
            assert!((col(&out, 0, 0) - proj(v0, col(&out, 0, 2))).length() < 1e-15);
            assert!((col(&out, n - 1, 0) - proj(v1, col(&out, n - 1, 2))).length() < 1e-12);
            let t: Vec<DVec3> = (0..n).map(|i| col(&out, i, 2)).collect();
            let dr = DoubleReflection {
                x: &x,
                t: &t,
                closed: false,
                tangent_chords: false,
            };
            let total = raw + TAU * turns as f64;
            for (i, a) in step_angles(&dr, &out, n, false).iter().enumerate() {
                assert!((a - wrap(total * h[i] / length)).abs() < 1e-10, "step {i}");
            }
        }
    }

    /// A bundle gives, bit for bit, the frames and angles of its curves computed one by one
    /// (also a curve long enough for the chunked scan, on two threads).
    #[test]
    fn compute_many_equals_each_curve_alone() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool");
        pool.install(|| {
            let lengths = [5, 2, 300, 2 * transport::PAR_CHUNK + 11, 7];
            let mut offsets = vec![0];
            for l in lengths {
                offsets.push(offsets[offsets.len() - 1] + l);
            }
            let x = wiggle(offsets[lengths.len()]);
            let initial: Vec<Orientation> = (0..lengths.len())
                .map(|c| Orientation::Vector(DVec3::new(1.0, c as f64, 0.5)))
                .collect();
            let end = [Orientation::Vector(DVec3::new(0.2, 0.1, 1.0))];
            for method in [Method::DoubleReflection, Method::Rotation] {
                let template = Request {
                    points: Some(&x),
                    method,
                    turns: 1,
                    ..Default::default()
                };
                let mut all = vec![0.0; 9 * x.len()];
                let angles = compute_many(&template, &offsets, &initial, &end, &mut all)
                    .expect("valid bundle");
                for (c, w) in offsets.windows(2).enumerate() {
                    let one = Request {
                        points: Some(&x[w[0]..w[1]]),
                        initial: Some(initial[c]),
                        end: Some(end[0]),
                        ..template
                    };
                    let (out, angle) = frames(&one).expect("valid curve");
                    assert_eq!(angle.to_bits(), angles[c].to_bits(), "curve {c}");
                    assert!(
                        out.iter()
                            .zip(&all[9 * w[0]..9 * w[1]])
                            .all(|(p, q)| p.to_bits() == q.to_bits()),
                        "{method:?}, curve {c}"
                    );
                }
            }
            // an error names the argument and the curve
            let mut y = x.clone();
            y[offsets[2] + 17].y = f64::NAN;
            let template = Request {
                points: Some(&y),
                ..Default::default()
            };
            let mut all = vec![0.0; 9 * y.len()];
            let err = compute_many(&template, &offsets, &[], &[], &mut all).unwrap_err();
            assert_eq!(err.arg, "points");
            let rows = format!("curve 2 (rows {} to {})", offsets[2], offsets[3] - 1);
            assert!(err.msg.starts_with(&rows), "{err}");
            assert!(err.msg.contains("row 17"), "{err}");
        });
    }

    /// Every refusal names the argument at fault.
    #[test]
    fn errors_name_the_argument() {
        let x = wiggle(30);
        let t: Vec<DVec3> = (0..30)
            .map(|i| x[(i + 1).min(29)] - x[i.saturating_sub(1)])
            .collect();
        let (u, d): (Vec<f64>, Vec<DVec3>) = ((0..30).map(f64::from).collect(), vec![DVec3::X; 59]);
        let analytic = Analytic {
            u: &u,
            d1: &d,
            d2: &d,
        };
        let mut nan = x.clone();
        nan[4].z = f64::NAN;
        let mut tnan = t.clone();
        tnan[3].x = f64::INFINITY;
        let mut zero_t = t.clone();
        zero_t[5] = DVec3::ZERO;
        let mut repeated = x.clone();
        repeated[7] = repeated[6];
        let mut reversed = x.clone();
        reversed.swap(10, 11);
        let mut u_back = u.clone();
        u_back[3] = 1.0;
        let mut d_zero = d.clone();
        d_zero[6] = DVec3::ZERO;
        let line: Vec<DVec3> = (0..30).map(|i| DVec3::X * f64::from(i)).collect();
        let two_distinct = [x[0], x[1], x[0]];
        let skew = DMat3::from_cols(DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::Z);
        let base = Request {
            points: Some(&x),
            ..Default::default()
        };
        let cases: Vec<(&str, Request, usize)> = vec![
            (
                "points",
                Request {
                    points: None,
                    ..base
                },
                30,
            ),
            (
                "tangents",
                Request {
                    tangents: Some(&t[..20]),
                    ..base
                },
                30,
            ),
            (
                "points",
                Request {
                    points: Some(&x[..1]),
                    ..base
                },
                1,
            ),
            (
                "tangents",
                Request {
                    points: None,
                    tangents: Some(&t[..1]),
                    tangent_chords: true,
                    ..base
                },
                1,
            ),
            ("out", base, 29),
            (
                "points",
                Request {
                    points: Some(&nan),
                    ..base
                },
                30,
            ),
            (
                "tangents",
                Request {
                    tangents: Some(&tnan),
                    ..base
                },
                30,
            ),
            (
                "tangents",
                Request {
                    tangents: Some(&zero_t),
                    ..base
                },
                30,
            ),
            (
                "points",
                Request {
                    points: Some(&repeated),
                    ..base
                },
                30,
            ),
            (
                "points",
                Request {
                    points: Some(&reversed),
                    ..base
                },
                30,
            ),
            (
                "method",
                Request {
                    method: Method::Rk4,
                    ..base
                },
                30,
            ),
            (
                "reflection",
                Request {
                    tangent_chords: true,
                    method: Method::Rotation,
                    ..base
                },
                30,
            ),
            (
                "points",
                Request {
                    points: None,
                    tangents: Some(&t),
                    ..base
                },
                30,
            ),
            (
                "end",
                Request {
                    closed: true,
                    end: Some(Orientation::Vector(DVec3::Z)),
                    ..base
                },
                30,
            ),
            (
                "points",
                Request {
                    points: Some(&two_distinct),
                    closed: true,
                    ..base
                },
                3,
            ),
            (
                "initial",
                Request {
                    initial: Some(Orientation::Vector(DVec3::ZERO)),
                    ..base
                },
                30,
            ),
            (
                "initial",
                Request {
                    initial: Some(Orientation::Frame(skew)),
                    ..base
                },
                30,
            ),
            (
                "initial",
                Request {
                    initial: Some(Orientation::Frame(DMat3::IDENTITY)),
                    points: Some(&line),
                    ..base
                },
                30,
            ),
            (
                "end",
                Request {
                    end: Some(Orientation::Vector(DVec3::new(f64::NAN, 0.0, 0.0))),
                    ..base
                },
                30,
            ),
            (
                "end",
                Request {
                    points: Some(&line),
                    end: Some(Orientation::Vector(DVec3::X)),
                    ..base
                },
                30,
            ),
            (
                "initial",
                Request {
                    method: Method::Frenet,
                    initial: Some(Orientation::Vector(DVec3::Z)),
                    ..base
                },
                30,
            ),
            (
                "turns",
                Request {
                    method: Method::Frenet,
                    turns: 1,
                    ..base
                },
                30,
            ),
            (
                "u",
                Request {
                    analytic: Some(Analytic {
                        u: &u[..29],
                        ..analytic
                    }),
                    ..base
                },
                30,
            ),
            (
                "u",
                Request {
                    analytic: Some(Analytic {
                        u: &u_back,
                        ..analytic
                    }),
                    ..base
                },
                30,
            ),
            (
                "u",
                Request {
                    points: Some(&line),
                    analytic: Some(analytic),
                    closed: true,
                    ..base
                },
                30,
            ),
            (
                "points",
                Request {
                    points: Some(&line),
                    analytic: Some(Analytic {
                        d1: &d_zero,
                        ..analytic
                    }),
                    ..base
                },
                30,
            ),
            (
                "tangents",
                Request {
                    points: None,
                    tangents: Some(&t[..3]),
                    tangent_chords: true,
                    ..base
                },
                3,
            ),
        ];
        for (k, (arg, req, rows)) in cases.iter().enumerate() {
            let mut out = vec![0.0; 9 * rows];
            match compute_into(req, &mut out) {
                Err(e) => assert_eq!(&e.arg, arg, "case {k}: {e}"),
                Ok(_) => panic!("case {k} ({arg}) was accepted"),
            }
        }
        let mut out = vec![0.0; 9 * 30];
        let two = [Orientation::Vector(DVec3::Z); 2];
        let err = compute_many(&base, &[0, 10, 20, 30], &two, &[], &mut out).unwrap_err();
        assert_eq!(err.arg, "initial");
        let err = compute_many(&base, &[0, 10, 20, 30], &[], &two, &mut out).unwrap_err();
        assert_eq!(err.arg, "end");
        let err = compute_many(&base, &[0, 20, 10, 30], &[], &[], &mut out).unwrap_err();
        assert_eq!(err.arg, "lengths");
        let err = compute_many(&base, &[0, 10, 29], &[], &[], &mut out).unwrap_err();
        assert_eq!(err.arg, "lengths");
    }
}
