//! The normal–binormal blend (Zhuo 2014 Ch. VIII, §8.1–8.3): a one-parameter family of
//! volume-preserving offset corrections between the normal (`w = 1`) and the binormal
//! (`w = 0`) solutions.
//!
//! Ch. VIII combines the two by assuming that the changes along N and B are independent
//! (Eq. 44, `(x1 − ½κ1x1²) y1 = (x0 − ½κ0x0²) y0`) or by moving along a prescribed direction
//! (Eq. 45–46); neither has Jacobian determinant 1 (at φ = 90° Eq. 46 reduces to Eq. 47,
//! `(1 − ½κ1x0) l = ½κ1x0y0`, where the exact binormal map needs `(1 − κ1x0) l = κ1x0y0`).
//! The thesis notes that a cascade of the two solutions is exact since every stage has
//! determinant 1. We use such a cascade inside unbend–transfer–bend, through virtual spines
//! whose curvature vector is a fraction `w` of the real one (same direction):
//!
//! * posed side (straight → posed curvature `κ1`, speed ratio `λ`, in the posed frame's N, B):
//!   the normal bend into `wκ1` with the stretch `λ^w` along N,
//!   `x_a − ½wκ1 x_a² = x'/λ^w`; then the binormal unbend at `wκ1`, `y_b = (1 − wκ1 x_a) y'`;
//!   then the binormal bend into `κ1` with the stretch `λ^(1−w)` along B,
//!   `y1 = y_b / (λ^(1−w) (1 − κ1 x_a))`, `x1 = x_a`;
//! * rest side (rest curvature `κ0` → straight) the mirror image, the inverse of the posed
//!   side's construction with `κ0` and no stretch: the binormal unbend at `κ0`, the binormal
//!   bend into `wκ0`, the normal unbend at `wκ0`: `y* = y0 (1 − κ0x0)/(1 − wκ0x0)`,
//!   `x* = x0 (1 − ½wκ0 x0)`.
//!
//! In the coordinates `(s, x, y)` of a spine of speed `σ` and curvature `κ` the volume
//! element is `σ (1 − κx) ds dx dy`; every stage carries the volume element of one (virtual)
//! spine onto that of the next, so each stage has determinant 1 and so has the whole map,
//! for every `w`, any twist, roll and stretch (the stretch is split as `λ^w · λ^(1−w)`).
//! At `w = 1` the binormal stages cancel (the same factor `1 − κx` divides and multiplies)
//! and the map is the normal solution; at `w = 0` the normal stages are the identity and the
//! map is the binormal solution — both at the rest and at the posed side, so the end points
//! hold for curved rest spines and stretch too.
//!
//! Fold-over (§4.3): the normal bend clamps at the focal point `1/(wκ1)` as in
//! [`super::solve`], the binormal factors are capped below at
//! [`super::BINORMAL_MIN_FACTOR`] unless they cancel (`w = 1`).

use glam::DVec2;

use super::{BINORMAL_MIN_FACTOR, CLAMPED_BEND, CLAMPED_UNBEND, TINY_CURVATURE, bent_normal};
use crate::error::{InputError, Result};

/// The blend weight `w` checked: finite and in `[0, 1]` (errors name `blend`).
pub fn check_weight(w: f64) -> Result<f64> {
    if (0.0..=1.0).contains(&w) {
        Ok(w)
    } else {
        Err(InputError::new(
            "blend",
            format!("the weight of the normal solution must be in [0, 1], got {w}"),
        ))
    }
}

/// Unit normal and curvature of a curvature vector (fallback `X` where straight).
#[inline(always)]
fn frenet(k: DVec2) -> (DVec2, f64) {
    let kk = k.length();
    if kk > TINY_CURVATURE && kk.is_finite() {
        (k * (1.0 / kk), kk)
    } else {
        (DVec2::X, 0.0)
    }
}

