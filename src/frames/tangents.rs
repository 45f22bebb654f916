//! Tangent and curvature-vector estimation from sampled points, and the tangents-only
//! reflection vectors of double reflection.
//!
//! All stencils treat the sample index as the curve parameter (uniform spacing `h = 1`), as
//! in Wang, Jüttler, Zheng & Liu (ACM TOG 2008, §6.1); the direction of the estimate does
//! not depend on the spacing as long as the samples come from a uniform step of *some*
//! smooth parameterisation.
//!
//! * Five-point first derivative (4th order; `12 x'(u_i) + O(h⁵)`, unit-tangent error
//!   O(h⁴), which keeps double reflection 4th order):
//!   interior `x_{i−2} − 8x_{i−1} + 8x_{i+1} − x_{i+2}`, one-sided
//!   `t_0 = −25x_0 + 48x_1 − 36x_2 + 16x_3 − 3x_4`, `t_1 = −3x_0 − 10x_1 + 18x_2 − 6x_3 + x_4`,
//!   mirrored (with a sign change) at the far end. Periodic for closed curves. Needs 5 points.
//! * Circle ("co-spherical") tangent of Zheng's thesis §7.1 (2nd order): the tangent at `x_i`
//!   of the circle through `x_{i−1}, x_i, x_{i+1}`, `w = |b|² a + |a|² b` with
//!   `a = x_i − x_{i−1}`, `b = x_{i+1} − x_i`. (The thesis prints `|b| a + |a| b`, which is
//!   the circle tangent only for equal chords; the squared weights are exact on any circle,
//!   as the unit test `circle_rule_exact_on_circle` checks.) At an open end the tangent
//!   of the same circle, `t_0 = 2(ĉ·t_1)ĉ − t_1` with `ĉ` the unit first chord. Used for 3 or 4
//!   points and on request. Two points: the chord direction (1st order).
//! * Five-point second derivative (for the principal normal of the Frenet frame):
//!   `(−x_{i−2} + 16x_{i−1} − 30x_i + 16x_{i+1} − x_{i+2})/12`, one-sided
//!   `(35x_0 − 104x_1 + 114x_2 − 56x_3 + 11x_4)/12`, `(11x_0 − 20x_1 + 6x_2 + 4x_3 − x_4)/12`.
//! * Tangents-only reflection vector (TOG Eq. 17): `v_1 = 13(t_i + t_{i+1}) − (t_{i−1} + t_{i+2})`,
//!   and at the open ends the 4-point Adams–Moulton weights `9t_0 + 19t_1 − 5t_2 + t_3` and
//!   its mirror (resolution A16 of the spec). Needs 4 tangents.

use glam::DVec3;
use rayon::prelude::*;

use crate::error::{InputError, Result};

/// How tangents are estimated from points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TangentRule {
    /// Five-point differences (4th order) where there are at least 5 points, else the
    /// circle rule (3–4 points) or the chord (2 points).
    FivePoint,
    /// Circle through three consecutive points (2nd order), chord for 2 points.
    Circle,
}

#[inline]
fn idx(i: isize, n: usize, closed: bool) -> usize {
    if closed {
        i.rem_euclid(n as isize) as usize
    } else {
        i as usize
    }
}

/// Raw five-point first-difference stencil at `i` (≈ 12 x′(i)); needs `n ≥ 5`.
fn five_point_raw(x: &[DVec3], i: usize, closed: bool) -> DVec3 {
    let n = x.len();
    let ii = i as isize;
    let p = |k: isize| x[idx(ii + k, n, closed)];
    if closed || (i >= 2 && i + 2 < n) {
        p(-2) - 8.0 * p(-1) + 8.0 * p(1) - p(2)
    } else if i == 0 {
        -25.0 * x[0] + 48.0 * x[1] - 36.0 * x[2] + 16.0 * x[3] - 3.0 * x[4]
    } else if i == 1 {
        -3.0 * x[0] - 10.0 * x[1] + 18.0 * x[2] - 6.0 * x[3] + x[4]
    } else if i == n - 1 {
        25.0 * x[n - 1] - 48.0 * x[n - 2] + 36.0 * x[n - 3] - 16.0 * x[n - 4] + 3.0 * x[n - 5]
    } else {
        3.0 * x[n - 1] + 10.0 * x[n - 2] - 18.0 * x[n - 3] + 6.0 * x[n - 4] - x[n - 5]
    }
}

