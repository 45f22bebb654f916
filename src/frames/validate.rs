//! Input checks shared by the frame methods. Every check runs in parallel and reports the
//! first offending row, naming the argument.
//!
//! * Non-finite values (NaN, ±inf) are refused.
//! * Consecutive samples closer than `2⁻⁴⁰ ≈ 9.1·10⁻¹³` times the curve's size
//!   (`|x_{i+1} − x_i|_∞ ≤ 2⁻⁴⁰·extent`) make a zero-length segment (the reflection `R₁` is
//!   undefined and no tangent can be estimated there): refused here with
//!   [`ErrorKind::Repeated`], on which the Python layer merges them ([`distinct_rows`]) and
//!   computes again.
//! * A segment whose chord runs against its tangents, `v̂₁·(t_i + t_{i+1}) ≤ 10⁻⁶`, is
//!   refused: double reflection degenerates there (`v₂ → 0`, TOG §4.4) and the rotation
//!   method meets opposite tangents. Estimated tangents pass it on any polyline but where two
//!   reversals follow each other (their chord guard, `tangents::guard_chords`); given
//!   tangents (or frames)
//!   that point backwards along a segment, and the unbounded end tangents of the `FivePoint`
//!   and `FivePointUniform` rules, can fail it.

use crate::run::cancel;
use glam::{DMat3, DVec3};
use rayon::prelude::*;

use crate::error::{ErrorKind, InputError, Result};
use crate::math::rotation;
use crate::run::alloc;

/// Relative round-off tolerance for coinciding points.
pub const COINCIDE_EPS: f64 = 8.0 * f64::EPSILON;
/// Smallest accepted `v̂₁·(t_i + t_{i+1})`.
pub const MIN_ALIGNMENT: f64 = 1e-6;

/// Rows per parallel task in the cheap whole-array checks.
const CHECK_CHUNK: usize = 1 << 12;

