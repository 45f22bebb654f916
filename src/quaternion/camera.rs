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
//! The frames themselves are then the rotation-minimising frames or the level frames of
//! the Python layer.

use glam::DVec3;

use super::unit_tangents_cancellable;
use crate::alloc;
use crate::error::{InputError, Result};
use crate::frames::validate;

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
pub fn inputs(
    x: &[DVec3],
    tangents: Option<&[DVec3]>,
    up: Option<DVec3>,
    bank: Option<&[f64]>,
    closed: bool,
    mode: Mode,
) -> Result<Inputs> {
    inputs_cancellable(x, tangents, up, bank, closed, mode, &crate::cancel::never)
}

/// [`inputs`] that polls `cancel` inside the tangent estimate and between its passes, and
/// returns at once (with incomplete inputs) when it says stop (see [`crate::cancel`]).
pub fn inputs_cancellable(
    x: &[DVec3],
    tangents: Option<&[DVec3]>,
    up: Option<DVec3>,
    bank: Option<&[f64]>,
    closed: bool,
    mode: Mode,
    cancel: crate::cancel::Cancel<'_>,
) -> Result<Inputs> {
    let t = unit_tangents_cancellable(x, tangents, closed, cancel)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn line() -> Vec<DVec3> {
        (0..5).map(|i| DVec3::new(f64::from(i), 0.0, 0.0)).collect()
    }

    fn arg(r: Result<Inputs>) -> &'static str {
        r.expect_err("an input error").arg
    }

    const LEVEL: Mode = Mode::Level {
        singular_angle: 1e-3,
    };

    #[test]
    fn points_and_tangents_are_checked() {
        let x = line();
        let tr = Mode::Transport;
        assert_eq!(arg(inputs(&x[..1], None, None, None, false, tr)), "points");
        let mut t = vec![DVec3::X; 5];
        t[2] = DVec3::ZERO;
        assert_eq!(arg(inputs(&x, Some(&t), None, None, false, tr)), "tangents");
        t[2] = DVec3::NAN;
        assert_eq!(arg(inputs(&x, Some(&t), None, None, false, tr)), "tangents");
        let t = vec![DVec3::new(3.0, 0.0, 0.0); 5];
        let ok = inputs(&x, Some(&t), None, None, false, tr).expect("valid");
        assert_eq!(ok.tangents, vec![DVec3::X; 5]);
        assert_eq!((ok.up, ok.vertical, ok.regular), (DVec3::Z, false, None));
    }

    #[test]
    fn up_is_checked() {
        let x = line();
        let tr = Mode::Transport;
        for bad in [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 1.0)] {
            assert_eq!(arg(inputs(&x, None, Some(bad), None, false, tr)), "up");
        }
        // parallel to the first tangent: an error when given, the default only flags it
        assert_eq!(arg(inputs(&x, None, Some(DVec3::X), None, false, tr)), "up");
        let z: Vec<DVec3> = x.iter().map(|p| DVec3::new(0.0, 0.0, p.x)).collect();
        assert!(
            inputs(&z, None, None, None, false, tr)
                .expect("default up")
                .vertical
        );
        let ok = inputs(&x, None, Some(DVec3::new(0.0, 2.0, 0.0)), None, false, tr);
        assert_eq!(ok.expect("valid").up, DVec3::Y);
    }

    #[test]
    fn bank_must_be_finite() {
        let x = line();
        let bank = [0.0, 1.0, f64::INFINITY, 0.0, 0.0];
        assert_eq!(
            arg(inputs(&x, None, None, Some(&bank), false, LEVEL)),
            "bank"
        );
    }

    #[test]
    fn a_level_horizon_needs_a_row_off_vertical() {
        let x = line();
        let e = inputs(&x, None, Some(DVec3::X), None, false, LEVEL).expect_err("vertical");
        assert_eq!(e.arg, "points");
        assert!(e.msg.starts_with("the path is parallel to up everywhere"));
        let ok = inputs(&x, None, None, None, false, LEVEL).expect("horizontal");
        assert_eq!(ok.regular, Some(vec![true; 5]));
    }
}
