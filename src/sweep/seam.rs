//! The seam of a closed sweep whose frames close up to a half turn.
//!
//! On a closed spine the rotation-minimising frames differ across the seam by the closing
//! angle `α`; spreading `α + 2πk` along the loop (Zheng 2008, *Studies on Motion and
//! Deformation in Graphics*, §7.3 eq. 7.3; Wang, Jüttler, Zheng & Liu, ACM TOG 27(1), 2008,
//! §6.3) closes them for whole `k`. Spreading `α + π + 2πk` instead (`turns = k + ½`)
//! leaves the last frame, carried across the closing segment, equal to the first turned by
//! π about the tangent: `(r, s) → (−r, −s)`. The profile vertex `p_j` then lands on `−p_j`,
//! and the sweep still closes when the profile is symmetric under that half turn: a closed
//! profile of even vertex count `m` with `p_{j + m/2} = −p_j` (point symmetric about the
//! spine; an ellipse or rectangle centred on it, a tube of an even number of sides). Ma
//! (1996, *Curve and Surface Framing*, Fig. G.1c) adds multiples of π to a closed ribbon's
//! twist for the same reason (`V → −V` gives the same ribbon).
//!
//! The mesh then joins column `j` of the last ring to column `j + m/2 (mod m)` of the first
//! (instead of `j`), every vertex shared as before, so the surface is watertight and wound
//! outwards throughout (the half turn keeps orientation: a torus, not a Möbius band; an open
//! profile would make a Möbius band and is refused). Across the seam the neighbouring
//! ring's axes are taken negated (the ring turned by π maps column `j` onto `j + m/2`), so
//! the normals' spine derivative, the twist test of the diagonals and the fold-over test
//! see the same surface as everywhere else.

use glam::DVec3;

use super::profile::Profile;
use crate::error::{InputError, Result};

/// Relative tolerance of the symmetry `p_{j + m/2} = −p_j` (of the profile's reach).
pub const SYMMETRY_TOL: f64 = 1e-9;

/// Is `turns` a half number (`k + ½`, the frames closing up to a half turn)?
pub fn is_half(turns: f64) -> bool {
    turns.is_finite() && turns != turns.round()
}

/// The column shift at the seam of a closed sweep with `turns` extra turns: 0 for whole
/// turns, `m/2` for half turns with a profile symmetric under the half turn; an error naming
/// `turns` for a non-half number, or `profile` for a profile without that symmetry.
pub fn shift(p: &Profile, closed: bool, turns: f64) -> Result<usize> {
    if !turns.is_finite() || 2.0 * turns != (2.0 * turns).round() {
        return Err(InputError::new(
            "turns",
            format!("expected a whole or half number of turns (e.g. 1, 0.5, -1.5), got {turns}"),
        ));
    }
    if turns != 0.0 && !closed {
        return Err(InputError::new(
            "turns",
            "applies to a closed spine (closed=True): an open sweep has no seam to close",
        ));
    }
    if !is_half(turns) {
        return Ok(0);
    }
    let m = p.points.len();
    if !p.closed {
        return Err(InputError::new(
            "profile",
            format!(
                "turns={turns} (a half turn at the seam) needs a closed profile: an open \
                 profile turned by π would close into a Möbius band"
            ),
        ));
    }
    if m % 2 == 1 {
        return Err(InputError::new(
            "profile",
            format!(
                "turns={turns} (a half turn at the seam) needs a profile symmetric under a half \
                 turn about the spine (vertex j + m/2 at −vertex j), which an odd number of \
                 vertices ({m}) cannot be"
            ),
        ));
    }
    let half = m / 2;
    let reach = p.points.iter().map(|q| q.length()).fold(0.0, f64::max);
    let (worst, at) = (0..half)
        .map(|j| ((p.points[j] + p.points[j + half]).length(), j))
        .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
    if worst > SYMMETRY_TOL * reach {
        return Err(InputError::new(
            "profile",
            format!(
                "turns={turns} (a half turn at the seam) needs a profile symmetric under a half \
                 turn about the spine, vertex j + m/2 at −vertex j (to {SYMMETRY_TOL:e} of its \
                 reach); vertices {at} and {} are {worst:.3e} from that (an ellipse, a \
                 rectangle or a tube of an even number of sides centred on the spine is)",
                at + half
            ),
        ));
    }
    Ok(half)
}

