//! Scale normalisation: arithmetic that does not depend on the units of the input.
//!
//! Products of coordinates overflow or underflow long before the coordinates do: a chord
//! `h` enters the circle and five-point formulas as `h⁵` and a length as `√(h²)`, so with
//! `|h| ≳ 1e61` or `≲ 1e-61` the arithmetic leaves the normal range of f64 although the
//! input is fine. The remedy (as in the scaled vector norms of LAPACK's `dnrm2`, Blue,
//! "A portable Fortran program to find the Euclidean norm of a vector", ACM TOMS 4(1), 1978)
//! is to divide by a scale first:
//!
//! * a **curve** is divided by the power of two `s` with `extent/s ∈ [1, 2)`, `extent` the
//!   largest side of its bounding box ([`curve_scale`]). A power of two makes the division
//!   exact (away from subnormals), so the normalised curve is bit-identical for every
//!   scaling of the input by a power of two and every result that is invariant under
//!   scaling (frames, angles, ratios of lengths) is the same to round-off for any scale;
//! * a **vector** (a tangent, a reference vector, a quaternion) is divided by its largest
//!   absolute component before it is squared ([`length`], [`normalize`], [`normalize4`]).

use glam::{DQuat, DVec3};

use crate::error::Result;
use crate::run::alloc;

/// Scales within `[2^-SAFE_EXP, 2^SAFE_EXP]` need no normalisation: fifth powers of
/// chords stay far inside the normal range (`2^±500`).
pub const SAFE_EXP: i32 = 100;

/// `2^k` for `k ∈ [−1022, 1023]`.
#[inline]
fn pow2(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// `x · 2^k`, exact while the result is normal (in at most three steps for `|k| ≤ 2100`).
pub fn ldexp(mut x: f64, mut k: i32) -> f64 {
    while k > 1023 {
        x *= pow2(1023);
        k -= 1023;
    }
    while k < -1022 {
        x *= pow2(-1022);
        k += 1022;
    }
    x * pow2(k)
}

/// `⌊log₂ v⌋` for finite `v > 0` (subnormals included).
pub fn exponent(v: f64) -> i32 {
    let bits = v.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    if biased == 0 {
        // subnormal: scale into the normal range first (exact)
        return exponent(v * pow2(64)) - 64;
    }
    biased - 1023
}

/// Multiplication by the power of two `2^k`, exact while the results are normal: one
/// multiplication when `2^k` is itself a normal number (`|k| ≤ 1022`), [`ldexp`] otherwise.
/// Carries a model built on normalised coordinates back and forth to the input's units
/// without a pass over the data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pow2 {
    k: i32,
    /// `2^k`, or 0 when it is not a normal number.
    f: f64,
}

impl Pow2 {
    pub fn new(k: i32) -> Pow2 {
        let f = if (-1022..=1022).contains(&k) {
            pow2(k)
        } else {
            0.0
        };
        Pow2 { k, f }
    }

    /// The exponent `k`.
    pub fn exp(&self) -> i32 {
        self.k
    }

    /// `2^-k`.
    pub fn inverse(&self) -> Pow2 {
        Pow2::new(-self.k)
    }

    /// `x · 2^k`.
    #[inline(always)]
    pub fn of(&self, x: f64) -> f64 {
        if self.f != 0.0 {
            x * self.f
        } else {
            ldexp(x, self.k)
        }
    }

    /// `v · 2^k` componentwise.
    #[inline(always)]
    pub fn of3(&self, v: DVec3) -> DVec3 {
        if self.f != 0.0 {
            v * self.f
        } else {
            ldexp3(v, self.k)
        }
    }
}

/// Largest absolute component.
#[inline]
pub fn max_abs(v: DVec3) -> f64 {
    v.abs().max_element()
}

/// `|v|` without overflow or underflow in the squares (`inf` only where the length itself
/// exceeds the f64 range; NaN for non-finite input).
#[inline]
pub fn length(v: DVec3) -> f64 {
    let m = max_abs(v);
    if m == 0.0 || !m.is_finite() {
        return if v.is_finite() { m } else { f64::NAN };
    }
    let k = exponent(m);
    ldexp(ldexp3(v, -k).length(), k)
}

/// `v · 2^k` componentwise.
#[inline]
fn ldexp3(v: DVec3, k: i32) -> DVec3 {
    DVec3::new(ldexp(v.x, k), ldexp(v.y, k), ldexp(v.z, k))
}

/// `v / |v|` for any finite non-zero `v` (subnormal or close to `f64::MAX` included).
#[inline]
pub fn normalize(v: DVec3) -> Option<DVec3> {
    let m = max_abs(v);
    if !(m > 0.0 && m.is_finite()) {
        return None;
    }
    let w = ldexp3(v, -exponent(m));
    let u = w / w.length();
    u.is_finite().then_some(u)
}

