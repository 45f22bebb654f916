//! The checks of one spine before it is swept: row counts, finite and distinct points, given
//! frames that are rotations with their tangents along the spine, positive scale, finite twist.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::corners::Corner;
use super::layout::{Plan, Size};
use super::{Options, Profile, Spine, columns};
use crate::error::{InputError, Result};
use crate::frames::validate;
use crate::run::cancel::Cancel;

/// Check one spine and plan its part of the mesh; polls `cancel` between its passes and
/// before every block of rows within them, and returns `None` once it says stop (see
/// [`crate::run::cancel`]). `given`: the frames came with the input and are checked too (frames
/// computed here are rotations along the spine by construction). `found`: the spine's size
/// and corners as its layout found them ([`Size::with_corners`]), or `None` to find them.
// Kept whole: the checks share the spine's chords buffer (reused for the arc lengths) and
// poll between and within their passes in one sequence.
pub(super) fn check_spine(
    s: &Spine,
    opts: &Options,
    p: &Profile,
    given: bool,
    found: Option<(Size, Vec<Corner>)>,
    cancel: Cancel<'_>,
) -> Result<Option<Plan>> {
    let n = s.points.len();
    if s.frames.len() != n {
        return Err(InputError::new(
            "frames",
            format!("has {} rows but points has {n}", s.frames.len()),
        ));
    }
    if s.scale.len() != n && s.scale.len() != 1 {
        return Err(InputError::new(
            opts.scale_name.to_owned(),
            format!("has {} rows but points has {n}", s.scale.len()),
        ));
    }
    if !s.twist.is_empty() && s.twist.len() != n {
        return Err(InputError::new(
            "twist",
            format!("has {} entries but points has {n} rows", s.twist.len()),
        ));
    }
    validate::finite("points", s.points, cancel)?;
    if cancel() {
        return Ok(None);
    }
    let (size, corners) = found.unwrap_or_else(|| Size::with_corners(s, opts, p));
    let rings = size.rings;
    let min = if opts.closed { 3 } else { 2 };
    if rings < min {
        return Err(InputError::new(
            "points",
            format!(
                "a{} spine needs at least {min} distinct points, got {rings}",
                if opts.closed { " closed" } else { "n open" }
            ),
        ));
    }
    let chords = validate::chords(&s.points[..rings], opts.closed, "points", cancel)?;
    if cancel() {
        return Ok(None);
    }
    let bad_frame = match given {
        true => validate::first_bad(s.frames, validate::is_rotation, cancel),
        false => None,
    };
    if let Some(i) = bad_frame {
        return Err(InputError::new(
            "frames",
            format!(
                "row {i} is not a rotation matrix (columns r, s, t must be orthonormal and \
                 right-handed; use spinal.frames)"
            ),
        ));
    }
    if cancel() {
        return Ok(None);
    }
    let against = match given {
        true => against_spine(&s.points[..rings], s.frames, opts.closed, cancel),
        false => None,
    };
    let hint = "the sweep would be inside out there; frames must be computed for the points \
                in their order (spinal.frames(points))";
    match against {
        Some(Against::Row(k)) => {
            return Err(InputError::new(
                "frames",
                format!(
                    "the tangent column t of row {k} points against the spine (negative \
                     dot product with the chord{} at point {k}): {hint}",
                    if opts.closed || (k > 0 && k + 1 < rings) {
                        "s"
                    } else {
                        ""
                    }
                ),
            ));
        }
        Some(Against::Segment(i)) => {
            let j = if i + 1 == rings { 0 } else { i + 1 };
            return Err(InputError::new(
                "frames",
                format!(
                    "the tangent column t of rows {i} and {j} points against the spine (from \
                     point {i} to point {j}): {hint}"
                ),
            ));
        }
        None => {}
    }
    if cancel() {
        return Ok(None);
    }
    let positive = |v: &DVec2| v.x > 0.0 && v.y > 0.0 && v.is_finite();
    if let Some(i) = validate::first_bad(s.scale, positive, cancel) {
        return Err(InputError::new(
            opts.scale_name.to_owned(),
            format!(
                "must be positive and finite, got {} at row {i} (for a pointed end use a \
                 small positive value)",
                shown(s.scale[i])
            ),
        ));
    }
    if let Some(i) = validate::first_bad(s.twist, |v| v.is_finite(), cancel) {
        return Err(InputError::new(
            "twist",
            format!("non-finite value at row {i}"),
        ));
    }
    if cancel() {
        return Ok(None);
    }
    // the arc lengths in the chords' buffer (no second array of the spine's length)
    let mut arc = chords;
    arc.reserve_exact(1);
    arc.insert(0, 0.0);
    let mut acc = 0.0;
    for a in arc.iter_mut() {
        acc += *a;
        *a = acc;
    }
    Ok(Some(Plan { size, arc, corners }))
}

/// A row of the scale as the user gave it: one number for a radius (both factors equal),
/// the pair otherwise.
fn shown(v: DVec2) -> String {
    if v.x == v.y || (v.x.is_nan() && v.y.is_nan()) {
        format!("{}", v.x)
    } else {
        format!("{:?}", v.to_array())
    }
}

/// Where given frames point against the spine, which would turn the mesh there inside out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Against {
    /// The tangent `t_k` of row `k` has a negative dot product with every chord at that row
    /// (both `x_k − x_{k−1}` and `x_{k+1} − x_k`; the one chord at an open end): a reversed
    /// frame. A tangent estimated from the points (any weighting of the two chords' unit
    /// vectors) agrees with at least one of them, however tight the turn.
    Row(usize),
    /// The chord of segment `i` (from sample `i` to the next) runs against the tangents of
    /// both its ends, `(x_{i+1} − x_i)·t_i < 0` and `(x_{i+1} − x_i)·t_{i+1} < 0`.
    Segment(usize),
}

/// The first row `k` where the frames point against the spine ([`Against`]; a row's own
/// test first, then the segment that starts there). Polls `cancel` before every block of
/// rows and finds nothing in the blocks after it says stop.
fn against_spine(
    x: &[DVec3],
    frames: &[[f64; 9]],
    closed: bool,
    cancel: Cancel<'_>,
) -> Option<Against> {
    const BLOCK: usize = 1 << 14;
    let n = x.len();
    let t = |k: usize| columns(&frames[k]).2;
    // the chord from row k to the next (None past the end of an open spine)
    let chord = |k: usize| match (k + 1 == n, closed) {
        (false, _) => Some(x[k + 1] - x[k]),
        (true, true) => Some(x[0] - x[k]),
        (true, false) => None,
    };
    let before = |k: usize| match (k, closed) {
        (0, false) => None,
        (0, true) => chord(n - 1),
        _ => chord(k - 1),
    };
    (0..n.div_ceil(BLOCK)).into_par_iter().find_map_first(|b| {
        if cancel() {
            return None;
        }
        (b * BLOCK..((b + 1) * BLOCK).min(n)).find_map(|k| {
            let tk = t(k);
            let (cin, cout) = (before(k), chord(k));
            let against = |c: Option<DVec3>| c.is_none_or(|c| c.dot(tk) < 0.0);
            if (cin.is_some() || cout.is_some()) && against(cin) && against(cout) {
                return Some(Against::Row(k));
            }
            let j = if k + 1 == n { 0 } else { k + 1 };
            cout.filter(|c| c.dot(tk) < 0.0 && c.dot(t(j)) < 0.0)
                .map(|_| Against::Segment(k))
        })
    })
}
