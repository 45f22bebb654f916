//! Small vector helpers shared by the frame methods.
//!
//! * `rotate_about(v, t, θ)`: rotation of a vector `v ⟂ t` by the angle θ about the unit
//!   axis `t` (right-handed, counter-clockwise seen from the tip of `t`):
//!   `cos θ · v + sin θ · (t × v)`.
//! * `signed_angle(a, b, t)`: the angle that turns `a` into `b` about `t`,
//!   `atan2((a × b)·t, a·b) ∈ (−π, π]`.
//! * `any_perpendicular(t)`: a deterministic unit vector ⟂ `t`: the world axis least aligned
//!   with `t` (first such axis on ties), projected onto the normal plane and normalised.

use glam::DVec3;

#[inline]
pub fn rotate_about(v: DVec3, t: DVec3, angle: f64) -> DVec3 {
    if angle == 0.0 {
        return v;
    }
    let (s, c) = angle.sin_cos();
    c * v + s * t.cross(v)
}

#[inline]
pub fn signed_angle(a: DVec3, b: DVec3, t: DVec3) -> f64 {
    a.cross(b).dot(t).atan2(a.dot(b))
}

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

/// Largest absolute coordinate, used as the scale for round-off thresholds.
pub fn max_abs(points: &[DVec3]) -> f64 {
    points
        .iter()
        .fold(0.0_f64, |m, p| m.max(p.abs().max_element()))
}

/// Diagonal of the axis-aligned bounding box.
pub fn bbox_diagonal(points: &[DVec3]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let (lo, hi) = points.iter().fold((points[0], points[0]), |(lo, hi), p| {
        (lo.min(*p), hi.max(*p))
    });
    (hi - lo).length()
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