/// The unit quaternion `q / |q|` for any finite non-zero `q` (components `[x, y, z, w]`).
#[inline]
pub fn normalize4(q: [f64; 4]) -> Option<DQuat> {
    let m = q.iter().fold(0.0_f64, |a, c| a.max(c.abs()));
    if !(m > 0.0 && m.is_finite()) || q.iter().any(|c| !c.is_finite()) {
        return None;
    }
    let k = -exponent(m);
    let s = q.map(|c| ldexp(c, k));
    let l = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + s[3] * s[3]).sqrt();
    Some(DQuat::from_xyzw(s[0] / l, s[1] / l, s[2] / l, s[3] / l))
}

/// Half the largest side of the axis-aligned bounding box `(lo, hi)` (halved so it cannot
/// overflow).
#[inline]
pub fn half_extent(lo: DVec3, hi: DVec3) -> f64 {
    (hi * 0.5 - lo * 0.5).max_element()
}

/// The exponent `k` such that the curve with bounding box `(lo, hi)` times `2^k` has its
/// largest side in `[1, 2)`, or `None` when no normalisation is needed (the side is within
/// `2^±SAFE_EXP`) or possible (zero, or not finite: the validation reports that).
pub fn curve_exponent(lo: DVec3, hi: DVec3) -> Option<i32> {
    let h = half_extent(lo, hi);
    if !(h > 0.0 && h.is_finite()) {
        return None;
    }
    let e = exponent(h) + 1;
    (e.abs() > SAFE_EXP).then_some(-e)
}

/// `points · 2^k` (exact away from subnormals); the copy is allocated fallibly, and the
/// out-of-memory error names `what`.
pub fn try_scaled(what: &'static str, points: &[DVec3], k: i32) -> Result<Vec<DVec3>> {
    use rayon::prelude::*;
    alloc::par_collect(
        what,
        points
            .par_iter()
            .with_min_len(1 << 12)
            .map(|p| ldexp3(*p, k)),
    )
}

/// [`try_scaled`] with an infallible allocation, for the sweep's normalisation (which has no
/// error path; its copy is the size of the curve, small beside the mesh it sweeps).
pub fn scaled(points: &[DVec3], k: i32) -> Vec<DVec3> {
    use rayon::prelude::*;
    let mut out = Vec::new();
    points
        .par_iter()
        .with_min_len(1 << 12)
        .map(|p| ldexp3(*p, k))
        .collect_into_vec(&mut out);
    out
}

/// The power of two `2^k` dividing a curve (see [`curve_exponent`]; 1 when none is needed).
pub fn curve_scale(lo: DVec3, hi: DVec3) -> f64 {
    curve_exponent(lo, hi).map_or(1.0, |k| ldexp(1.0, -k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_and_ldexp_cover_the_range() {
        for &v in &[
            1.0,
            1.5,
            3.0,
            1e-300,
            5e-324,
            1e300,
            f64::MAX,
            f64::MIN_POSITIVE,
        ] {
            let e = exponent(v);
            let m = ldexp(v, -e);
            assert!((1.0..2.0).contains(&m), "{v}: {m}");
            assert_eq!(ldexp(m, e), v);
        }
    }

    #[test]
    fn length_and_normalize_do_not_overflow() {
        let v = DVec3::new(3.0, 4.0, 0.0);
        for &s in &[1e-320, 1e-300, 1.0, 1e300] {
            assert!((length(v * s) / (5.0 * s) - 1.0).abs() < 1e-12, "{s}");
            let u = normalize(v * s).unwrap();
            assert!((u - DVec3::new(0.6, 0.8, 0.0)).length() < 1e-15, "{s}");
        }
        assert_eq!(length(DVec3::splat(f64::MAX)), f64::INFINITY);
        assert!(normalize(DVec3::ZERO).is_none());
        assert!(normalize(DVec3::new(f64::NAN, 0.0, 0.0)).is_none());
        let q = normalize4([1e300, 0.0, 0.0, 1e300]).unwrap();
        assert!((q.x - 0.5f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn curve_exponent_only_outside_the_safe_range() {
        let lo = DVec3::ZERO;
        assert_eq!(curve_exponent(lo, DVec3::splat(3.0)), None);
        let k = curve_exponent(lo, DVec3::new(1e100, 0.0, 0.0)).unwrap();
        assert!((1.0..2.0).contains(&ldexp(1e100, k)));
        let k = curve_exponent(lo, DVec3::new(1e-100, 0.0, 0.0)).unwrap();
        assert!((1.0..2.0).contains(&ldexp(1e-100, k)));
        assert_eq!(curve_exponent(lo, DVec3::new(f64::NAN, 0.0, 0.0)), None);
        assert_eq!(
            curve_exponent(-DVec3::splat(f64::MAX), DVec3::splat(f64::MAX)).map(|k| k < 0),
            Some(true)
        );
    }
}
