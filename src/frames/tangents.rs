//! Tangent and curvature-vector estimation from sampled points, and the tangents-only
//! reflection vectors of double reflection.
//!
//! * Five-point chord-length rule (the default): the derivative at `x_i` of the quartic that
//!   interpolates five consecutive samples at their cumulative chord lengths (Lagrange
//!   weights by Fornberg's algorithm, centred where possible, one-sided at open ends,
//!   periodic for loops). For equal chords it is the formula below; for unequal spacing it
//!   stays 4th order in the direction and is exact on straight lines whatever the spacing,
//!   where index-based stencils can even point backwards. At an open end whose first chord
//!   is much longer than the next ones the one-sided quartic extrapolates from a distant
//!   cluster and amplifies rounding by ~(H/h)³; there the farthest samples are dropped
//!   (cubic, quadratic, down to the end chord) until the amplification is at most 10³, which
//!   keeps equal and moderately uneven chords (ratios up to about 7.5) at 4th order.
//!   Guard: where it turns more than 60° away from the circle estimate below (the quartic
//!   overshooting at a kink next to very uneven chords), the circle estimate is used
//!   instead.
//! * Bounded ends (the default rule, `FivePointBounded`): the five-point chord-length rule
//!   with each open end tangent kept inside a cone about the end chord `ĉ`, set by the turn
//!   `φ` between the end chord and its neighbour (the discrete curvature at the end,
//!   `φ ≈ κh`): half the turn, `φ/2`, on coarse samplings (`φ ≥ 20°`), the whole turn on
//!   fine ones (`φ ≤ 10°`), a smoothstep between, and never wider than 45°; a tangent
//!   leaning further is turned towards `ĉ` onto the cone, in the plane of `ĉ` and the
//!   tangent. On a smooth curve the exact end tangent leans `κh/2 + O(h²)` from the end
//!   chord: half the turn only to first order (the `O(h²)` term has either sign, and uneven
//!   end chords move it towards the longer one), so a half-turn cone would clip fine
//!   samplings at `O(h²)`; the whole-turn cone below 10° keeps them at 4th order. On coarse
//!   samplings (20-point streamlines) the one-sided quartic extrapolates the last bends and
//!   overshoots, which made chisel-shaped tube ends; there the end leans at most half the
//!   turn, as the circle through the last three points does on equal chords. (The cone is
//!   ours: Wang et al. §6.1 give only the one-sided stencils; the circle rule of Zheng §7.1
//!   at an end leans exactly by the circle's half-turn.)
//! * Chord guard (every rule, at every sample with two chords; [`guard_chords`]): where the
//!   chords turn by more than 30° the estimate is blended towards their bisector, the tangent
//!   of a corner (fully from 60° on), and an estimate that points more than about 60° from
//!   either chord is turned towards the bisector until its margin against both chords is at
//!   least half the bisector's. So no segment of a jagged polyline (a random walk, a coarse
//!   streamline, a hairpin) runs against its tangents, and tubes keep their cross-section
//!   through sharp corners. Smooth samplings never reach it. (The centred rows of the
//!   chord-length rules on open curves run four at a time, [`super::tangent_lanes`]: the
//!   same operations, the same bits.)
//! * Five-point uniform rule of Wang, Jüttler, Zheng & Liu (ACM TOG 2008, §6.1), with the
//!   sample index as parameter (`12 x'(u_i) + O(h⁵)`, unit-tangent error O(h⁴) when the
//!   samples come from a uniform step of a smooth parameterisation):
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
//! * Principal normal (for the Frenet frame and the default initial frame): towards the
//!   centre of the circle through the sample and its two neighbours (see [`circle_normal`]).
//! * Tangents-only reflection vector (TOG Eq. 17): `v_1 = 13(t_i + t_{i+1}) − (t_{i−1} + t_{i+2})`,
//!   and at the open ends the 4-point Adams–Moulton weights `9t_0 + 19t_1 − 5t_2 + t_3` and
//!   its mirror (a choice of ours: the paper omits the two end vectors; these weights keep
//!   the 4th order). Needs 4 tangents.

