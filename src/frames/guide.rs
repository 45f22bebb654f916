//! Frames whose reference vector follows a guide direction (a chemical bond along a
//! backbone, "up" for a camera), smoothed.
//!
//! As in [`super::constraints`], the frame is the RMF turned about `t` by `α`
//! (Zheng 2008, §7.3 eq. 7.3); its twist rate is `α′` (eq. 7.4, `ω = κ b + α′ t`). The guide
//! `g_i`, projected on the normal plane, sits at the angle `φ_i` from the RMF's `r_i`. The
//! twist balances the squared twist rate against the squared guide error, a discrete form of
//! `∫ α′² ds + W ∫ w (α − φ)² ds / h̄²` (`h̄` the mean segment length, so `W` counts per
//! sample and the result does not change under scaling):
//!
//! `E(α) = Σ_i (h̄ / h_i)(α_{i+1} − α_i)² + W Σ_i w_i (μ_i / h̄)(α_i − φ_i)²`
//!
//! with `h_i` the segment lengths, `μ_i` the half-lengths of the segments at sample `i` and
//! `w_i = sin²∠(g_i, t_i)` (0 where the guide is within `tolerance` of `±t_i`: there the
//! frame falls back to the RMF's twist rate, 0). `E` is quadratic, its normal equations a
//! symmetric tridiagonal system (cyclic for a closed curve), solved in O(n) (Thomas; Sherman
//! and Morrison's formula for the cyclic corner). `φ` is unwrapped along the samples first
//! (each angle within π of the one before), so the twist never jumps by a turn. Where a
//! sample is pinned (a constraint) `α` is fixed there. For a smooth `φ` the solution's bias
//! is `α − φ ≈ φ″ h̄² / W` (derivative per sample): it shrinks like `1 / W`.
//!
//! A closed curve's RMF differs across the seam by its closing angle `c`; the seam term is
//! `(h̄ / h)(α_0 + D − α_{n−1})²` with `D = c + 2πk`, `k` chosen so that the unwrapped guide
//! angle continues across the seam (plus `2π·turns`). A half number of turns `k + ½` asks for
//! frames that close up to a half turn: then the guide angle plus π continues across the
//! seam (`D = c + π + 2πk′`, the unwrapping done about the half turn, so a guide that itself
//! comes back reversed, such as the `r` of frames that closed that way, is followed), plus
//! `2π·k`.
//!
//! A guide of axes (`axis`: a carbonyl bond, a director field, where `g` and `−g` say the
//! same) is unwrapped modulo π instead (each angle within π/2 of the one before): the frame
//! follows the sign that continues it, as molecular cartoon renderers flip alternate
//! peptide planes. The first usable row keeps its sign; a closed curve still closes (the
//! seam stays modulo 2π: axes that come back reversed after a round spread the half turn).
//!
//! The frames of the previous time step may be a second target (`previous`, their `r`
//! columns `p_i` at the angles `ψ_i` from the RMF, weight `W_p`, `v_i = sin²∠(p_i, t_i)`):
//!
//! `E(α) = Σ_i (h̄ / h_i)(α_{i+1} − α_i)² + Σ_i (μ_i / h̄)[W w_i (α_i − φ_i)² + W_p v_i (α_i − ψ_i)²]`
//!
//! `ψ` is unwrapped along the samples like `φ`, then shifted by whole turns to within π of
//! `φ` at the first sample with both. A row's two terms are one, `c (α_i − ᾱ_i)²` plus a
//! constant, with `c = W w_i + W_p v_i` and `ᾱ_i = (W w_i φ_i + W_p v_i ψ_i) / c`, so the
//! system is the one above with these weights and angles.

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::constraints::wrap;
use super::geometry::signed_angle;
use crate::error::{InputError, Result};

