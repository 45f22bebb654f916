//! Quaternion frames (Hanson & Ma 1995; Ma's thesis 1996; see docs/references.md).
//!
//! A frame `F = (r, s, t)` (columns) is the rotation `R(q)` of a unit quaternion
//! `q = (w, x, y, z)`; `q` and `−q` give the same frame. Arrays here store `(x, y, z, w)`
//! (glam's and scipy's default order); the Python layer offers `scalar_first`.
//!
//! * **Matrix → quaternion** by Shepperd's method: take the square root of the largest of
//!   `1 + tr R`, `1 + 2R₀₀ − tr R`, `1 + 2R₁₁ − tr R`, `1 + 2R₂₂ − tr R` and the other
//!   components from sums/differences of off-diagonal pairs, so no division by a small
//!   number happens (Ma's Fig. 3.1 tests `> 0` exactly and fails at half turns).
//! * **Sign continuity**: `q₀` canonical (`w ≥ 0`), then `q_i ← −q_i` whenever
//!   `q_i·q_{i−1} < 0`, so that neighbours are close on S³ and slerp takes the short arc.
//! * **Parallel transport** as a quaternion recurrence (Ma §2.2.1): the rotation taking
//!   `T_i` to `T_{i+1}` about `T_i × T_{i+1}` is `Δq_i = normalise(1 + T_i·T_{i+1},
//!   T_i × T_{i+1})`, and `Q_{i+1} = Δq_i Q_i` (a rotation of the world multiplies on the
//!   left). This is Bloomenthal's rotation method written with quaternions.
//! * **Closure** of a closed curve: after one circuit the transported `r` differs from
//!   `r₀` by the closing angle `α` (signed, about `t₀`, from the end vector to the start
//!   vector, = ∮τ ds mod 2π); the body rotation `Q_i ← Q_i (cos(a_i/2), 0, 0, sin(a_i/2))`
//!   about the tangent with `a_i = (α + 2π·turns) L_i / L` closes the frames (Ma's text
//!   applies the angle with the opposite sign, which doubles the mismatch).
//! * **Path length** `Σ 2 atan2(|q_{i+1} − q_i|, |q_{i+1} + q_i|)`: the length of the
//!   quaternion curve on S³, half the total rotation angle of the frames — a measure of
//!   their total twist and turn (`½∫|ω| ds` in the limit).

pub mod camera;
pub mod spin;
pub mod walk;

use glam::{DMat3, DQuat, DVec3};
use rayon::prelude::*;

use crate::error::{InputError, Result};
use crate::frames::tangents::{self as tangent_estimate, TangentRule};
use crate::frames::{self, Method, Orientation, Request, validate};
use crate::math::rotation;
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

use crate::run::cancel::GRAIN;

/// Rows per segment of a cancellable conversion ([`from_frames`]).
const CANCEL_SEGMENT: usize = 1 << 20;

/// The unit quaternion of a row-major rotation matrix (columns `r, s, t`), Shepperd's
/// method ([`rotation::quat_from_mat3`]). The result is normalised; its sign is not canonical.
pub fn from_matrix(f: &[f64; 9]) -> DQuat {
    // row-major f read as column-major is the transpose: transpose back (exact)
    rotation::quat_from_mat3(&DMat3::from_cols_array(f).transpose())
}

/// The row-major rotation matrix of a unit quaternion.
pub fn to_matrix(q: DQuat) -> [f64; 9] {
    let m = rotation::mat3_from_quat(q);
    let (a, b, c) = (m.x_axis, m.y_axis, m.z_axis);
    [a.x, b.x, c.x, a.y, b.y, c.y, a.z, b.z, c.z]
}

/// `q` or `−q`, whichever has `w > 0` (or, for `w = 0`, the first non-zero of `x, y, z`
/// positive), as scipy's canonical form.
pub fn canonical(q: DQuat) -> DQuat {
    let lead = [q.w, q.x, q.y, q.z]
        .into_iter()
        .find(|v| *v != 0.0)
        .unwrap_or(1.0);
    if lead < 0.0 { -q } else { q }
}

