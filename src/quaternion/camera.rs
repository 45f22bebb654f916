//! The inputs of a camera flying along a path (`spinal.quaternions.camera_frames`): the
//! gaze is the unit tangent, the up vector comes from a world `up`. Checked and prepared
//! here:
//!
//! * the unit tangents (given, or estimated as by `spinal.estimate_tangents`, a closed path
//!   may repeat its first point);
//! * the unit world `up`, and whether the path starts within `10⁻³` (sine of the angle) of
//!   it — there the start up vector of a transported camera is undefined;
//! * for a level horizon, the rows where the path runs more than `singular_angle` from
//!   vertical (`|up − (t·up) t| > sin(singular_angle)`): the projection of `up` onto the
//!   normal plane defines the camera's up there; at least one such row is needed;
//! * the bank (roll) angles, finite.
//!
//! The frames themselves are the rotation-minimising frames of `spinal.frames` or the level
//! frames ([`level_rows`] on the regular rows, carried by the rotation-minimising
//! frame across the singular runs); [`orient`] then rolls them by the bank and
//! reorders them into camera columns.

use glam::DVec3;
use rayon::prelude::*;

use super::unit_tangents;
use crate::error::{InputError, Result};
use crate::frames::validate;
use crate::run::alloc;

/// Largest `|t₀ × up|` at which a path counts as starting vertical.
pub const VERTICAL_SIN: f64 = 1e-3;

/// The checked inputs of a camera path.
#[derive(Debug, Clone)]
pub struct Inputs {
    /// Unit tangents, one per point.
    pub tangents: Vec<DVec3>,
    /// The unit world up vector.
    pub up: DVec3,
    /// The path starts within [`VERTICAL_SIN`] of `up` (only without a given `up`).
    pub vertical: bool,
    /// Level horizon only: the rows where `up` projects onto the normal plane.
    pub regular: Option<Vec<bool>>,
}

/// How the camera's up vector is found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    /// Transported (rotation-minimising) from the start.
    Transport,
    /// A level horizon; rows within this angle (radians) of vertical are singular.
    Level { singular_angle: f64 },
}

