//! The fused fast path of the most common call: frames of one open curve from its points
//! alone, by double reflection with the five-point chord-length tangents.
//!
//! The general driver ([`super::compute_into`]) makes one pass per stage over the whole
//! curve: finite check, chord lengths, tangents (a fresh `(n, 3)` buffer), alignment check,
//! then the transport scan. On long curves these passes and the page faults of the fresh
//! buffers cost more than the transport itself. Here every chunk of the parallel scan
//! works through its samples in blocks of [`BLOCK`]: chord lengths and unit tangents of the
//! block go into small buffers that stay in cache, the checks run on them, and the frames are
//! written at once. The arithmetic is exactly that of the general path (the same functions
//! on the same values, the same chunks), so the frames are bit-identical; a test compares
//! the two.
//!
//! Errors are never reported from here: where any check fails (a NaN, a repeated point, a
//! cusp, a segment against its tangents, a bad `initial`/`end`) this returns `None` and the
//! caller runs the general path, which names the argument and the row.

use glam::DVec3;
use rayon::prelude::*;

use super::double_reflection::{dr_step, dr_step_with};
use super::geometry::{any_perpendicular, rotate_about, scale_and_diagonal, signed_angle};
use super::tangents::{circle_normal, five_point_unit_open, five_point_unit_open_lanes};
use super::transport::{ChunkEnds, Finish, Twist, plan, write_frame};
use super::validate::{COINCIDE_EPS, MIN_ALIGNMENT, coincide};
use super::{Method, Request, STRAIGHT_TOL, TangentRule, resolve};

/// Samples per block: chords and tangents of a block stay in the L1/L2 cache.
pub const BLOCK: usize = 1024;

/// Tangents estimated together (see [`five_point_unit_open_lanes`]).
const LANES: usize = 4;

/// Samples searched serially for the first bend (the default initial vector) before the
/// search goes parallel.
const SERIAL_SEARCH: usize = 256;

/// `v̂·(t_i + t_{i+1}) > MIN_ALIGNMENT`, as `validate::aligned` tests it.
#[inline(always)]
fn aligned(v: DVec3, ti: DVec3, tj: DVec3) -> bool {
    aligned_with(v, v.length_squared(), ti, tj)
}

#[inline(always)]
fn aligned_with(v: DVec3, vv: f64, ti: DVec3, tj: DVec3) -> bool {
    let d = v.dot(ti + tj);
    d > 0.0 && d * d > MIN_ALIGNMENT * MIN_ALIGNMENT * vv
}

/// Frames of an open curve given by points only (double reflection, five-point tangents,
/// `n ≥ 5`), or `None` when the request is of another kind or any check fails.
pub(super) fn try_open_points(req: &Request, out: &mut [f64]) -> Option<f64> {
    let x = req.points?;
    let n = x.len();
    if req.tangents.is_some()
        || req.analytic.is_some()
        || req.closed
        || req.method != Method::DoubleReflection
        || req.tangent_chords
        || req.tangent_rule != TangentRule::FivePoint
        || n < 5
        || out.len() != 9 * n
    {
        return None;
    }
    let h = |j: usize| (x[j + 1] - x[j]).length();
    let tan = |i: usize| five_point_unit_open(x, i, h);

    // The default initial vector: the principal normal at the first sample where the curve
    // bends, carried back to sample 0 (as `Ctx::run`).
    let (scale, diag) = scale_and_diagonal(x);
    if !(scale.is_finite() && diag.is_finite()) {
        return None;
    }
    let noise = 64.0 * f64::EPSILON * scale;
    // chords longer than this are not repeated points: `coincide` needs
    // |b − a|_∞ ≤ 8ε·max(|a|_∞, |b|_∞) ≤ 8ε·scale, and |b − a|_∞ ≥ |b − a|/√3 (with a margin
    // for the rounding of the computed length)
    let apart = 2.0 * COINCIDE_EPS * scale;
    let normal = |i: usize, ti: DVec3| {
        circle_normal(x, ti, i, false, noise)
            .and_then(|(nrm, kappa)| (kappa * diag > STRAIGHT_TOL).then_some(nrm))
    };
    let t0 = tan(0)?;
    let r0 = match &req.initial {
        Some(o) => resolve(o, t0, 0, "initial").ok()?,
        None => {
            let p = any_perpendicular(t0);
            let lim = n.min(SERIAL_SEARCH);
            let mut found = None;
            for i in 0..lim {
                if let Some(v) = normal(i, tan(i)?) {
                    found = Some((i, v));
                    break;
                }
            }
            if found.is_none() && lim < n {
                found = (lim..n)
                    .into_par_iter()
                    .find_map_first(|i| tan(i).and_then(|ti| normal(i, ti)).map(|v| (i, v)));
            }
            match found {
                None => p,
                Some((k, nk)) => {
                    let (mut r, mut ti) = (p, t0);
                    for i in 0..k {
                        let tj = tan(i + 1)?;
                        r = dr_step(x[i + 1] - x[i], ti, tj, r);
                        ti = tj;
                    }
                    rotate_about(p, t0, signed_angle(r, nk, ti))
                }
            }
        }
    };
    let twist = match &req.end {
        Some(o) => Twist::End {
            target: resolve(o, tan(n - 1)?, n - 1, "end").ok()?,
            turns: req.turns,
        },
        None => Twist::None,
    };

    // Phase 1 of the scan, fused with the chords, tangents and checks.
    let (chunks, cs) = plan(n, true);
    let prov: Vec<Option<ChunkEnds>> = out
        .par_chunks_mut(9 * cs)
        .enumerate()
        .map(|(c, buf)| {
            let a = c * cs;
            chunk(x, apart, a, (a + cs).min(n), (c == 0).then_some(r0), buf)
        })
        .collect();
    let prov: Vec<ChunkEnds> = prov.into_iter().collect::<Option<_>>()?;
    debug_assert_eq!(prov.len(), chunks);
    // the segments across chunk boundaries
    for c in 1..chunks {
        let i = c * cs - 1;
        if !aligned(x[i + 1] - x[i], tan(i)?, tan(i + 1)?) {
            return None;
        }
    }

    // Phases 2 and 3 as in `transport_into`; every tangent is valid by now.
    let tt = |i: usize| tan(i).unwrap_or(DVec3::ZERO);
    Some(
        Finish {
            boundary_step: |i: usize, r: DVec3| dr_step(x[i + 1] - x[i], tt(i), tt(i + 1), r),
            tangent: tt,
            seg: |i: usize| h(i.min(n - 2)),
            n,
            closed: false,
            r0,
            twist,
            cs,
            ext: n,
        }
        .run(&prov, out),
    )
}

