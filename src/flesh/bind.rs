//! Registration (Zhuo 2014 §1.1, Fig. 1, the registration step; Ch. VII "accurate projection").
//!
//! Each vertex is attached to the cross-section plane it lies in: on edge `k` the plane at
//! `a` passes through the interpolated position `C(a)` normal to the interpolated tangent
//! `m(a)` (both cubic in `a`, see [`super::spine`]), and `(P − C(a))·m(a) = 0` is solved to
//! full precision. Among the roots in `[0, 1]` of
//! every edge (and the straight extensions past both ends) the one closest to `P` wins — the
//! closest point of the polyline with the cross-sections turned smoothly from sample to
//! sample, so no vertex snaps to a sample (§7.1's "slicing") and the offset is exactly
//! normal to the interpolated tangent.
//!
//! Stored per vertex: `k` and [`COORDS`] numbers `[a, τ, α, β, σ0, σ0κα0, σ0κβ0]`: the edge
//! parameter, the tangential coordinate past an end (0 inside), the offset in the RMF
//! `(α, β)`, the rest spine's speed `σ0` and its curvature vector (RMF coordinates) at
//! `(k, a)` times `σ0`. Lengths are in the units of the input and the last two numbers have
//! none, so a binding does not depend on the normalisation of the rest spine's model (see
//! [`SpineModel`]) and any posed spine's model can read it.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::spine::SpineModel;
use crate::alloc;
use crate::cancel::{self, Cancel};
use crate::error::Result;

/// Numbers stored per vertex besides the edge index.
pub const COORDS: usize = 7;

/// The registration of many vertices on one rest spine.
#[derive(Clone, Debug)]
pub struct Binding {
    pub edge: Vec<i64>,
    pub coords: Vec<f64>,
}

/// Roots in `[0, 1]` of `f(a) = (P − C(a))·m(a)` (degree 6): sign changes on a grid of 4
/// steps, each refined by the Illinois variant of regula falsi to full precision. A point
/// on the section plane of a sample (`f` zero at `a = 0` or `a = 1` up to the round-off of
/// its evaluation) is a root there, so that it is not lost between two edges whose end
/// values round to the same sign.
fn edge_roots(sp: &SpineModel, k: usize, p: DVec3) -> [f64; 4] {
    let f = |a: f64| (p - sp.c_at(k, a)).dot(sp.m_at(k, a));
    let on_plane = |a: f64, fa: f64| {
        let c = sp.c_at(k, a);
        fa.abs() <= 16.0 * f64::EPSILON * (p.length() + c.length()) * sp.m_at(k, a).length()
    };
    let mut out = [f64::NAN; 4];
    let mut prev = (0.0, f(0.0));
    for (i, slot) in out.iter_mut().enumerate() {
        let b = (i + 1) as f64 / 4.0;
        let fb = f(b);
        let (mut a0, mut f0) = prev;
        prev = (b, fb);
        if f0 == 0.0 || (i == 0 && on_plane(0.0, f0)) {
            *slot = a0;
            continue;
        }
        if (f0 > 0.0) == (fb > 0.0) {
            if i == 3 && on_plane(1.0, fb) {
                *slot = 1.0;
            }
            continue;
        }
        let (mut a1, mut f1) = (b, fb);
        let mut side = 0i8;
        for _ in 0..200 {
            let x = (a0 * f1 - a1 * f0) / (f1 - f0);
            let x = if x > a0.min(a1) && x < a0.max(a1) {
                x
            } else {
                0.5 * (a0 + a1)
            };
            let fx = f(x);
            if fx == 0.0 || (a1 - a0).abs() <= 1e-15 {
                a0 = x;
                a1 = x;
                break;
            }
            if (fx > 0.0) == (f1 > 0.0) {
                a1 = x;
                f1 = fx;
                if side == -1 {
                    f0 *= 0.5;
                }
                side = -1;
            } else {
                a0 = x;
                f0 = fx;
                if side == 1 {
                    f1 *= 0.5;
                }
                side = 1;
            }
        }
        *slot = 0.5 * (a0 + a1);
    }
    out
}

