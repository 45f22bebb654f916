//! The input checks of the driver: shapes, finite values, analytic samples, options that
//! fit together, the distinct samples of a closed curve and the segments against the tangents.

use crate::run::cancel;
use glam::DVec3;
use rayon::prelude::*;

use super::double_reflection::DoubleReflection;
use super::request::{Analytic, Method, Request, STRAIGHT_TOL};
use super::validate;
use crate::error::{InputError, Result};

/// `tangents` (passed as `name`) must have one row per point.
pub(super) fn rows_match(points: &[DVec3], tangents: &[DVec3], name: &str) -> Result<()> {
    if points.len() == tangents.len() {
        return Ok(());
    }
    Err(InputError::new(
        name.to_owned(),
        format!(
            "shape ({}, 3) does not match points ({}, 3): one tangent per point",
            tangents.len(),
            points.len()
        ),
    ))
}

/// The shapes and values of the input, and the options that fit together; returns the
/// number of rows.
pub(super) fn check_input(req: &Request, out: &[f64]) -> Result<usize> {
    let rows = check_shapes(req, out)?;
    if let Some(a) = req.analytic {
        check_analytic(&a, rows, req.names.points)?;
    }
    check_options(req)?;
    if req.method == Method::Torsion {
        check_torsion(req)?;
    }
    Ok(rows)
}

/// Is `turns` a whole number (within `f64`)?
pub fn whole(turns: f64) -> bool {
    turns == turns.round()
}

/// `turns` (see [`Request::turns`]) is finite and a whole or half number of turns; a half
/// number only on a closed curve without an `end`, where it is the closing twist
/// `α + 2π·turns` = `α + π·(2·turns)`: the frames then close up to a half turn about the
/// tangent (`r_n = −r_0`), which only a profile symmetric under that half turn absorbs
/// (`spinal.sweep(..., turns=0.5)`). Without a twist to add it to (an open curve without
/// `end`), turns must be 0; the Frenet frame takes none.
pub fn turns(req: &Request) -> Result<()> {
    let t = req.turns;
    if !t.is_finite() || !whole(2.0 * t) || t.abs() > 1e15 {
        return Err(InputError::new(
            "turns",
            format!("expected a whole or half number of turns (e.g. 1, 0.5, -1.5), got {t}"),
        ));
    }
    if t != 0.0 && !req.closed && req.end.is_none() && req.method != Method::Frenet {
        return Err(InputError::new(
            "turns",
            "applies to a closed curve (closed=True) or with a prescribed end; an open curve \
             without end has no twist to add turns to",
        ));
    }
    if !whole(t) && (!req.closed || req.end.is_some()) {
        return Err(InputError::new(
            "turns",
            format!(
                "a half number of turns ({t}) applies only to the closing twist of a closed \
                 curve: a prescribed end is met exactly, so its twist takes whole turns"
            ),
        ));
    }
    Ok(())
}

/// The torsion method needs `x‴` and a curvature that vanishes nowhere (at the samples and
/// midpoints its quadrature reads): there the Frenet frame and the torsion are undefined.
fn check_torsion(req: &Request) -> Result<()> {
    let Some(a) = req.analytic else {
        return Ok(());
    };
    if a.d3.len() != a.d1.len() {
        return Err(InputError::new(
            "method",
            "'torsion' needs the third derivative x‴ of an analytic curve (a spinal.curves \
             object with u=...)",
        ));
    }
    validate::finite(req.names.points, a.d3, &cancel::never)?;
    let diag = super::geometry::scale_and_diagonal(req.points.unwrap_or(&[])).1;
    let flat = |k: usize| {
        let (d1, d2) = (a.d1[k], a.d2[k]);
        let c = d1.cross(d2).length();
        !(c > 64.0 * f64::EPSILON * d1.length() * d2.length()
            && c / d1.length().powi(3) * diag > STRAIGHT_TOL)
    };
    if let Some(k) = (0..a.d1.len()).into_par_iter().position_first(flat) {
        let u = if k % 2 == 0 {
            a.u[k / 2]
        } else {
            0.5 * (a.u[k / 2] + a.u[k / 2 + 1])
        };
        return Err(InputError::new(
            "method",
            format!(
                "'torsion' turns the Frenet frame, which is undefined where the curvature \
                 vanishes (at u = {u}); use method='double_reflection'"
            ),
        ));
    }
    Ok(())
}

