//! The sections of one rest spine edge through a point (Zhuo 2014 §1.1, registration; Ch. VII
//! "accurate projection"): the roots in `[0, 1]` of `f(a) = (P − C(a))·m(a)` (degree 6) with
//! `C` and `m` the edge's cubic position and tangent (see [`super::spine`]). Sign changes on
//! a grid of 4 steps, each refined by the Illinois variant of regula falsi (Dowell & Jarratt,
//! BIT 11, 1971) to full precision. A point on the section plane of a sample (`f` zero at
//! `a = 0` or `a = 1` up to the round-off of its evaluation) is a root there, so that it is
//! not lost between two edges whose end values round to the same sign.
//!
//! [`edge_roots_lanes`] refines the brackets of several points at once, one step of every
//! bracket per round: each bracket takes exactly the steps it takes alone (so the roots are
//! the same bits), while the evaluations of different brackets, independent of each other,
//! overlap in the processor (one bracket alone waits on each division and evaluation).

use glam::DVec3;

use super::spine::SpineModel;

/// Most points refined together (4 brackets each at most).
pub const MAX_LANES: usize = 4;

/// `f` at `a` on edge `k` with the curve point and tangent it used.
#[inline(always)]
fn fcm(sp: &SpineModel, k: usize, p: DVec3, a: f64) -> (f64, DVec3, DVec3) {
    let (c, m) = (sp.c_at(k, a), sp.m_at(k, a));
    ((p - c).dot(m), c, m)
}

/// `f(a) = (P − C(a))·m(a)` on edge `k` (the value of [`fcm`]).
#[inline(always)]
fn f(sp: &SpineModel, k: usize, p: DVec3, a: f64) -> f64 {
    (p - sp.c_at(k, a)).dot(sp.m_at(k, a))
}

/// Whether `P` lies on the section plane through `c` normal to `m`, where `f = fa`: `|fa|`
/// within the round-off of its evaluation, `16 ε (|P| + |c|) |m|`.
#[inline(always)]
fn on_plane(p: DVec3, (fa, c, m): (f64, DVec3, DVec3)) -> bool {
    // a bound of the threshold first (1-norms bound the lengths; below 1e150 their squares
    // do not overflow), which rules out almost every point without square roots
    let l1 = |x: DVec3| x.abs().element_sum();
    let (lpc, lm) = (l1(p) + l1(c), l1(m));
    let cheap = 16.0 * f64::EPSILON * lpc * lm * (1.0 + 1e-6);
    if lpc < 1e150 && lm < 1e150 && fa.abs() > cheap {
        return false;
    }
    fa.abs() <= 16.0 * f64::EPSILON * (p.length() + c.length()) * m.length()
}

/// One sign change being refined: lane, grid slot, the bracket `[a0, a1]` with its values
/// and the side last kept (the Illinois halving).
#[derive(Clone, Copy, Default)]
struct Bracket {
    lane: usize,
    slot: usize,
    a0: f64,
    f0: f64,
    a1: f64,
    f1: f64,
    side: i8,
    live: bool,
}

/// The roots of edge `k` for point `p`: up to one per grid step (`NaN` where none).
pub fn edge_roots(sp: &SpineModel, k: usize, p: DVec3) -> [f64; 4] {
    edge_roots_lanes::<1>(sp, &[k], &[p])[0]
}

