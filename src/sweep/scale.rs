//! Input far from unit size brought near it by powers of two (exact) and scaled back on output,
//! and the numeric types of the output: `Real` coordinates (f64, f32), `Index` face indices.

use glam::{DVec2, DVec3};

use crate::error::InputError;
use crate::frames::validate;
use crate::run::cancel::Cancel;

/// Storage of the output coordinates: `f64`, or `f32` rounded from the `f64` results.
pub trait Real: Copy + Send + Sync + 'static {
    fn of(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn finite(self) -> bool;
}

impl Real for f64 {
    #[inline(always)]
    fn of(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Real for f32 {
    #[inline(always)]
    fn of(x: f64) -> f32 {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// A spine, profile and scale far from unit size brought near it by powers of two (exact):
/// spine points times `2^k` (`k` from the spine's size), the profile divided by `2^j` (its
/// largest coordinate) and the scale multiplied by `2^(k + j)`, so `x + M (scale ⊙ profile)`
/// is the swept surface times `2^k`. The normals and fold tests multiply lengths, which
/// would overflow or underflow otherwise; [`unscaled`] divides the vertices and arc lengths
/// by `2^k` again as they are written.
pub(super) struct Scaled {
    pub(super) k: i32,
    pub(super) points: Vec<DVec3>,
    pub(super) profile: Vec<DVec2>,
    pub(super) scale: Vec<DVec2>,
}

/// The [`Scaled`] input, or `None` when the input is near unit size (or not finite: the
/// checks then report it as given).
///
/// Polls `cancel` between its passes and returns `None` once it says stop (the caller polls
/// again and discards the result).
pub(super) fn scaled_input(
    points: &[DVec3],
    profile: &[DVec2],
    scale: &[DVec2],
    cancel: Cancel<'_>,
) -> Option<Scaled> {
    use crate::math::scale as s;
    let finite = validate::first_bad(points, |p| p.is_finite(), cancel).is_none()
        && !cancel()
        && profile.iter().all(|p| p.is_finite())
        && scale
            .iter()
            .all(|v| v.x > 0.0 && v.y > 0.0 && v.is_finite());
    if !finite {
        return None;
    }
    let (lo, hi) = crate::frames::geometry::bounds(points);
    let k = s::curve_exponent(lo, hi);
    let pmax = profile
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs().max_element()));
    let j = match pmax > 0.0 {
        true => Some(s::exponent(pmax)).filter(|e| e.abs() > s::SAFE_EXP),
        false => None,
    };
    if (k.is_none() && j.is_none()) || cancel() {
        return None;
    }
    let (k, j) = (k.unwrap_or(0), j.unwrap_or(0));
    let mul2 = |v: &DVec2, e: i32| DVec2::new(s::ldexp(v.x, e), s::ldexp(v.y, e));
    Some(Scaled {
        k,
        points: s::scaled(points, k),
        profile: profile.iter().map(|v| mul2(v, -j)).collect(),
        scale: scale.iter().map(|v| mul2(v, k + j)).collect(),
    })
}

/// The output value of a coordinate computed for input scaled by `2^k` ([`scaled_input`]):
/// stored in `R`, then divided by `2^k` again (`k = None`: stored as computed).
#[inline(always)]
pub(super) fn unscaled<R: Real>(x: f64, k: Option<i32>) -> R {
    match k {
        None => R::of(x),
        Some(k) => R::of(crate::math::scale::ldexp(R::of(x).to_f64(), -k)),
    }
}

/// The error for swept vertex `i` beyond the range of the output type (float64, or float32
/// with `dtype=float32`); named by the profile's scale, passed as `scale_name`.
pub(super) fn out_of_range<R>(i: usize, scale_name: &str) -> InputError {
    InputError::new(
        scale_name.to_owned(),
        format!(
            "the swept vertex {i} (spine point + frame · scale · profile) is out of the \
             representable range of the output dtype (float{}); reduce the profile, its \
             scale or the spine",
            8 * std::mem::size_of::<R>()
        ),
    )
}

/// Storage of the face indices: `i64`, or `i32` (the caller checks that they fit).
pub trait Index: Copy + Send + Sync + 'static {
    fn of(i: usize) -> Self;
    /// The index as written by [`Index::of`] (every index written is non-negative).
    fn get(self) -> usize;
}

impl Index for i64 {
    #[inline(always)]
    fn of(i: usize) -> i64 {
        i as i64
    }
    #[inline(always)]
    fn get(self) -> usize {
        self as usize
    }
}

impl Index for i32 {
    #[inline(always)]
    fn of(i: usize) -> i32 {
        i as i32
    }
    #[inline(always)]
    fn get(self) -> usize {
        self as usize
    }
}

#[inline(always)]
pub(super) fn put3<R: Real>(v: DVec3) -> [R; 3] {
    [R::of(v.x), R::of(v.y), R::of(v.z)]
}
