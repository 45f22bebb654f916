//! Registration (spec §1.1 step 2, §2.8 "accurate projection", A-13).
//!
//! Each vertex is attached to the cross-section plane it lies in: on edge `k` the plane at
//! `a` passes through `C(a) = C_k + a E_k` normal to `m(a) = (1 − a) t_k + a t_{k+1}`, and
//! `(P − C(a))·m(a) = 0` is a quadratic in `a`, solved exactly. Among the roots in `[0, 1]` of
//! every edge (and the straight extensions past both ends) the one closest to `P` wins — the
//! closest point of the polyline with the cross-sections turned smoothly from sample to
//! sample, so no vertex snaps to a sample (§7.1's "slicing") and the offset is exactly
//! normal to the interpolated tangent.
//!
//! Stored per vertex: `k` and [`COORDS`] numbers `[a, τ, α, β, σ0, κα0, κβ0]`: the edge
//! parameter, the tangential coordinate past an end (0 inside), the offset in the RMF
//! `(α, β)`, and the rest spine's speed and curvature vector (RMF coordinates) at `(k, a)`.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::spine::Spine;
use crate::error::{InputError, Result};

/// Numbers stored per vertex besides the edge index.
pub const COORDS: usize = 7;

/// The registration of many vertices on one rest spine.
#[derive(Clone, Debug)]
pub struct Binding {
    pub edge: Vec<i64>,
    pub coords: Vec<f64>,
}

fn edge_roots(w: DVec3, e: DVec3, t0: DVec3, t1: DVec3) -> [f64; 2] {
    let d = t1 - t0;
    // f(a) = (w − a e)·(t0 + a d) = c + b a + q a²
    let (q, b, c) = (-e.dot(d), w.dot(d) - e.dot(t0), w.dot(t0));
    let mut out = [f64::NAN; 2];
    if q.abs() <= 1e-14 * b.abs() {
        if b != 0.0 {
            out[0] = -c / b;
        }
        return out;
    }
    let disc = b * b - 4.0 * q * c;
    if disc < 0.0 {
        return out;
    }
    let s = -0.5 * (b + b.signum() * disc.sqrt());
    if s != 0.0 {
        out[0] = s / q;
        out[1] = c / s;
    } else {
        out[0] = 0.0;
    }
    out
}

/// Register one vertex: `(k, a, τ)`.
fn locate(sp: &Spine, p: DVec3) -> (usize, f64, f64) {
    let n = sp.len();
    let mut best = (f64::INFINITY, 0usize, 0.0f64, 0.0f64);
    // straight extensions past both ends
    let w = p - sp.c[0];
    let tau = w.dot(sp.t[0]);
    if tau < 0.0 {
        best = ((w - tau * sp.t[0]).length_squared(), 0, 0.0, tau);
    }
    let w = p - sp.c[n - 1];
    let tau = w.dot(sp.t[n - 1]);
    if tau > 0.0 {
        let d2 = (w - tau * sp.t[n - 1]).length_squared();
        if d2 < best.0 {
            best = (d2, n - 2, 1.0, tau);
        }
    }
    for k in 0..n - 1 {
        let w = p - sp.c[k];
        let e = sp.c[k + 1] - sp.c[k];
        // every point of the edge is at least |w| − |e| away
        let lo = w.length() - e.length();
        if lo > 0.0 && lo * lo > best.0 {
            continue;
        }
        for a in edge_roots(w, e, sp.t[k], sp.t[k + 1]) {
            if !(-1e-12..=1.0 + 1e-12).contains(&a) {
                continue;
            }
            let a = a.clamp(0.0, 1.0);
            let d2 = (w - a * e).length_squared();
            if d2 < best.0 {
                best = (d2, k, a, 0.0);
            }
        }
    }
    if best.0.is_infinite() {
        // cannot happen for finite input (the plane signs change somewhere); keep a
        // defined answer anyway: the nearest sample
        let (k, _) =
            sp.c.iter()
                .enumerate()
                .fold((0, f64::INFINITY), |acc, (i, c)| {
                    let d = (p - *c).length_squared();
                    if d < acc.1 { (i, d) } else { acc }
                });
        let (k, a) = if k + 1 < n { (k, 0.0) } else { (n - 2, 1.0) };
        return (k, a, 0.0);
    }
    (best.1, best.2, best.3)
}

/// Register `vertices` on the rest spine.
pub fn bind(rest: &Spine, vertices: &[DVec3]) -> Result<Binding> {
    if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
        return Err(InputError::new(
            "vertices",
            format!("row {i} is not finite"),
        ));
    }
    let nv = vertices.len();
    let mut edge = vec![0i64; nv];
    let mut coords = vec![0.0; COORDS * nv];
    edge.par_iter_mut()
        .zip(coords.par_chunks_mut(COORDS))
        .zip(vertices.par_iter())
        .for_each(|((e, c), &p)| {
            let (k, a, tau) = locate(rest, p);
            let l = rest.eval(k, a);
            let d = p - l.q - tau * l.t;
            let kappa = if tau != 0.0 { DVec2::ZERO } else { l.kappa };
            *e = k as i64;
            c.copy_from_slice(&[a, tau, d.dot(l.u), d.dot(l.v), l.sigma, kappa.x, kappa.y]);
        });
    Ok(Binding { edge, coords })
}
