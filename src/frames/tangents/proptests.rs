//! Property tests (proptest) of the estimator over random curves, motions and scales.

use super::*;
use glam::DQuat;
use proptest::prelude::*;

const RULES: [TangentRule; 4] = [
    TangentRule::FivePoint,
    TangentRule::FivePointBounded,
    TangentRule::FivePointUniform,
    TangentRule::Circle,
];

/// A smooth random open curve: unit steps turning by at most 0.3 rad, lengths 0.2…2.
fn walk() -> impl Strategy<Value = Vec<DVec3>> {
    proptest::collection::vec(
        ((-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64), 0.2..2.0f64),
        4..30,
    )
    .prop_map(|steps| {
        let mut d = DVec3::new(0.6, -0.3, 0.74).normalize();
        let mut x = vec![DVec3::new(0.1, 0.2, -0.3)];
        for ((a, b, c), h) in steps {
            let turn = DVec3::new(a, b, c) * 0.17;
            d = (d + turn - turn.dot(d) * d).normalize();
            x.push(*x.last().unwrap() + h * d);
        }
        x
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Unit tangents, turned with the curve by any rotation and unchanged by a scale
    /// 2^e (exact in binary) and a shift: the estimate depends on the shape only.
    #[test]
    fn tangents_are_unit_and_move_with_the_curve(
        x in walk(), axis in (-1.0..1.0f64, -1.0..1.0f64, 0.1..1.0f64),
        angle in -3.1..3.1f64, e in -900i32..900, rule in 0usize..4,
    ) {
        let rule = RULES[rule];
        let t = estimate_rows(&x, false, rule, &cancel::never).unwrap();
        let q = DQuat::from_axis_angle(DVec3::new(axis.0, axis.1, axis.2).normalize(), angle);
        let s = crate::math::scale::ldexp(1.0, e);
        let shift = DVec3::new(3.0, -1.0, 2.0) * s;
        let y: Vec<DVec3> = x.iter().map(|&p| q * p * s + shift).collect();
        let ty = estimate_rows(&y, false, rule, &cancel::never).unwrap();
        for (a, b) in t.iter().zip(&ty) {
            prop_assert!((a.length() - 1.0).abs() < 1e-13);
            prop_assert!((q * *a - *b).length() < 1e-9, "{a} {b}");
        }
    }

    /// On a uniformly sampled circle every rule gives the exact tangent (the stencils
    /// are symmetric about each sample), at any radius.
    #[test]
    fn uniform_circle_gives_the_exact_tangent(
        n in 5usize..64, e in -900i32..900, phase in 0.0..6.3f64, rule in 0usize..4,
    ) {
        let r = crate::math::scale::ldexp(1.0, e);
        let u = |i: usize| phase + std::f64::consts::TAU * i as f64 / n as f64;
        let x: Vec<DVec3> =
            (0..n).map(|i| DVec3::new(u(i).cos(), u(i).sin(), 0.0) * r).collect();
        let t = estimate_rows(&x, true, RULES[rule], &cancel::never).unwrap();
        for (i, ti) in t.iter().enumerate() {
            let want = DVec3::new(-u(i).sin(), u(i).cos(), 0.0);
            prop_assert!((*ti - want).length() < 1e-12, "{i}: {ti} {want}");
        }
    }

    /// Points on a line at any spacing: every tangent is the line's direction (the
    /// chord-length rules; the uniform stencils take the index as parameter and can
    /// point backwards where the spacing jumps by a factor of ~100).
    #[test]
    fn straight_line_at_any_spacing(
        d in (-1.0..1.0f64, -1.0..1.0f64, 0.1..1.0f64),
        h in proptest::collection::vec(0.01..10.0f64, 1..25),
        rule in prop_oneof![Just(0usize), Just(1), Just(3)],
    ) {
        let d = DVec3::new(d.0, d.1, d.2).normalize();
        let mut x = vec![DVec3::new(1.0, 2.0, 3.0)];
        for hi in &h {
            x.push(*x.last().unwrap() + *hi * d);
        }
        let t = estimate_rows(&x, false, RULES[rule], &cancel::never).unwrap();
        for ti in &t {
            prop_assert!((*ti - d).length() < 1e-12, "{ti} {d}");
        }
    }
}