/// [`edge_roots`] of `L ≤ MAX_LANES` points (edge `k[l]`, point `p[l]`), refined together.
#[inline(always)]
pub fn edge_roots_lanes<const L: usize>(
    sp: &SpineModel,
    k: &[usize; L],
    p: &[DVec3; L],
) -> [[f64; 4]; L] {
    const { assert!(L <= MAX_LANES) };
    let mut out = [[f64::NAN; 4]; L];
    // f on the grid, and the curve point and tangent at both ends (for `on_plane`)
    let mut fg = [[0.0; 5]; L];
    let mut ends = [[(0.0, DVec3::ZERO, DVec3::ZERO); 2]; L];
    for l in 0..L {
        for (i, fi) in fg[l].iter_mut().enumerate() {
            let v = fcm(sp, k[l], p[l], i as f64 / 4.0);
            *fi = v.0;
            if i % 4 == 0 {
                ends[l][i / 4] = v;
            }
        }
    }
    let mut br = [Bracket::default(); 4 * MAX_LANES];
    let mut nb = 0;
    for l in 0..L {
        for i in 0..4 {
            let (a0, f0) = (i as f64 / 4.0, fg[l][i]);
            let (b, fb) = ((i + 1) as f64 / 4.0, fg[l][i + 1]);
            if f0 == 0.0 || (i == 0 && on_plane(p[l], ends[l][0])) {
                out[l][i] = a0;
                continue;
            }
            if (f0 > 0.0) == (fb > 0.0) {
                if i == 3 && on_plane(p[l], ends[l][1]) {
                    out[l][i] = 1.0;
                }
                continue;
            }
            br[nb] = Bracket {
                lane: l,
                slot: i,
                a0,
                f0,
                a1: b,
                f1: fb,
                side: 0,
                live: true,
            };
            nb += 1;
        }
    }
    let br = &mut br[..nb];
    let mut live = nb;
    // at most 200 steps each, all brackets starting together
    for _ in 0..200 {
        if live == 0 {
            break;
        }
        let mut x = [0.0; 4 * MAX_LANES];
        let mut fx = [0.0; 4 * MAX_LANES];
        for (j, b) in br.iter().enumerate() {
            if b.live {
                let (a0, a1) = (b.a0, b.a1);
                let xj = (a0 * b.f1 - a1 * b.f0) / (b.f1 - b.f0);
                x[j] = if xj > a0.min(a1) && xj < a0.max(a1) {
                    xj
                } else {
                    0.5 * (a0 + a1)
                };
            }
        }
        for (j, b) in br.iter().enumerate() {
            if b.live {
                fx[j] = f(sp, k[b.lane], p[b.lane], x[j]);
            }
        }
        for (j, b) in br.iter_mut().enumerate() {
            if !b.live {
                continue;
            }
            let (x, fx) = (x[j], fx[j]);
            if fx == 0.0 || (b.a1 - b.a0).abs() <= 1e-15 {
                b.a0 = x;
                b.a1 = x;
                b.live = false;
                live -= 1;
                continue;
            }
            if (fx > 0.0) == (b.f1 > 0.0) {
                b.a1 = x;
                b.f1 = fx;
                if b.side == -1 {
                    b.f0 *= 0.5;
                }
                b.side = -1;
            } else {
                b.a0 = x;
                b.f0 = fx;
                if b.side == 1 {
                    b.f1 *= 0.5;
                }
                b.side = 1;
            }
        }
    }
    for b in br.iter() {
        out[b.lane][b.slot] = 0.5 * (b.a0 + b.a1);
    }
    out
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::run::cancel;

    /// The roots one bracket at a time, with the threshold of `on_plane` computed in full
    /// (the reference of the tests below).
    fn roots_alone(sp: &SpineModel, k: usize, p: DVec3) -> [f64; 4] {
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

    /// An open spine through `pts` with its default frames.
    pub(in crate::flesh) fn model(pts: &[DVec3]) -> SpineModel {
        let req = crate::frames::Request {
            points: Some(pts),
            ..Default::default()
        };
        let mut frames = vec![0.0; 9 * pts.len()];
        crate::frames::compute_into(&req, &mut frames, &cancel::never).unwrap();
        SpineModel::new("rest_spine", pts, &frames, false, &cancel::never).unwrap()
    }

    #[test]
    fn lanes_give_the_roots_of_one_point_at_a_time_bit_for_bit() {
        // a wavy spine (several roots per edge for points near its centres of curvature) and
        // a straight one along x; points near and far (up to 1e160, past the cheap bound
        // of the plane test), on sample planes and at samples
        let wavy: Vec<DVec3> = (0..40)
            .map(|i| {
                let u = i as f64 * 0.3;
                DVec3::new(u, (2.0 * u).sin() * 0.8, (0.7 * u).cos() * 0.5)
            })
            .collect();
        let straight: Vec<DVec3> = (0..30)
            .map(|i| DVec3::new(i as f64 * 0.1, 0.0, 0.0))
            .collect();
        let (mut on_plane_roots, mut solved) = (0, 0);
        for sp in [model(&wavy), model(&straight)] {
            let n = sp.len();
            for q in 0..3000usize {
                let x = q as f64 * 0.618_033_988_7;
                let k0 = q % (n - 1);
                let mut p = [DVec3::ZERO; 4];
                let mut k = [0usize; 4];
                for l in 0..4 {
                    let y = x + l as f64 * 0.37;
                    k[l] = if l == 3 { (k0 + 1) % (n - 1) } else { k0 };
                    let c = sp.c_at(k[l], (y * 1.3).sin().abs());
                    let off = match q % 5 {
                        0 => 1e-9,
                        4 => 1e160,
                        _ => 0.7,
                    };
                    p[l] = c + off * DVec3::new((y * 2.1).cos(), (y * 3.7).sin(), y.cos());
                    if q % 7 == 0 {
                        // on the plane of sample k (or of k + 1): the plane test decides
                        let j = k[l] + l % 2;
                        p[l] = sp.c[j] + 0.3 * sp.r[j] * (y * 0.9).cos();
                    }
                }
                let got = edge_roots_lanes(&sp, &k, &p);
                for l in 0..4 {
                    let want = roots_alone(&sp, k[l], p[l]);
                    assert_eq!(got[l].map(f64::to_bits), want.map(f64::to_bits), "{q} {l}");
                    assert_eq!(
                        edge_roots(&sp, k[l], p[l]).map(f64::to_bits),
                        want.map(f64::to_bits)
                    );
                    on_plane_roots += want.iter().filter(|&&a| a == 0.0 || a == 1.0).count();
                    solved += want.iter().filter(|&&a| a > 0.0 && a < 1.0).count();
                }
            }
        }
        // both kinds of roots occur
        assert!(
            on_plane_roots > 100 && solved > 1000,
            "{on_plane_roots} {solved}"
        );
    }
}