/// The guide and how it is followed.
#[derive(Debug, Clone, Copy)]
pub struct Guide<'a> {
    /// One vector per distinct sample, or one vector for all.
    pub vectors: &'a [DVec3],
    /// `W`: the weight of the guide error against the twist rate (per sample).
    pub weight: f64,
    /// Angle (radians) between guide and `±t` below which the guide is ignored.
    pub tolerance: f64,
    /// Each vector is an axis (`±g` alike): the guide angles are unwrapped modulo π, so the
    /// frame follows whichever sign continues it.
    pub axis: bool,
    /// A second target: the `r` columns of the frames of the previous time step, one per
    /// distinct sample (empty: none), followed as directions.
    pub previous: &'a [DVec3],
    /// `W_p`: the weight of the previous frames' error against the twist rate (per sample).
    pub previous_weight: f64,
}

/// `a` modulo π, in `(−π/2, π/2]`: the turn to the nearer of `±g`.
fn wrap_half(a: f64) -> f64 {
    let w = a.rem_euclid(PI);
    if w > FRAC_PI_2 { w - PI } else { w }
}

/// Check the scalar options.
pub fn check(g: &Guide) -> Result<()> {
    if !(g.weight.is_finite() && g.weight > 0.0) {
        return Err(InputError::new(
            "guide_weight",
            format!("must be a positive finite number, got {}", g.weight),
        ));
    }
    if !(g.tolerance.is_finite() && g.tolerance >= 0.0 && g.tolerance < std::f64::consts::FRAC_PI_2)
    {
        return Err(InputError::new(
            "guide_tolerance",
            format!("must be an angle in [0, π/2) radians, got {}", g.tolerance),
        ));
    }
    if let Some(i) = g.vectors.iter().position(|v| !v.is_finite()) {
        return Err(InputError::new(
            "guide",
            format!("contains a non-finite value at row {i}"),
        ));
    }
    let weighed = g.previous_weight.is_finite() && g.previous_weight > 0.0;
    if !g.previous.is_empty() && !weighed {
        return Err(InputError::new(
            "previous_weight",
            format!(
                "must be a positive finite number, got {}",
                g.previous_weight
            ),
        ));
    }
    if let Some(i) = g.previous.iter().position(|v| !v.is_finite()) {
        return Err(InputError::new(
            "previous",
            format!("contains a non-finite value at row {i}"),
        ));
    }
    Ok(())
}

/// Solve the tridiagonal system `lo_i x_{i−1} + d_i x_i + up_i x_{i+1} = b_i` (`lo_0`,
/// `up_{n−1}` unused) by Thomas' algorithm; stable for the diagonally dominant systems here.
fn thomas(lo: &[f64], d: &[f64], up: &[f64], b: &[f64]) -> Vec<f64> {
    let n = d.len();
    // per-row working vectors (of this module: at most ~140 bytes a row at once), within
    // `super::WORKING_BYTES_PER_ROW` (checked free by the binding's `ensure_memory` probe)
    let mut c = vec![0.0; n];
    let mut x = vec![0.0; n];
    let mut den = d[0];
    c[0] = up[0] / den;
    x[0] = b[0] / den;
    for i in 1..n {
        den = d[i] - lo[i] * c[i - 1];
        if den == 0.0 {
            // the last pivot of a twist-rate system whose guide weight vanished below the
            // rounding of its diagonal: the row is the constant mode, which the caller has
            // already taken out (its right-hand side is rounding), so no correction there
            (c[i], x[i]) = (0.0, 0.0);
            continue;
        }
        c[i] = up[i] / den;
        x[i] = (b[i] - lo[i] * x[i - 1]) / den;
    }
    for i in (0..n - 1).rev() {
        x[i] -= c[i] * x[i + 1];
    }
    x
}