/// Unnormalised circle tangent at an interior (or periodic) index.
fn circle_raw(x: &[DVec3], i: usize, closed: bool) -> DVec3 {
    let n = x.len();
    let ii = i as isize;
    let a = x[i] - x[idx(ii - 1, n, closed)];
    let b = x[idx(ii + 1, n, closed)] - x[i];
    b.length_squared() * a + a.length_squared() * b
}

fn cusp_error(i: usize) -> InputError {
    InputError::new(
        "points",
        format!(
            "cannot estimate a tangent at row {i}: the neighbouring points cancel (the curve \
             reverses on itself there, a cusp); sample the curve more densely or pass `tangents`"
        ),
    )
}

/// Unit tangents estimated from points (`closed`: the points form a loop, no repeated end).
///
/// Errors if fewer than 2 points (3 for a loop) or if an estimate vanishes (a cusp).
/// Points are assumed finite and free of repeated consecutive points (checked by the caller).
pub fn estimate(x: &[DVec3], closed: bool, rule: TangentRule) -> Result<Vec<DVec3>> {
    let n = x.len();
    let min = if closed { 3 } else { 2 };
    if n < min {
        return Err(InputError::new(
            "points",
            format!(
                "need at least {min} points to estimate tangents{}, got {n}",
                if closed { " of a closed curve" } else { "" }
            ),
        ));
    }
    let five = rule == TangentRule::FivePoint && n >= 5;
    let mut t = vec![DVec3::ZERO; n];
    t.par_iter_mut().enumerate().for_each(|(i, ti)| {
        *ti = if n == 2 {
            x[1] - x[0]
        } else if five {
            five_point_raw(x, i, closed)
        } else if closed || (i > 0 && i + 1 < n) {
            circle_raw(x, i, closed)
        } else {
            DVec3::ZERO // open ends of the circle rule: filled below
        };
    });
    if !five && !closed && n >= 3 {
        for (end, inner, chord) in [(0, 1, x[1] - x[0]), (n - 1, n - 2, x[n - 1] - x[n - 2])] {
            let ti = t[inner].normalize_or_zero();
            let c = chord.normalize_or_zero();
            t[end] = 2.0 * c.dot(ti) * c - ti;
        }
    }
    normalize_all(&mut t).map_err(cusp_error)?;
    Ok(t)
}

/// Normalise in place; on a zero or non-finite result returns the first bad index.
pub fn normalize_all(t: &mut [DVec3]) -> std::result::Result<(), usize> {
    let bad = t
        .par_iter_mut()
        .enumerate()
        .filter_map(|(i, v)| {
            let l = v.length();
            if l > 0.0 && l.is_finite() && (*v / l).is_finite() {
                *v /= l;
                None
            } else {
                Some(i)
            }
        })
        .min();
    match bad {
        Some(i) => Err(i),
        None => Ok(()),
    }
}