/// `num/den` applied to `y` (the pair of binormal stages), the factors capped below at
/// [`BINORMAL_MIN_FACTOR`] unless they are equal (then the stages cancel exactly).
#[inline(always)]
fn binormal_pair(y: f64, num: f64, den: f64, flag: u8, flags: &mut u8) -> f64 {
    if num == den {
        return y;
    }
    let cap = |f: f64, flags: &mut u8| {
        if f < BINORMAL_MIN_FACTOR {
            *flags |= flag;
            BINORMAL_MIN_FACTOR
        } else {
            f
        }
    };
    let (num, den) = (cap(num, flags), cap(den, flags));
    y / den * num
}

/// Rest side of the blend: the binormal unbend at `k0`, the binormal bend into `w k0`, the
/// normal unbend at `w k0` (rest cross-section coordinates `d`).
#[inline(always)]
pub fn unbend_blend(w: f64, d: DVec2, k0: DVec2, flags: &mut u8) -> DVec2 {
    let (n, kk) = frenet(k0);
    if kk == 0.0 {
        return d;
    }
    let b = n.perp();
    let (x, y) = (d.dot(n), d.dot(b));
    let wk = w * kk;
    let y1 = binormal_pair(y, 1.0 - kk * x, 1.0 - wk * x, CLAMPED_UNBEND, flags);
    let xc = if wk * x >= 1.0 {
        *flags |= CLAMPED_UNBEND;
        1.0 / wk
    } else {
        x
    };
    xc * (1.0 - 0.5 * wk * xc) * n + y1 * b
}

/// Posed side of the blend: the normal bend into `w k1` with the stretch `λ^w`, the binormal
/// unbend at `w k1`, the binormal bend into `k1` with the stretch `λ^(1−w)` (transferred
/// coordinates `d` in the posed frame).
#[inline(always)]
pub fn bend_blend(w: f64, d: DVec2, k1: DVec2, lam: f64, flags: &mut u8) -> DVec2 {
    let (n, kk) = frenet(k1);
    let b = n.perp();
    let (x, y) = (d.dot(n), d.dot(b));
    // λ^w and λ^(1−w), exact at the end points
    let (lam_n, lam_b) = if w == 1.0 {
        (lam, 1.0)
    } else if w == 0.0 {
        (1.0, lam)
    } else {
        (lam.powf(w), lam.powf(1.0 - w))
    };
    let wk = w * kk;
    let xt = x / lam_n;
    let xa = bent_normal(wk, xt, flags);
    let y1 = binormal_pair(y / lam_b, 1.0 - wk * xa, 1.0 - kk * xa, CLAMPED_BEND, flags);
    xa * n + y1 * b
}

#[cfg(test)]
mod tests {
    use super::super::solve::{Solution, bend, unbend};
    use super::*;

    #[test]
    fn end_points_are_normal_and_binormal() {
        let k0 = DVec2::new(0.7, -0.4);
        let k1 = DVec2::new(-0.3, 1.1);
        for d in [
            DVec2::new(0.2, 0.1),
            DVec2::new(-0.15, 0.2),
            DVec2::new(0.1, -0.25),
        ] {
            for lam in [0.8, 1.0, 1.3] {
                let mut f = 0;
                let n = bend(
                    Solution::Normal,
                    unbend(Solution::Normal, d, k0, &mut f),
                    k1,
                    lam,
                    &mut f,
                );
                let b = bend(
                    Solution::Binormal,
                    unbend(Solution::Binormal, d, k0, &mut f),
                    k1,
                    lam,
                    &mut f,
                );
                assert_eq!(f, 0);
                let n1 = bend_blend(1.0, unbend_blend(1.0, d, k0, &mut f), k1, lam, &mut f);
                let b1 = bend_blend(0.0, unbend_blend(0.0, d, k0, &mut f), k1, lam, &mut f);
                assert_eq!(f, 0);
                assert!((n - n1).length() < 1e-15, "{n} {n1}");
                assert_eq!(b, b1);
            }
        }
    }

    #[test]
    fn weights_are_checked() {
        assert_eq!(check_weight(0.0), Ok(0.0));
        assert_eq!(check_weight(1.0), Ok(1.0));
        for w in [-1e-300, 1.0 + 1e-15, f64::NAN, f64::INFINITY] {
            let e = check_weight(w).unwrap_err();
            assert_eq!(e.arg, "blend");
        }
    }
}
