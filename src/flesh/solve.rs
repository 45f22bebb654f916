//! Offset solutions in one cross-section (Zhuo 2014, Ch. III–V: §3.1, §4.2.1, §5.2.1).
//!
//! Everything works in the 2D coordinates `d = (α, β)` of the cross-section (components along
//! the RMF columns `r, s` of the spine frame) and the curvature vector `k = κ N` expressed in
//! the same coordinates (`k ⊥ t`, pointing to the centre of curvature), so the formulas are
//! frame free (our reformulation: the thesis's maps need the Frenet frame only through
//! `κ N`): `κ x = d·k`, `κ r cosθ = d·k`.
//!
//! * unbend (κ1 = 0 in the thesis' formulas), with the rest curvature `k0`:
//!   normal Eq. 14 `x* = x0 (1 − ½κ0 x0)`; binormal Eq. 17 `y* = (1 − κ0 x) y0`;
//!   radial Eq. 20 `r* = r0 √(1 − ⅔ κ0 r0 cosθ0)`.
//! * stretch by `λ` = new speed / old speed (the thesis's σ of Ch. V): normal `x/λ`
//!   along N1, binormal `y/λ` along B1, radial `r/√λ`.
//! * bend (κ0 = 0) with the posed curvature `k1`, read in the posed frame after the transfer
//!   (as Eq. 21's `θ1` implies): normal Eq. 15 in the stable form
//!   `x1 = 2x_t/(1 + √(1 − 2κ1 x_t))`; binormal Eq. 18 `y1 = y_t/(1 − κ1 x')`; radial Eq. 21
//!   `r1²(1 − ⅔ r1 κ1 cosθ1) = r_t²`, root rule in [`radial_ratio`]. (§4.2.1 places the
//!   minimum of `f(m) = α m³ + m² − 1` at `m = 1` and says "if α > 0, λ2 > 0"; as
//!   `f'(m) = m(3αm + 2)` the minimum is at `m = 0` and the condition is `α < 0`.)
//!
//! * blend (Ch. VIII): a cascade of normal and binormal stages weighted by `w`, exact for
//!   every `w` (see [`super::blend`]).
//!
//! Existence (§3.1.2, §4.3): the thesis only says that no valid solution exists past the
//! limits; a choice of ours: where no fold-free root exists the offset is clamped to the
//! largest safe one (normal: the focal point `1/κ1`; radial: `r1 = 1/(κ1 cosθ1)`, the local
//! maximum of the cubic; binormal: the factor `1 − κ1 x'` is capped below at
//! [`BINORMAL_MIN_FACTOR`]) and the vertex is reported. Unbending needs `κ0 x0 < 1` (§4.2.1
//! states `|κ0 x0| ≤ 2`, which only keeps `x*` non-negative; a fold-free inverse needs more):
//! points past the rest spine's centre of curvature are clamped there and reported.

use glam::DVec2;

use super::bent_normal;
pub use super::{BINORMAL_MIN_FACTOR, CLAMPED_BEND, CLAMPED_UNBEND, TINY_CURVATURE};

/// Which offset correction to apply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solution {
    /// The uncorrected map: the same local offset in the posed frame (the industry baseline).
    None,
    /// Only the coordinate along the principal normal changes (quadratic, Eq. 11/23).
    Normal,
    /// Only the coordinate along the binormal changes (linear, Eq. 12/24).
    Binormal,
    /// Only the distance from the spine changes, the angle is kept (cubic, Eq. 13/25).
    Radial,
    /// The cascade of normal and binormal stages with the weight `w ∈ [0, 1]` of the
    /// normal solution (Ch. VIII; see [`super::blend`]): `w = 1` is [`Solution::Normal`],
    /// `w = 0` is [`Solution::Binormal`].
    Blend(f64),
}

