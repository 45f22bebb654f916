//! The twist between two frames with the same tangent.
//!
//! With frames `A = (r_a, s_a, t)` and `B = (r_b, s_b, t)` (rotation matrices, columns
//! `r, s, t`), `r_b = cos φ r_a + sin φ s_a` for the angle `φ` that turns `A` into `B` about
//! the common tangent, so `φ = atan2(r_b·s_a, r_b·r_a) ∈ (−π, π]` (the angle between two
//! rotation-minimising or Frenet frames, Wang et al., "Computation of rotation minimizing
//! frames", ACM TOG 27(1), 2008, §2). Both frames must be rotation matrices and their
//! tangents must agree (within [`crate::frames::FRAME_TANGENT_TOL`] radians): otherwise the
//! angle about `t_a` is not the twist between them.

use glam::DVec3;

use crate::error::{InputError, Result};
use crate::frames::FRAME_TANGENT_TOL;
use crate::frames::validate;
use crate::run::alloc;
use crate::run::cancel::{self, Cancel};

/// Column `k` (0: r, 1: s, 2: t) of a row-major frame.
#[inline]
fn col(f: &[f64; 9], k: usize) -> DVec3 {
    DVec3::new(f[k], f[3 + k], f[6 + k])
}

/// Finite rotation matrices, else an error naming `arg` and the row (a stopped check finds
/// nothing; see [`crate::run::cancel`]).
fn check_frames(arg: &'static str, f: &[[f64; 9]], cancel: Cancel<'_>) -> Result<()> {
    let finite = |m: &[f64; 9]| m.iter().all(|v| v.is_finite());
    if let Some(i) = validate::first_bad(f, finite, cancel) {
        return Err(InputError::new(
            arg,
            format!("non-finite value in frame {i}"),
        ));
    }
    if let Some(i) = validate::first_bad(f, validate::is_rotation, cancel) {
        return Err(InputError::new(
            arg,
            format!(
                "frame {i} is not a rotation matrix (columns r, s, t must be orthonormal to \
                 1e-6 and right-handed)"
            ),
        ));
    }
    Ok(())
}

/// The number of rows of [`spin`]'s result: that of `a` and `b`, or of the one that holds
/// more than a single frame.
pub fn rows(a: &[[f64; 9]], b: &[[f64; 9]]) -> Result<usize> {
    let n = a.len().max(b.len());
    if !(a.len() == b.len() || a.len() == 1 || b.len() == 1) || n == 0 {
        return Err(InputError::new(
            "b",
            format!(
                "has {} frames but a has {}: pass the same number, or a single frame for one \
                 of them",
                b.len(),
                a.len()
            ),
        ));
    }
    Ok(n)
}

/// The signed angle from `a[i]`'s reference vector to `b[i]`'s about `a[i]`'s tangent, for
/// `n` rows (one of `a`, `b` may hold a single frame, used for every row).
pub fn spin(a: &[[f64; 9]], b: &[[f64; 9]]) -> Result<Vec<f64>> {
    let mut out = alloc::filled("spin", a.len().max(b.len()), 0.0)?;
    spin_into(a, b, &mut out, &cancel::never)?;
    Ok(out)
}

/// [`spin`] into `out` (of [`rows`] rows: `max(len a, len b)` when the lengths are valid),
/// the frames checked before the lengths, polling `cancel` in the checks and between blocks
/// of rows (`out` incomplete once it says stop; see [`crate::run::cancel`]).
pub fn spin_into(
    a: &[[f64; 9]],
    b: &[[f64; 9]],
    out: &mut [f64],
    cancel: Cancel<'_>,
) -> Result<()> {
    check_frames("a", a, cancel)?;
    check_frames("b", b, cancel)?;
    let n = rows(a, b)?;
    if out.len() != n {
        return Err(InputError::new("out", "output buffer has the wrong size"));
    }
    let pick = |v: &[[f64; 9]], i: usize| v[if v.len() == 1 { 0 } else { i }];
    let turn = |i: usize| col(&pick(a, i), 2).angle_between(col(&pick(b, i), 2));
    if let Some(i) = cancel::first_bad_index(n, cancel, |i| turn(i) <= FRAME_TANGENT_TOL) {
        return Err(InputError::new(
            "b",
            format!(
                "the tangent of frame {i} (third column) differs from a's by {:.3e} rad: the \
                 spin is the twist between frames with the same tangent",
                turn(i)
            ),
        ));
    }
    cancel::fill(out, cancel, |i| {
        let (fa, rb) = (pick(a, i), col(&pick(b, i), 0));
        rb.dot(col(&fa, 1)).atan2(rb.dot(col(&fa, 0)))
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    fn rowmajor(m: DMat3) -> [f64; 9] {
        m.transpose().to_cols_array()
    }

    #[test]
    fn spin_is_the_angle_about_the_tangent() {
        let a = DMat3::from_rotation_y(0.4);
        for &phi in &[0.3, -2.0, 3.0] {
            let b = a * DMat3::from_rotation_z(phi);
            let got = spin(&[rowmajor(a)], &[rowmajor(b)]).unwrap();
            assert!((got[0] - phi).abs() < 1e-14, "{phi}: {got:?}");
        }
        let bad = [f64::NAN; 9];
        assert_eq!(spin(&[bad], &[rowmajor(a)]).unwrap_err().arg, "a");
        let twice = rowmajor(DMat3::IDENTITY * 2.0);
        assert_eq!(spin(&[rowmajor(a)], &[twice]).unwrap_err().arg, "b");
        let other = rowmajor(DMat3::from_rotation_x(0.5));
        assert!(
            spin(&[rowmajor(a)], &[other])
                .unwrap_err()
                .msg
                .contains("tangent")
        );
        let two = [rowmajor(a); 2];
        assert_eq!(spin(&two, &[rowmajor(a); 3]).unwrap_err().arg, "b");
        assert_eq!(spin(&two, &[rowmajor(a)]).unwrap().len(), 2);
    }
}