/// The cyclic system (corners `lo_0` at column `n − 1`, `up_{n−1}` at column 0) by Sherman
/// and Morrison's formula over two Thomas solves.
fn cyclic(lo: &[f64], d: &[f64], up: &[f64], b: &[f64]) -> Vec<f64> {
    let n = d.len();
    let (alpha, beta) = (up[n - 1], lo[0]);
    let gamma = -d[0];
    // per-row working vectors, within `super::WORKING_BYTES_PER_ROW` (checked free by the
    // binding's `ensure_memory` probe)
    let mut dd = d.to_vec();
    dd[0] -= gamma;
    dd[n - 1] -= alpha * beta / gamma;
    let x = thomas(lo, &dd, up, b);
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = alpha;
    let z = thomas(lo, &dd, up, &u);
    let f = (x[0] + beta * x[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
    x.iter().zip(&z).map(|(x, z)| x - f * z).collect()
}

/// Unwrap the angles along the samples (NaN: none), each within π (`axis`: π/2) of the one
/// before; the first row with an angle and the last angle.
fn unwrap(value: &mut [f64], axis: bool) -> Option<(usize, f64)> {
    let mut prev: Option<f64> = None;
    let mut first: Option<usize> = None;
    for (i, v) in value.iter_mut().enumerate() {
        if v.is_nan() {
            continue;
        }
        if let Some(p) = prev {
            *v = p + if axis {
                wrap_half(*v - p)
            } else {
                wrap(*v - p)
            };
        }
        prev = Some(*v);
        first.get_or_insert(i);
    }
    first.zip(prev)
}

/// Shift the unwrapped angles `a` by whole turns so that, at the first row where `b` has an
/// angle too (else at `a`'s first row against `b`'s first angle), `a` is within π of `b`.
fn align(a: &mut [f64], b: &[f64]) {
    let both = (0..a.len()).find(|&i| !a[i].is_nan() && !b[i].is_nan());
    let pair = match both {
        Some(i) => Some((a[i], b[i])),
        None => a
            .iter()
            .find(|v| !v.is_nan())
            .zip(b.iter().find(|v| !v.is_nan()))
            .map(|(&x, &y)| (x, y)),
    };
    if let Some((x, y)) = pair {
        let shift = (y - wrap(y - x)) - x;
        let turns = (shift / TAU).round() * TAU;
        for v in a.iter_mut() {
            *v += turns;
        }
    }
}

/// The twist `α_i` of every distinct sample (see the module text). `r`, `t`: the RMF's
/// reference vectors and unit tangents; `seg`: segment lengths; `closing`: the RMF's closing
/// angle (closed curves); `pins`: fixed orientations (sorted distinct rows, unit vectors
/// ⟂ their tangents); `turns`: extra turns across the seam of a closed curve. `cancel` is
/// polled between the passes; a cancelled call returns no twist (see [`crate::run::cancel`]).
// Kept whole: one assembly of the cyclic tridiagonal system (guide terms, pins, the seam)
// over shared working vectors, then its solve.
#[allow(clippy::too_many_arguments)]
pub fn twist(
    r: &[DVec3],
    t: &[DVec3],
    seg: &[f64],
    closed: bool,
    closing: f64,
    guide: &Guide,
    pins: &[(usize, DVec3)],
    turns: f64,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<f64>> {
    check(guide)?;
    let n = t.len();
    let g = |i: usize| guide.vectors[if guide.vectors.len() == 1 { 0 } else { i }];
    let min_sin = guide.tolerance.sin();
    // data per sample: None, a guide angle with its weight, or a pin; these and the
    // system's rows below are per-row working vectors, within `super::WORKING_BYTES_PER_ROW`
    // (checked free by the binding's `ensure_memory` probe)
    let mut value = vec![f64::NAN; n];
    let mut weight = vec![0.0; n];
    let mut pinned = vec![false; n];
    for &(k, v) in pins {
        value[k] = signed_angle(r[k], v, t[k]);
        pinned[k] = true;
    }
    let usable = |v: DVec3, i: usize| -> Option<(f64, f64)> {
        let len = v.length();
        let p = v - v.dot(t[i]) * t[i];
        let s = p.length() / len;
        (len > 0.0 && s > min_sin && s > 1e-12).then(|| (signed_angle(r[i], p, t[i]), s * s))
    };
    for i in 0..n {
        if pinned[i] {
            continue;
        }
        if let Some((v, w)) = usable(g(i), i) {
            value[i] = v;
            weight[i] = w;
        }
    }
    if cancel() {
        return Ok(Vec::new());
    }
    // unwrap along the samples
    let mut ends = unwrap(&mut value, guide.axis);
    // the weight of the guide term in the rows below (1 where the previous frames are
    // merged in, their weights then folded into `weight`)
    let mut scale = guide.weight;
    if !guide.previous.is_empty() {
        let mut before = vec![f64::NAN; n];
        let mut wp = vec![0.0; n];
        for i in 0..n {
            if !pinned[i] {
                if let Some((v, w)) = usable(guide.previous[i], i) {
                    before[i] = v;
                    wp[i] = w;
                }
            }
        }
        if unwrap(&mut before, false).is_some() {
            align(&mut before, &value);
        }
        for i in 0..n {
            let (cg, cp) = (guide.weight * weight[i], guide.previous_weight * wp[i]);
            if pinned[i] || cp == 0.0 {
                weight[i] = cg;
            } else if cg == 0.0 {
                (value[i], weight[i]) = (before[i], cp);
            } else {
                (value[i], weight[i]) = ((cg * value[i] + cp * before[i]) / (cg + cp), cg + cp);
            }
        }
        scale = 1.0;
        let first = value.iter().position(|v| !v.is_nan());
        let last = value.iter().rposition(|v| !v.is_nan());
        ends = first.zip(last).map(|(f, l)| (f, value[l]));
    }
    let first = ends.map(|e| e.0);
    let prev = ends.map(|e| e.1);
    let Some(first) = first else {
        // no usable guide and no pin: the RMF (a closed curve with its closing twist)
        let mut alpha = vec![0.0; n];
        if closed {
            let total = wrap(closing) + TAU * turns;
            let length: f64 = seg.iter().sum();
            let mut arc = 0.0;
            for (i, a) in alpha.iter_mut().enumerate() {
                *a = total * arc / length;
                arc += seg[i];
            }
        }
        return Ok(alpha);
    };
    let m = if closed { n } else { n - 1 };
    let mean = seg[..m].iter().sum::<f64>() / m as f64;
    // seam offset: the first value seen again after one round, unwrapped after the last
    let seam = if closed {
        let last = prev.unwrap_or(value[first]);
        // a half turn at the seam (turns = k + ½): unwrapped about it, the whole turns after
        let whole = turns.floor();
        let half = if whole == turns { 0.0 } else { PI };
        let again = value[first] + closing + half;
        let again = last + wrap(again - last);
        again - value[first] + TAU * if half == 0.0 { turns } else { whole }
    } else {
        0.0
    };
    if cancel() {
        return Ok(Vec::new());
    }
    let mut lo = vec![0.0; n];
    let mut up = vec![0.0; n];
    let mut d = vec![0.0; n];
    let mut b = vec![0.0; n];
    for i in 0..m {
        let j = (i + 1) % n;
        let e = mean / seg[i];
        d[i] += e;
        d[j] += e;
        up[i] -= e;
        lo[j] -= e;
        if closed && i == n - 1 {
            // e (α_0 + D − α_{n−1})²
            b[0] -= e * seam;
            b[n - 1] += e * seam;
        }
    }
    if cancel() {
        return Ok(Vec::new());
    }
    for i in 0..n {
        let mu = 0.5
            * (if i > 0 || closed {
                seg[(i + n - 1) % n]
            } else {
                0.0
            } + if i < m { seg[i] } else { 0.0 });
        let c = scale * weight[i] * mu / mean;
        d[i] += c;
        if c > 0.0 {
            b[i] += c * value[i];
        }
        weight[i] = c; // the guide's term of the row, for the shift below
    }
    if cancel() {
        return Ok(Vec::new());
    }
    // pins: identity rows, their couplings moved to the right-hand side (rows p and q couple
    // to row i through up[p] and lo[q]; across the seam these are the corners)
    for i in 0..n {
        if !pinned[i] {
            continue;
        }
        let v = value[i];
        if i > 0 || closed {
            let p = (i + n - 1) % n;
            b[p] -= up[p] * v;
            up[p] = 0.0;
        }
        if i < n - 1 || closed {
            let q = (i + 1) % n;
            b[q] -= lo[q] * v;
            lo[q] = 0.0;
        }
        d[i] = 1.0;
        lo[i] = 0.0;
        up[i] = 0.0;
        b[i] = v;
    }
    if cancel() {
        return Ok(Vec::new());
    }
    let any_pin = pinned.iter().any(|&p| p);
    if !any_pin {
        // Without pins the twist-rate term has the constants as its null space, and as the
        // guide's weight goes to 0 the system's condition grows like 1/weight. Solved for the
        // difference δ = α − ᾱ from the guide's weighted mean ᾱ instead (the same solution:
        // the twist-rate rows annihilate a constant), the right-hand side is of the weight's
        // size too, so rounding stays at the level of α and the limit weight → 0⁺ is the best
        // constant fit, ᾱ.
        let (mut sw, mut swv) = (0.0, 0.0);
        for (&c, &v) in weight.iter().zip(&value) {
            if c > 0.0 {
                sw += c;
                swv += c * v;
            }
        }
        let shift = if sw > 0.0 { swv / sw } else { 0.0 };
        for (bi, &c) in b.iter_mut().zip(&weight) {
            *bi -= c * shift;
        }
        let x = match closed {
            true => cyclic(&lo, &d, &up, &b),
            false => thomas(&lo, &d, &up, &b),
        };
        return Ok(x.into_iter().map(|v| v + shift).collect());
    }
    // a closed curve with a pin: the corners are gone once a pin sits at row 0; rotate the
    // rows so that it does, solve the open system and rotate back
    let p0 = pinned.iter().position(|&p| p).unwrap_or(0);
    let rot = |v: &[f64]| -> Vec<f64> { (0..n).map(|i| v[(i + p0) % n]).collect() };
    let (mut lo2, d2, mut up2, b2) = (rot(&lo), rot(&d), rot(&up), rot(&b));
    lo2[0] = 0.0;
    up2[n - 1] = 0.0;
    let x = thomas(&lo2, &d2, &up2, &b2);
    Ok((0..n).map(|i| x[(i + n - p0) % n]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gaussian elimination with partial pivoting on a dense copy.
    #[allow(clippy::needless_range_loop)]
    fn dense(a: &mut [Vec<f64>], b: &mut [f64]) -> Vec<f64> {
        let n = b.len();
        for k in 0..n {
            let p = (k..n)
                .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
                .unwrap_or(k);
            a.swap(k, p);
            b.swap(k, p);
            for i in k + 1..n {
                let f = a[i][k] / a[k][k];
                for j in k..n {
                    a[i][j] -= f * a[k][j];
                }
                b[i] -= f * b[k];
            }
        }
        let mut x = vec![0.0; n];
        for k in (0..n).rev() {
            let s: f64 = (k + 1..n).map(|j| a[k][j] * x[j]).sum();
            x[k] = (b[k] - s) / a[k][k];
        }
        x
    }

    /// The cyclic solver agrees with a dense solve of the same SPD system.
    #[allow(clippy::needless_range_loop)]
    #[test]
    fn cyclic_tridiagonal_matches_a_dense_solve() {
        let n = 9;
        let e: Vec<f64> = (0..n).map(|i| 1.0 + 0.3 * (i as f64).sin()).collect();
        let c: Vec<f64> = (0..n).map(|i| 0.1 + 0.05 * i as f64).collect();
        let mut lo = vec![0.0; n];
        let mut up = vec![0.0; n];
        let mut d = c.clone();
        for i in 0..n {
            let j = (i + 1) % n;
            d[i] += e[i];
            d[j] += e[i];
            up[i] = -e[i];
            lo[j] = -e[i];
        }
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).cos()).collect();
        let x = cyclic(&lo, &d, &up, &b);
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            a[i][i] = d[i];
            a[i][(i + n - 1) % n] += lo[i];
            a[i][(i + 1) % n] += up[i];
        }
        let want = dense(&mut a, &mut b.clone());
        for i in 0..n {
            assert!(
                (x[i] - want[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                x[i],
                want[i]
            );
        }
    }
}