impl Solution {
    /// The solution with the blend weight `blend` (given only with [`Solution::Blend`],
    /// whose weight it sets; checked to be in `[0, 1]`); errors name `blend`.
    pub fn with_blend(self, blend: Option<f64>) -> crate::error::Result<Solution> {
        use crate::error::InputError;
        match (self, blend) {
            (Solution::Blend(_), Some(w)) => Ok(Solution::Blend(super::blend::check_weight(w)?)),
            (Solution::Blend(_), None) => Err(InputError::new(
                "blend",
                "solution=\"blend\" needs the weight of the normal solution, a number in [0, 1]",
            )),
            (_, Some(_)) => Err(InputError::new(
                "blend",
                "only with solution=\"blend\" (the other solutions take no weight)",
            )),
            (s, None) => Ok(s),
        }
    }
}

#[inline(always)]
fn unit_normal(k: DVec2, fallback: DVec2) -> (DVec2, f64) {
    let kk = k.length();
    if kk > TINY_CURVATURE && kk.is_finite() {
        (k * (1.0 / kk), kk)
    } else {
        (fallback, 0.0)
    }
}

/// Unbend `d` (rest cross-section coordinates) with the rest curvature `k0`.
#[inline(always)]
pub fn unbend(sol: Solution, d: DVec2, k0: DVec2, flags: &mut u8) -> DVec2 {
    match sol {
        Solution::None => d,
        Solution::Normal => {
            let (n, kk) = unit_normal(k0, DVec2::X);
            if kk == 0.0 {
                return d;
            }
            let x = d.dot(n);
            let xc = if kk * x >= 1.0 {
                *flags |= CLAMPED_UNBEND;
                1.0 / kk
            } else {
                x
            };
            d + (xc * (1.0 - 0.5 * kk * xc) - x) * n
        }
        Solution::Binormal => {
            let (n, kk) = unit_normal(k0, DVec2::X);
            if kk == 0.0 {
                return d;
            }
            let b = n.perp();
            let (x, y) = (d.dot(n), d.dot(b));
            let mut f = 1.0 - kk * x;
            if f < BINORMAL_MIN_FACTOR {
                *flags |= CLAMPED_UNBEND;
                f = BINORMAL_MIN_FACTOR;
            }
            x * n + f * y * b
        }
        Solution::Radial => {
            let mut c = d.dot(k0); // κ0 r0 cosθ0
            if c >= 1.0 {
                *flags |= CLAMPED_UNBEND;
                c = 1.0;
            }
            d * (1.0 - (2.0 / 3.0) * c).sqrt()
        }
        Solution::Blend(w) => super::blend::unbend_blend(w, d, k0, flags),
    }
}

/// Bend the transferred coordinates `d` (posed frame) with posed curvature `k1` and stretch
/// `lam` (new/old speed). `fallback` is the direction used as "normal" where `k1 = 0`.
#[inline(always)]
pub fn bend(sol: Solution, d: DVec2, k1: DVec2, lam: f64, flags: &mut u8) -> DVec2 {
    match sol {
        Solution::None => d,
        Solution::Normal => {
            let (n, kk) = unit_normal(k1, DVec2::X);
            let x = d.dot(n);
            let xt = x / lam;
            let x1 = bent_normal(kk, xt, flags);
            d + (x1 - x) * n
        }
        Solution::Binormal => {
            let (n, kk) = unit_normal(k1, DVec2::X);
            let b = n.perp();
            let (x, y) = (d.dot(n), d.dot(b));
            let mut den = 1.0 - kk * x;
            if den < BINORMAL_MIN_FACTOR {
                *flags |= CLAMPED_BEND;
                den = BINORMAL_MIN_FACTOR;
            }
            x * n + (y / lam / den) * b
        }
        Solution::Radial => {
            // with r_t = |d|/√λ and û = d/|d|: α = −⅔ r_t û·k1 = −⅔ (d·k1)/√λ and the result
            // û r_t m = d m/√λ (no norm needed)
            if d == DVec2::ZERO {
                return d; // on the spine: nothing to correct, whatever λ and k1
            }
            let s = 1.0 / lam.sqrt();
            let alpha = -(2.0 / 3.0) * s * d.dot(k1);
            let (m, ok) = radial_ratio(alpha);
            if !ok {
                *flags |= CLAMPED_BEND;
            }
            d * (s * m)
        }
        Solution::Blend(w) => super::blend::bend_blend(w, d, k1, lam, flags),
    }
}