/// Row counts of the sample arrays and the output buffer, and finite samples.
fn check_shapes(req: &Request, out: &[f64]) -> Result<usize> {
    let rows = match (req.points, req.tangents) {
        (Some(p), _) => p.len(),
        (None, Some(t)) => t.len(),
        (None, None) => {
            return Err(InputError::new(
                req.points_arg(),
                "points or tangents are required",
            ));
        }
    };
    if let (Some(p), Some(t)) = (req.points, req.tangents) {
        rows_match(p, t, req.names.tangents)?;
    }
    if rows < 2 {
        return Err(InputError::new(
            if req.analytic.is_some() {
                "u"
            } else if req.points.is_some() {
                req.names.points
            } else {
                req.names.tangents
            }
            .to_owned(),
            format!("need at least 2 samples, got {rows}"),
        ));
    }
    if out.len() != 9 * rows {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    if let Some(p) = req.points {
        validate::finite(req.names.points, p, &cancel::never)?;
    }
    if let Some(t) = req.tangents {
        validate::finite(req.names.tangents, t, &cancel::never)?;
    }
    Ok(rows)
}

/// The analytic samples: `rows` parameter values increasing strictly, `2·rows − 1` finite
/// derivatives of each order (of the curve passed as `points`).
fn check_analytic(a: &Analytic, rows: usize, points: &str) -> Result<()> {
    if a.u.len() != rows || a.d1.len() != 2 * rows - 1 || a.d2.len() != 2 * rows - 1 {
        return Err(InputError::new(
            "u",
            "analytic samples have inconsistent lengths",
        ));
    }
    validate::finite_scalars("u", a.u)?;
    validate::finite(points, a.d1, &cancel::never)?;
    validate::finite(points, a.d2, &cancel::never)?;
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
    if matches!(req.method, Method::Rk4 | Method::Rk4Phi | Method::Torsion)
        && req.analytic.is_none()
    {
        let name = match req.method {
            Method::Rk4 => "rk4",
            Method::Rk4Phi => "rk4_phi",
            _ => "torsion",
        };
        return Err(InputError::new(
            "method",
            format!(
                "'{name}' integrates the RMF ODE and needs an analytic curve (x′ and x″): pass \
                 a spinal.curves object with u=..., e.g. frames(spinal.curves.Helix(), \
                 u=200, method='{name}')"
            ),
        ));
    }
    if req.method == Method::Bisector {
        if req.analytic.is_some() {
            return Err(InputError::new(
                "method",
                "'bisector' is Klok's projection for polygons given as points; an analytic \
                 curve has exact tangents: use method='projection' or 'double_reflection'",
            ));
        }
        if req.tangents.is_some() {
            return Err(InputError::new(
                req.tangents_arg(),
                "not used by method='bisector': its tangents are the normals of the polygon's \
                 bisector planes (use method='projection' with given tangents)",
            ));
        }
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
            req.points_arg(),
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
pub(super) fn distinct_samples(req: &Request, rows: usize) -> Result<usize> {
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
            req.points_arg(),
            format!("a closed curve needs at least 3 distinct points, got {n}"),
        ));
    }
    Ok(n)
}

/// Every segment must run along its tangents; the projection method also needs each chord
/// to cross the next normal plane.
pub(super) fn check_segments(req: &Request, dr: &DoubleReflection) -> Result<()> {
    let (t, closed) = (dr.t, dr.closed);
    let n = t.len();
    if !matches!(req.method, Method::Rk4 | Method::Rk4Phi | Method::Torsion) {
        let what = if req.tangent_chords {
            req.names.tangents
        } else {
            req.names.points
        };
        validate::aligned(t, closed, |i| dr.chord(i), what)?;
    }
    if matches!(req.method, Method::Projection | Method::Bisector) {
        let m = if closed { n } else { n - 1 };
        if let Some(i) = (0..m).into_par_iter().position_first(|i| {
            let d = dr.chord(i);
            !(d.dot(t[(i + 1) % n]) > 1e-9 * d.length())
        }) {
            return Err(InputError::new(
                req.points_arg(),
                format!(
                    "the projection method needs each chord to cross the next normal plane; \
                     the segment from row {i} lies in it; sample more densely"
                ),
            ));
        }
    }
    Ok(())
}