pub use super::end_cone::{END_CONE_COS, END_HALF_COS, bound_end};
use super::tangent_lanes;
use super::tangent_lanes::centred_weights;
pub use super::tangent_lanes::{CHORD_MARGIN, CORNER_COS, CORNER_COS2, OVERSHOOT_COS};
use crate::run::cancel;
use glam::DVec3;
use rayon::prelude::*;

use crate::error::{InputError, Result};
use crate::run::alloc;

/// How tangents are estimated from points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TangentRule {
    /// Five-point chord-length Lagrange derivative (4th order, any spacing) where there are
    /// at least 5 points, else the circle rule (3–4 points) or the chord (2 points).
    FivePoint,
    /// [`TangentRule::FivePoint`] with bounded open ends (the default): an end tangent leans
    /// from the end chord by at most half the turn `φ` between the last two chords where
    /// `φ ≥ 20°`, by at most `φ` where `φ ≤ 10°` (fine samplings keep their 4th order), and
    /// never more than 45° ([`bound_end`]).
    FivePointBounded,
    /// The uniform five-point stencils of the TOG paper (index as parameter).
    FivePointUniform,
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

/// Stencil (first sample index, evaluation offset) of `width` consecutive samples around `i`.
#[inline]
fn window(i: usize, n: usize, width: usize, closed: bool) -> (isize, usize) {
    let half = width / 2;
    if closed {
        (i as isize - half as isize, half)
    } else {
        let first = i.saturating_sub(half).min(n - width);
        (first as isize, i - first)
    }
}

/// Principal normal and curvature at sample `i` from the circle through three consecutive
/// samples (`i−1, i, i+1`; the first or last three at open ends): the unit vector from `x_i`
/// towards the circle's centre, projected onto the normal plane of `t_i`, and `κ = 1/ρ`.
/// Exact on circles, exactly straight (None) on collinear samples, and free of the overshoot
/// that higher-order stencils show next to a jump in curvature; 2nd order otherwise.
/// `noise` is the round-off level of the coordinates (64ε·max|x|).
pub fn circle_normal(
    x: &[DVec3],
    t: DVec3,
    i: usize,
    closed: bool,
    noise: f64,
) -> Option<(DVec3, f64)> {
    let n = x.len();
    if n < 3 {
        return None;
    }
    let (first, _) = window(i, n, 3, closed);
    let p0 = x[idx(first, n, closed)];
    let a = x[idx(first + 1, n, closed)] - p0;
    let b = x[idx(first + 2, n, closed)] - p0;
    let axb = a.cross(b);
    let l2 = axb.length_squared();
    if !(axb.length() > noise * (a.length() + b.length())) {
        return None;
    }
    let centre =
        p0 + (a.length_squared() * b.cross(axb) + b.length_squared() * axb.cross(a)) / (2.0 * l2);
    let d = centre - x[i];
    let perp = d - d.dot(t) * t;
    let kappa = 1.0 / d.length();
    // the centre seen along the tangent (a tangent along a chord through the centre, as at
    // an end corner whose chord is a diameter) leaves no normal but rounding
    if !(perp.length() > 1e-9 * d.length()) {
        return None;
    }
    perp.try_normalize().map(|v| (v, kappa))
}