/// The fold-free root `m` of `α m³ + m² − 1 = 0` (Zhuo 2014 §4.2.1, Eq. 21 normalised by
/// `m = r1/r_t`, `α = −⅔ κ1 r_t cosθ1`) and whether it exists: `m = 1` for `α = 0`, the unique
/// root in `(0, 1)` for `α > 0`, and for `α < 0` the smallest root in `[1, −2/(3α)]`, which
/// exists iff `α² ≤ 4/27`; without one, the local maximum `m = −2/(3α)` (the focal point).
#[inline(always)]
pub fn radial_ratio(alpha: f64) -> (f64, bool) {
    let f = |m: f64| (alpha * m + 1.0) * m * m - 1.0;
    let df = |m: f64| (3.0 * alpha * m + 2.0) * m;
    if alpha == 0.0 {
        return (1.0, true);
    }
    let a2 = alpha * alpha;
    if a2 <= RADIAL_FAST_2 * RADIAL_FAST_2 {
        // the series start is within 7.2e-3 of the root for |α| ≤ 1/4 (0.1 at 0.36); one
        // Halley step (cubic convergence) brings it to ~1e-7 (two to ~1e-10 at 0.36) and one
        // Newton step to the rounding level (the unit test checks this against the
        // safeguarded iteration below)
        let halley = |m: f64| {
            let (f0, d0) = (f(m), df(m));
            let d2 = 6.0 * alpha * m + 2.0;
            m - 2.0 * f0 * d0 / (2.0 * d0 * d0 - f0 * d2)
        };
        let m0 = 1.0 - 0.5 * alpha + 0.625 * a2 - a2 * alpha + (231.0 / 128.0) * a2 * a2;
        let mut m1 = halley(m0);
        if a2 > RADIAL_FAST * RADIAL_FAST {
            m1 = halley(m1);
        }
        return (m1 - f(m1) / df(m1), true);
    }
    radial_ratio_safe(alpha)
}

/// `|α|` up to which [`radial_ratio`] takes one Halley step and a Newton step.
pub const RADIAL_FAST: f64 = 0.25;
/// `|α|` up to which it takes two Halley steps and a Newton step (the fold limit is
/// `|α| = 2/√27 ≈ 0.385`); beyond, the safeguarded iteration.
pub const RADIAL_FAST_2: f64 = 0.36;

