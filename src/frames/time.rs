//! Frames coherent in time: the frames of a moving curve that change no more between time
//! steps than the curve does.
//!
//! All rotation-minimising frames of a curve differ by one constant turn `c` about the
//! tangents (Zheng 2008, *Studies on Motion and Deformation in Graphics*, Cor. 4.1.3; the
//! closing twist of a closed curve does not depend on the start either). Of these, the one
//! closest to the frames `P_i` of the previous time step (Ma 1996, *Curve and Surface Framing
//! for Scientific Visualization and Domain Dependent Navigation*, §3.5.3: align the frames of
//! similar curves by one rotation) minimises `Σ_i ‖R_t(c) U_i − P_i‖²_F` (every frame counts
//! the same). With `U_i = (r, s, t)` and `R_t(c)` turning `(r, s)` by `c`, the sum is least
//! for `c = atan2(Σ s·P_r − r·P_s, Σ r·P_r + s·P_s)` (`P_r`, `P_s` the first two columns of
//! `P_i`), in closed form and O(n). A sequence of curves `(T, n)` gets its RMFs in parallel
//! over `T`; then, in order, each step is turned to its predecessor.

use crate::run::cancel;
use glam::DVec3;
use rayon::prelude::*;

use super::carry::turn_frame;
use super::{Orientation, Request, compute_into, validate};
use crate::error::{InputError, Result};
use crate::run::cancel::Cancel;

/// Column `k` of a row-major frame.
fn col(f: &[f64], k: usize) -> DVec3 {
    DVec3::new(f[k], f[3 + k], f[6 + k])
}

/// Rows per block of the passes over the frames (a block is skipped once the hook says
/// stop).
const BLOCK: usize = 1024;

/// Turn every frame of `out` about its tangent by `c` (the columns `r, s`).
///
/// Polls `cancel` before every block of rows and skips the remaining blocks once it says stop (see
/// [`crate::run::cancel`]).
pub fn turn_all(out: &mut [f64], c: f64, cancel: Cancel<'_>) {
    let (sin, cos) = c.sin_cos();
    out.par_chunks_mut(9 * BLOCK).for_each(|b| {
        if cancel() {
            return;
        }
        for f in b.chunks_exact_mut(9) {
            turn_frame(f, cos, sin);
        }
    });
}

/// The turn `c` that brings the frames `out` closest to `previous` (both row-major,
/// `9·rows` values).
///
/// Polls `cancel` before every block of rows (a cancelled call returns a meaningless turn, see
/// [`crate::run::cancel`]).
pub fn best_turn(out: &[f64], previous: &[f64], cancel: Cancel<'_>) -> f64 {
    let (y, x) = out
        .par_chunks(9 * BLOCK)
        .zip(previous.par_chunks(9 * BLOCK))
        .map(|(a, b)| {
            if cancel() {
                return (0.0, 0.0);
            }
            a.chunks_exact(9)
                .zip(b.chunks_exact(9))
                .fold((0.0, 0.0), |(y, x), (f, p)| {
                    let (r, s, pr, ps) = (col(f, 0), col(f, 1), col(p, 0), col(p, 1));
                    (y + s.dot(pr) - r.dot(ps), x + r.dot(pr) + s.dot(ps))
                })
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    y.atan2(x)
}

/// `previous` must hold one finite rotation per row.
pub fn check_previous(previous: &[[f64; 9]], rows: usize) -> Result<()> {
    if previous.len() != rows {
        return Err(InputError::new(
            "previous",
            format!(
                "expected shape ({rows}, 3, 3) (one frame per sample of the curve), got \
                 ({}, 3, 3)",
                previous.len()
            ),
        ));
    }
    if let Some(i) = validate::first_bad(previous, validate::is_rotation, &cancel::never) {
        return Err(InputError::new(
            "previous",
            format!("row {i} is not a rotation matrix (columns r, s, t orthonormal, det +1)"),
        ));
    }
    Ok(())
}

/// Turn the frames `out` (one curve) to be closest to `previous`.
///
/// Polls `cancel` before every block of rows of its two passes (a cancelled call leaves `out`
/// incomplete, see [`crate::run::cancel`]).
pub fn align(out: &mut [f64], previous: &[[f64; 9]], cancel: Cancel<'_>) -> Result<()> {
    check_previous(previous, out.len() / 9)?;
    let prev: &[f64] = bytemuck::cast_slice(previous);
    let c = best_turn(out, prev, cancel);
    if cancel() {
        return Ok(());
    }
    turn_all(out, c, cancel);
    Ok(())
}

/// Frames of `steps` time steps of one curve of `rows` samples stored back to back in the
/// request's arrays: the RMF of every step (in parallel), then each turned to be closest to
/// the step before (step 0 to `previous` when given, else it starts from `initial`).
///
/// Polls `cancel` before every time step, inside each step's frames
/// ([`super::compute_into`]) and before every block of rows of the turns, and returns
/// at once (with `out` incomplete) when it says stop (see [`crate::run::cancel`]); adds 1 to `done`
/// as each step's frames are computed (a progress count).
#[allow(clippy::too_many_arguments)]
pub fn frames_in_time(
    template: &Request,
    steps: usize,
    rows: usize,
    initial: Option<Orientation>,
    previous: Option<&[[f64; 9]]>,
    out: &mut [f64],
    cancel: Cancel<'_>,
    done: Option<&std::sync::atomic::AtomicUsize>,
) -> Result<()> {
    if template.end.is_some() {
        return Err(InputError::new(
            "end",
            "cannot be combined with frames in time (each step's start is chosen to match \
             the step before)",
        ));
    }
    if let Some(p) = previous {
        if initial.is_some() {
            return Err(InputError::new(
                "initial",
                "cannot be combined with previous (the start is chosen to match previous)",
            ));
        }
        check_previous(p, rows)?;
    }
    let total = template
        .points
        .map(<[DVec3]>::len)
        .or(template.tangents.map(<[DVec3]>::len))
        .unwrap_or(0);
    if total != steps * rows || out.len() != 9 * total {
        return Err(InputError::new(
            template.points_arg(),
            format!("expected {steps} time steps of {rows} samples, got {total} rows"),
        ));
    }
    out.par_chunks_mut(9 * rows.max(1))
        .enumerate()
        .map(|(k, buf)| {
            if cancel() {
                return Ok(());
            }
            let (a, b) = (k * rows, (k + 1) * rows);
            let req = Request {
                points: template.points.map(|p| &p[a..b]),
                tangents: template.tangents.map(|t| &t[a..b]),
                analytic: None,
                initial,
                end: None,
                ..*template
            };
            let step = compute_into(&req, buf, cancel)
                .map(|_| ())
                .map_err(|e| e.context(&format!("time step {k}")));
            if let Some(d) = done {
                d.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
            step
        })
        .collect::<Result<()>>()?; // no buffer: the first error or `()`
    if cancel() {
        return Ok(());
    }
    if let Some(p) = previous {
        let c = best_turn(&out[..9 * rows], bytemuck::cast_slice(p), cancel);
        turn_all(&mut out[..9 * rows], c, cancel);
    }
    for k in 1..steps {
        if cancel() {
            return Ok(());
        }
        let (before, now) = out[9 * rows * (k - 1)..9 * rows * (k + 1)].split_at_mut(9 * rows);
        let c = best_turn(now, before, cancel);
        turn_all(now, c, cancel);
    }
    Ok(())
}