/// Flip signs so that consecutive quaternions have a non-negative dot product, starting
/// from the canonical sign of the first.
///
/// Polls `cancel` every [`cancel::BLOCK`] rows and leaves the rest as they are once it says stop
/// (see [`crate::run::cancel`]).
pub fn make_continuous(q: &mut [DQuat], cancel: Cancel<'_>) {
    if let Some(first) = q.first_mut() {
        *first = canonical(*first);
    }
    for i in 1..q.len() {
        if i % cancel::BLOCK == 0 && cancel() {
            return;
        }
        if q[i].dot(q[i - 1]) < 0.0 {
            q[i] = -q[i];
        }
    }
}

/// A sign-continuous copy of quaternions ([`make_continuous`]); non-finite rows are refused.
///
/// Polls `cancel` in its check and every [`cancel::BLOCK`] rows of the sign pass (an incomplete
/// result once it says stop; see [`crate::run::cancel`]).
pub fn continuous(q: &[DQuat], cancel: Cancel<'_>) -> Result<Vec<DQuat>> {
    if let Some(i) = validate::first_bad(q, |v| v.is_finite(), cancel) {
        return Err(InputError::new(
            "quaternions",
            format!("contains non-finite values (row {i})"),
        ));
    }
    // copied in blocks that poll, then the signs
    let mut v = alloc::with_capacity("quaternions", q.len())?;
    for block in q.chunks(cancel::BLOCK) {
        if cancel() {
            return Ok(v);
        }
        v.extend_from_slice(block);
    }
    make_continuous(&mut v, cancel);
    Ok(v)
}

