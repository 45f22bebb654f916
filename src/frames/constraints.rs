//! Frames meeting several prescribed orientations ("constraints"), interior samples included.
//!
//! Every frame that keeps `t` is the RMF `(r, s, t)` turned about `t` by an angle `α`:
//! `g = cos α r + sin α (t × r)` (Zheng 2008, *Studies on Motion and Deformation in
//! Graphics*, §7.3 eq. 7.3; Wang, Jüttler, Zheng & Liu, *Computation of Rotation Minimizing
//! Frames*, ACM TOG 27(1), 2008, §6.3). Its angular velocity is `ω = κ b + α′ t` (eq. 7.4).
//! A constraint at sample `k` fixes `α_k = a_k + 2πj`, `a_k` the signed angle from the RMF's
//! `r_k` to the prescribed vector. Between consecutive constraints `k_j < k_{j+1}` the twist
//! `Δ_j = wrap(a_{j+1} − a_j) + 2π·turns_j` (`wrap` into (−π, π]: the least turn) is spread
//! by one of two variational rules:
//!
//! * **arc length** — least total *squared* angular speed `∫(κ² + α′²) ds` (eq. 7.8): `α″ = 0`,
//!   `α` linear in arc length. Discretely `Σ Δα_i² / h_i` is least for `Δα_i ∝ h_i` (the
//!   segment lengths).
//! * **min angular speed** — least total angular speed `∫√(κ² + α′²) ds` (eq. 7.5); its Euler
//!   equation (7.6) gives `α′ = Cκ` (7.7): the twist follows the curvature. Discretely, with
//!   `θ_i` the angle between consecutive tangents, `Σ √(θ_i² + Δα_i²)` under `Σ Δα_i = Δ`
//!   has the stationarity condition `Δα_i / √(θ_i² + Δα_i²) = λ`, i.e. `Δα_i = Δ θ_i / Σθ`
//!   (exactly, per interval). On an interval with no turning (`Σθ ≤` [`STRAIGHT_TURN`]) the
//!   minimiser is not unique (any monotone `α`); the arc-length rule is used there.
//!
//! Before the first and after the last constraint of an open curve `α` stays constant (the
//! RMF turned to meet the nearest constraint). On a closed curve the intervals are cyclic;
//! across the seam the RMF does not close but differs by its closing angle `c`, so the
//! interval from the last constraint `k_m` round to the first `k_0` has the twist
//! `wrap(a_0 + c − a_m) + 2π·turns`.

use glam::DVec3;
use std::f64::consts::{PI, TAU};

use super::geometry::signed_angle;
use crate::error::{InputError, Result};

/// Total turning (radians) of an interval below which the curvature rule falls back to arc
/// length.
pub const STRAIGHT_TURN: f64 = 1e-9;

/// How the twist between consecutive constraints is spread.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TwistRule {
    /// Linear in arc length (least `∫(κ² + α′²) ds`).
    #[default]
    ArcLength,
    /// Proportional to the turning of the tangent (least `∫√(κ² + α′²) ds`).
    MinAngularSpeed,
}

