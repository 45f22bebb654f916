//! Reconstruction on the posed spine: unbend – transfer – bend (Zhuo 2014 §4.2.1, §5.2.1).
//! The bend reads the binormal `x` and the radial `θ` in the posed spine's Frenet frame after
//! the transfer (as Eq. 21's `θ1` implies; the old `x0`, `θ0` break `det = 1`). The thesis
//! leaves open whether the stretch `x*/σ` is applied before or after the change of frame;
//! both are exactly volume preserving, and we stretch after the rotation, in the posed frame.
//!
//! Per vertex: evaluate the posed spine at the registered `(k, a)`; `λ = σ1/σ0`; unbend the
//! stored offset with the rest curvature; carry its RMF coordinates over to the posed RMF
//! (the transfer is a rotation about the straightened axis, det 1), turned by the optional
//! twist `φ(k, a)` (linear between samples; Fig. 23); stretch and bend with the posed
//! curvature read in the posed frame. Past the spine's ends (τ ≠ 0) both curvatures are 0
//! and `τ` is scaled by `λ` while the section shrinks by `1/λ`: still det 1.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::bind::COORDS;
use super::solve::{Solution, bend, unbend};
use super::spine::SpineModel;
use crate::error::{InputError, Result};
use crate::math::scale;
use crate::run::cancel::Cancel;