/// Derivative direction at sample `i` of the quartic through five consecutive samples
/// parameterised by cumulative chord length (weights `w_j = L_j′(τ_i)` of the Lagrange basis).
fn chord_five_point(x: &[DVec3], chords: &[f64], i: usize, closed: bool) -> DVec3 {
    let n = x.len();
    let (first, at) = window(i, n, 5, closed);
    let mut tau = [0.0; 5];
    for k in 1..5 {
        tau[k] = tau[k - 1] + chords[idx(first + k as isize - 1, n, closed)];
    }
    let z = tau[at];
    for v in tau.iter_mut() {
        *v -= z;
    }
    let p0 = x[idx(first + at as isize, n, closed)];
    let mut rel = [DVec3::ZERO; 5];
    for (j, r) in rel.iter_mut().enumerate() {
        *r = x[idx(first + j as isize, n, closed)] - p0;
    }
    // The nodes in use (in index order, `at` among them); the one farthest from τ = 0 is
    // dropped while the stencil amplifies rounding by more than `MAX_AMPLIFICATION` (a
    // one-sided end whose first chord is over 7.5× longer than the next ones extrapolates a
    // quartic from a distant cluster: amplification ~(H/h)³, 3·10⁸ at a ratio of 600).
    // Two nodes give the chord (factor 1).
    let mut nodes = [true; 5];
    loop {
        let (d, amplification) = lagrange_derivative(&tau, &rel, at, &nodes);
        let left = nodes.iter().filter(|&&u| u).count();
        if left == 2 || d == DVec3::ZERO || amplification <= MAX_AMPLIFICATION {
            return d;
        }
        let far = (0..5)
            .filter(|&j| nodes[j] && j != at)
            .max_by(|&a, &b| tau[a].abs().total_cmp(&tau[b].abs()))
            .unwrap_or(at);
        nodes[far] = false;
    }
}

/// Largest accepted ratio `Σ_j |w_j| |x_j − x_at| / |Σ_j w_j (x_j − x_at)|` of an end stencil:
/// the factor by which it amplifies relative rounding in the samples (15 for equal chords).
/// Above it the stencil loses more than ~10⁻¹³ of the direction to rounding alone.
const MAX_AMPLIFICATION: f64 = 1e3;

/// The derivative at `τ_at = 0` of the polynomial through `(τ_j, rel_j)` for the nodes `j`
/// with `used[j]` (`rel_at = 0`), and its rounding amplification (see
/// [`MAX_AMPLIFICATION`]). For `j ≠ at`: `L_j′(0) = Π_{m≠j,at}(−τ_m) / Π_{m≠j}(τ_j − τ_m)`
/// over the nodes in use; `Σ_j w_j = 0`, so the derivative is `Σ_{j≠at} w_j (x_j − x_at)`.
fn lagrange_derivative(
    tau: &[f64; 5],
    rel: &[DVec3; 5],
    at: usize,
    used: &[bool; 5],
) -> (DVec3, f64) {
    let mut d = DVec3::ZERO;
    let mut size = 0.0;
    for j in 0..5 {
        if j == at || !used[j] {
            continue;
        }
        let (mut num, mut den) = (1.0, 1.0);
        for m in 0..5 {
            if m != j && used[m] {
                den *= tau[j] - tau[m];
                if m != at {
                    num *= -tau[m];
                }
            }
        }
        let w = num / den;
        d += w * rel[j];
        size += w.abs() * rel[j].length();
    }
    let l = d.length();
    (d, if l > 0.0 { size / l } else { f64::INFINITY })
}

/// The direction of `chord_five_point` at a centred stencil (a positive multiple of the
/// derivative, to be normalised): chords `h = (|x₁−x₀|, …, |x₄−x₃|)` of the samples
/// `x₀ … x₄`, derivative at `x₂` (the same Lagrange weights, unrolled).
#[inline(always)]
fn centred_five_point(x: [DVec3; 5], h: [f64; 4]) -> DVec3 {
    let w = centred_weights(h[0], h[1], h[2], h[3]);
    centred_sum(&x, w)
}

#[inline(always)]
fn centred_sum(x: &[DVec3], w: [f64; 4]) -> DVec3 {
    let p = x[2];
    w[0] * (x[0] - p) + w[1] * (x[1] - p) + w[2] * (x[3] - p) + w[3] * (x[4] - p)
}