/// An angle brought into (−π, π].
pub fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// The angle between unit tangents `a` and `b`.
fn turning(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Cumulative weights `W_0 = 0 … W_m` (`m` segments, `m = n` for a closed curve) of the
/// rule: arc length, or the turning of the tangent.
fn cumulative(t: &[DVec3], seg: &[f64], closed: bool, rule: TwistRule) -> (Vec<f64>, Vec<f64>) {
    let n = t.len();
    let m = if closed { n } else { n - 1 };
    // per-row working vectors, within `super::WORKING_BYTES_PER_ROW` (checked free by the
    // binding's `ensure_memory` probe)
    let mut arc = vec![0.0; m + 1];
    let mut turn = vec![0.0; m + 1];
    for i in 0..m {
        arc[i + 1] = arc[i] + seg[i];
        if rule == TwistRule::MinAngularSpeed {
            turn[i + 1] = turn[i] + turning(t[i], t[(i + 1) % n]);
        }
    }
    (arc, turn)
}

/// The number of twist intervals of `pins` constraints.
pub fn intervals(pins: usize, closed: bool) -> usize {
    if closed { pins } else { pins.saturating_sub(1) }
}

/// The extra turns of interval `j`: one count for all, or one per interval.
fn turns_of(turns: &[f64], j: usize, count: usize) -> Result<f64> {
    match turns.len() {
        0 => Ok(0.0),
        1 => Ok(turns[0]),
        k if k == count => Ok(turns[j]),
        k => Err(InputError::new(
            "turns",
            format!("expected one count or one per twist interval ({count}), got {k}"),
        )),
    }
}

/// The twist `α_i` (about `t_i`, from the RMF's `r_i`) of every distinct sample that meets
/// `pins` (sorted by row, distinct rows `< n`, unit target vectors ⟂ their tangents).
///
/// * `r`, `t`: the RMF's reference vectors and unit tangents of the `n` distinct samples.
/// * `seg`: segment lengths (`n − 1`, or `n` for a closed curve).
/// * `closing`: the RMF's closing angle (closed curves).
#[allow(clippy::too_many_arguments)]
pub fn twist(
    r: &[DVec3],
    t: &[DVec3],
    seg: &[f64],
    closed: bool,
    closing: f64,
    pins: &[(usize, DVec3)],
    rule: TwistRule,
    turns: &[f64],
) -> Result<Vec<f64>> {
    let n = t.len();
    // per-row (and per-pin, pins ≤ rows) working vectors, within
    // `super::WORKING_BYTES_PER_ROW` (checked free by the binding's `ensure_memory` probe)
    let mut alpha = vec![0.0; n];
    if pins.is_empty() {
        return Ok(alpha);
    }
    let a: Vec<f64> = pins
        .iter()
        .map(|&(k, g)| signed_angle(r[k], g, t[k]))
        .collect();
    let (arc, turn) = cumulative(t, seg, closed, rule);
    let count = intervals(pins.len(), closed);
    let m = if closed { n } else { n - 1 };
    // the weight at extended index e (e ≥ n: once round a closed curve)
    let at = |w: &[f64], e: usize| {
        if e > m { w[m] + w[e - n] } else { w[e] }
    };
    alpha[pins[0].0] = a[0];
    for j in 0..count {
        let (k0, a0) = (pins[j].0, a[j]);
        let (k1, a1) = if j + 1 < pins.len() {
            (pins[j + 1].0, a[j + 1])
        } else {
            // closed: round the seam to the first constraint
            (pins[0].0 + n, a[0] + closing)
        };
        let extra = turns_of(turns, j, count)?;
        let total = wrap(a1 - a0) + TAU * extra;
        // round the seam to the first pin again: a whole number of turns lands on its own
        // value (up to whole turns); a half number (the closing twist only) lands a half turn
        // off it, and the pinned row keeps its value (the frames close up to a half turn)
        let last = match k1 >= n && extra != extra.round() {
            true => k1 - 1,
            false => k1,
        };
        let w = if rule == TwistRule::MinAngularSpeed
            && at(&turn, k1) - at(&turn, k0) > STRAIGHT_TURN
        {
            &turn
        } else {
            &arc
        };
        let (w0, span) = (at(w, k0), at(w, k1) - at(w, k0));
        for e in k0..=last {
            let f = if span > 0.0 {
                (at(w, e) - w0) / span
            } else {
                (e - k0) as f64 / (k1 - k0) as f64
            };
            let v = a0 + total * f;
            if e < n {
                alpha[e] = v;
            } else {
                // row e − n carries the RMF, which is the extended one turned by `closing`
                alpha[e - n] = v - closing;
            }
        }
    }
    if !closed {
        let (first, last) = (pins[0].0, pins[pins.len() - 1].0);
        let (lo, hi) = (alpha[first], alpha[last]);
        alpha[..first].fill(lo);
        alpha[last + 1..].fill(hi);
    }
    Ok(alpha)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_the_half_open_range() {
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(-PI), PI);
        assert!((wrap(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap(0.25) - 0.25).abs() < 1e-16);
    }

    /// On a plane circle the RMF is the constant normal; two constraints a quarter turn apart
    /// spread the turn linearly, and the rows outside keep the nearest constraint's angle.
    #[test]
    fn two_constraints_on_a_circle_spread_the_turn() {
        let n = 11;
        let t: Vec<DVec3> = (0..n)
            .map(|i| {
                let u = 0.1 * i as f64;
                DVec3::new(-u.sin(), u.cos(), 0.0)
            })
            .collect();
        let r = vec![DVec3::Z; n];
        let seg = vec![0.1; n - 1];
        let g = |a: f64, i: usize| a.cos() * DVec3::Z + a.sin() * t[i].cross(DVec3::Z);
        let pins = [(2, g(0.0, 2)), (7, g(PI / 2.0, 7))];
        for rule in [TwistRule::ArcLength, TwistRule::MinAngularSpeed] {
            let alpha = twist(&r, &t, &seg, false, 0.0, &pins, rule, &[]).expect("valid");
            for (i, a) in alpha.iter().enumerate() {
                let want = (i.clamp(2, 7) - 2) as f64 / 5.0 * PI / 2.0;
                assert!((a - want).abs() < 1e-12, "{rule:?} row {i}: {a} vs {want}");
            }
        }
        let e = twist(
            &r,
            &t,
            &seg,
            false,
            0.0,
            &pins,
            TwistRule::ArcLength,
            &[1.0, 2.0, 3.0],
        );
        assert_eq!(e.map_err(|e| e.arg).unwrap_err(), "turns");
    }
}
