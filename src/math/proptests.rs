//! Property tests (proptest) of the kernels the frames rest on, over random inputs and
//! scales 2^±1000: normalisation by the largest component, the minimal rotation, quaternion
//! ↔ matrix (Shepperd), the double-reflection step (Wang et al., ACM TOG 27(1), 2008, §4)
//! and the scale invariance of whole frame computations.

use crate::run::cancel;
use glam::{DMat3, DQuat, DVec3};
use proptest::prelude::*;

use crate::frames::double_reflection::dr_step;
use crate::frames::{Request, compute_into};
use crate::math::rotation::{mat3_from_quat, minimal_rotate, quat_from_mat3};
use crate::math::scale;

fn vec3() -> impl Strategy<Value = DVec3> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_map(|(x, y, z)| DVec3::new(x, y, z))
        .prop_filter("not tiny", |v| v.length() > 1e-3)
}

fn unit3() -> impl Strategy<Value = DVec3> {
    vec3().prop_map(|v| v.normalize())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn normalize_is_scale_free(v in vec3(), e in -1000i32..1000) {
        let u = scale::normalize(scale::ldexp(1.0, e) * v).unwrap();
        prop_assert!((u - v.normalize()).length() < 1e-15);
        let l = scale::length(v * scale::ldexp(1.0, e));
        prop_assert!((scale::ldexp(l, -e) / v.length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn normalize4_gives_the_unit_quaternion(q in (vec3(), -1.0..1.0f64), e in -1000i32..1000) {
        let raw = [q.0.x, q.0.y, q.0.z, q.1];
        let s = raw.map(|c| scale::ldexp(c, e));
        let u = scale::normalize4(s).unwrap();
        let want = DQuat::from_xyzw(raw[0], raw[1], raw[2], raw[3]).normalize();
        prop_assert!((u - want).length() < 1e-15);
    }

    #[test]
    fn minimal_rotation_takes_a_to_b(a in unit3(), b in unit3(), v in vec3()) {
        prop_assume!(a.dot(b) > -0.99);
        prop_assert!((minimal_rotate(a, b, a) - b).length() < 1e-13);
        let w = minimal_rotate(a, b, v);
        prop_assert!((w.length() - v.length()).abs() < 1e-13);
        // the rotation axis a × b is fixed
        let k = a.cross(b);
        prop_assert!((minimal_rotate(a, b, k) - k).length() < 1e-13);
    }

    #[test]
    fn quaternion_matrix_round_trip(axis in unit3(), angle in -3.0..3.0f64) {
        let q = DQuat::from_axis_angle(axis, angle);
        let m = mat3_from_quat(q);
        let back = quat_from_mat3(&m);
        prop_assert!((back - q).length() < 1e-13 || (back + q).length() < 1e-13);
        let m2: DMat3 = mat3_from_quat(back);
        prop_assert!((m2.x_axis - m.x_axis).length() < 1e-13);
        prop_assert!((m.determinant() - 1.0).abs() < 1e-13);
    }

    #[test]
    fn double_reflection_step_is_a_frame_step(
        t0 in unit3(), turn in vec3(), r in vec3(), h in 1e-3..10.0f64, e in -900i32..900
    ) {
        let t1 = (t0 + 0.3 * turn).normalize();
        prop_assume!(t0.dot(t1) > 0.2);
        let r0 = (r - r.dot(t0) * t0).normalize();
        prop_assume!(r0.is_finite());
        let chord = h * (t0 + t1).normalize();
        let r1 = dr_step(chord, t0, t1, r0);
        prop_assert!((r1.length() - 1.0).abs() < 1e-12);
        prop_assert!(r1.dot(t1).abs() < 1e-12);
        // the step depends on the chord's direction only (scale-free)
        let big = dr_step(chord * scale::ldexp(1.0, e / 2), t0, t1, r0);
        prop_assert!((big - r1).length() < 1e-12);
    }

    #[test]
    fn frames_are_the_same_at_every_scale(
        seed in proptest::collection::vec(vec3(), 6..20), e in -1000i32..1000
    ) {
        // a random walk with forward steps
        let mut x = vec![DVec3::ZERO];
        let mut d = DVec3::X;
        for k in &seed {
            d = (d + 0.3 * *k).normalize();
            let last = *x.last().unwrap();
            x.push(last + (0.2 + k.length()) * d);
        }
        let run = |pts: &[DVec3]| {
            let mut out = vec![0.0; 9 * pts.len()];
            let req = Request { points: Some(pts), ..Request::default() };
            compute_into(&req, &mut out, &cancel::never).map(|_| out)
        };
        let f = scale::ldexp(1.0, e);
        let xs: Vec<DVec3> = x.iter().map(|p| *p * f).collect();
        match (run(&x), run(&xs)) {
            (Ok(a), Ok(b)) => {
                let worst = a.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
                prop_assert!(worst < 1e-12, "scale 2^{e}: {worst}");
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.arg, b.arg),
            (a, b) => prop_assert!(false, "{:?} vs {:?}", a.err(), b.err()),
        }
    }
}
