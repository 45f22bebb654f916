//! Value checks of PH-cubic input, each naming the Python argument it is about: finite
//! control points, tolerances, knots, and the conditions of a G¹ PH spline (every cubic PH
//! by the control-polygon test of Mäurer & Jüttler (17) within 1e-7, consecutive cubics
//! joined end to end and sharing the tangent direction at the joint). The binding layer only
//! converts types and shapes; these are the one place the values are checked.

use glam::DVec3;

use super::{Cubic, Invariants};
use crate::error::{InputError, Result};
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// Tolerance of the control-polygon PH test for spline input.
pub const SPLINE_PH_TOL: f64 = 1e-7;

/// `arg: contains non-finite values (at index (i, j, k))` for the first non-finite
/// coordinate of the cubics (cubic, control point, coordinate).
pub fn finite_cubics(cubics: &[Cubic]) -> Result<()> {
    for (i, c) in cubics.iter().enumerate() {
        for (j, p) in c.b.iter().enumerate() {
            if let Some(k) = p.to_array().iter().position(|x| !x.is_finite()) {
                return Err(InputError::new(
                    "control_points",
                    format!("contains non-finite values (at index ({i}, {j}, {k}))"),
                ));
            }
        }
    }
    Ok(())
}

/// The first non-finite row of `rows` as an error naming `arg` (the row only: quaternion
/// rows arrive reordered, scalar first).
pub fn finite_rows<const N: usize>(arg: &'static str, rows: &[[f64; N]]) -> Result<()> {
    match rows.iter().position(|r| !r.iter().all(|x| x.is_finite())) {
        Some(i) => Err(InputError::new(
            arg,
            format!("contains non-finite values (in row {i})"),
        )),
        None => Ok(()),
    }
}

/// [`Cubic::is_ph`] per cubic, after checking the cubics (finite) and `tol` (≥ 0).
///
/// Polls `cancel` between blocks of cubics (an incomplete result once it says stop; see
/// [`crate::run::cancel`]).
pub fn is_ph_rows(cubics: &[Cubic], tol: f64, cancel: Cancel<'_>) -> Result<Vec<bool>> {
    if !(tol >= 0.0) {
        return Err(InputError::new(
            "tol",
            format!("must be non-negative, got {tol}"),
        ));
    }
    finite_cubics(cubics)?;
    alloc::try_collect("ph.is_ph", cubics.iter().map(|c| Ok(c.is_ph(tol))), cancel)
}

/// [`Cubic::invariants`] per cubic; a control polygon with a zero-length leg (relative to
/// the largest coordinate, 1e-14) or with undefined invariants (any but κ/τ non-finite: a
/// straight or degenerate polygon) is an error naming the cubic.
///
/// Polls `cancel` between blocks of cubics (an incomplete result once it says stop; see
/// [`crate::run::cancel`]).
pub fn invariant_rows(cubics: &[Cubic], cancel: Cancel<'_>) -> Result<Vec<Invariants>> {
    finite_cubics(cubics)?;
    alloc::try_collect(
        "ph.invariants",
        cubics.iter().enumerate().map(|(i, c)| {
            let scale =
                c.b.iter()
                    .map(|p| p.abs().max_element())
                    .fold(0.0, f64::max)
                    .max(1e-300);
            if !c.legs().iter().all(|d| d.length() > 1e-14 * scale) {
                return Err(InputError::new(
                    "control_points",
                    format!(
                        "cubic {i} has a zero-length leg of its control polygon (a degenerate \
                         polygon is not a PH cubic)"
                    ),
                ));
            }
            let v = c.invariants();
            let defined = v
                .row()
                .iter()
                .enumerate()
                .all(|(j, x)| j == Invariants::KAPPA_OVER_TAU || x.is_finite());
            if !defined {
                return Err(InputError::new(
                    "control_points",
                    format!(
                        "the invariants of cubic {i} are undefined (a straight or degenerate \
                         polygon)"
                    ),
                ));
            }
            Ok(v)
        }),
        cancel,
    )
}

