//! Reconstruction on the posed spine: unbend – transfer – bend (Zhuo 2014 §4.2.1, §5.2.1;
//! spec §2.5 with default "stretch after the rotation").
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
use super::spine::Spine;
use crate::error::{InputError, Result};

/// Deform a registered shape. `twist` is empty or one angle (rad) per spine sample.
/// Writes the vertices to `out` and the per-vertex flags (see [`super::solve`]) to `flags`.
pub fn deform(
    posed: &Spine,
    edge: &[i64],
    coords: &[f64],
    sol: Solution,
    twist: &[f64],
    out: &mut [DVec3],
    flags: &mut [u8],
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
    out.par_iter_mut()
        .zip(flags.par_iter_mut())
        .zip(edge.par_iter().zip(coords.par_chunks(COORDS)))
        .for_each(|((o, f), (&k, c))| {
            let k = k as usize;
            let (a, tau) = (c[0], c[1]);
            let mut d = DVec2::new(c[2], c[3]);
            let l = posed.eval(k, a);
            let lam = l.sigma / c[4];
            let (k0, k1) = if tau != 0.0 {
                (DVec2::ZERO, DVec2::ZERO)
            } else {
                (DVec2::new(c[5], c[6]), l.kappa)
            };
            let mut fl = 0u8;
            d = unbend(sol, d, k0, &mut fl);
            if !twist.is_empty() {
                let phi = twist[k] + a * (twist[k + 1] - twist[k]);
                let (s, cs) = phi.sin_cos();
                d = DVec2::new(cs * d.x - s * d.y, s * d.x + cs * d.y);
            }
            d = bend(sol, d, k1, lam, &mut fl);
            let along = if sol == Solution::None {
                tau
            } else {
                lam * tau
            };
            *o = l.q + along * l.t + d.x * l.u + d.y * l.v;
            *f = fl;
        });
    Ok(())
}