/// Index of the first element failing `ok`, scanning blocks in parallel.
///
/// Polls `cancel` before every block and finds nothing in the blocks after it says stop (see
/// [`crate::run::cancel`]; the caller discards the result then).
pub(crate) fn first_bad<T: Sync>(
    v: &[T],
    ok: impl Fn(&T) -> bool + Sync,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Option<usize> {
    crate::run::cancel::first_bad_index(v.len(), cancel, |i| ok(&v[i]))
}

/// Polls `cancel` before every block ([`first_bad`]).
pub fn finite(arg: &str, v: &[DVec3], cancel: crate::run::cancel::Cancel<'_>) -> Result<()> {
    match first_bad(v, |p| p.is_finite(), cancel) {
        None => Ok(()),
        Some(i) => Err(InputError::new(
            arg.to_owned(),
            format!("non-finite value ({}) at row {i}", describe(v[i])),
        )),
    }
}

pub fn finite_scalars(arg: &'static str, v: &[f64]) -> Result<()> {
    match first_bad(v, |p| p.is_finite(), &cancel::never) {
        None => Ok(()),
        Some(i) => Err(InputError::new(
            arg,
            format!("non-finite value ({}) at index {i}", v[i]),
        )),
    }
}

fn describe(p: DVec3) -> String {
    format!("[{}, {}, {}]", p.x, p.y, p.z)
}

/// The same point up to the round-off of its coordinates (`|b − a|_∞ ≤ 8ε·max|·|_∞`): the
/// test for a closed curve's repeated first sample at the end.
#[inline]
pub fn coincide(a: DVec3, b: DVec3) -> bool {
    let d = (b - a).abs().max_element();
    d <= COINCIDE_EPS * a.abs().max_element().max(b.abs().max_element())
}

/// Consecutive samples closer than this fraction of the curve's size (the largest side of
/// its bounding box, `2⁻⁴⁰ ≈ 9.1·10⁻¹³`) make a zero-length segment: the same point, up to
/// the rounding of a few arithmetic steps on the coordinates. Relative to the size, not to
/// the coordinates: samples 1e-3 apart at 1e12 are distinct points on a curve 1 long, and
/// every chord that passes keeps its fifth power in the normal range.
pub const REPEAT_REL: f64 = 1.0 / (1u64 << 40) as f64;

/// The largest `|x_{i+1} − x_i|_∞` that counts as a repeated point on the curve `x`.
pub fn repeat_floor(x: &[DVec3]) -> f64 {
    let (lo, hi) = crate::frames::geometry::bounds(x);
    2.0 * crate::math::scale::half_extent(lo, hi) * REPEAT_REL
}

/// A zero-length segment: `|b − a|_∞ ≤ floor` (see [`repeat_floor`]).
#[inline]
pub fn repeated(a: DVec3, b: DVec3, floor: f64) -> bool {
    (b - a).abs().max_element() <= floor
}

/// Rows per segment of [`chords`] between two polls of the cancel hook.
const CHORD_SEGMENT: usize = 1 << 20;

/// Chord lengths `|x_{i+1} − x_i|` (and `|x_0 − x_{n−1}|` when `closed`), refusing repeated
/// consecutive points ([`repeated`]) of the points passed as `name`.
///
/// Polls `cancel` before every segment of [`CHORD_SEGMENT`] chords and every block of the check for
/// repeated points, and returns the chords done so far once it says stop (see
/// [`crate::run::cancel`]). The chords are written in parallel into reserved room, so no thread
/// zero-fills the whole buffer first.
pub fn chords(
    x: &[DVec3],
    closed: bool,
    name: &str,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<f64>> {
    let n = x.len();
    let floor = repeat_floor(x);
    let m = if closed { n } else { n.saturating_sub(1) };
    let next = |i: usize| if i + 1 == n { 0 } else { i + 1 };
    let mut seg = alloc::with_capacity("chord lengths", m)?;
    for start in (0..m).step_by(CHORD_SEGMENT) {
        if cancel() {
            return Ok(seg);
        }
        // the chords i → i + 1 of the segment, then the closing one (closed curves)
        let stop = (start + CHORD_SEGMENT).min(m);
        let inner = stop.min(n.saturating_sub(1));
        seg.par_extend(
            x[start..inner + 1]
                .par_windows(2)
                .with_min_len(CHECK_CHUNK)
                .map(|w| chord_length(w[1] - w[0])),
        );
        if stop > inner {
            seg.push(chord_length(x[0] - x[n - 1]));
        }
    }
    // the first repeated point (a cancelled search finds none; the result is discarded); a
    // chord longer than twice the floor repeats nothing (`|d|_∞ ≥ |d|/√3`), so the exact test
    // runs only on the short ones
    let short = 2.0 * floor;
    let bad = crate::run::cancel::first_bad_index(m, cancel, |i| {
        seg[i] > short || !repeated(x[i], x[next(i)], floor)
    });
    match bad {
        None => Ok(seg),
        Some(i) => Err(InputError::new(
            name.to_owned(),
            format!(
                "rows {i} and {} coincide (a zero-length segment); remove repeated \
                 consecutive points",
                (i + 1) % n
            ),
        )
        .with_kind(ErrorKind::Repeated)),
    }
}

/// `|d|`, scaled first where its square under- or overflows.
#[inline(always)]
fn chord_length(d: DVec3) -> f64 {
    let l = d.length();
    if !(l > 1e-150 && l < 1e150) {
        crate::math::scale::length(d)
    } else {
        l
    }
}

/// What [`distinct_rows`] finds about each curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum CurveStatus {
    /// Finite, with enough distinct samples.
    Valid = 0,
    /// A NaN or an infinity among its samples.
    NonFinite = 1,
    /// Fewer distinct samples than a curve needs (2, or 3 for a closed curve).
    TooFew = 2,
}

/// The samples that remain of each curve when consecutive repeats are merged: for every row
/// `j` (curves `offsets[c]..offsets[c + 1]`), the row it is merged into (`j` itself where it
/// is kept), and each curve's [`CurveStatus`].
///
/// A row is merged into the last kept row before it when they are closer than the curve's
/// [`repeat_floor`] (`|x_j − x_k|_∞ ≤ 2⁻⁴⁰·extent`, compared with the last *kept* row so a
/// creep of tiny steps cannot add up to a segment). On a closed curve the last kept rows
/// are merged into the curve's first row while they repeat it (or [`coincide`] with it). The kept rows then have no chord
/// at or under the floor of their own (never larger) extent, so the frame and sweep checks
/// accept them. Curves with a non-finite sample are left as they are (every row kept).
/// Curves in parallel, each scanned in order; polls `cancel` before every curve (the
/// result is incomplete once it says stop).
pub fn distinct_rows(
    x: &[DVec3],
    offsets: &[usize],
    closed: bool,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<(Vec<usize>, Vec<CurveStatus>)> {
    self::offsets(offsets, x.len())?;
    let mut into = alloc::with_capacity("distinct_rows", x.len())?;
    into.extend(0..x.len());
    let min = if closed { 3 } else { 2 };
    let mut parts: Vec<&mut [usize]> = Vec::with_capacity(offsets.len() - 1);
    let mut rest = &mut into[..];
    for w in offsets.windows(2) {
        let (a, b) = rest.split_at_mut(w[1] - w[0]);
        parts.push(a);
        rest = b;
    }
    let status = parts
        .into_par_iter()
        .enumerate()
        .map(|(c, rows)| {
            let (a, b) = (offsets[c], offsets[c + 1]);
            let xc = &x[a..b];
            if cancel() {
                return CurveStatus::Valid;
            }
            if xc.iter().any(|p| !p.is_finite()) {
                return CurveStatus::NonFinite;
            }
            let floor = repeat_floor(xc);
            let mut last = 0;
            let mut kept = usize::from(!xc.is_empty());
            for j in 1..xc.len() {
                if repeated(xc[last], xc[j], floor) {
                    rows[j] = a + last;
                } else {
                    last = j;
                    kept += 1;
                }
            }
            // closed: the last kept rows that repeat the first (within the floor, or its
            // rounding far from the origin, as the core's closing test has it) join it
            while closed
                && last > 0
                && (repeated(xc[last], xc[0], floor) || coincide(xc[last], xc[0]))
            {
                for r in rows.iter_mut().skip(last) {
                    *r = a;
                }
                kept -= 1;
                last = rows[last - 1] - a;
            }
            if kept < min {
                CurveStatus::TooFew
            } else {
                CurveStatus::Valid
            }
        })
        .collect();
    Ok((into, status))
}

/// Refuse segments whose chord `v1(i)` runs against the tangents.
pub fn aligned(
    t: &[DVec3],
    closed: bool,
    chord: impl Fn(usize) -> DVec3 + Sync,
    what: &str,
) -> Result<()> {
    let n = t.len();
    let m = if closed { n } else { n - 1 };
    // v̂·(t_i + t_j) > MIN  ⇔  d > 0 and d² > MIN²·|v|²  with d = v·(t_i + t_j).
    let ok = |i: usize| {
        let v = chord(i);
        let j = if i + 1 == n { 0 } else { i + 1 };
        let d = v.dot(t[i] + t[j]);
        d > 0.0 && d * d > MIN_ALIGNMENT * MIN_ALIGNMENT * v.length_squared()
    };
    let bad = crate::run::cancel::first_bad_index(m, &crate::run::cancel::never, ok);
    match bad {
        None => Ok(()),
        Some(i) => Err(InputError::new(
            what.to_owned(),
            format!(
                "the segment from row {i} to row {} runs against its tangents (the curve \
                 reverses there, a cusp, or the tangents point backwards; they turn by \
                 {:.1}° across it); check the tangents' orientation, or let spinal \
                 estimate them",
                (i + 1) % n,
                t[i].dot(t[(i + 1) % n])
                    .clamp(-1.0, 1.0)
                    .acos()
                    .to_degrees()
            ),
        )),
    }
}

/// Is `f` (row-major 3×3, columns `r, s, t`) a rotation matrix to 10⁻⁶ (orthonormal columns,
/// det > 0)? False for any non-finite entry.
pub fn is_rotation(f: &[f64; 9]) -> bool {
    // row-major f read as column-major is the transpose: transpose back (exact)
    rotation::is_rotation(&DMat3::from_cols_array(f).transpose())
}

/// Check CSR-style curve offsets (`offsets[c]..offsets[c + 1]` are the rows of curve `c`)
/// over `rows` rows. The Python functions take `lengths` (converted to offsets by a
/// cumulative sum, so they start at 0) or `offsets`; a rule broken by either is named by
/// the argument whose words describe it.
pub fn offsets(offsets: &[usize], rows: usize) -> Result<()> {
    match offsets.first() {
        None => return Err(InputError::new("offsets", "must not be empty (start at 0)")),
        Some(&o) if o != 0 => {
            return Err(InputError::new(
                "offsets",
                format!("must start at 0, got {o}"),
            ));
        }
        _ => {}
    }
    if let Some(c) = offsets.windows(2).position(|w| w[1] < w[0]) {
        return Err(InputError::new(
            "lengths",
            format!(
                "must be non-negative: curve {c} has length {} (offsets must never decrease)",
                offsets[c + 1] as i64 - offsets[c] as i64
            ),
        ));
    }
    let last = offsets[offsets.len() - 1];
    if last != rows {
        return Err(InputError::new(
            "lengths",
            format!("the curves cover {last} rows but the input has {rows}"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distinct_rows_merge_repeats_into_the_last_kept_row() {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let e = 1e-13; // under 2⁻⁴⁰ of the size 1 (9.1e-13)
        let x = [
            // curve 0: a repeat, then a creep of three tiny steps (adding up past the floor)
            p(0.0, 0.0),
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(1.0 + e, 0.0),
            p(1.0 + 2.0 * e, 0.0),
            p(1.0 + 12.0 * e, 0.0),
            p(1.0, 1.0),
            // curve 1: one point twice
            p(5.0, 5.0),
            p(5.0, 5.0),
            // curve 2: a NaN
            p(0.0, f64::NAN),
            p(1.0, 1.0),
        ];
        let (into, status) = distinct_rows(&x, &[0, 7, 9, 11], false, &crate::run::cancel::never)
            .expect("valid offsets");
        assert_eq!(into, [0, 0, 2, 2, 2, 5, 6, 7, 7, 9, 10]);
        assert_eq!(
            status,
            [
                CurveStatus::Valid,
                CurveStatus::TooFew,
                CurveStatus::NonFinite
            ]
        );
        // the kept rows pass the chord check the frames and sweeps make
        let kept: Vec<DVec3> = (0..7).filter(|&j| into[j] == j).map(|j| x[j]).collect();
        assert!(chords(&kept, false, "points", &cancel::never).is_ok());
        assert!(
            chords(&x[..7], false, "points", &cancel::never)
                .unwrap_err()
                .kind
                == ErrorKind::Repeated
        );
        // closed: a last row that repeats the first joins it; a triangle with a repeat has
        // too few distinct points
        let tri = [
            p(0.0, 0.0),
            p(1.0, 0.0),
            p(1.0, 0.0),
            p(0.0, 1.0),
            p(e, 0.0),
        ];
        let (into, status) =
            distinct_rows(&tri, &[0, 5], true, &crate::run::cancel::never).expect("valid offsets");
        assert_eq!(
            (into, status),
            (vec![0, 1, 1, 3, 0], vec![CurveStatus::Valid])
        );
        // two jittered closing samples, each far enough from the other: both join the first
        let f = 0.8 * 2.0f64.powi(-40);
        let jit = [p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0), p(f, 0.0), p(-f, 0.0)];
        let (into, _) =
            distinct_rows(&jit, &[0, 5], true, &crate::run::cancel::never).expect("valid offsets");
        assert_eq!(into, [0, 1, 2, 0, 0]);
        assert!(chords(&jit[..3], true, "points", &cancel::never).is_ok());
        let (_, status) = distinct_rows(&tri[..3], &[0, 3], true, &crate::run::cancel::never)
            .expect("valid offsets");
        assert_eq!(status, [CurveStatus::TooFew]);
    }

    #[test]
    fn offsets_name_the_broken_rule() {
        assert!(offsets(&[0, 3, 5], 5).is_ok());
        assert_eq!(offsets(&[], 5).unwrap_err().arg, "offsets");
        assert_eq!(offsets(&[1, 5], 5).unwrap_err().arg, "offsets");
        let e = offsets(&[0, 4, 2, 5], 5).unwrap_err();
        assert_eq!(e.arg, "lengths");
        assert!(e.msg.contains("curve 1 has length -2"), "{e}");
        let e = offsets(&[0, 2, 4], 5).unwrap_err();
        assert!(e.msg.contains("cover 4 rows but the input has 5"), "{e}");
    }
}