/// Unnormalised circle tangent at an interior (or periodic) index.
#[inline(always)]
fn circle_raw(x: &[DVec3], i: usize, closed: bool) -> DVec3 {
    let n = x.len();
    let ii = i as isize;
    let a = x[i] - x[idx(ii - 1, n, closed)];
    let b = x[idx(ii + 1, n, closed)] - x[i];
    b.length_squared() * a + a.length_squared() * b
}

fn cusp_error(i: usize, name: &str) -> InputError {
    InputError::new(
        name.to_owned(),
        format!(
            "cannot estimate a tangent at row {i}: the neighbouring points cancel (the curve \
             reverses on itself there, a cusp); sample the curve more densely or pass `tangents`"
        ),
    )
}

/// Rows per segment of a cancellable estimate ([`estimate`]).
const CANCEL_SEGMENT: usize = 1 << 20;

/// Unit tangents estimated from points (`closed`: the points form a loop, no repeated end).
///
/// Errors if fewer than 2 points (3 for a loop) or if an estimate vanishes at an open end
/// (an interior zero estimate, a symmetric reversal, takes the chord guard's normal).
/// Points are assumed finite and free of repeated consecutive points (checked by the caller).
///
/// `chords[i] = |x_{i+1} − x_i|` (mod n when closed), as returned by `validate::chords`.
///
/// Errors name the points `name` (the argument the user passed them as).
///
/// Polls `cancel` before every segment of [`CANCEL_SEGMENT`] rows and returns the rows done so far
/// once it says stop (see [`crate::run::cancel`]).
pub fn estimate(
    x: &[DVec3],
    chords: &[f64],
    closed: bool,
    rule: TangentRule,
    name: &str,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<DVec3>> {
    let n = x.len();
    let min = if closed { 3 } else { 2 };
    if n < min {
        return Err(InputError::new(
            name.to_owned(),
            format!(
                "need at least {min} points to estimate tangents{}, got {n}",
                if closed { " of a closed curve" } else { "" }
            ),
        ));
    }
    let five = rule != TangentRule::Circle && n >= 5;
    let chordal = matches!(rule, TangentRule::FivePoint | TangentRule::FivePointBounded);
    // Estimate and normalise in one pass; a zero (or non-finite) estimate is a cusp. The open
    // ends of the circle rule are zero here and filled below.
    let mut t = alloc::with_capacity("estimate_tangents", n)?;
    // in segments, each written in parallel into the reserved room, so that a cancelled
    // call neither computes nor touches the pages of the rows it skips
    for start in (0..n).step_by(CANCEL_SEGMENT) {
        if cancel() {
            return Ok(t);
        }
        t.par_extend(
            (start..(start + CANCEL_SEGMENT).min(n))
                .into_par_iter()
                .with_min_len(1 << 12)
                .map_init(
                    || (usize::MAX, [DVec3::ZERO; 4]),
                    |(at, group), i| {
                        if five && chordal && !closed {
                            let row = |i: usize| {
                                if rule == TangentRule::FivePointBounded {
                                    five_point_unit_open(x, i, |j| chords[j])
                                } else {
                                    five_point_unit_unbounded(x, i, |j| chords[j])
                                }
                                .unwrap_or(DVec3::ZERO)
                            };
                            // centred rows four at a time (the same bits), the rest one by one
                            let Some(g) = tangent_lanes::group_of(i, n) else {
                                return row(i);
                            };
                            if *at != g {
                                *group = tangent_lanes::centred_group(x, chords, g)
                                    .unwrap_or_else(|| std::array::from_fn(|k| row(g + k)));
                                *at = g;
                            }
                            return group[i - g];
                        }
                        let v = raw_tangent(x, chords, i, closed, rule, five);
                        let l = v.length();
                        let u = v * (1.0 / l);
                        let interior = closed || (i > 0 && i + 1 < n);
                        if !(l > 0.0 && u.is_finite()) {
                            // the neighbours cancel (a symmetric reversal): the chord guard's
                            // bisector, at a sample with two chords
                            if !(interior && v == DVec3::ZERO) {
                                return DVec3::ZERO;
                            }
                        }
                        let u = match (l > 0.0, five && chordal) {
                            (false, _) => DVec3::ZERO,
                            (true, true) => guard_overshoot(x, i, closed, u),
                            (true, false) => u,
                        };
                        if interior {
                            let ii = i as isize;
                            let (a, b) = (x[idx(ii - 1, n, closed)], x[idx(ii + 1, n, closed)]);
                            guard_chords(x[i] - a, b - x[i], u)
                        } else {
                            u
                        }
                    },
                ),
        );
    }
    if !five && !closed && n >= 3 {
        for (end, inner, chord) in [(0, 1, x[1] - x[0]), (n - 1, n - 2, x[n - 1] - x[n - 2])] {
            let ti = t[inner];
            let c = chord.normalize_or_zero();
            t[end] = (2.0 * c.dot(ti) * c - ti).normalize_or_zero();
            if rule == TangentRule::FivePointBounded {
                // the default rule's end cone also on 3 and 4 points (the circle's end
                // tangent leans by half its turn over the end chord, up to 90°)
                t[end] = bound_end(x, end, t[end]);
            }
        }
    }
    match first_zero(&t) {
        Some(i) => Err(cusp_error(i, name)),
        None => Ok(t),
    }
}

/// The unit tangent of the default rule ([`TangentRule::FivePointBounded`]) at `i` of an open
/// curve with `n ≥ 5` samples: the guarded five-point chord-length tangent, its two end
/// values bounded by the turn of the end chords ([`bound_end`]); what [`estimate`] returns
/// there. `h(j)` is the chord length `|x_{j+1} − x_j|` (callers pass a table or compute it on
/// the fly: the values must be those of `validate::chords`). `None` where the estimate is
/// not finite, or vanishes at an end.
#[inline(always)]
pub fn five_point_unit_open(x: &[DVec3], i: usize, h: impl Fn(usize) -> f64) -> Option<DVec3> {
    let u = five_point_unit_unbounded(x, i, h)?;
    Some(if i == 0 || i + 1 == x.len() {
        bound_end(x, i, u)
    } else {
        u
    })
}

/// The guarded five-point chord-length tangent of [`TangentRule::FivePoint`] at `i` of an
/// open curve (`n ≥ 5`), ends unbounded; see [`five_point_unit_open`].
#[inline(always)]
pub fn five_point_unit_unbounded(x: &[DVec3], i: usize, h: impl Fn(usize) -> f64) -> Option<DVec3> {
    let n = x.len();
    let v = if i >= 2 && i + 2 < n {
        centred_five_point(
            [x[i - 2], x[i - 1], x[i], x[i + 1], x[i + 2]],
            [h(i - 2), h(i - 1), h(i), h(i + 1)],
        )
    } else {
        // the one-sided stencil on the first or last five samples
        let first = if i < 2 { 0 } else { n - 5 };
        let hl = [h(first), h(first + 1), h(first + 2), h(first + 3)];
        chord_five_point(&x[first..first + 5], &hl, i - first, false)
    };
    let l = v.length();
    let u = v * (1.0 / l);
    let interior = i > 0 && i + 1 < n;
    let u = match (l > 0.0 && u.is_finite(), interior && v == DVec3::ZERO) {
        (true, _) => guard_overshoot(x, i, false, u),
        // the neighbours cancel (a symmetric reversal): the chord guard's bisector
        (false, true) => DVec3::ZERO,
        (false, false) => return None,
    };
    Some(if interior {
        guard_chords(x[i] - x[i - 1], x[i + 1] - x[i], u)
    } else {
        u
    })
}

/// `|p̂ + q̂| = 2 cos(φ/2)` at or below which two unit chords reverse (a turn within 10⁻⁶ rad
/// of 180°): their bisector would be rounding noise (see [`guard_chords`]).
const REVERSAL: f64 = 1e-6;

/// The unit tangent `u` estimated at a sample between the chords `c_in = x_i − x_{i−1}` and
/// `c_out = x_{i+1} − x_i`, turned towards their bisector where the polyline turns sharply
/// there or where `u` points too far from either chord.
///
/// With `p̂, q̂` the unit chords and `φ` the turn between them, the bisector
/// `b̂ = (p̂ + q̂)/|p̂ + q̂|` is the tangent of a corner: the normal plane of `b̂` is the plane
/// in which the straight tubes about the two chords meet, and `b̂·p̂ = b̂·q̂ = cos(φ/2)`, larger
/// than the smaller dot product of any other unit vector. Two steps, each continuous in the
/// points short of reversals (below):
///
/// 1. **Corners.** Where the chords turn by more than 30° the samples no longer resolve a
///    smooth curve (fewer than 12 samples per turn of a circle), and the estimate, which
///    interpolates across the corner, is blended towards `b̂`:
///    `u ← normalise((1 − w) u + w b̂)` with `w` the smoothstep `3s² − 2s³` of
///    `s = (cos 30° − cos φ)/(cos 30° − cos 60°)` clamped to `[0, 1]`: the bisector itself
///    from 60° on, so tubes of coarse polylines keep their cross-section through corners.
/// 2. **Margin.** With `m = min(u·p̂, u·q̂) / cos(φ/2)` (1 for the bisector), an estimate with
///    `m < ½` (pointing more than about 60° from a chord: a quartic overshooting next to very
///    uneven chords) becomes `normalise((1 − w) u + w b̂)`, `w = min(1, (½ − m)/½)`, whose
///    margin against both chords is at least `½ cos(φ/2)`.
///
/// So every segment runs along the tangents of its ends (`ĉ·(t_i + t_{i+1}) > 0`) unless
/// both of its ends reverse, and double reflection and the sweep's rings exist on any
/// polyline (a jagged random walk, a coarse streamline, a hairpin). At a reversal (chords
/// within 10⁻⁶ rad of opposite, where `p̂ + q̂` is rounding noise) the result is normal to the
/// chord, the limit of the bisectors of near reversals, on the side the estimate leans to.
///
/// A smooth curve sampled with turns under 30° and estimates within 60° of both chords (the
/// cheap test made first) keeps its 4th-order estimate bit for bit. (Our rule: Wang et al.
/// 2008 §4.4 only require that no segment runs against its tangents.)
#[inline(always)]
pub fn guard_chords(c_in: DVec3, c_out: DVec3, u: DVec3) -> DVec3 {
    let (a, b) = (u.dot(c_in), u.dot(c_out));
    let m2 = CHORD_MARGIN * CHORD_MARGIN;
    let (qi, qo, turn) = (
        c_in.length_squared(),
        c_out.length_squared(),
        c_in.dot(c_out),
    );
    // a turn under 30° and within 60° of both chords, without a square root; all six
    // comparisons made, without a branch between them (a smooth curve passes them all)
    let pass = (turn >= 0.0)
        & (turn * turn >= CORNER_COS2 * (qi * qo))
        & (a >= 0.0)
        & (b >= 0.0)
        & (a * a >= m2 * qi)
        & (b * b >= m2 * qo);
    if pass {
        return u;
    }
    towards_bisector(c_in, c_out, u)
}

/// The two steps of [`guard_chords`] past its cheap test.
#[cold]
fn towards_bisector(c_in: DVec3, c_out: DVec3, u: DVec3) -> DVec3 {
    let scale = crate::math::scale::normalize;
    let (Some(p), Some(q)) = (scale(c_in), scale(c_out)) else {
        return u; // a zero chord: refused by the chord check
    };
    let sum = p + q;
    if !(sum.length() > REVERSAL) {
        // a reversal (the curve turns back onto its last chord, to within 10⁻⁶ rad, where
        // the bisector would be the rounding of p + q): no direction runs forwards along
        // both chords; the limit of the bisectors of near reversals is normal to the
        // chord, on the side the estimate leans to
        return (u - u.dot(p) * p)
            .try_normalize()
            .unwrap_or_else(|| super::geometry::any_perpendicular(p));
    }
    let b = sum / sum.length();
    let blend = |u: DVec3, w: f64| ((1.0 - w) * u + w * b).try_normalize().unwrap_or(b);
    let s = ((CORNER_COS[0] - p.dot(q)) / (CORNER_COS[0] - CORNER_COS[1])).clamp(0.0, 1.0);
    let u = if s > 0.0 {
        blend(u, s * s * (3.0 - 2.0 * s))
    } else {
        u
    };
    let half = 0.5 * sum.length(); // cos(φ/2)
    let m = u.dot(p).min(u.dot(q)) / half;
    if m >= CHORD_MARGIN {
        return u;
    }
    blend(u, ((CHORD_MARGIN - m) / CHORD_MARGIN).min(1.0))
}

/// The five-point unit tangent `u` at `i`, or the circle estimate where they disagree by
/// more than 60°. On smoothly sampled curves the two agree to O(h²), so this never changes
/// the 4th-order estimate there; on a polyline with a kink next to very uneven chords the
/// interpolating quartic can swing round and point backwards, which the frames would accept
/// but a sweep would fold over.
#[inline(always)]
fn guard_overshoot(x: &[DVec3], i: usize, closed: bool, u: DVec3) -> DVec3 {
    let n = x.len();
    let w = if closed || (i > 0 && i + 1 < n) {
        circle_raw(x, i, closed)
    } else {
        // open end: the tangent there of the circle through the first (last) three points
        let (inner, chord) = if i == 0 {
            (1, x[1] - x[0])
        } else {
            (n - 2, x[n - 1] - x[n - 2])
        };
        let ti = circle_raw(x, inner, false).normalize_or_zero();
        let c = chord.normalize_or_zero();
        2.0 * c.dot(ti) * c - ti
    };
    guard_with(u, w)
}

/// `u`, or the circle estimate `w` (unnormalised) where `u` turns more than 60° from it.
#[inline(always)]
fn guard_with(u: DVec3, w: DVec3) -> DVec3 {
    // u·ŵ ≥ cos 60° without a square root in the common case
    let d = u.dot(w);
    if d >= 0.0 && d * d >= OVERSHOOT_COS * OVERSHOOT_COS * w.length_squared() {
        return u;
    }
    match w.try_normalize() {
        Some(c) => c,
        None => u,
    }
}

/// Index of the first zero vector (an estimate that could not be normalised).
fn first_zero(t: &[DVec3]) -> Option<usize> {
    t.par_chunks(1 << 12)
        .position_first(|c| c.contains(&DVec3::ZERO))
        .and_then(|b| {
            let a = b << 12;
            t[a..].iter().position(|v| *v == DVec3::ZERO).map(|k| a + k)
        })
}

/// The unnormalised tangent estimate at `i` (zero at the open ends of the circle rule, which
/// `estimate` fills afterwards).
#[inline(always)]
fn raw_tangent(
    x: &[DVec3],
    chords: &[f64],
    i: usize,
    closed: bool,
    rule: TangentRule,
    five: bool,
) -> DVec3 {
    let n = x.len();
    if n == 2 {
        x[1] - x[0]
    } else if five && rule != TangentRule::FivePointUniform {
        if i >= 2 && i + 2 < n {
            centred_five_point(
                [x[i - 2], x[i - 1], x[i], x[i + 1], x[i + 2]],
                [chords[i - 2], chords[i - 1], chords[i], chords[i + 1]],
            )
        } else {
            chord_five_point(x, chords, i, closed)
        }
    } else if five {
        five_point_raw(x, i, closed)
    } else if closed || (i > 0 && i + 1 < n) {
        circle_raw(x, i, closed)
    } else {
        DVec3::ZERO
    }
}

/// Unit tangents for one curve as the user gave it: validates the points, accepts a closed
/// curve that repeats its first point at the end (that row gets the first tangent).
///
/// A curve whose size is far from 1 is divided by a power of two first (exact; see
/// [`crate::math::scale`]): unit tangents do not depend on the units.
///
/// Polls `cancel` between its passes and for every row of the estimate (see
/// [`crate::run::cancel`]); a cancelled call returns an incomplete result.
pub fn estimate_rows(
    x: &[DVec3],
    closed: bool,
    rule: TangentRule,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<DVec3>> {
    crate::frames::validate::finite("points", x, &cancel::never)?;
    if cancel() {
        return Ok(Vec::new());
    }
    let (lo, hi) = crate::frames::geometry::bounds(x);
    let owned = crate::math::scale::curve_exponent(lo, hi)
        .map(|k| crate::math::scale::try_scaled("estimate_tangents", x, k))
        .transpose()?;
    let x = owned.as_deref().unwrap_or(x);
    let mut n = x.len();
    if closed && n >= 2 && crate::frames::validate::coincide(x[n - 1], x[0]) {
        n -= 1;
    }
    if cancel() {
        return Ok(Vec::new());
    }
    let chords = crate::frames::validate::chords(&x[..n], closed, "points", cancel)?;
    if cancel() {
        return Ok(Vec::new());
    }
    let mut t = estimate(&x[..n], &chords, closed, rule, "points", cancel)?;
    if cancel() {
        return Ok(t);
    }
    if n < x.len() {
        let first = t[0];
        alloc::push("estimate_tangents", &mut t, first)?;
    }
    Ok(t)
}

/// Unit tangents of many curves stored back to back (`offsets`: C + 1 start rows ending at
/// `x.len()`), each as [`estimate_rows`] gives it, curves in parallel. Errors name the curve
/// and its rows when there are several.
///
/// Polls `cancel` before every curve, inside each curve's estimate ([`estimate_rows`])
/// and before every [`CANCEL_SEGMENT`] rows of the copy into the result; a cancelled call returns
/// an incomplete result (see [`crate::run::cancel`]).
pub fn estimate_many(
    x: &[DVec3],
    offsets: &[usize],
    closed: bool,
    rule: TangentRule,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<DVec3>> {
    crate::frames::validate::offsets(offsets, x.len())?;
    let curves = offsets.len() - 1;
    let parts: Vec<Result<Vec<DVec3>>> = (0..curves)
        .into_par_iter()
        .map(|c| {
            if cancel() {
                return Ok(Vec::new());
            }
            let (a, b) = (offsets[c], offsets[c + 1]);
            estimate_rows(&x[a..b], closed, rule, cancel).map_err(|e| {
                if curves > 1 {
                    e.context(&format!("curve {c} (rows {a} to {})", b.max(1) - 1))
                } else {
                    e
                }
            })
        })
        .collect();
    if cancel() {
        return Ok(Vec::new());
    }
    let mut out = alloc::with_capacity("estimate_tangents", x.len())?;
    for p in parts {
        for block in p?.chunks(CANCEL_SEGMENT) {
            if cancel() {
                return Ok(out);
            }
            out.extend_from_slice(block);
        }
    }
    Ok(out)
}

/// Normalise in place (scaled by the largest component first, so any finite non-zero vector
/// works); on a zero or non-finite vector returns the first bad index.
pub fn normalize_all(t: &mut [DVec3]) -> std::result::Result<(), usize> {
    let bad = t
        .par_chunks_mut(1 << 12)
        .enumerate()
        .filter_map(|(c, block)| {
            let mut bad = None;
            for (k, v) in block.iter_mut().enumerate() {
                if let Some(u) = crate::math::scale::normalize(*v) {
                    *v = u;
                } else if bad.is_none() {
                    bad = Some((c << 12) + k);
                }
            }
            bad
        })
        .min();
    match bad {
        Some(i) => Err(i),
        None => Ok(()),
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
mod tests;

/// Property tests (proptest) of the estimator over random curves, motions and scales.
#[cfg(test)]
mod proptests;