/// The safeguarded iteration behind [`radial_ratio`], valid for every finite `α` (a
/// non-finite one, from degenerate input, gives the uncorrected ratio 1, reported).
pub fn radial_ratio_safe(alpha: f64) -> (f64, bool) {
    if !alpha.is_finite() {
        return (1.0, false);
    }
    let f = |m: f64| (alpha * m + 1.0) * m * m - 1.0;
    let df = |m: f64| (3.0 * alpha * m + 2.0) * m;
    if alpha == 0.0 {
        return (1.0, true);
    }
    let (mut lo, mut hi) = if alpha > 0.0 {
        (0.0, 1.0)
    } else {
        let top = -2.0 / (3.0 * alpha);
        if alpha * alpha > 4.0 / 27.0 {
            return (top, false);
        }
        (1.0, top)
    };
    // safeguarded Newton on the increasing branch [lo, hi], f(lo) ≤ 0 ≤ f(hi), from the
    // series m = 1 − α/2 + 5α²/8 − α³ + 231α⁴/128 (error ~1e-6 at |α| = 0.05)
    let a2 = alpha * alpha;
    let mut m =
        (1.0 - 0.5 * alpha + 0.625 * a2 - a2 * alpha + (231.0 / 128.0) * a2 * a2).clamp(lo, hi);
    for _ in 0..100 {
        let fm = f(m);
        if fm < 0.0 {
            lo = m;
        } else if fm > 0.0 {
            hi = m;
        } else {
            return (m, true);
        }
        let step = fm / df(m);
        let next = m - step;
        if !(next > lo && next < hi) {
            m = 0.5 * (lo + hi);
            if hi - lo <= 4.0 * f64::EPSILON * hi {
                return (m, true);
            }
            continue;
        }
        // quadratic convergence: after a Newton step of 1e-8 the error is ~1e-16; one more
        // step reaches the rounding level
        if step.abs() <= 1e-8 * m {
            let last = next - f(next) / df(next);
            return (if last >= lo && last <= hi { last } else { next }, true);
        }
        m = next;
    }
    (m, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radial_reference_values() {
        // Eq. 21 solved by hand: r_t = 0.3, κ1 = 1, cosθ = 1 → 0.3413416; cosθ = −1 → 0.2757267
        let mut fl = 0;
        let a = bend(
            Solution::Radial,
            DVec2::new(0.3, 0.0),
            DVec2::new(1.0, 0.0),
            1.0,
            &mut fl,
        );
        assert!((a.x - 0.3413416).abs() < 5e-8, "{a}");
        let b = bend(
            Solution::Radial,
            DVec2::new(-0.3, 0.0),
            DVec2::new(1.0, 0.0),
            1.0,
            &mut fl,
        );
        assert!((b.x + 0.2757267).abs() < 5e-8, "{b}");
        let c = unbend(
            Solution::Radial,
            DVec2::new(0.3, 0.0),
            DVec2::new(1.0, 0.0),
            &mut fl,
        );
        assert!((c.x - 0.2683282).abs() < 5e-8, "{c}");
        assert_eq!(fl, 0);
    }

    #[test]
    fn normal_reference_and_clamp() {
        let mut fl = 0;
        let a = bend(
            Solution::Normal,
            DVec2::new(0.3, 0.0),
            DVec2::new(1.0, 0.0),
            1.0,
            &mut fl,
        );
        assert!((a.x - 0.3675445).abs() < 5e-8);
        let b = bend(
            Solution::Normal,
            DVec2::new(-0.3, 0.0),
            DVec2::new(1.0, 0.0),
            1.0,
            &mut fl,
        );
        assert!((b.x + 0.2649111).abs() < 5e-8);
        assert_eq!(fl, 0);
        let c = bend(
            Solution::Normal,
            DVec2::new(0.6, 0.0),
            DVec2::new(1.0, 0.0),
            1.0,
            &mut fl,
        );
        assert_eq!(fl, CLAMPED_BEND);
        assert_eq!(c.x, 1.0);
    }

    #[test]
    fn radial_fast_path_matches_the_safeguarded_root() {
        let mut worst = 0.0_f64;
        for i in 0..=40_000 {
            let alpha = RADIAL_FAST_2 * (i as f64 / 20_000.0 - 1.0);
            let (fast, ok) = radial_ratio(alpha);
            let (safe, ok2) = radial_ratio_safe(alpha);
            assert!(ok && ok2);
            worst = worst.max((fast - safe).abs() / safe);
        }
        assert!(
            worst < 4.0 * f64::EPSILON,
            "worst relative difference {worst:e}"
        );
    }

    #[test]
    fn radial_degenerate_input_never_panics() {
        let mut fl = 0;
        // a vertex on the spine stays there whatever the stretch and curvature
        for lam in [-1.0, 0.0, f64::NAN, 1.0] {
            let d = bend(Solution::Radial, DVec2::ZERO, DVec2::X, lam, &mut fl);
            assert_eq!(d, DVec2::ZERO);
        }
        assert_eq!(fl, 0);
        assert_eq!(radial_ratio(f64::NAN), (1.0, false));
        assert_eq!(radial_ratio(f64::INFINITY), (1.0, false));
    }

    #[test]
    fn radial_root_is_a_root_and_limit() {
        for i in 0..2000 {
            let alpha = -0.39 + 0.0008 * i as f64;
            let (m, ok) = radial_ratio(alpha);
            assert!(m.is_finite());
            if ok {
                let f = alpha * m * m * m + m * m - 1.0;
                assert!(f.abs() < 1e-12, "alpha {alpha} m {m} f {f}");
            } else {
                assert!(alpha * alpha > 4.0 / 27.0);
            }
        }
    }
}

/// Property tests (proptest) of the radial solve: the root, its branch, the inverse of the
/// unbend step and the scale freedom.
#[cfg(test)]
mod proptests {
    use super::*;
    use proptest::prelude::*;

    /// `2/√27`: the fold limit of `α m³ + m² − 1` for `α < 0`.
    const LIMIT: f64 = 0.384_900_179_459_750_5;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]

        /// Within the limit the ratio is a root on the increasing (fold-free) branch
        /// `3αm + 2 > 0`, in `(0, 1)` for `α > 0` and in `[1, −2/(3α)]` for `α < 0`; the
        /// fast path agrees with the safeguarded iteration.
        #[test]
        fn radial_ratio_is_the_fold_free_root(alpha in -LIMIT * 0.999_999..50.0f64) {
            let (m, ok) = radial_ratio(alpha);
            prop_assert!(ok);
            let f = (alpha * m + 1.0) * m * m - 1.0;
            prop_assert!(f.abs() < 1e-13, "f({m}) = {f}");
            prop_assert!(3.0 * alpha * m + 2.0 > 0.0);
            if alpha > 0.0 {
                prop_assert!(m > 0.0 && m < 1.0);
            } else {
                prop_assert!(m >= 1.0 && m <= -2.0 / (3.0 * alpha) + 1e-15);
            }
            let (ms, _) = radial_ratio_safe(alpha);
            prop_assert!((m - ms).abs() < 1e-14 * m.max(1.0), "{m} {ms}");
        }

        /// Past the limit: the focal ratio `−2/(3α)`, reported.
        #[test]
        fn radial_ratio_past_the_limit_is_clamped(alpha in -1e6..-LIMIT * 1.000_001) {
            let (m, ok) = radial_ratio(alpha);
            prop_assert!(!ok);
            prop_assert!((m + 2.0 / (3.0 * alpha)).abs() < 1e-15 * m);
        }

        /// Bending back by the curvature that was unbent (no stretch) returns the point:
        /// `r* = r0 √(1 − ⅔ c)` has the root `r1 = r0` of `r1²(1 − ⅔ r1 κ cos θ) = r*²` on
        /// the fold-free branch iff `c = κ r0 cos θ < 1`. With a stretch λ the bent point
        /// solves that cubic for `r_t = |d|/√λ`, and the solve is free of scale.
        #[test]
        fn radial_bend_inverts_unbend_and_solves_the_cubic(
            d in (-1.0..1.0f64, -1.0..1.0f64), k in (-2.0..2.0f64, -2.0..2.0f64),
            lam in 0.25..4.0f64, e in -900i32..900,
        ) {
            let (d, k) = (DVec2::new(d.0, d.1), DVec2::new(k.0, k.1));
            prop_assume!(d.length() > 1e-3);
            let mut flags = 0u8;
            if d.dot(k) < 0.95 {
                let u = unbend(Solution::Radial, d, k, &mut flags);
                let back = bend(Solution::Radial, u, k, 1.0, &mut flags);
                prop_assert_eq!(flags, 0);
                prop_assert!((back - d).length() < 1e-12 * d.length(), "{back} {d}");
            }
            let mut flags = 0u8;
            let b = bend(Solution::Radial, d, k, lam, &mut flags);
            if flags == 0 {
                let (r1, rt) = (b.length(), d.length() / lam.sqrt());
                let c = b.dot(k); // κ r1 cos θ1 (the angle is kept)
                prop_assert!(b.perp_dot(d).abs() < 1e-12 * d.length_squared());
                let res = r1 * r1 * (1.0 - (2.0 / 3.0) * c) - rt * rt;
                prop_assert!(res.abs() < 1e-12 * rt * rt, "residual {res}");
            }
            let s = crate::math::scale::ldexp(1.0, e);
            let mut f2 = 0u8;
            let bs = bend(Solution::Radial, d * s, k / s, lam, &mut f2);
            prop_assert_eq!(flags, f2);
            prop_assert!((bs / s - b).length() < 1e-13 * b.length().max(1e-300));
        }
    }
}
