//! Frenet frame with a continuous fill where it is undefined.
//!
//! Where the curvature is non-negligible the frame is the Frenet frame:
//! `r = N` (principal normal, towards the centre of curvature), `s = B = t × N`, `t`.
//! Where `κ ≈ 0` (an inflection sample or a straight run) the Frenet frame does not exist.
//! There the frame is carried by double reflection (the rotation-minimising frame) from the
//! last defined frame, and the mismatch with the next defined Frenet frame is spread
//! linearly in arc length over the run (the least-squared-angular-speed interpolation of
//! Wang et al. §6.3), so the filled frames are continuous in the run. Runs at the open ends
//! are carried from the nearest defined frame; a closed curve wraps around. A curve that is
//! straight everywhere gets the RMF from [`super::geometry::any_perpendicular`].
//!
//! Note that the Frenet frame itself turns by π about `t` across an inflection; that is a
//! property of the frame, not of the fill.

use glam::DVec3;

use super::double_reflection::DoubleReflection;
use super::geometry::{rotate_about, signed_angle};
use super::transport::{Step, write_frame};

/// Rows between two polls of the cancel hook ([`frenet_into`]).
const CANCEL_ROWS: usize = 1 << 16;

/// Fill `out` (`rows` frames) from principal normals `normal[i]` (None where undefined).
///
/// Polls `cancel` between its passes and every [`CANCEL_ROWS`] rows of the transport across gaps,
/// and returns at once (with `out` incomplete) when it says stop (see [`crate::run::cancel`]).
pub fn frenet_into(
    dr: &DoubleReflection,
    normal: &[Option<DVec3>],
    seg: &[f64],
    closed: bool,
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) {
    let t = dr.t;
    let n = t.len();
    let rows = out.len() / 9;
    // `defined`, `r`, `gaps` and a gap's `prov`/`arc` are per-row working vectors, within
    // `super::WORKING_BYTES_PER_ROW` (checked free by the binding's `ensure_memory` probe)
    let defined: Vec<usize> = (0..n).filter(|&i| normal[i].is_some()).collect();
    if cancel() {
        return;
    }
    let mut r = vec![DVec3::ZERO; n];
    for &d in &defined {
        r[d] = normal[d].unwrap_or(DVec3::ZERO);
    }
    let seg_at = |i: usize| seg[i % seg.len()];
    // gaps between consecutive defined samples (wrapping when closed)
    let mut gaps: Vec<(usize, usize)> = defined
        .windows(2)
        .filter(|w| w[1] > w[0] + 1)
        .map(|w| (w[0], w[1]))
        .collect();
    if closed {
        let (first, last) = (defined[0], defined[defined.len() - 1]);
        if first + n > last + 1 {
            gaps.push((last, first + n));
        }
    }
    if cancel() {
        return;
    }
    for (a, b) in gaps {
        // forward transport a -> b (indices mod n), then spread the mismatch in arc length
        let mut cur = r[a];
        let mut s = 0.0;
        let mut prov = Vec::with_capacity(b - a);
        let mut arc = Vec::with_capacity(b - a);
        for i in a..b {
            if (i - a) % CANCEL_ROWS == CANCEL_ROWS - 1 && cancel() {
                return;
            }
            cur = dr.step(i % n, cur);
            s += seg_at(i);
            prov.push(cur);
            arc.push(s);
        }
        let (rb, tb) = (r[b % n], t[b % n]);
        let beta = signed_angle(cur, rb, tb);
        let total = s;
        for (k, i) in (a + 1..b).enumerate() {
            let ti = t[i % n];
            r[i % n] = rotate_about(prov[k], ti, beta * arc[k] / total);
        }
    }
    if cancel() {
        return;
    }
    if !closed {
        let (first, last) = (defined[0], defined[defined.len() - 1]);
        for i in (0..first).rev() {
            r[i] = dr.step_back(i, r[i + 1]);
        }
        for i in last + 1..n {
            r[i] = dr.step(i - 1, r[i - 1]);
        }
    }
    if cancel() {
        return;
    }
    for (i, f) in out.chunks_exact_mut(9).enumerate().take(n) {
        if i % CANCEL_ROWS == CANCEL_ROWS - 1 && cancel() {
            return;
        }
        write_frame(f, r[i], t[i]);
    }
    if rows == n + 1 {
        let (head, tail) = out.split_at_mut(9 * n);
        tail[..9].copy_from_slice(&head[..9]);
    }
}
