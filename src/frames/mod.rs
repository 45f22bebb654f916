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
//! length ([`transport`]). The driver [`compute_into`] validates the input, estimates the
//! tangents when they are not given ([`tangents`]), picks the initial vector and writes the
//! frames into a caller-provided buffer; [`compute_many`] maps it over a bundle of curves in
//! parallel.

pub mod double_reflection;
pub mod frenet;
pub mod fused;
pub mod geometry;
pub mod lanes;
pub mod projection;
pub mod rk4;
pub mod rotation;
pub mod tangents;
pub mod transport;
pub mod validate;

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::error::{InputError, Result};
use double_reflection::DoubleReflection;
use geometry::{any_perpendicular, rotate_about, scale_and_diagonal, signed_angle};
pub use tangents::TangentRule;
use transport::{Step, Twist, transport_into};

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
            tangent_rule: TangentRule::FivePoint,
            initial: None,
            end: None,
            turns: 0,
        }
    }
}

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
            let p = v - v.dot(t) * t;
            let l = p.length();
            if l == 0.0 || l <= 1e-8 * v.length() {
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

/// Compute the frames of one curve into `out` (`9 × rows` values, row-major `(rows, 3, 3)`).
///
/// Returns the raw end angle of the boundary condition (the closing angle for a closed
/// curve, the angle from the transported frame to `end` otherwise; 0 without a condition),
/// before `2π·turns` is added.
pub fn compute_into(req: &Request, out: &mut [f64]) -> Result<f64> {
    match fused::try_open_points(req, out) {
        Some(angle) => Ok(angle),
        None => compute_general(req, out),
    }
}

/// [`compute_into`] without the fused fast path: one pass per stage, and the only place
/// that reports input errors.
pub fn compute_general(req: &Request, out: &mut [f64]) -> Result<f64> {
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
    if let Some(a) = req.analytic {
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
    }
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

    // Closed curves: drop a repeated first sample at the end.
    let mut n = rows;
    if req.closed {
        let repeat = match (req.points, req.tangents) {
            (Some(p), _) => validate::coincide(p[rows - 1], p[0]),
            (None, Some(t)) => validate::coincide(t[rows - 1], t[0]),
            _ => false,
        };
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
    }
    let closed = req.closed;
    let x: &[DVec3] = req.points.map(|p| &p[..n]).unwrap_or(&[]);
    let chords = if x.is_empty() {
        Vec::new()
    } else {
        validate::chords(x, closed)?
    };

    // Unit tangents.
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
        tangents::estimate(x, &chords, closed, req.tangent_rule)?
    };
    if req.tangent_chords && n < 4 {
        return Err(InputError::new(
            "tangents",
            format!("tangents-only double reflection needs at least 4 samples, got {n}"),
        ));
    }

    let dr = DoubleReflection {
        x,
        t: &t,
        closed,
        tangent_chords: req.tangent_chords,
    };
    if req.method != Method::Rk4 {
        let what = if req.tangent_chords {
            "tangents"
        } else {
            "points"
        };
        validate::aligned(&t, closed, |i| dr.chord(i), what)?;
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

    // Segment lengths for the twist distribution.
    let m = if closed { n } else { n - 1 };
    let seg: Vec<f64> = if let Some(a) = req.analytic {
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
    };

    let curvature = if let Some(a) = req.analytic {
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
    };

    if req.method == Method::Frenet {
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
        let normals: Vec<Option<DVec3>> = (0..n)
            .into_par_iter()
            .map(|i| curvature.normal(&t, i, closed))
            .collect();
        if normals.iter().any(Option::is_some) {
            frenet::frenet_into(&dr, &normals, &seg, closed, out);
            return Ok(0.0);
        }
        transport_into(
            &dr,
            &t,
            &seg,
            closed,
            any_perpendicular(t[0]),
            Twist::None,
            out,
        );
        return Ok(0.0);
    }

    let ctx = Ctx {
        req,
        t: &t,
        seg: &seg,
        curvature: &curvature,
        closed,
    };
    match req.method {
        Method::DoubleReflection => ctx.run(&dr, out),
        Method::Rotation => ctx.run(&rotation::Rotation { t: &t }, out),
        Method::Projection => ctx.run(&projection::Projection { x, t: &t }, out),
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
                    t: &t,
                },
                out,
            )
        }
        Method::Frenet => unreachable!("handled above"),
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
    fn run<S: Step>(&self, step: &S, out: &mut [f64]) -> Result<f64> {
        let (req, t, closed) = (self.req, self.t, self.closed);
        let n = t.len();
        let curvature = self.curvature;
        let r0 = match &req.initial {
            Some(o) => resolve(o, t[0], 0, "initial")?,
            None => {
                let found = (0..n)
                    .into_par_iter()
                    .find_map_first(|i| curvature.normal(t, i, closed).map(|v| (i, v)));
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
        Ok(transport_into(step, t, self.seg, closed, r0, twist, out))
    }
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
    let results: Vec<Result<f64>> = slices
        .into_par_iter()
        .enumerate()
        .map(|(c, buf)| {
            let (a, b) = (offsets[c], offsets[c + 1]);
            let req = Request {
                points: template.points.map(|p| &p[a..b]),
                tangents: template.tangents.map(|t| &t[a..b]),
                analytic: None,
                initial: pick(initial, c),
                end: pick(end, c),
                ..*template
            };
            compute_into(&req, buf).map_err(|e| {
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