/// Estimated second derivative of the curve with respect to the sample index.
pub fn second_derivative(x: &[DVec3], i: usize, closed: bool) -> DVec3 {
    let n = x.len();
    let ii = i as isize;
    let p = |k: isize| x[idx(ii + k, n, closed)];
    if n < 3 {
        DVec3::ZERO
    } else if n < 5 {
        if closed || (i > 0 && i + 1 < n) {
            p(-1) - 2.0 * x[i] + p(1)
        } else if i == 0 {
            x[0] - 2.0 * x[1] + x[2]
        } else {
            x[n - 3] - 2.0 * x[n - 2] + x[n - 1]
        }
    } else if closed || (i >= 2 && i + 2 < n) {
        (-p(-2) + 16.0 * p(-1) - 30.0 * x[i] + 16.0 * p(1) - p(2)) / 12.0
    } else if i == 0 {
        (35.0 * x[0] - 104.0 * x[1] + 114.0 * x[2] - 56.0 * x[3] + 11.0 * x[4]) / 12.0
    } else if i == 1 {
        (11.0 * x[0] - 20.0 * x[1] + 6.0 * x[2] + 4.0 * x[3] - x[4]) / 12.0
    } else if i == n - 1 {
        (35.0 * x[n - 1] - 104.0 * x[n - 2] + 114.0 * x[n - 3] - 56.0 * x[n - 4] + 11.0 * x[n - 5])
            / 12.0
    } else {
        (11.0 * x[n - 1] - 20.0 * x[n - 2] + 6.0 * x[n - 3] + 4.0 * x[n - 4] - x[n - 5]) / 12.0
    }
}

/// Estimated first derivative with respect to the sample index (speed scale for curvature).
pub fn first_derivative(x: &[DVec3], i: usize, closed: bool) -> DVec3 {
    let n = x.len();
    if n >= 5 {
        five_point_raw(x, i, closed) / 12.0
    } else if n == 2 {
        x[1] - x[0]
    } else {
        let ii = i as isize;
        if closed || (i > 0 && i + 1 < n) {
            0.5 * (x[idx(ii + 1, n, closed)] - x[idx(ii - 1, n, closed)])
        } else if i == 0 {
            x[1] - x[0]
        } else {
            x[n - 1] - x[n - 2]
        }
    }
}

/// Reflection vector of segment `i` (from sample `i` to `i+1`, indices mod n when closed)
/// built from unit tangents only (TOG Eq. 17 with Adams–Moulton ends). Needs `n ≥ 4`.
#[inline]
pub fn tangent_chord(t: &[DVec3], i: usize, closed: bool) -> DVec3 {
    let n = t.len();
    let ii = i as isize;
    let q = |k: isize| t[idx(ii + k, n, closed)];
    if closed || (i >= 1 && i + 2 < n) {
        13.0 * (q(0) + q(1)) - (q(-1) + q(2))
    } else if i == 0 {
        9.0 * t[0] + 19.0 * t[1] - 5.0 * t[2] + t[3]
    } else {
        t[n - 4] - 5.0 * t[n - 3] + 19.0 * t[n - 2] + 9.0 * t[n - 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn helix(u: f64) -> DVec3 {
        DVec3::new(u.cos(), u.sin(), 0.5 * u)
    }
    fn helix_t(u: f64) -> DVec3 {
        DVec3::new(-u.sin(), u.cos(), 0.5).normalize()
    }

    #[test]
    fn five_point_is_fourth_order() {
        let err = |n: usize| {
            let h = 3.0 / n as f64;
            let x: Vec<DVec3> = (0..=n).map(|i| helix(i as f64 * h)).collect();
            let t = estimate(&x, false, TangentRule::FivePoint).unwrap();
            (0..=n)
                .map(|i| (t[i] - helix_t(i as f64 * h)).length())
                .fold(0.0, f64::max)
        };
        let ratio = err(64) / err(128);
        assert!((14.0..18.0).contains(&ratio), "ratio {ratio}");
    }

    #[test]
    fn circle_rule_exact_on_circle() {
        let x: Vec<DVec3> = [0.0, 0.3, 1.1, 1.2]
            .iter()
            .map(|&u: &f64| DVec3::new(u.cos(), u.sin(), 0.0))
            .collect();
        let t = estimate(&x, false, TangentRule::Circle).unwrap();
        for (i, &u) in [0.0_f64, 0.3, 1.1, 1.2].iter().enumerate() {
            let e = DVec3::new(-u.sin(), u.cos(), 0.0);
            assert!((t[i] - e).length() < 1e-14, "{i}");
        }
    }

    #[test]
    fn cusp_is_an_error() {
        let x = [DVec3::ZERO, DVec3::X, DVec3::ZERO];
        assert!(estimate(&x, false, TangentRule::FivePoint).is_err());
    }
}