/// Deform a registered shape. `twist` is empty or one angle (rad) per spine sample.
/// Writes the vertices to `out` and the per-vertex flags (see [`super::solve`]) to `flags`.
///
/// Polls `cancel` before each block of vertices (see [`crate::run::cancel`]).
#[allow(clippy::too_many_arguments)]
pub fn deform(
    posed: &SpineModel,
    edge: &[i64],
    coords: &[f64],
    sol: Solution,
    twist: &[f64],
    out: &mut [DVec3],
    flags: &mut [u8],
    cancel: Cancel<'_>,
) -> Result<()> {
    let n = posed.len();
    let nv = edge.len();
    if coords.len() != COORDS * nv || out.len() != nv || flags.len() != nv {
        return Err(InputError::new("coords", "inconsistent array sizes"));
    }
    if !twist.is_empty() && twist.len() != n {
        return Err(InputError::new(
            "twist",
            format!(
                "expected one angle per spine sample ({n}), got {}",
                twist.len()
            ),
        ));
    }
    if let Some(i) = twist.iter().position(|x| !x.is_finite()) {
        return Err(InputError::new("twist", format!("row {i} is not finite")));
    }
    if let Some(i) = edge.iter().position(|&k| k < 0 || k as usize + 1 >= n) {
        return Err(InputError::new(
            "posed_spine",
            format!(
                "vertex {i} is bound to edge {} of a spine with {n} points",
                edge[i]
            ),
        ));
    }
    let (run, w) = match sol {
        Solution::None => (batch::<0> as Batch, 0.0),
        Solution::Normal => (batch::<1> as Batch, 0.0),
        Solution::Binormal => (batch::<2> as Batch, 0.0),
        Solution::Radial => (batch::<3> as Batch, 0.0),
        Solution::Blend(w) => (batch::<4> as Batch, super::blend::check_weight(w)?),
    };
    out.par_chunks_mut(TASK)
        .zip(flags.par_chunks_mut(TASK))
        .zip(edge.par_chunks(TASK).zip(coords.par_chunks(COORDS * TASK)))
        .for_each(|((o, f), (e, c))| {
            if !cancel() {
                run(posed, w, twist, e, c, o, f)
            }
        });
    if posed.scale.exp() != 0 {
        // a binding and a pose whose sizes differ by more than the range of f64 between
        // them (a stretch λ past it), or a result past the largest float
        if let Some(i) = out.par_iter().position_first(|p| !p.is_finite()) {
            if !cancel() {
                return Err(InputError::new(
                    "posed_spine",
                    format!(
                        "vertex {i}: the posed position is out of range of float64 (the \
                         stretch between the rest spine and the posed spine at size {:e} is \
                         out of range)",
                        scale::ldexp(1.0, -posed.scale.exp())
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Vertices per parallel task.
const TASK: usize = 1024;
/// Vertices evaluated together (see [`SpineModel::eval_lanes`]).
const LANES: usize = 4;

/// One task's vertices (see [`batch`]).
type Batch = fn(&SpineModel, f64, &[f64], &[i64], &[f64], &mut [DVec3], &mut [u8]);

/// The solution of instance `S` (`w`: the blend weight, used by `S = 4` only).
#[inline(always)]
const fn solution(s: u8, w: f64) -> Solution {
    match s {
        0 => Solution::None,
        1 => Solution::Normal,
        2 => Solution::Binormal,
        3 => Solution::Radial,
        _ => Solution::Blend(w),
    }
}

/// One task's vertices, `LANES` at a time; the solution is a constant of the instance, so
/// its branch leaves the loop (`w`: the blend weight of [`Solution::Blend`]).
fn batch<const S: u8>(
    posed: &SpineModel,
    w: f64,
    twist: &[f64],
    edge: &[i64],
    coords: &[f64],
    out: &mut [DVec3],
    flags: &mut [u8],
) {
    let mut i = 0;
    while i + LANES <= out.len() {
        lanes::<S, LANES>(
            posed,
            w,
            twist,
            &edge[i..],
            &coords[COORDS * i..],
            &mut out[i..],
            &mut flags[i..],
        );
        i += LANES;
    }
    while i < out.len() {
        lanes::<S, 1>(
            posed,
            w,
            twist,
            &edge[i..],
            &coords[COORDS * i..],
            &mut out[i..],
            &mut flags[i..],
        );
        i += 1;
    }
}

#[inline(always)]
fn lanes<const S: u8, const L: usize>(
    posed: &SpineModel,
    w: f64,
    twist: &[f64],
    edge: &[i64],
    coords: &[f64],
    out: &mut [DVec3],
    flags: &mut [u8],
) {
    let sol = solution(S, w);
    // lengths of the binding (input units) to the posed model's units and back
    let (to_model, to_input) = (posed.scale, posed.scale.inverse());
    let k: [usize; L] = std::array::from_fn(|l| edge[l] as usize);
    let a: [f64; L] = std::array::from_fn(|l| coords[COORDS * l]);
    let loc = posed.eval_lanes(&k, &a);
    // unbend and transfer every lane, then bend every lane: the square roots and divisions
    // of the lanes interleave
    let mut d = [DVec2::ZERO; L];
    let mut lam = [0.0; L];
    let mut k1 = [DVec2::ZERO; L];
    let mut fl = [0u8; L];
    for l in 0..L {
        let c = &coords[COORDS * l..COORDS * (l + 1)];
        let (k, a, tau) = (k[l], c[0], c[1]);
        let s0 = to_model.of(c[4]);
        lam[l] = loc[l].sigma / s0;
        let k0 = if tau != 0.0 {
            DVec2::ZERO
        } else {
            k1[l] = loc[l].kappa;
            DVec2::new(c[5], c[6]) * (1.0 / s0)
        };
        let d0 = DVec2::new(to_model.of(c[2]), to_model.of(c[3]));
        let mut dl = unbend(sol, d0, k0, &mut fl[l]);
        if !twist.is_empty() {
            let phi = twist[k] + a * (twist[k + 1] - twist[k]);
            let (s, cs) = phi.sin_cos();
            dl = DVec2::new(cs * dl.x - s * dl.y, s * dl.x + cs * dl.y);
        }
        d[l] = dl;
    }
    for l in 0..L {
        d[l] = bend(sol, d[l], k1[l], lam[l], &mut fl[l]);
    }
    for l in 0..L {
        let tau = to_model.of(coords[COORDS * l + 1]);
        let (loc, d, lam) = (&loc[l], d[l], lam[l]);
        let along = if sol == Solution::None {
            tau
        } else {
            lam * tau
        };
        out[l] = to_input.of3(loc.q + along * loc.t + d.x * loc.u + d.y * loc.v);
        flags[l] = fl[l];
    }
}
