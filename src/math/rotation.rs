//! Rotation kernels.
//!
//! * **Minimal rotation** taking unit `a` to unit `b` (the rotation about `k = a × b` by the
//!   angle between them; Bloomenthal, "Calculation of reference frames along a space curve",
//!   Graphics Gems I, 1990): with `c = a·b` and `|k|² = 1 − c²`, Rodrigues' formula becomes
//!   `R v = c v + k × v + (k·v) k / (1 + c)` — no threshold for parallel vectors (`k = 0`
//!   gives the identity), undefined only for `b = −a` (`c = −1`: the result is not finite,
//!   or `−v` when round-off leaves `1 + c` a few ulps above 0; callers refuse reversals
//!   first). As a unit quaternion it is `normalise(1 + c, k)`
//!   ([`minimal_rotation_quat`], `None` near the antipodal case).
//! * **Rodrigues' rotation** of `v` about the unit axis `a` by `θ`:
//!   `v cos θ + (a × v) sin θ + a (a·v)(1 − cos θ)`; for `v ⟂ a` the last term vanishes
//!   ([`rotate_about`]).
//! * **Signed angle** turning `a` into `b` about `t`: `atan2((a × b)·t, a·b) ∈ (−π, π]`.
//! * **Matrix → quaternion** by Shepperd's method (Shepperd, "Quaternion from rotation
//!   matrix", J. Guidance and Control 1, 1978): the square root of the largest of
//!   `1 + tr R`, `1 + 2R₀₀ − tr R`, `1 + 2R₁₁ − tr R`, `1 + 2R₂₂ − tr R`, the other
//!   components from sums and differences of off-diagonal pairs, so no small divisor.
//! * **Rotation test**: orthonormal columns to [`ROTATION_TOL`] and a positive determinant.

use glam::{DMat3, DQuat, DVec3};

/// Tolerance of [`is_rotation`] on every entry of `RᵀR − I`.
pub const ROTATION_TOL: f64 = 1e-6;

/// `v` turned by the minimal rotation with axis `k = a × b`, cosine `c = a·b` and
/// `den = 1 + c` already computed (the arithmetic of [`minimal_rotate`]).
#[inline(always)]
pub fn minimal_rotate_with(k: DVec3, c: f64, den: f64, v: DVec3) -> DVec3 {
    c * v + k.cross(v) + k * (k.dot(v) / den)
}

/// `v` turned by the minimal rotation taking unit `a` to unit `b` (meaningless for `b = −a`,
/// see the module docs: callers refuse that case first).
#[inline(always)]
pub fn minimal_rotate(a: DVec3, b: DVec3, v: DVec3) -> DVec3 {
    let c = a.dot(b);
    minimal_rotate_with(a.cross(b), c, 1.0 + c, v)
}

/// The unit quaternion of the minimal rotation taking unit `a` to unit `b`,
/// `normalise(1 + a·b, a × b)`; `None` when `1 + a·b ≤ 10⁻¹²` (`b ≈ −a`, the axis is
/// undefined).
#[inline]
pub fn minimal_rotation_quat(a: DVec3, b: DVec3) -> Option<DQuat> {
    let c = a.dot(b);
    if !(1.0 + c > 1e-12) {
        return None;
    }
    let v = a.cross(b);
    Some(DQuat::from_xyzw(v.x, v.y, v.z, 1.0 + c).normalize())
}

/// The matrix of the rotation by the smallest angle taking unit `a` to unit `b`
/// (`I + K + K²/(1 + a·b)`, `K = [a × b]×`); for opposite vectors (`a·b ≤ −1 + 10⁻¹²`) a
/// half turn about an axis perpendicular to `a` (`a × e_x`, or `a × e_y` when `a` is near
/// `e_x`).
pub fn minimal_rotation_matrix(a: DVec3, b: DVec3) -> DMat3 {
    let c = a.dot(b);
    if c <= -1.0 + 1e-12 {
        let e = if a.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let axis = a.cross(e).normalize();
        return DMat3::from_cols(
            axis * (2.0 * axis.x),
            axis * (2.0 * axis.y),
            axis * (2.0 * axis.z),
        ) - DMat3::IDENTITY;
    }
    DMat3::from_cols(
        minimal_rotate(a, b, DVec3::X),
        minimal_rotate(a, b, DVec3::Y),
        minimal_rotate(a, b, DVec3::Z),
    )
}

/// Rodrigues' rotation of `v` about the unit `axis` by `angle`.
#[inline]
pub fn rodrigues(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(v) * s + axis * (axis.dot(v) * (1.0 - c))
}

