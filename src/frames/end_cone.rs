//! The end cone of the default tangent rule: an open end's tangent kept within a cone about
//! the end chord `ĉ` whose half-angle follows the turn `φ` of the last two chords — the whole
//! turn on fine samplings (`φ ≤ 10°`), where a smooth end leans `κh/2 + O(h²)` and must keep
//! its 4th order, half the turn on coarse ones (`φ ≥ 20°`), where the one-sided quartic
//! overshoots and makes chisel-shaped tube ends, and never more than 45°; next to a corner
//! (a turn over 30°) the end tangent goes on towards `ĉ` as the chord guard of
//! [`super::tangents`] turns interior tangents towards the bisector. (The cone is ours: Wang
//! et al. §6.1 give only the one-sided stencils; the circle through the last three points
//! leans by half its turn on equal chords.)

use glam::DVec3;

use super::tangent_lanes::CORNER_COS;

/// Cosine of the widest end cone of [`bound_end`], 45°.
pub const END_CONE_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// Cosines of the end turns `φ` between which [`bound_end`]'s cone narrows from the whole
/// turn (fine samplings, up to 10°) to half the turn (coarse ones, from 20° on).
pub const END_HALF_COS: [f64; 2] = [0.984_807_753_012_208, 0.939_692_620_785_908_4];

/// The end tangent `u` at the open end `i` (0 or n − 1, `n ≥ 3`), turned towards the end
/// chord `ĉ` onto the cone about it where it leans further; unchanged inside the cone. With
/// `φ = ∠(ĉ, p̂)` the turn of the end chords (`p̂` the neighbouring chord), the cone's
/// half-angle is `φ` up to `φ = 10°`, `φ/2` from 20° on, `φ·(1 − w/2)` between (`w` the
/// smoothstep from 10° to 20°), and at most 45°. A smooth curve's end leans `κh/2 + O(h²)`,
/// inside the whole-turn cone of fine samplings; coarse samplings end within half their
/// last turn, so the end faces of their tubes stay close to square to the end chord. Where
/// the end chords turn by more than 30° (a corner of the polyline, as [`guard_chords`](super::tangents::guard_chords) has
/// it) the result is then blended towards `ĉ` with the same smoothstep weight, `ĉ` itself
/// from 60° on: the end of a coarse polyline is cut square to its last chord.
#[inline]
pub fn bound_end(x: &[DVec3], i: usize, u: DVec3) -> DVec3 {
    let n = x.len();
    let (c, p) = if i == 0 {
        (x[1] - x[0], x[2] - x[1])
    } else {
        (x[n - 1] - x[n - 2], x[n - 2] - x[n - 3])
    };
    let (Some(c), Some(p)) = (c.try_normalize(), p.try_normalize()) else {
        return u;
    };
    let d = c.dot(p);
    let (cos_a, sin_a) = end_cone(d, c.cross(p).length());
    let u = if u.dot(c) >= cos_a {
        u
    } else {
        // the direction of the lean in the normal plane of ĉ; for a tangent along −ĉ, the
        // turn of the chords continued (away from p̂), or any normal on a straight end
        let side = (u - u.dot(c) * c)
            .try_normalize()
            .or_else(|| (c * d - p).try_normalize())
            .unwrap_or_else(|| super::geometry::any_perpendicular(c));
        (cos_a * c + sin_a * side).normalize_or(c)
    };
    // a corner next to the end (a turn over 30°): towards the end chord, as the chord guard
    // turns interior tangents towards the bisector, fully from 60° on
    let s = ((CORNER_COS[0] - d) / (CORNER_COS[0] - CORNER_COS[1])).clamp(0.0, 1.0);
    if s > 0.0 {
        let w = s * s * (3.0 - 2.0 * s);
        ((1.0 - w) * u + w * c).normalize_or(c)
    } else {
        u
    }
}

/// Cosine and sine of [`bound_end`]'s cone half-angle for end chords turning by `φ`, given
/// as `cos φ` and `sin φ`: `φ` itself (the same values, bit for bit) up to 10°, `φ/2` from
/// 20° on with a smoothstep between, at most 45°.
#[inline]
fn end_cone(cos_phi: f64, sin_phi: f64) -> (f64, f64) {
    if cos_phi >= END_HALF_COS[0] {
        return (cos_phi, sin_phi);
    }
    let phi = sin_phi.atan2(cos_phi);
    let (lo, hi) = (END_HALF_COS[0].acos(), END_HALF_COS[1].acos());
    let s = ((phi - lo) / (hi - lo)).clamp(0.0, 1.0);
    let half = phi * (1.0 - 0.5 * s * s * (3.0 - 2.0 * s));
    if half >= std::f64::consts::FRAC_PI_4 {
        (END_CONE_COS, END_CONE_COS)
    } else {
        (half.cos(), half.sin())
    }
}