/// The checks of a G¹ PH spline: at least one cubic, finite control points, `knots` (one
/// more than the cubics) finite and strictly increasing, consecutive cubics joined (gap
/// ≤ 1e-9 of the scale `max|b| + 1`), every cubic PH (tolerance [`SPLINE_PH_TOL`]) and
/// common tangent directions at the joints (cosine ≥ 1 − 1e-12). `single`: the input was
/// one cubic (the messages do not number it).
pub fn check_spline(cubics: &[Cubic], knots: &[f64], single: bool) -> Result<()> {
    let m = cubics.len();
    if m == 0 {
        return Err(InputError::new("control_points", "no cubics"));
    }
    finite_cubics(cubics)?;
    if knots.len() != m + 1 {
        return Err(InputError::new(
            "knots",
            format!("expected shape ({},), got ({},)", m + 1, knots.len()),
        ));
    }
    if let Some(i) = knots.iter().position(|x| !x.is_finite()) {
        return Err(InputError::new(
            "knots",
            format!("contains non-finite values (at index ({i},))"),
        ));
    }
    if !knots.windows(2).all(|w| w[1] > w[0]) {
        return Err(InputError::new("knots", "must be strictly increasing"));
    }
    let scale = cubics
        .iter()
        .flat_map(|c| c.b)
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max)
        + 1.0;
    let gaps = alloc::collect(
        "PHSpline",
        cubics.windows(2).map(|w| (w[1].b[0] - w[0].b[3]).length()),
    )?;
    if let Some((i, g)) = argmax(&gaps) {
        if g > 1e-9 * scale {
            return Err(InputError::new(
                "control_points",
                format!(
                    "cubic {} does not start where cubic {i} ends (gap {g:.3e})",
                    i + 1
                ),
            ));
        }
    }
    if let Some(i) = cubics.iter().position(|c| !c.is_ph(SPLINE_PH_TOL)) {
        let which = if single {
            String::new()
        } else {
            format!("cubic {i} is ")
        };
        return Err(InputError::new(
            "control_points",
            format!("{which}not a PH cubic (control-polygon test, tolerance {SPLINE_PH_TOL:e})"),
        ));
    }
    // the negated cosines (negation is exact), for the worst joint by `argmax`
    let neg_cos = alloc::collect(
        "PHSpline",
        cubics.windows(2).map(|w| {
            let (a, b): (DVec3, DVec3) = (w[0].b[3] - w[0].b[2], w[1].b[1] - w[1].b[0]);
            -(a.dot(b) / (a.length() * b.length()))
        }),
    )?;
    if let Some((i, c)) = argmax(&neg_cos) {
        let c = -c;
        if !(c >= 1.0 - 1e-12) {
            return Err(InputError::new(
                "control_points",
                format!(
                    "cubics {i} and {} do not join with a common tangent (G¹; angle {:.3e} rad)",
                    i + 1,
                    c.clamp(-1.0, 1.0).acos()
                ),
            ));
        }
    }
    Ok(())
}