/// Rows `a..b` of phase 1: transport from `start` (a provisional vector ⟂ `t_a` when
/// `None`), writing the frames into `buf`; `None` if a check fails in the chunk.
fn chunk(
    x: &[DVec3],
    apart: f64,
    a: usize,
    b: usize,
    start: Option<DVec3>,
    buf: &mut [f64],
) -> Option<ChunkEnds> {
    let n = x.len();
    let mut hb = [0.0f64; BLOCK + 4];
    let mut qb = [0.0f64; BLOCK + 4];
    let mut tb = [DVec3::ZERO; BLOCK + 1];
    let mut rows = buf.chunks_exact_mut(9);
    let (mut s0, mut r, mut len) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    let mut s = a;
    while s < b {
        let e = (s + BLOCK).min(b);
        // tangents t_s … t_{te−1} (one past the block for its last step); chords of their
        // stencils, j ∈ [lo, hi)
        let te = if e < b { e + 1 } else { e };
        let lo = s.saturating_sub(2);
        let hi = (te + 1).min(n - 1);
        // Non-finite samples need no test of their own: sample i enters its own tangent's
        // stencil (every term is a difference with x_i), so a NaN or inf there makes that
        // tangent non-finite, and the block is refused below.
        let mut ok = true;
        for j in lo..hi {
            // `length()` is `dot(self).sqrt()`: keep the square for the checks and steps
            let c = x[j + 1] - x[j];
            qb[j - lo] = c.dot(c);
            hb[j - lo] = qb[j - lo].sqrt();
        }
        for j in s..e.min(n - 1) {
            // |b − a|_∞ ≥ h/√3: a chord longer than `apart` cannot coincide (the exact test
            // of `validate::coincide` runs only on the rare short ones)
            let hj = hb[j - lo];
            ok &= hj > apart || !coincide(x[j], x[j + 1]);
            len += hj;
        }
        let h = |j: usize| {
            if j >= lo && j < hi {
                hb[j - lo]
            } else {
                (x[j + 1] - x[j]).length()
            }
        };
        let mut i = s;
        while i < te {
            if i >= 2 && i + LANES + 1 < n && i + LANES <= te {
                let (a, z) = (i - 2 - lo, hi - lo);
                let lanes = five_point_unit_open_lanes::<LANES>(&x[i - 2..], &hb[a..z], &qb[a..z]);
                for (l, t) in lanes.into_iter().enumerate() {
                    tb[i + l - s] = t?;
                }
                i += LANES;
            } else {
                tb[i - s] = five_point_unit_open(x, i, h)?;
                i += 1;
            }
        }
        if !ok {
            return None;
        }
        if s == a {
            r = start.unwrap_or_else(|| any_perpendicular(tb[0]));
            s0 = r;
        }
        for i in s..e {
            let ti = tb[i - s];
            if let Some(f) = rows.next() {
                write_frame(f, r, ti);
            }
            if i + 1 < b {
                let (v, vv, tj) = (x[i + 1] - x[i], qb[i - lo], tb[i + 1 - s]);
                if !aligned_with(v, vv, ti, tj) {
                    return None;
                }
                r = dr_step_with(v, vv, ti, tj, r);
            }
        }
        s = e;
    }
    Some((s0, r, len))
}