/// Rotation of `v ⟂ t` by `angle` about the unit axis `t` (right-handed):
/// `cos θ · v + sin θ · (t × v)` (Rodrigues without the axial term; `v` itself for θ = 0).
#[inline]
pub fn rotate_about(v: DVec3, t: DVec3, angle: f64) -> DVec3 {
    if angle == 0.0 {
        return v;
    }
    let (s, c) = angle.sin_cos();
    c * v + s * t.cross(v)
}

/// The angle that turns `a` into `b` about `t`, `atan2((a × b)·t, a·b) ∈ (−π, π]`.
#[inline]
pub fn signed_angle(a: DVec3, b: DVec3, t: DVec3) -> f64 {
    a.cross(b).dot(t).atan2(a.dot(b))
}

/// The unit quaternion of a rotation matrix (Shepperd's method; normalised, sign not
/// canonical).
pub fn quat_from_mat3(m: &DMat3) -> DQuat {
    let (r00, r01, r02) = (m.x_axis.x, m.y_axis.x, m.z_axis.x);
    let (r10, r11, r12) = (m.x_axis.y, m.y_axis.y, m.z_axis.y);
    let (r20, r21, r22) = (m.x_axis.z, m.y_axis.z, m.z_axis.z);
    let tr = r00 + r11 + r22;
    let q = if tr >= r00 && tr >= r11 && tr >= r22 {
        let w = 0.5 * (1.0 + tr).max(0.0).sqrt();
        let k = 0.25 / w;
        DQuat::from_xyzw((r21 - r12) * k, (r02 - r20) * k, (r10 - r01) * k, w)
    } else if r00 >= r11 && r00 >= r22 {
        let x = 0.5 * (1.0 + r00 - r11 - r22).max(0.0).sqrt();
        let k = 0.25 / x;
        DQuat::from_xyzw(x, (r01 + r10) * k, (r02 + r20) * k, (r21 - r12) * k)
    } else if r11 >= r22 {
        let y = 0.5 * (1.0 - r00 + r11 - r22).max(0.0).sqrt();
        let k = 0.25 / y;
        DQuat::from_xyzw((r01 + r10) * k, y, (r12 + r21) * k, (r02 - r20) * k)
    } else {
        let z = 0.5 * (1.0 - r00 - r11 + r22).max(0.0).sqrt();
        let k = 0.25 / z;
        DQuat::from_xyzw((r02 + r20) * k, (r12 + r21) * k, z, (r10 - r01) * k)
    };
    q.normalize()
}

/// The rotation matrix of a unit quaternion.
#[inline]
pub fn mat3_from_quat(q: DQuat) -> DMat3 {
    DMat3::from_quat(q)
}