/// Register one vertex: `(k, a, τ)`.
fn locate(sp: &SpineModel, p: DVec3) -> (usize, f64, f64) {
    let n = sp.len();
    let mut best = (f64::INFINITY, 0usize, 0.0f64, 0.0f64);
    // straight extensions past both ends (a loop has none)
    let w = p - sp.c[0];
    let tau = w.dot(sp.t[0]);
    if tau < 0.0 && !sp.closed {
        best = ((w - tau * sp.t[0]).length_squared(), 0, 0.0, tau);
    }
    let w = p - sp.c[n - 1];
    let tau = w.dot(sp.t[n - 1]);
    if tau > 0.0 && !sp.closed {
        let d2 = (w - tau * sp.t[n - 1]).length_squared();
        if d2 < best.0 {
            best = (d2, n - 2, 1.0, tau);
        }
    }
    // the edges next to the nearest sample first: a good bound prunes almost all others
    let near =
        sp.c.iter()
            .enumerate()
            .fold((0, f64::INFINITY), |acc, (i, c)| {
                let d = (p - *c).length_squared();
                if d < acc.1 { (i, d) } else { acc }
            })
            .0;
    let first = near.saturating_sub(1);
    let order =
        (first..(near + 1).min(n - 1)).chain((0..n - 1).filter(|&k| k + 1 < near || k > near));
    for k in order {
        let w = p - sp.c[k];
        let e = sp.c[k + 1] - sp.c[k];
        // every point of the edge's curve (within 1.5 chords of C_k) is at least this far
        let lo = w.length() - 1.5 * e.length();
        if lo > 0.0 && lo * lo > best.0 {
            continue;
        }
        for a in edge_roots(sp, k, p) {
            if !(-1e-12..=1.0 + 1e-12).contains(&a) {
                continue;
            }
            let a = a.clamp(0.0, 1.0);
            let d2 = (p - sp.c_at(k, a)).length_squared();
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
pub fn bind(rest: &SpineModel, vertices: &[DVec3]) -> Result<Binding> {
    bind_cancellable(rest, vertices, &cancel::never)
}

/// [`bind`] that polls `cancel` before each vertex (see [`crate::cancel`]).
pub fn bind_cancellable(
    rest: &SpineModel,
    vertices: &[DVec3],
    cancel: Cancel<'_>,
) -> Result<Binding> {
    super::check_vertices(vertices, rest.scale, "spine")?;
    let (to_model, to_input) = (rest.scale, rest.scale.inverse());
    let nv = vertices.len();
    let mut edge = alloc::filled("SpineBinding", nv, 0i64)?;
    let mut coords = alloc::filled(
        "SpineBinding",
        alloc::product("SpineBinding", COORDS, nv, 8)?,
        0.0,
    )?;
    edge.par_iter_mut()
        .zip(coords.par_chunks_mut(COORDS))
        .zip(vertices.par_iter())
        .for_each(|((e, c), &p)| {
            if cancel() {
                return;
            }
            let p = to_model.of3(p);
            let (k, a, tau) = locate(rest, p);
            let l = rest.eval(k, a);
            let d = p - l.q - tau * l.t;
            let sk = if tau != 0.0 {
                DVec2::ZERO
            } else {
                l.kappa * l.sigma
            };
            let len = |x: f64| to_input.of(x);
            *e = k as i64;
            c.copy_from_slice(&[
                a,
                len(tau),
                len(d.dot(l.u)),
                len(d.dot(l.v)),
                len(l.sigma),
                sk.x,
                sk.y,
            ]);
        });
    Ok(Binding { edge, coords })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of `n` samples as a loop (first row repeated), with its RMF (`r` the
    /// binormal z all along, which closes).
    fn circle(n: usize) -> (Vec<DVec3>, Vec<f64>) {
        let mut pts = Vec::new();
        let mut frames = Vec::new();
        for i in 0..=n {
            let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
            let (s, c) = a.sin_cos();
            pts.push(DVec3::new(c, s, 0.0));
            let (r, t) = (DVec3::Z, DVec3::new(-s, c, 0.0));
            let q = t.cross(r);
            // row-major (n, 3, 3), columns r, s, t
            frames.extend_from_slice(&[r.x, q.x, t.x, r.y, q.y, t.y, r.z, q.z, t.z]);
        }
        (pts, frames)
    }

    #[test]
    fn loops_bind_on_the_closing_edge_and_on_sample_planes() {
        let (pts, frames) = circle(12);
        let sp = SpineModel::new("rest_spine", &pts, &frames, true).unwrap();
        // the curvature at the seam is that of every other sample, from both sides
        let inner = sp.eval(6, 0.0).kappa.length();
        assert!((inner - 1.0).abs() < 0.04);
        for (k, a) in [(0, 0.0), (11, 1.0)] {
            let l = sp.eval(k, a);
            assert!(
                (l.kappa.length() - inner).abs() < 1e-12,
                "{k} {a}: {}",
                l.kappa
            );
        }
        // points in the closing edge's slab, on sample planes (angle π: sample 6), and
        // outside the ring: never past an end
        for ang in [-0.2_f64, -0.01, 0.0, std::f64::consts::PI, 1.3] {
            for rad in [0.7, 1.25] {
                let p = DVec3::new(rad * ang.cos(), rad * ang.sin(), 0.1);
                let b = bind(&sp, &[p]).unwrap();
                let (k, a, tau) = (b.edge[0] as usize, b.coords[0], b.coords[1]);
                assert_eq!(tau, 0.0);
                let l = sp.eval(k, a);
                let d = p - l.q;
                assert!(
                    d.dot(l.t).abs() < 1e-12 && d.length() < 0.35,
                    "{ang} {rad}: {k} {a}"
                );
                if ang < 0.0 {
                    assert_eq!(k, 11);
                }
            }
        }
        // an open spine's point past its end extends the end instead
        let open = SpineModel::new("rest_spine", &pts[..7], &frames[..63], false).unwrap();
        let b = bind(&open, &[DVec3::new(-1.0, -0.2, 0.0)]).unwrap();
        assert!(b.coords[1] > 0.0);
        // a loop must repeat its first point
        assert!(SpineModel::new("rest_spine", &pts[..12], &frames[..108], true).is_err());
    }
}