/// Check and prepare the inputs of `camera_frames`: points `x` (`n ≥ 2`), optional tangents
/// (`n` rows, finite and non-zero), optional world `up` (finite, non-zero; default `+z`),
/// optional `bank` angles (finite), `closed`, and the mode.
///
/// Polls `cancel` inside the tangent estimate and between its passes, and returns at once (with
/// incomplete inputs) when it says stop (see [`crate::run::cancel`]).
pub fn inputs(
    x: &[DVec3],
    tangents: Option<&[DVec3]>,
    up: Option<DVec3>,
    bank: Option<&[f64]>,
    closed: bool,
    mode: Mode,
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<Inputs> {
    let t = unit_tangents(x, tangents, closed, cancel)?;
    let stopped = |t: Vec<DVec3>| Inputs {
        tangents: t,
        up: DVec3::Z,
        vertical: false,
        regular: None,
    };
    // a cancelled estimate is incomplete: nothing below may read it
    if cancel() {
        return Ok(stopped(t));
    }
    let u = up.unwrap_or(DVec3::Z);
    let Some(u) = crate::math::scale::normalize(u) else {
        return Err(InputError::new(
            "up",
            "expected a finite non-zero (3,) vector",
        ));
    };
    let vertical = t[0].cross(u).length() <= VERTICAL_SIN;
    if let Some(b) = bank {
        validate::finite_scalars("bank", b)?;
    }
    if cancel() {
        return Ok(stopped(t));
    }
    let regular = match mode {
        Mode::Transport => {
            if vertical && up.is_some() {
                return Err(InputError::new(
                    "up",
                    "parallel to the path's first tangent; the start up vector is undefined",
                ));
            }
            None
        }
        Mode::Level { singular_angle } => {
            let s = singular_angle.sin();
            let regular = alloc::collect(
                "camera_frames",
                t.iter().map(|t| (u - t.dot(u) * *t).length() > s),
            )?;
            if !regular.contains(&true) {
                return Err(InputError::new(
                    "points",
                    "the path is parallel to up everywhere; a level horizon is undefined (use \
                     mode='transport' or another up)",
                ));
            }
            Some(regular)
        }
    };
    Ok(Inputs {
        tangents: t,
        up: u,
        vertical,
        regular,
    })
}

/// Rows per block of the writing loops: the first write to a fresh output page costs a
/// page fault, so the loops poll `cancel` between blocks, not only between passes.
const GRAIN: usize = 1 << 12;

/// The level-horizon frames `(r, t × r, t)` (row-major, columns `r, s, t`) at the rows where
/// `regular` is true, `r = (u − (t·u) t)/|u − (t·u) t|` the world up projected onto the normal
/// plane of the unit tangent `t`; the other rows are zero (the caller carries the
/// rotation-minimising frame across them). Stops between blocks once `cancel` says so (`out`
/// is then incomplete).
pub fn level_rows(
    tangents: &[DVec3],
    up: DVec3,
    regular: &[bool],
    out: &mut [[f64; 9]],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<()> {
    if regular.len() != tangents.len() || out.len() != tangents.len() {
        return Err(InputError::new(
            "regular",
            "expected one flag and one output frame per tangent",
        ));
    }
    out.par_chunks_mut(GRAIN)
        .zip(tangents.par_chunks(GRAIN).zip(regular.par_chunks(GRAIN)))
        .for_each(|(o, (t, g))| {
            if cancel() {
                return;
            }
            for ((o, t), g) in o.iter_mut().zip(t).zip(g) {
                *o = if *g {
                    let w = up - t.dot(up) * *t;
                    let r = w / w.length();
                    let s = t.cross(r);
                    [r.x, s.x, t.x, r.y, s.y, t.y, r.z, s.z, t.z]
                } else {
                    [0.0; 9]
                };
            }
        });
    Ok(())
}

/// Camera rotations `(right, up, back)` (row-major columns) of spinal frames `(r, s, t)`
/// rolled by `bank` about the gaze `t`: `up = cos b r + sin b s`, `right = cos b s − sin b r`,
/// `back = −t` (a right-handed turn by `b` about the direction of travel). Stops between
/// blocks once `cancel` says so (`out` is then incomplete).
pub fn orient(
    frames: &[[f64; 9]],
    bank: Option<&[f64]>,
    out: &mut [[f64; 9]],
    cancel: crate::run::cancel::Cancel<'_>,
) -> Result<()> {
    if out.len() != frames.len() || bank.is_some_and(|b| b.len() != frames.len()) {
        return Err(InputError::new(
            "bank",
            "expected one angle and one output frame per frame",
        ));
    }
    out.par_chunks_mut(GRAIN)
        .zip(frames.par_chunks(GRAIN))
        .enumerate()
        .for_each(|(k, (o, f))| {
            if cancel() {
                return;
            }
            let b = bank.map(|b| &b[k * GRAIN..(k * GRAIN + f.len())]);
            for (i, (o, f)) in o.iter_mut().zip(f).enumerate() {
                let (sn, c) = b.map_or((0.0, 1.0), |b| b[i].sin_cos());
                for row in 0..3 {
                    let (r, s, t) = (f[3 * row], f[3 * row + 1], f[3 * row + 2]);
                    o[3 * row] = c * s - sn * r;
                    o[3 * row + 1] = c * r + sn * s;
                    o[3 * row + 2] = -t;
                }
            }
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;

    fn line() -> Vec<DVec3> {
        (0..5).map(|i| DVec3::new(f64::from(i), 0.0, 0.0)).collect()
    }

    fn arg(r: Result<Inputs>) -> std::borrow::Cow<'static, str> {
        r.expect_err("an input error").arg
    }

    const LEVEL: Mode = Mode::Level {
        singular_angle: 1e-3,
    };

    #[test]
    fn points_and_tangents_are_checked() {
        let x = line();
        let tr = Mode::Transport;
        assert_eq!(
            arg(inputs(&x[..1], None, None, None, false, tr, &cancel::never)),
            "points"
        );
        let mut t = vec![DVec3::X; 5];
        t[2] = DVec3::ZERO;
        assert_eq!(
            arg(inputs(&x, Some(&t), None, None, false, tr, &cancel::never)),
            "tangents"
        );
        t[2] = DVec3::NAN;
        assert_eq!(
            arg(inputs(&x, Some(&t), None, None, false, tr, &cancel::never)),
            "tangents"
        );
        let t = vec![DVec3::new(3.0, 0.0, 0.0); 5];
        let ok = inputs(&x, Some(&t), None, None, false, tr, &cancel::never).expect("valid");
        assert_eq!(ok.tangents, vec![DVec3::X; 5]);
        assert_eq!((ok.up, ok.vertical, ok.regular), (DVec3::Z, false, None));
    }

    #[test]
    fn up_is_checked() {
        let x = line();
        let tr = Mode::Transport;
        for bad in [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 1.0)] {
            assert_eq!(
                arg(inputs(&x, None, Some(bad), None, false, tr, &cancel::never)),
                "up"
            );
        }
        // parallel to the first tangent: an error when given, the default only flags it
        assert_eq!(
            arg(inputs(
                &x,
                None,
                Some(DVec3::X),
                None,
                false,
                tr,
                &cancel::never
            )),
            "up"
        );
        let z: Vec<DVec3> = x.iter().map(|p| DVec3::new(0.0, 0.0, p.x)).collect();
        assert!(
            inputs(&z, None, None, None, false, tr, &cancel::never)
                .expect("default up")
                .vertical
        );
        let ok = inputs(
            &x,
            None,
            Some(DVec3::new(0.0, 2.0, 0.0)),
            None,
            false,
            tr,
            &cancel::never,
        );
        assert_eq!(ok.expect("valid").up, DVec3::Y);
    }

    #[test]
    fn bank_must_be_finite() {
        let x = line();
        let bank = [0.0, 1.0, f64::INFINITY, 0.0, 0.0];
        assert_eq!(
            arg(inputs(
                &x,
                None,
                None,
                Some(&bank),
                false,
                LEVEL,
                &cancel::never
            )),
            "bank"
        );
    }

    #[test]
    fn a_level_horizon_needs_a_row_off_vertical() {
        let x = line();
        let e = inputs(&x, None, Some(DVec3::X), None, false, LEVEL, &cancel::never)
            .expect_err("vertical");
        assert_eq!(e.arg, "points");
        assert!(e.msg.starts_with("the path is parallel to up everywhere"));
        let ok = inputs(&x, None, None, None, false, LEVEL, &cancel::never).expect("horizontal");
        assert_eq!(ok.regular, Some(vec![true; 5]));
    }

    fn col(f: &[f64; 9], j: usize) -> DVec3 {
        DVec3::new(f[j], f[3 + j], f[6 + j])
    }

    #[test]
    fn level_rows_are_the_projected_up_and_zero_elsewhere() {
        let t = [DVec3::new(1.0, 0.0, 1.0).normalize(), DVec3::Z];
        let mut out = [[1.0; 9]; 2];
        level_rows(
            &t,
            DVec3::Z,
            &[true, false],
            &mut out,
            &crate::run::cancel::never,
        )
        .expect("valid");
        // up projected onto the plane normal to (1, 0, 1)/√2 is (−1, 0, 1)/√2
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((col(&out[0], 0) - DVec3::new(-h, 0.0, h)).length() < 1e-15);
        assert!((col(&out[0], 1) - t[0].cross(col(&out[0], 0))).length() < 1e-15);
        assert_eq!(col(&out[0], 2), t[0]);
        assert_eq!(out[1], [0.0; 9]);
    }

    #[test]
    fn orient_reorders_and_rolls_right_handed_about_the_gaze() {
        // (r, s, t) = (Z, −Y, X): travel along X, up Z, s = t × r = −Y
        let f = [[0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0]; 2];
        let b = [0.0, std::f64::consts::FRAC_PI_2];
        let mut out = [[0.0; 9]; 2];
        orient(&f, Some(&b), &mut out, &crate::run::cancel::never).expect("valid");
        // no roll: right = s, up = r, back = −t
        assert_eq!(col(&out[0], 0), -DVec3::Y);
        assert_eq!(col(&out[0], 1), DVec3::Z);
        assert_eq!(col(&out[0], 2), -DVec3::X);
        // a quarter turn about the travel direction X takes up = Z to −Y (right-handed about
        // +X turns Z towards −Y), and right = −Y to −Z
        assert!((col(&out[1], 1) + DVec3::Y).length() < 1e-15);
        assert!((col(&out[1], 0) + DVec3::Z).length() < 1e-15);
        let mut short = [[0.0; 9]; 1];
        assert_eq!(
            orient(&f, None, &mut short, &crate::run::cancel::never)
                .expect_err("sizes")
                .arg,
            "bank"
        );
    }
}