/// Is `m` a rotation matrix: finite, every entry of `mᵀm − I` below [`ROTATION_TOL`] in
/// size, and `det m > 0`?
#[inline]
pub fn is_rotation(m: &DMat3) -> bool {
    let (r, s, t) = (m.x_axis, m.y_axis, m.z_axis);
    r.is_finite()
        && s.is_finite()
        && t.is_finite()
        && (r.length_squared() - 1.0).abs() < ROTATION_TOL
        && (s.length_squared() - 1.0).abs() < ROTATION_TOL
        && (t.length_squared() - 1.0).abs() < ROTATION_TOL
        && r.dot(s).abs() < ROTATION_TOL
        && r.dot(t).abs() < ROTATION_TOL
        && s.dot(t).abs() < ROTATION_TOL
        && r.cross(s).dot(t) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_rotation_matrix_takes_a_to_b_and_is_a_rotation() {
        let a = DVec3::new(0.3, -0.5, 0.8).normalize();
        for b in [
            DVec3::new(-0.2, 0.9, 0.1).normalize(),
            a,
            -a,
            DVec3::new(0.3, -0.5, 0.81).normalize(),
        ] {
            let m = minimal_rotation_matrix(a, b);
            assert!((m * a - b).length() < 1e-12, "{b}");
            assert!(is_rotation(&m));
            // vectors perpendicular to both stay put
            let k = a.cross(b);
            if k.length() > 1e-6 {
                assert!((m * k - k).length() < 1e-12);
            }
        }
    }
    use std::f64::consts::{PI, TAU};

    fn units() -> Vec<DVec3> {
        [
            DVec3::X,
            DVec3::new(0.3, -0.8, 0.5),
            DVec3::new(-1.0, 2.0, 3.0),
            DVec3::new(0.0, 1.0, 1e-9),
            DVec3::new(-0.7, -0.1, 0.2),
        ]
        .iter()
        .map(|v| v.normalize())
        .collect()
    }

    #[test]
    fn minimal_rotation_maps_a_to_b_and_fixes_the_axis() {
        for &a in &units() {
            for &b in &units() {
                if a.dot(b) < -0.99 {
                    continue;
                }
                assert!((minimal_rotate(a, b, a) - b).length() < 1e-14);
                // vectors orthogonal to both (the axis) stay fixed
                let k = a.cross(b);
                if k.length() > 1e-6 {
                    let n = k.normalize();
                    assert!((minimal_rotate(a, b, n) - n).length() < 1e-14);
                }
                // it is a rotation: lengths and the quaternion form agree
                let v = DVec3::new(0.4, -1.3, 2.2);
                let w = minimal_rotate(a, b, v);
                assert!((w.length() - v.length()).abs() < 1e-13);
                let q = minimal_rotation_quat(a, b).unwrap();
                assert!((q * v - w).length() < 1e-13);
            }
            // identity for a = b
            let v = DVec3::new(0.4, -1.3, 2.2);
            assert!((minimal_rotate(a, a, v) - v).length() < 1e-15);
            assert!((minimal_rotation_quat(a, a).unwrap() - DQuat::IDENTITY).length() < 1e-15);
        }
    }

    #[test]
    fn antipodal_vectors_are_flagged() {
        // the quaternion form refuses; the vector form has no rotation to give (its callers
        // refuse reversals first): not finite at `a·b = −1` exactly, `−v` (a reflection)
        // when round-off leaves `1 + a·b` a few ulps above 0
        let v = DVec3::new(0.1, 0.2, 0.3);
        for &a in &units() {
            assert!(minimal_rotation_quat(a, -a).is_none());
            let w = minimal_rotate(a, -a, v);
            assert!(!w.is_finite() || (w + v).length() < 1e-15);
        }
        assert!(!minimal_rotate(DVec3::X, -DVec3::X, v).is_finite());
    }

    #[test]
    fn rodrigues_agrees_with_quaternions_and_closes_at_a_full_turn() {
        let v = DVec3::new(0.4, -1.3, 2.2);
        for &a in &units() {
            assert!((rodrigues(v, a, TAU) - v).length() < 1e-14);
            assert_eq!(rodrigues(v, a, 0.0), v);
            for angle in [0.3, -1.2, PI, 2.9] {
                let q = DQuat::from_axis_angle(a, angle);
                assert!((rodrigues(v, a, angle) - q * v).length() < 1e-14);
                // the perpendicular part turns alike
                let p = v - a * a.dot(v);
                let want = rodrigues(p, a, angle);
                assert!((rotate_about(p, a, angle) - want).length() < 1e-14);
                assert!((signed_angle(p, want, a) - angle).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn matrix_quaternion_round_trip_in_every_branch() {
        // half turns about x, y, z and a diagonal take the trace-negative branches
        let cases = [
            (DVec3::X, 0.3),
            (DVec3::new(1.0, 2.0, -1.0), 1.5),
            (DVec3::X, PI),
            (DVec3::Y, PI),
            (DVec3::Z, PI),
            (DVec3::new(1.0, 1.0, 0.0), 3.0),
            (DVec3::new(0.2, 1.0, 0.1), 2.8),
            (DVec3::new(0.1, 0.2, 1.0), 2.9),
        ];
        for (axis, angle) in cases {
            let q = DQuat::from_axis_angle(axis.normalize(), angle);
            let m = mat3_from_quat(q);
            let back = quat_from_mat3(&m);
            assert!((back.length() - 1.0).abs() < 1e-15);
            assert!(back.dot(q).abs() > 1.0 - 1e-15, "{axis} {angle}");
            assert!(mat3_from_quat(back).abs_diff_eq(m, 4e-15));
            assert!(is_rotation(&m));
        }
    }

    #[test]
    fn rotation_test_refuses_reflections_and_skew() {
        assert!(is_rotation(&DMat3::IDENTITY));
        assert!(!is_rotation(&DMat3::from_diagonal(DVec3::new(
            1.0, 1.0, -1.0
        ))));
        assert!(!is_rotation(&DMat3::from_diagonal(DVec3::new(
            1.0, 1.0, 1.01
        ))));
        let mut m = DMat3::IDENTITY;
        m.x_axis.y = 1e-5;
        assert!(!is_rotation(&m));
        m.x_axis.y = 1e-7;
        assert!(is_rotation(&m));
        m.x_axis.y = f64::NAN;
        assert!(!is_rotation(&m));
    }
}