/// Index and value of the largest entry (a NaN counts as the largest), None when empty.
fn argmax(x: &[f64]) -> Option<(usize, f64)> {
    let mut best: Option<(usize, f64)> = None;
    for (i, &v) in x.iter().enumerate() {
        match best {
            _ if v.is_nan() => return Some((i, v)),
            Some((_, b)) if b >= v => {}
            _ => best = Some((i, v)),
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;

    fn spline() -> Vec<Cubic> {
        let a = Cubic::from_quaternions([0.3, -1.2, 0.7, 0.4], [-0.5, 0.2, 1.1, -0.9], DVec3::ZERO);
        // the second cubic starts with the end tangent of the first: A₀ of b = A₁ of a
        let b = Cubic::from_quaternions([-0.5, 0.2, 1.1, -0.9], [0.4, 0.9, 0.2, -0.6], a.b[3]);
        vec![a, b]
    }

    #[test]
    fn non_finite_control_points_name_the_argument() {
        let mut c = spline();
        c[1].b[2].y = f64::NAN;
        let e = finite_cubics(&c).unwrap_err();
        assert_eq!(e.arg, "control_points");
        assert_eq!(e.msg, "contains non-finite values (at index (1, 2, 1))");
        assert_eq!(
            is_ph_rows(&c, 1e-9, &cancel::never).unwrap_err().arg,
            "control_points"
        );
        assert_eq!(
            invariant_rows(&c, &cancel::never).unwrap_err().arg,
            "control_points"
        );
        let e = finite_rows(
            "A0",
            &[[1.0, 2.0, 3.0, 4.0], [0.0, f64::INFINITY, 0.0, 0.0]],
        )
        .unwrap_err();
        assert_eq!(e.to_string(), "A0: contains non-finite values (in row 1)");
    }

    #[test]
    fn is_ph_tolerance_must_be_non_negative() {
        let c = spline();
        assert_eq!(
            is_ph_rows(&c, 1e-9, &cancel::never).unwrap(),
            vec![true, true]
        );
        for tol in [-1.0, f64::NAN] {
            let e = is_ph_rows(&c, tol, &cancel::never).unwrap_err();
            assert_eq!(e.arg, "tol");
            assert!(e.msg.starts_with("must be non-negative"), "{e}");
        }
    }

    #[test]
    fn invariants_of_degenerate_polygons_are_errors() {
        let c = spline();
        assert_eq!(invariant_rows(&c, &cancel::never).unwrap().len(), 2);
        let zero = Cubic::new([DVec3::ZERO, DVec3::ZERO, DVec3::X, DVec3::Y]);
        let e = invariant_rows(&[c[0], zero], &cancel::never).unwrap_err();
        assert_eq!(e.arg, "control_points");
        assert!(e.msg.starts_with("cubic 1 has a zero-length leg"), "{e}");
        // a straight polygon that turns back: σ vanishes inside, κ_max = 0/0
        let back = Cubic::new([DVec3::ZERO, DVec3::X, DVec3::ZERO, DVec3::X]);
        let e = invariant_rows(&[back], &cancel::never).unwrap_err();
        assert_eq!(e.arg, "control_points");
        assert!(
            e.msg.starts_with("the invariants of cubic 0 are undefined"),
            "{e}"
        );
    }

    #[test]
    fn spline_checks_name_the_argument() {
        let c = spline();
        assert!(check_spline(&c, &[0.0, 1.0, 2.0], false).is_ok());
        let e = check_spline(&[], &[0.0], false).unwrap_err();
        assert_eq!(e.to_string(), "control_points: no cubics");
        let e = check_spline(&c, &[0.0, 2.0, 1.0], false).unwrap_err();
        assert_eq!(e.to_string(), "knots: must be strictly increasing");
        let e = check_spline(&c, &[0.0, f64::NAN, 1.0], false).unwrap_err();
        assert_eq!(e.arg, "knots");
        assert!(e.msg.starts_with("contains non-finite values"), "{e}");
        let e = check_spline(&c, &[0.0, 1.0], false).unwrap_err();
        assert_eq!(e.arg, "knots");
        // a gap
        let mut g = c.clone();
        for p in &mut g[1].b {
            *p += DVec3::X;
        }
        let e = check_spline(&g, &[0.0, 1.0, 2.0], false).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("control_points: cubic 1 does not start"),
            "{e}"
        );
        // not PH
        let mut n = c.clone();
        n[1].b[1] += DVec3::new(0.0, 1e-3, 0.0);
        n[0].b[3] = n[1].b[0];
        let e = check_spline(&n, &[0.0, 1.0, 2.0], false).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("control_points: cubic 1 is not a PH cubic"),
            "{e}"
        );
        let e = check_spline(&n[1..], &[0.0, 1.0], true).unwrap_err();
        assert!(
            e.to_string().starts_with("control_points: not a PH cubic"),
            "{e}"
        );
        // a corner at the joint
        let b = Cubic::from_quaternions([1.0, 0.2, -0.3, 0.1], [0.4, 0.9, 0.2, -0.6], c[0].b[3]);
        let e = check_spline(&[c[0], b], &[0.0, 1.0, 2.0], false).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("control_points: cubics 0 and 1 do not join"),
            "{e}"
        );
    }
}
