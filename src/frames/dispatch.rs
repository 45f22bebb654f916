//! The driver: one curve ([`compute_into`], the fused fast path or the general stages), the
//! plain RMF parts the steering modules build on, and a bundle of curves ([`compute_many`]).

use crate::run::cancel;
use glam::DVec3;
use rayon::prelude::*;

use super::carry::turn_frame;
use super::check::{check_input, check_segments, distinct_samples, rows_match};
use super::double_reflection::DoubleReflection;
use super::geometry::{self, any_perpendicular, rotate_about, scale_and_diagonal, signed_angle};
use super::request::{Analytic, Method, Orientation, Request, STRAIGHT_TOL, pick, resolve};
use super::transport::{Step, Twist, transport_into};
use super::{frenet, fused, projection, rk4, rotation, tangents, torsion, validate};
use crate::error::{InputError, Result};

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
        rows_match(p, t, template.names.tangents)?;
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
///
/// Polls `cancel` before every chunk of the fused scan and returns at once (with `out`
/// incomplete) when it says stop (see [`crate::run::cancel`]).
///
/// Memory: the per-row working vectors of this module (tangents, chords, segment lengths,
/// normals, ω) take less than [`WORKING_BYTES_PER_ROW`], which the binding's
/// `ensure_memory` probe checks before the call, so they are allocated infallibly; the
/// normalised copy of the input is allocated fallibly.
///
/// [`WORKING_BYTES_PER_ROW`]: super::WORKING_BYTES_PER_ROW
pub fn compute_into(
    req: &Request,
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<f64> {
    super::check::turns(req)?;
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
        None => compute_general(req, out, cancel),
    }
}

/// The points (and exact derivatives) of a request divided by the curve's power-of-two
/// scale, or `None` when its size needs no normalisation.
struct Normalised {
    points: Vec<DVec3>,
    d1: Vec<DVec3>,
    d2: Vec<DVec3>,
    d3: Vec<DVec3>,
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
        d3: req.analytic.map_or(Ok(Vec::new()), |a| scaled(a.d3))?,
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
                d3: &self.d3,
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
///
/// Polls `cancel` between its stages and inside the long ones (the tangent estimate, the search for
/// a defined normal, the transport and the Frenet fill) and returns at once (with `out` incomplete)
/// when it says stop (see [`crate::run::cancel`]).
pub fn compute_general(
    req: &Request,
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
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
        validate::chords(x, closed, req.names.points, cancel)?
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

/// Unit tangents of the `n` distinct samples: the analytic derivative, the given tangents or
/// the estimate from the points `x` (with their `chords`).
fn unit_tangents(
    req: &Request,
    x: &[DVec3],
    chords: &[f64],
    n: usize,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<DVec3>> {
    let t: Vec<DVec3> = if let Some(a) = req.analytic {
        if let Some(j) = a.d1.par_iter().position_first(|d| !(d.length() > 0.0)) {
            return Err(InputError::new(
                req.points_arg(),
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
            InputError::new(
                req.points_arg(),
                format!("cannot normalise the tangent at row {i}"),
            )
        })?;
        t
    } else if req.method == Method::Bisector {
        projection::bisector_tangents(x, req.closed).map_err(|i| {
            InputError::new(
                req.points_arg(),
                format!(
                    "the polygon turns back on itself at row {i} (the segments there are \
                     opposite), so the bisector plane is undefined"
                ),
            )
        })?
    } else if let Some(tg) = req.tangents {
        let mut t = tg[..n].to_vec();
        tangents::normalize_all(&mut t).map_err(|i| {
            InputError::new(
                req.tangents_arg(),
                format!("zero-length (or too small to normalise) tangent at row {i}"),
            )
        })?;
        t
    } else {
        tangents::estimate(
            x,
            chords,
            req.closed,
            req.tangent_rule,
            req.names.points,
            cancel,
        )?
    };
    if req.tangent_chords && n < 4 {
        return Err(InputError::new(
            req.tangents_arg(),
            format!("tangents-only double reflection needs at least 4 samples, got {n}"),
        ));
    }
    Ok(t)
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
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<f64> {
    if req.initial.is_some() || req.end.is_some() || req.turns != 0.0 {
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
        frenet::frenet_into(dr, &normals, seg, closed, out, cancel);
        return Ok(0.0);
    }
    transport_into(
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
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<f64> {
    let (req, t) = (ctx.req, ctx.t);
    match req.method {
        Method::DoubleReflection => ctx.run(dr, out, cancel),
        Method::Rotation => ctx.run(&rotation::Rotation { t }, out, cancel),
        Method::Projection | Method::Bisector => {
            ctx.run(&projection::Projection { x: dr.x, t }, out, cancel)
        }
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
        Method::Rk4Phi => {
            let a = req
                .analytic
                .ok_or_else(|| InputError::new("method", "rk4_phi"))?;
            ctx.run(&rk4::Rk4Phi::new(a.u, a.d1, a.d2, t), out, cancel)
        }
        Method::Torsion => {
            let a = req
                .analytic
                .ok_or_else(|| InputError::new("method", "torsion"))?;
            ctx.run(
                &torsion::Torsion::new(a.u, a.d1, a.d2, a.d3, t),
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
        cancel: crate::run::cancel::Cancel<'_>,
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
        Ok(transport_into(
            step, t, self.seg, closed, r0, twist, out, cancel,
        ))
    }
}

/// What the steering modules ([`steer`]) need besides the frames: the number of distinct
/// samples, the segment lengths of the twist distribution and the RMF's closing angle.
///
/// [`steer`]: super::steer
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
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<RmfParts> {
    let base = Request {
        end: None,
        turns: 0.0,
        ..*req
    };
    let closing = compute_into(&base, out, cancel)?;
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
        validate::chords(x, req.closed, req.names.points, &cancel::never)?
    };
    let seg = segment_lengths(req, x, n, chords);
    if req.closed && closing != 0.0 {
        // undo the closing twist `closing · s / L` that compute_into spread along the loop
        let length: f64 = seg.iter().sum();
        let mut arc = 0.0;
        for (i, f) in out.chunks_exact_mut(9).take(n).enumerate() {
            let (sin, cos) = (-closing * arc / length).sin_cos();
            turn_frame(f, cos, sin);
            arc += seg[i];
        }
    }
    Ok(RmfParts { n, seg, closing })
}

/// Frames of many curves stored back to back (`offsets[c]..offsets[c+1]` are the rows of
/// curve `c`), computed in parallel. `initial`/`end` hold 0, 1 or one entry per curve.
/// Returns the raw end angle of every curve.
///
/// Polls `cancel` before each curve (see [`crate::run::cancel`]) and adds each curve's row count to
/// `done` once its frames are written (a progress count).
pub fn compute_many(
    template: &Request,
    offsets: &[usize],
    initial: &[Orientation],
    end: &[Orientation],
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
    done: Option<&std::sync::atomic::AtomicUsize>,
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
            let angle = compute_into(&req, buf, cancel).map_err(|e| {
                if curves > 1 {
                    e.context(&format!("curve {c} (rows {a} to {})", b.max(1) - 1))
                } else {
                    e
                }
            });
            if let Some(d) = done {
                d.fetch_add(b - a, std::sync::atomic::Ordering::Relaxed);
            }
            angle
        })
        .collect();
    results.into_iter().collect()
}