#[cfg(test)]
mod tests {
    use super::super::{Orientation, compute_general};
    use super::*;

    fn both(req: &Request) -> (Vec<f64>, Vec<f64>, f64, f64) {
        let n = req.points.map_or(0, <[DVec3]>::len);
        let (mut a, mut b) = (vec![0.0; 9 * n], vec![0.0; 9 * n]);
        let fa = try_open_points(req, &mut a).expect("fast path taken");
        let fb = compute_general(req, &mut b).expect("valid input");
        (a, b, fa, fb)
    }

    /// A curve with uneven spacing, a straight start (the default initial vector is found
    /// past the serial search) and a bend.
    fn curve(n: usize, straight: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let u = i as f64 + 0.3 * (i as f64 * 0.7).sin();
                if i < straight {
                    DVec3::new(u, 0.0, 0.0)
                } else {
                    let v = (u - straight as f64) * 0.01;
                    DVec3::new(
                        straight as f64 + v.sin() * 100.0,
                        100.0 * (1.0 - v.cos()),
                        v * v,
                    )
                }
            })
            .collect()
    }

    #[test]
    fn fused_equals_general_bit_for_bit() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        pool.install(|| {
            for (n, straight) in [(5, 0), (6, 0), (1100, 0), (3000, 600), (70_001, 10)] {
                let x = curve(n, straight);
                for (initial, end) in [
                    (None, None),
                    (Some(Orientation::Vector(DVec3::new(0.0, 0.3, 1.0))), None),
                    (None, Some(Orientation::Vector(DVec3::new(0.2, 1.0, 0.5)))),
                ] {
                    let req = Request {
                        points: Some(&x),
                        initial,
                        end,
                        turns: 1,
                        ..Default::default()
                    };
                    let (a, b, fa, fb) = both(&req);
                    assert_eq!(fa.to_bits(), fb.to_bits(), "n {n}");
                    assert!(
                        a.iter().zip(&b).all(|(p, q)| p.to_bits() == q.to_bits()),
                        "n {n}, initial {initial:?}, end {end:?}"
                    );
                }
            }
            // a straight line: no bend anywhere
            let x: Vec<DVec3> = (0..2000)
                .map(|i| DVec3::new(1.0, 2.0, 3.0) * i as f64)
                .collect();
            let (a, b, _, _) = both(&Request {
                points: Some(&x),
                ..Default::default()
            });
            assert_eq!(a, b);
        });
    }

    #[test]
    fn fused_declines_what_it_does_not_check() {
        let mut x = curve(3000, 0);
        let mut out = vec![0.0; 9 * x.len()];
        fn req(x: &[DVec3]) -> Request<'_> {
            Request {
                points: Some(x),
                ..Default::default()
            }
        }
        assert!(try_open_points(&req(&x), &mut out).is_some());
        x[1500] = x[1499]; // a repeated point
        assert!(try_open_points(&req(&x), &mut out).is_none());
        x[1500] = DVec3::new(f64::NAN, 0.0, 0.0);
        assert!(try_open_points(&req(&x), &mut out).is_none());
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            for row in [0, 1, 2, 1500, 2997, 2998, 2999] {
                let mut y = curve(3000, 0);
                y[row].y = bad;
                assert!(
                    try_open_points(&req(&y), &mut out).is_none(),
                    "{bad} at {row}"
                );
            }
        }
        x[1500] = x[1498]; // a reversal: a cusp or a segment against its tangents
        assert!(try_open_points(&req(&x), &mut out).is_none());
        let x = curve(3000, 0);
        let bad = Request {
            points: Some(&x),
            initial: Some(Orientation::Vector(DVec3::ZERO)), // no normal-plane component
            ..Default::default()
        };
        assert!(try_open_points(&bad, &mut out).is_none());
        assert!(super::super::compute_into(&bad, &mut out).is_err());
        let closed = Request {
            points: Some(&x),
            closed: true,
            ..Default::default()
        };
        assert!(try_open_points(&closed, &mut out).is_none());
    }
}
