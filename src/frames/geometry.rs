//! Small vector helpers shared by the frame methods.
//!
//! * `rotate_about(v, t, θ)`: rotation of a vector `v ⟂ t` by the angle θ about the unit
//!   axis `t` (right-handed, counter-clockwise seen from the tip of `t`):
//!   `cos θ · v + sin θ · (t × v)` (from [`crate::math::rotation`]).
//! * `signed_angle(a, b, t)`: the angle that turns `a` into `b` about `t`,
//!   `atan2((a × b)·t, a·b) ∈ (−π, π]` (from [`crate::math::rotation`]).
//! * `any_perpendicular(t)`: a deterministic unit vector ⟂ `t`: the world axis least aligned
//!   with `t` (first such axis on ties), projected onto the normal plane and normalised.

use glam::DVec3;
use rayon::prelude::*;

pub use crate::math::rotation::{rotate_about, signed_angle};

pub fn any_perpendicular(t: DVec3) -> DVec3 {
    let a = t.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    (axis - axis.dot(t) * t).normalize()
}

/// Axis-aligned bounding box `(lo, hi)` (both zero for no points), in parallel.
pub fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    let Some(&p0) = points.first() else {
        return (DVec3::ZERO, DVec3::ZERO);
    };
    points
        .par_chunks(1 << 12)
        .map(|c| {
            c.iter()
                .fold((p0, p0), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
        })
        .reduce(|| (p0, p0), |a, b| (a.0.min(b.0), a.1.max(b.1)))
}

/// Largest absolute coordinate (the scale for round-off thresholds) and the diagonal of the
/// bounding box.
pub fn scale_and_diagonal(points: &[DVec3]) -> (f64, f64) {
    let (lo, hi) = bounds(points);
    (lo.abs().max(hi.abs()).max_element(), (hi - lo).length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_and_angle_are_inverse() {
        let t = DVec3::new(1.0, 2.0, 2.0).normalize();
        let v = any_perpendicular(t);
        assert!(v.dot(t).abs() < 1e-15 && (v.length() - 1.0).abs() < 1e-15);
        for &a in &[0.3, -2.0, 3.0, -3.1] {
            let w = rotate_about(v, t, a);
            assert!((signed_angle(v, w, t) - a).abs() < 1e-14);
        }
    }
}