/// Quaternions of frames (row-major `(n, 3, 3)`), sign-continuous if asked.
///
/// Polls `cancel` before every segment of [`CANCEL_SEGMENT`] rows and returns the rows done so far
/// once it says stop (see [`crate::run::cancel`]).
pub fn from_frames(
    frames: &[[f64; 9]],
    continuous: bool,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<DQuat>> {
    // a cancelled check passes every row (the result is discarded)
    if let Some(i) = validate::first_bad(
        frames,
        |f| cancel() || validate::is_rotation(f),
        &cancel::never,
    ) {
        return Err(InputError::new(
            "frames",
            format!(
                "row {i} is not a rotation matrix (columns must be orthonormal to 1e-6 and \
                 right-handed; a reflection has no quaternion)"
            ),
        ));
    }
    let mut q: Vec<DQuat> = alloc::with_capacity("to_quaternions", frames.len())?;
    // in segments written into the reserved room: a cancelled call neither computes nor
    // touches the pages of the rows it skips
    for seg in frames.chunks(CANCEL_SEGMENT) {
        if cancel() {
            return Ok(q);
        }
        q.par_extend(
            seg.par_iter()
                .with_min_len(GRAIN)
                .map(|f| canonical(from_matrix(f))),
        );
    }
    if continuous {
        make_continuous(&mut q, cancel);
    }
    Ok(q)
}

/// `q / |q|`, divided by its largest component first so that any finite non-zero quaternion
/// (|q| from 1e-320 to 1e308) gives its rotation; `None` for zero or non-finite `q`.
#[inline]
pub fn unit(q: DQuat) -> Option<DQuat> {
    crate::math::scale::normalize4(q.to_array())
}

/// Can `q` be normalised ([`unit`])?
#[inline]
fn normalisable(q: &DQuat) -> bool {
    unit(*q).is_some()
}

/// [`unit`] of a quaternion already checked by [`normalisable`].
#[inline]
fn unit_checked(q: DQuat) -> DQuat {
    unit(q).unwrap_or(DQuat::IDENTITY)
}

/// Frames of quaternions (normalised first; a zero or non-finite quaternion is refused).
///
/// Polls `cancel` before every block of rows and skips the remaining blocks once it returns `true`
/// (`out` is then incomplete; see [`crate::run::cancel`]). Blocks, not rows: the first write to a
/// fresh output page costs a page fault, so the loop also stops between the faults.
pub fn to_frames(
    q: &[DQuat],
    out: &mut [[f64; 9]],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<()> {
    if let Some(i) = validate::first_bad(q, |v| cancel() || normalisable(v), &cancel::never) {
        return Err(InputError::new(
            "quaternions",
            format!("row {i} is zero or not finite and cannot be normalised"),
        ));
    }
    if out.len() != q.len() {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    cancel::fill(out, cancel, |i| to_matrix(unit_checked(q[i])));
    Ok(())
}

/// Spherical linear interpolation from `a` to `b` (the short arc: `b` is negated when
/// `a·b < 0`) at `u` (0 gives `a`, 1 gives ±`b`). The angle comes from
/// `2 atan2(|b − a|, |b + a|)`, accurate for small and large angles alike.
pub fn slerp(a: DQuat, b: DQuat, u: f64) -> DQuat {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    let half = ((b - a).length()).atan2((b + a).length()); // θ/2 ∈ [0, π/4]
    let theta = 2.0 * half;
    if theta < 1e-8 {
        return (a * (1.0 - u) + b * u).normalize();
    }
    let s = theta.sin();
    (a * (((1.0 - u) * theta).sin() / s) + b * ((u * theta).sin() / s)).normalize()
}

/// Slerp row by row (all three slices have the same length).
///
/// Polls `cancel` in its checks and between blocks of rows (an incomplete result once it says stop;
/// see [`crate::run::cancel`]).
pub fn slerp_many(
    a: &[DQuat],
    b: &[DQuat],
    u: &[f64],
    out: &mut [DQuat],
    cancel: Cancel<'_>,
) -> Result<()> {
    for (arg, v) in [("q0", a), ("q1", b)] {
        if let Some(i) = validate::first_bad(v, normalisable, cancel) {
            return Err(InputError::new(
                arg,
                format!("row {i} is zero or not finite"),
            ));
        }
    }
    validate::finite_scalars("u", u)?;
    cancel::fill(out, cancel, |i| {
        slerp(unit_checked(a[i]), unit_checked(b[i]), u[i])
    });
    Ok(())
}

/// Key frames interpolated by slerp: `frames` (row-major `(n, 3, 3)`, `n ≥ 2`) at the
/// finite, strictly increasing `key_u`, evaluated at `new_u` inside `[key_u[0],
/// key_u[n−1]]`. The quaternions of the keys are made sign-continuous, so each interval
/// takes the short arc; `u` in `[key_u[i], key_u[i+1])` (the last interval closed) uses
/// keys `i, i+1` with the weight `(u − key_u[i]) / (key_u[i+1] − key_u[i])`.
///
/// Polls `cancel` in its checks and between blocks of rows (an incomplete result once it says stop;
/// see [`crate::run::cancel`]).
pub fn slerp_frames(
    frames: &[[f64; 9]],
    key_u: &[f64],
    new_u: &[f64],
    out: &mut [[f64; 9]],
    cancel: Cancel<'_>,
) -> Result<()> {
    let n = frames.len();
    if n < 2 {
        return Err(InputError::new(
            "frames",
            format!("need at least 2 key frames, got {n}"),
        ));
    }
    if key_u.len() != n {
        return Err(InputError::new(
            "key_u",
            format!("expected {n} values to match frames, got {}", key_u.len()),
        ));
    }
    let increasing = |i: usize| key_u[i].is_finite() && (i == 0 || key_u[i] > key_u[i - 1]);
    if let Some(i) = cancel::first_bad_index(n, cancel, increasing) {
        return Err(InputError::new(
            "key_u",
            format!("must be finite and strictly increasing (index {i})"),
        ));
    }
    if let Some(i) = validate::first_bad(new_u, |u| u.is_finite(), cancel) {
        return Err(InputError::new(
            "new_u",
            format!("contains non-finite values (index {i})"),
        ));
    }
    let (lo, hi) = (key_u[0], key_u[n - 1]);
    if let Some(i) = validate::first_bad(new_u, |&u| (lo..=hi).contains(&u), cancel) {
        return Err(InputError::new(
            "new_u",
            format!(
                "values must lie in [{lo:?}, {hi:?}] (the key range); index {i} is {:?}",
                new_u[i]
            ),
        ));
    }
    if out.len() != new_u.len() {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    let q = from_frames(frames, true, cancel)?;
    // a stopped conversion returns fewer rows
    if q.len() != n || cancel() {
        return Ok(());
    }
    cancel::fill(out, cancel, |j| {
        let u = new_u[j];
        let i = key_u
            .partition_point(|&k| k <= u)
            .saturating_sub(1)
            .min(n - 2);
        let w = (u - key_u[i]) / (key_u[i + 1] - key_u[i]);
        let s = slerp(q[i].normalize(), q[i + 1].normalize(), w);
        to_matrix(s.normalize())
    });
    Ok(())
}

/// Angle between two frames' quaternions: the length of the short arc on S³,
/// `2 atan2(|b − a|, |b + a|)` after sign alignment (half the relative rotation angle).
#[inline]
fn arc(a: DQuat, b: DQuat) -> f64 {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    2.0 * (b - a).length().atan2((b + a).length())
}

/// Length of the quaternion curve (unit quaternions, any signs), `closed` adding the arc
/// from the last to the first.
///
/// Polls `cancel` in its check and between blocks of arcs (a meaningless result once it says stop;
/// see [`crate::run::cancel`]). The arcs are summed per block of [`GRAIN`] and the block sums in
/// order, so the result does not depend on the number of threads.
pub fn path_length(q: &[DQuat], closed: bool, cancel: Cancel<'_>) -> Result<f64> {
    if let Some(i) = validate::first_bad(q, normalisable, cancel) {
        return Err(InputError::new(
            "quaternions",
            format!("row {i} is zero or not finite"),
        ));
    }
    let n = q.len();
    let m = if closed { n } else { n.saturating_sub(1) };
    let arc_at = |i: usize| arc(unit_checked(q[i]), unit_checked(q[(i + 1) % n]));
    let sums = alloc::rows("quaternion_length", m.div_ceil(GRAIN), 1, cancel, |b| {
        (b * GRAIN..m.min((b + 1) * GRAIN)).map(arc_at).sum::<f64>()
    })?;
    Ok(sums.map_or(0.0, |s| s.iter().sum()))
}

/// The unit tangents at the points `x` (`n ≥ 2` rows): the given `t` (finite, non-zero
/// rows) normalised, or without them the estimate of `spinal.estimate_tangents`
/// ([`tangent_estimate::estimate_rows`], five-point rule). Polls `cancel` inside the
/// estimate and between the passes over given tangents; a cancelled call returns an
/// incomplete result (see [`crate::run::cancel`]).
pub(crate) fn unit_tangents(
    x: &[DVec3],
    t: Option<&[DVec3]>,
    closed: bool,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Vec<DVec3>> {
    if x.len() < 2 {
        return Err(InputError::new(
            "points",
            format!("need at least 2 samples, got {}", x.len()),
        ));
    }
    let Some(t) = t else {
        return tangent_estimate::estimate_rows(x, closed, TangentRule::FivePointBounded, cancel);
    };
    if t.len() != x.len() {
        return Err(InputError::new(
            "tangents",
            format!("expected {} rows to match points, got {}", x.len(), t.len()),
        ));
    }
    // a cancelled check passes every row (the result is discarded)
    if let Some(i) = validate::first_bad(t, |v| cancel() || v.is_finite(), &cancel::never) {
        return Err(InputError::new(
            "tangents",
            format!("contains non-finite values (row {i})"),
        ));
    }
    if let Some(i) = validate::first_bad(
        t,
        |v| cancel() || crate::math::scale::normalize(*v).is_some(),
        &cancel::never,
    ) {
        return Err(InputError::new(
            "tangents",
            format!("zero-length tangent at row {i}"),
        ));
    }
    let mut out = alloc::with_capacity("quaternion_frames", t.len())?;
    t.par_iter()
        .with_min_len(GRAIN)
        .map(|v| crate::math::scale::normalize(*v).unwrap_or(DVec3::Z))
        .collect_into_vec(&mut out);
    Ok(out)
}

/// The reference vector at row 0 of the rotation-method frames of `x` with unit tangents
/// `t` ([`frames::compute_into`], spinal's default initial vector).
fn default_reference(
    x: &[DVec3],
    t: &[DVec3],
    closed: bool,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<DVec3> {
    let req = Request {
        points: Some(x),
        tangents: Some(t),
        closed,
        method: Method::Rotation,
        ..Request::default()
    };
    let mut buf = alloc::filled(
        "quaternion_frames",
        alloc::product("quaternion_frames", 9, x.len(), 8)?,
        0.0,
    )?;
    // the scan's working vectors take under `frames::WORKING_BYTES_PER_ROW`: probe for them
    // (freed at once) so that their infallible allocation cannot abort
    alloc::with_capacity::<u8>(
        "quaternion_frames",
        alloc::product(
            "quaternion_frames",
            x.len(),
            frames::WORKING_BYTES_PER_ROW,
            1,
        )?,
    )?;
    frames::compute_into(&req, &mut buf, cancel)?;
    Ok(DVec3::new(buf[0], buf[3], buf[6]))
}

/// Parallel transport as a quaternion curve.
///
/// * `x`: the points (for arc lengths; `n ≥ 2` rows), `t`: tangents (`n` rows, finite and
///   non-zero; normalised here), default the estimate of `spinal.estimate_tangents`;
/// * `initial`: reference vector at row 0, projected onto the normal plane of `t[0]` (it
///   must be finite and not parallel to `t[0]`); `None`: the reference vector of the
///   rotation-method frames ([`frames::compute_into`]);
/// * `closed`: the samples form a loop (no repeated end point); the closing angle is then
///   spread linearly in arc length (plus `2π·turns`) so the frames close; a half number
///   of turns leaves them closing up to a half turn about the tangent.
///
/// Writes `n` quaternions (sign-continuous, `out[0]` canonical), and for a closed curve with
/// `out.len() == n + 1` also the frame carried once round the loop, corrected (`±q₀`: the
/// sign tells whether the frames' circuit is an even or odd number of turns on S³). Returns
/// the closing angle (0 for an open curve).
///
/// Polls `cancel` inside the tangent estimate and the default frames and before every segment of
/// [`CANCEL_SEGMENT`] rows of the recurrence and the closing correction; once it says stop the rows
/// not yet written are left as they are and `out` is incomplete (see [`crate::run::cancel`]).
pub fn transport(
    x: &[DVec3],
    t: Option<&[DVec3]>,
    initial: Option<DVec3>,
    closed: bool,
    turns: f64,
    out: &mut [DQuat],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<f64> {
    if !turns.is_finite() || 2.0 * turns != (2.0 * turns).round() {
        return Err(InputError::new(
            "turns",
            format!("expected a whole or half number of turns (e.g. 1, 0.5, -1.5), got {turns}"),
        ));
    }
    if turns != turns.round() && !closed {
        return Err(InputError::new(
            "turns",
            format!(
                "a half number of turns ({turns}) applies only to the closing twist of a \
                 closed curve (closed=True)"
            ),
        ));
    }
    let t = &unit_tangents(x, t, closed, cancel)?;
    if cancel() {
        return Ok(0.0);
    }
    let r0 = match initial {
        Some(v) => frames::resolve(&Orientation::Vector(v), t[0], 0, "initial")?,
        None => default_reference(x, t, closed, cancel)?,
    };
    if cancel() {
        return Ok(0.0);
    }
    let n = t.len();
    debug_assert!(out.len() == n || (closed && out.len() == n + 1));
    let q0 = canonical(from_matrix(&{
        let s0 = t[0].cross(r0);
        [r0.x, s0.x, t[0].x, r0.y, s0.y, t[0].y, r0.z, s0.z, t[0].z]
    }));
    out[0] = q0;
    let step = |i: usize| {
        let j = if i + 1 == n { 0 } else { i + 1 };
        rotation::minimal_rotation_quat(t[i], t[j]).ok_or_else(|| {
            InputError::new(
                "tangents",
                format!(
                    "the tangents at rows {i} and {j} are opposite (the curve reverses, a \
                     cusp); parallel transport is undefined there"
                ),
            )
        })
    };
    for i in 0..n - 1 {
        if i % CANCEL_SEGMENT == 0 && cancel() {
            return Ok(0.0);
        }
        let q = (step(i)? * out[i]).normalize();
        out[i + 1] = q;
    }
    if !closed {
        return Ok(0.0);
    }
    // One more step closes the loop; compare the carried r with r0.
    let q_end = (step(n - 1)? * out[n - 1]).normalize();
    let r_end = q_end * DVec3::X;
    let alpha = rotation::signed_angle(r_end, r0, t[0]);
    let total = alpha + std::f64::consts::TAU * turns;
    let mut arc = alloc::with_capacity("quaternion_frames", n + 1)?;
    let mut acc = 0.0;
    arc.push(0.0);
    for i in 0..n {
        if i % CANCEL_SEGMENT == 0 && cancel() {
            return Ok(0.0);
        }
        acc += crate::math::scale::length(x[(i + 1) % n] - x[i]);
        arc.push(acc);
    }
    let len = arc[n];
    if out.len() == n + 1 {
        out[n] = q_end;
    }
    out.par_chunks_mut(CANCEL_SEGMENT)
        .enumerate()
        .for_each(|(c, rows)| {
            if cancel() {
                return;
            }
            rows.par_iter_mut()
                .enumerate()
                .with_min_len(GRAIN)
                .for_each(|(j, q)| {
                    let i = c * CANCEL_SEGMENT + j;
                    let a = 0.5 * total * arc[i] / len;
                    *q = (*q * DQuat::from_xyzw(0.0, 0.0, a.sin(), a.cos())).normalize();
                });
        });
    make_continuous(out, cancel);
    Ok(alpha)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(axis: DVec3, angle: f64) -> [f64; 9] {
        to_matrix(DQuat::from_axis_angle(axis.normalize(), angle))
    }

    #[test]
    fn shepperd_round_trip_including_half_turns() {
        let axes = [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 2.0, 3.0),
        ];
        for a in axes {
            for ang in [0.0, 0.3, 1.5, 3.0, std::f64::consts::PI] {
                let m = rot(a, ang);
                let back = to_matrix(from_matrix(&m));
                for k in 0..9 {
                    assert!((back[k] - m[k]).abs() < 1e-15 * 4.0, "{a:?} {ang}");
                }
            }
        }
    }

    /// Each refused input names the Python argument.
    fn arg_of<T: std::fmt::Debug>(r: Result<T>) -> std::borrow::Cow<'static, str> {
        r.expect_err("an input error").arg
    }

    #[test]
    fn continuous_refuses_non_finite_quaternions() {
        let q = [DQuat::IDENTITY, DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0)];
        assert_eq!(arg_of(continuous(&q, &cancel::never)), "quaternions");
        let ok = continuous(&[-DQuat::IDENTITY, DQuat::IDENTITY], &cancel::never).expect("finite");
        assert_eq!(ok, vec![DQuat::IDENTITY; 2]);
    }

    #[test]
    fn slerp_frames_checks_keys_and_parameters() {
        let keys = [rot(DVec3::Z, 0.0), rot(DVec3::Z, 1.0), rot(DVec3::X, 1.0)];
        let mut out = [[0.0; 9]; 1];
        let run = |f: &[[f64; 9]], ku: &[f64], nu: &[f64], out: &mut [[f64; 9]]| {
            slerp_frames(f, ku, nu, out, &cancel::never)
        };
        assert_eq!(arg_of(run(&keys[..1], &[0.0], &[0.0], &mut out)), "frames");
        assert_eq!(
            arg_of(run(&keys, &[0.0, 2.0, 1.0], &[0.5], &mut out)),
            "key_u"
        );
        assert_eq!(
            arg_of(run(&keys, &[0.0, 1.0, f64::NAN], &[0.5], &mut out)),
            "key_u"
        );
        assert_eq!(
            arg_of(run(&keys, &[0.0, 1.0, 1.0], &[0.5], &mut out)),
            "key_u"
        );
        assert_eq!(
            arg_of(run(&keys, &[0.0, 1.0, 2.0], &[f64::NAN], &mut out)),
            "new_u"
        );
        assert_eq!(
            arg_of(run(&keys, &[0.0, 1.0, 2.0], &[2.5], &mut out)),
            "new_u"
        );
        assert_eq!(
            arg_of(run(&keys, &[0.0, 1.0, 2.0], &[-0.1], &mut out)),
            "new_u"
        );
        // inside the range: the keys at the keys, the half turn between the first two
        let mut out = [[0.0; 9]; 3];
        run(&keys, &[0.0, 1.0, 2.0], &[0.0, 0.5, 2.0], &mut out).expect("valid keys");
        let want = [keys[0], rot(DVec3::Z, 0.5), keys[2]];
        for (a, b) in out.iter().zip(&want) {
            assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-15));
        }
    }

    #[test]
    fn transport_checks_points_tangents_and_initial() {
        let x: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(f64::from(i), (0.5 * f64::from(i)).sin(), 0.0))
            .collect();
        let mut out = vec![DQuat::IDENTITY; x.len()];
        let mut run = |x: &[DVec3], t: Option<&[DVec3]>, r: Option<DVec3>| {
            transport(x, t, r, false, 0.0, &mut out[..x.len()], &cancel::never)
        };
        assert_eq!(arg_of(run(&x[..1], None, None)), "points");
        assert_eq!(arg_of(run(&x[..1], Some(&x[..1]), None)), "points");
        let mut t = vec![DVec3::X; x.len()];
        t[3] = DVec3::ZERO;
        let e = run(&x, Some(&t), None).expect_err("a zero tangent");
        assert_eq!(
            (&*e.arg, e.msg.as_str()),
            ("tangents", "zero-length tangent at row 3")
        );
        t[3] = DVec3::new(f64::INFINITY, 0.0, 0.0);
        assert_eq!(arg_of(run(&x, Some(&t), None)), "tangents");
        assert_eq!(arg_of(run(&x, Some(&t[1..]), None)), "tangents");
        let t = vec![DVec3::new(2.0, 0.0, 0.0); x.len()];
        assert_eq!(
            arg_of(run(&x, Some(&t), Some(DVec3::new(-3.0, 0.0, 0.0)))),
            "initial"
        );
        assert_eq!(arg_of(run(&x, Some(&t), Some(DVec3::ZERO))), "initial");
        assert_eq!(arg_of(run(&x, Some(&t), Some(DVec3::NAN))), "initial");
        // a valid call: unit tangents, the frame at row 0 from the projected initial vector
        run(&x, Some(&t), Some(DVec3::new(1.0, 0.0, 2.0))).expect("valid input");
        let f0 = to_matrix(out[0]);
        assert!((f0[2] - 1.0).abs() < 1e-15 && (f0[6] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn slerp_ends_and_short_arc() {
        let a = DQuat::from_axis_angle(DVec3::Z, 0.2);
        let b = -DQuat::from_axis_angle(DVec3::Z, 1.0);
        assert!((slerp(a, b, 0.0) - a).length() < 1e-15);
        assert!((slerp(a, b, 1.0) + b).length() < 1e-15);
        let mid = slerp(a, b, 0.5);
        assert!((mid - DQuat::from_axis_angle(DVec3::Z, 0.6)).length() < 1e-15);
    }
}