/// Given frames of a closed spine whose seam takes a half turn: the last frame (row
/// `rings − 1`), carried to the first sample's tangent by the minimal rotation, must be
/// within π/2 of the first frame turned by π (an error naming `frames` otherwise; frames
/// that close as they are take whole `turns`).
pub fn check_given(frames: &[[f64; 9]], rings: usize) -> Result<()> {
    let col = |f: &[f64; 9], k: usize| DVec3::new(f[k], f[3 + k], f[6 + k]);
    let (first, last) = (&frames[0], &frames[rings - 1]);
    let r = crate::math::rotation::minimal_rotate(col(last, 2), col(first, 2), col(last, 0));
    let angle = crate::math::rotation::signed_angle(r, col(first, 0), col(first, 2));
    if angle.abs() >= std::f64::consts::FRAC_PI_2 {
        return Ok(());
    }
    Err(InputError::new(
        "frames",
        format!(
            "with a half number of turns the frames must close up to a half turn (the last \
             frame carried across the seam within π/2 of the first turned by π), but they \
             close to within {:.3} rad of the first frame; pass whole turns (e.g. 0) for \
             frames that close",
            angle.abs()
        ),
    ))
}

/// A seam with a half turn takes no corner joins on its spine (a join's extra rings and
/// welds are laid out column by column from the neighbouring rings, which the shift at the
/// seam would break where they reach it): an error naming `turns` where there are any.
pub fn no_corners<C>(corners: &[C]) -> Result<()> {
    match corners.is_empty() {
        true => Ok(()),
        false => Err(InputError::new(
            "turns",
            format!(
                "a half number of turns needs a spine without corner joins, and this one has \
                 {} sharp corner(s) (a turn of 15° or more between chords); sample the spine \
                 more densely or smooth it",
                corners.len()
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::cancel;
    use glam::DVec2;

    fn polygon(m: usize, a: f64, b: f64, off: f64) -> Profile {
        let pts: Vec<DVec2> = (0..m)
            .map(|j| {
                let u = std::f64::consts::TAU * j as f64 / m as f64;
                DVec2::new(off + a * u.cos(), b * u.sin())
            })
            .collect();
        Profile::new(&pts, true, &cancel::never).expect("a simple polygon")
    }

    #[test]
    fn half_turns_shift_symmetric_profiles_by_half_their_vertices() {
        let p = polygon(12, 1.0, 0.4, 0.0);
        assert_eq!(shift(&p, true, 0.0).ok(), Some(0));
        assert_eq!(shift(&p, true, 2.0).ok(), Some(0));
        assert_eq!(shift(&p, true, 0.5).ok(), Some(6));
        assert_eq!(shift(&p, true, -1.5).ok(), Some(6));
        let arg = |r: Result<usize>| r.err().map(|e| e.arg.into_owned());
        assert_eq!(arg(shift(&p, true, 0.25)), Some("turns".to_string()));
        assert_eq!(arg(shift(&p, false, 0.5)), Some("turns".to_string()));
        assert_eq!(
            arg(shift(&polygon(12, 1.0, 0.4, 0.1), true, 0.5)),
            Some("profile".to_string())
        );
        assert_eq!(
            arg(shift(&polygon(11, 1.0, 0.4, 0.0), true, 0.5)),
            Some("profile".to_string())
        );
    }

    #[test]
    fn given_frames_must_close_up_to_a_half_turn() {
        // frames about e_z at two rows: r = e_x, then r turned by `a`
        let frame = |a: f64| {
            let (s, c) = a.sin_cos();
            [c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0]
        };
        assert!(check_given(&[frame(0.0), frame(3.0)], 2).is_ok());
        assert!(check_given(&[frame(0.0), frame(-2.0)], 2).is_ok());
        let e = check_given(&[frame(0.0), frame(0.3)], 2).err();
        assert_eq!(e.map(|e| e.arg.into_owned()), Some("frames".to_string()));
    }
}
