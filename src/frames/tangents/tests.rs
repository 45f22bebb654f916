//! Unit tests of the tangent rules: their orders, exactness on lines and circles, the
//! Lagrange weights against Fornberg's, the bounded ends and the chord guard.

use super::*;

fn ch(x: &[DVec3]) -> Vec<f64> {
    crate::frames::validate::chords(x, false, "points", &cancel::never).unwrap()
}

fn helix(u: f64) -> DVec3 {
    DVec3::new(u.cos(), u.sin(), 0.5 * u)
}
fn helix_t(u: f64) -> DVec3 {
    DVec3::new(-u.sin(), u.cos(), 0.5).normalize()
}

#[test]
fn five_point_is_fourth_order() {
    let err = |n: usize| {
        let h = 3.0 / n as f64;
        let x: Vec<DVec3> = (0..=n).map(|i| helix(i as f64 * h)).collect();
        let t = estimate(
            &x,
            &ch(&x),
            false,
            TangentRule::FivePoint,
            "points",
            &cancel::never,
        )
        .unwrap();
        (0..=n)
            .map(|i| (t[i] - helix_t(i as f64 * h)).length())
            .fold(0.0, f64::max)
    };
    let ratio = err(64) / err(128);
    assert!((14.0..18.0).contains(&ratio), "ratio {ratio}");
}

/// A long first chord before a tight cluster (ratio 610): the one-sided quartic at the
/// first sample would amplify rounding ~3·10⁸ times (a 6.6·10⁻⁹ error on a straight
/// line); the stencil drops to the end chord there and stays exact.
#[test]
fn long_end_chord_before_a_cluster_keeps_a_line_exact() {
    let d = DVec3::new(0.0, -0.8641143000711117, 0.853716779585615).normalize();
    let mut x = vec![DVec3::new(1.0, 2.0, 3.0)];
    for h in [6.096199463032909, 0.01, 0.01, 0.01] {
        x.push(*x.last().unwrap() + h * d);
    }
    for rule in [TangentRule::FivePoint, TangentRule::FivePointBounded] {
        let t = estimate_rows(&x, false, rule, &cancel::never).unwrap();
        for (i, ti) in t.iter().enumerate() {
            assert!((*ti - d).length() < 1e-12, "{rule:?} {i}: {ti} {d}");
        }
    }
    // on a circle of radius 2 (chord 3, then 0.01): a quadratic through the end and the
    // cluster (amplification ~600), leaning from the true tangent (0, 1, 0) by less than
    // half the end chord's lean (0.26 against 0.75 rad)
    let s = [0.0, 3.0, 3.01, 3.02, 3.03];
    let x: Vec<DVec3> = s
        .iter()
        .map(|&u: &f64| DVec3::new((u / 2.0).cos(), (u / 2.0).sin(), 0.0) * 2.0)
        .collect();
    let t = estimate_rows(&x, false, TangentRule::FivePoint, &cancel::never).unwrap();
    let exact = DVec3::Y;
    let chord = (x[1] - x[0]).normalize();
    assert!(
        t[0].angle_between(exact) < 0.5 * chord.angle_between(exact),
        "{}",
        t[0]
    );
}

#[test]
fn circle_rule_exact_on_circle() {
    // uneven arcs 0.2, 0.4, 0.1 rad: turns of 0.3 and 0.25 rad (under 30°)
    let u = [0.0_f64, 0.2, 0.6, 0.7];
    let x: Vec<DVec3> = u
        .iter()
        .map(|&u| DVec3::new(u.cos(), u.sin(), 0.0))
        .collect();
    let t = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::Circle,
        "points",
        &cancel::never,
    )
    .unwrap();
    for (i, &u) in u.iter().enumerate() {
        let e = DVec3::new(-u.sin(), u.cos(), 0.0);
        assert!((t[i] - e).length() < 1e-14, "{i}");
    }
    // turns of 60° or more are corners of the polyline: the chords' bisector there
    let u = [0.0_f64, 0.3, 2.3, 2.4];
    let x: Vec<DVec3> = u
        .iter()
        .map(|&u| DVec3::new(u.cos(), u.sin(), 0.0))
        .collect();
    let t = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::Circle,
        "points",
        &cancel::never,
    )
    .unwrap();
    let b = ((x[1] - x[0]).normalize() + (x[2] - x[1]).normalize()).normalize();
    assert!(
        (t[1] - b).length() < 1e-15
            && (t[1] - DVec3::new(-0.3f64.sin(), 0.3f64.cos(), 0.0)).length() > 0.1
    );
}

#[test]
fn chord_rule_exact_on_lines_and_uniform_rule_on_equal_chords() {
    let d = DVec3::new(1.0, -2.0, 0.5).normalize();
    let s = [0.0, 1e-3, 1.3e-3, 0.2, 0.21, 0.5, 0.5001];
    let x: Vec<DVec3> = s
        .iter()
        .map(|&v| DVec3::new(1.0, 2.0, 3.0) + v * d)
        .collect();
    let t = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePoint,
        "points",
        &cancel::never,
    )
    .unwrap();
    for ti in &t {
        assert!((*ti - d).length() < 1e-9, "{ti}");
    }
    // equal chords (a regular polygon): chord rule = uniform stencil
    let x: Vec<DVec3> = (0..9)
        .map(|i| {
            let a = 0.4 * i as f64;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let a = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePoint,
        "points",
        &cancel::never,
    )
    .unwrap();
    let b = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePointUniform,
        "points",
        &cancel::never,
    )
    .unwrap();
    for i in 0..9 {
        assert!((a[i] - b[i]).length() < 1e-14);
    }
}

#[test]
fn circle_normal_of_a_circle_and_a_line() {
    let c = DVec3::new(1.0, -2.0, 0.5);
    let x: Vec<DVec3> = [0.1_f64, 0.5, 1.7, 2.0]
        .iter()
        .map(|&u| c + 3.0 * DVec3::new(u.cos(), u.sin(), 0.0))
        .collect();
    for (i, &u) in [0.1_f64, 0.5, 1.7, 2.0].iter().enumerate() {
        let t = DVec3::new(-u.sin(), u.cos(), 0.0);
        let (nrm, k) = circle_normal(&x, t, i, false, 1e-14).unwrap();
        assert!((nrm + DVec3::new(u.cos(), u.sin(), 0.0)).length() < 1e-13);
        assert!((k - 1.0 / 3.0).abs() < 1e-13);
    }
    let line: Vec<DVec3> = (0..5).map(|i| DVec3::splat(i as f64 * 0.3)).collect();
    assert!(circle_normal(&line, DVec3::ONE.normalize(), 2, false, 1e-14).is_none());
}

/// Independent reference: finite-difference weights by Fornberg's algorithm (1988);
/// `w[j][k]` weights node `j` for the `k`-th derivative at `z` (k ≤ 2).
fn fornberg<const N: usize>(z: f64, x: &[f64; N]) -> [[f64; 3]; N] {
    let mut c = [[0.0; 3]; N];
    let mut c1 = 1.0;
    let mut c4 = x[0] - z;
    c[0][0] = 1.0;
    for i in 1..N {
        let mn = i.min(2);
        let mut c2 = 1.0;
        let c5 = c4;
        c4 = x[i] - z;
        for j in 0..i {
            let c3 = x[i] - x[j];
            c2 *= c3;
            if j == i - 1 {
                for k in (1..=mn).rev() {
                    c[i][k] = c1 * (k as f64 * c[i - 1][k - 1] - c5 * c[i - 1][k]) / c2;
                }
                c[i][0] = -c1 * c5 * c[i - 1][0] / c2;
            }
            for k in (1..=mn).rev() {
                c[j][k] = (c4 * c[j][k] - k as f64 * c[j][k - 1]) / c3;
            }
            c[j][0] = c4 * c[j][0] / c3;
        }
        c1 = c2;
    }
    c
}

#[test]
fn chord_rule_uses_lagrange_weights_on_uneven_chords() {
    // unevenly sampled space curve: the chord rule equals Fornberg's first-derivative
    // weights at the cumulative chord lengths, one-sided and centred
    let x: Vec<DVec3> = [0.0, 0.1, 0.35, 0.5, 0.9, 1.0]
        .iter()
        .map(|&u: &f64| DVec3::new(u, u * u, 0.3 * u * u * u))
        .collect();
    let chords = ch(&x);
    for (i, first) in [(0, 0), (1, 0), (2, 0), (3, 1), (5, 1)] {
        let mut tau = [0.0; 5];
        for k in 1..5 {
            tau[k] = tau[k - 1] + chords[first + k - 1];
        }
        let w = fornberg(tau[i - first], &tau);
        let d: DVec3 = (0..5).map(|k| w[k][1] * x[first + k]).sum();
        let e = chord_five_point(&x, &chords, i, false);
        assert!((d - e).length() < 1e-12 * d.length(), "{i}: {d} vs {e}");
    }
}

#[test]
fn unrolled_centred_stencil_has_the_lagrange_direction() {
    // very uneven chords too: the division-free weights keep the direction
    for scale in [1e-9, 1.0, 1e9] {
        let x: Vec<DVec3> = [0.0, 0.1, 0.35, 0.5, 0.9, 1.0, 1.001, 3.0]
            .iter()
            .map(|&u: &f64| scale * DVec3::new(u, u * u, 0.3 * u * u * u))
            .collect();
        let chords = ch(&x);
        for i in 2..x.len() - 2 {
            let e = chord_five_point(&x, &chords, i, false).normalize();
            let c = centred_five_point(
                [x[i - 2], x[i - 1], x[i], x[i + 1], x[i + 2]],
                [chords[i - 2], chords[i - 1], chords[i], chords[i + 1]],
            )
            .normalize();
            assert!((e - c).length() < 1e-13, "{scale} {i}: {e} vs {c}");
        }
    }
}

#[test]
fn fornberg_matches_central_differences() {
    let w = fornberg(0.0, &[-2.0, -1.0, 0.0, 1.0, 2.0]);
    let d1 = [1.0 / 12.0, -8.0 / 12.0, 0.0, 8.0 / 12.0, -1.0 / 12.0];
    let d2 = [
        -1.0 / 12.0,
        16.0 / 12.0,
        -30.0 / 12.0,
        16.0 / 12.0,
        -1.0 / 12.0,
    ];
    for k in 0..5 {
        assert!((w[k][1] - d1[k]).abs() < 1e-15 && (w[k][2] - d2[k]).abs() < 1e-14);
    }
}

#[test]
fn bounded_ends_stay_in_the_cone_and_keep_the_order() {
    // a coarse sampling whose one-sided quartic overshoots at the ends
    let x: Vec<DVec3> = [
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.0],
        [2.0, 0.3, 0.1],
        [3.0, 0.6, 0.1],
        [4.0, 1.0, 0.3],
        [4.6, 1.8, 0.7],
    ]
    .iter()
    .map(|&p| DVec3::from_array(p))
    .collect();
    let a = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePoint,
        "points",
        &cancel::never,
    )
    .unwrap();
    let b = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePointBounded,
        "points",
        &cancel::never,
    )
    .unwrap();
    let n = x.len();
    // the cone's half-angle: the whole turn up to 10°, half of it from 20° on
    let cone = |turn: f64| {
        let (lo, hi) = (10f64.to_radians(), 20f64.to_radians());
        let s = ((turn - lo) / (hi - lo)).clamp(0.0, 1.0);
        (turn * (1.0 - 0.5 * s * s * (3.0 - 2.0 * s))).min(std::f64::consts::FRAC_PI_4)
    };
    let mut acted = 0;
    for (i, c, p) in [
        (0, x[1] - x[0], x[2] - x[1]),
        (n - 1, x[n - 1] - x[n - 2], x[n - 2] - x[n - 3]),
    ] {
        let (c, p) = (c.normalize(), p.normalize());
        let phi = c.angle_between(p);
        let turn = cone(phi);
        assert!(b[i].angle_between(c) <= turn + 1e-12, "{i}");
        if a[i].angle_between(c) > turn {
            acted += 1;
            // on the cone (closer to ĉ next to a corner of over 30°), leaning to the
            // same side as the unbounded tangent
            let lean = b[i].angle_between(c);
            if phi < 30f64.to_radians() {
                assert!((lean - turn).abs() < 1e-12);
            } else {
                assert!(lean < turn);
            }
            assert!(c.cross(a[i]).normalize().dot(c.cross(b[i]).normalize()) > 1.0 - 1e-12);
        }
    }
    assert!(acted > 0);
    for i in 1..n - 1 {
        assert_eq!(a[i], b[i]);
    }
    // fine samplings: the bound never acts
    let x: Vec<DVec3> = (0..=200).map(|i| helix(i as f64 * 0.015)).collect();
    let a = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePoint,
        "points",
        &cancel::never,
    )
    .unwrap();
    let b = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePointBounded,
        "points",
        &cancel::never,
    )
    .unwrap();
    assert_eq!(a, b);
}

#[test]
fn many_curves_name_the_curve() {
    let x: Vec<DVec3> = (0..9).map(|i| helix(i as f64 * 0.3)).collect();
    let t = estimate_many(
        &x,
        &[0, 4, 9],
        false,
        TangentRule::FivePointBounded,
        &cancel::never,
    )
    .unwrap();
    assert_eq!(
        &t[..4],
        &estimate_rows(
            &x[..4],
            false,
            TangentRule::FivePointBounded,
            &cancel::never
        )
        .unwrap()[..]
    );
    let mut y = x.clone();
    y[6] = y[5];
    let e = estimate_many(
        &y,
        &[0, 4, 9],
        false,
        TangentRule::FivePointBounded,
        &cancel::never,
    )
    .unwrap_err();
    assert!(e.to_string().contains("curve 1 (rows 4 to 8)"), "{e}");
}

/// A deterministic stream of numbers in [−1, 1) (a linear congruential generator).
fn stream(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

#[test]
fn chord_guard_keeps_estimates_near_both_chords_and_bounds_the_rest() {
    let mut r = stream(7);
    let mut v = || DVec3::new(r(), r(), r());
    let (mut kept, mut turned) = (0, 0);
    for _ in 0..20_000 {
        let (ci, co, u) = (v() * 3.0, v() * 0.5, v().normalize());
        let g = guard_chords(ci, co, u);
        let (p, q) = (ci.normalize(), co.normalize());
        let half = 0.5 * (p + q).length(); // cos(φ/2)
        if half < 1e-6 {
            continue;
        }
        assert!((g.length() - 1.0).abs() < 1e-14);
        if u.dot(p) >= 0.5 && u.dot(q) >= 0.5 && p.dot(q) >= CORNER_COS[0] + 1e-12 {
            // within 60° of both chords turning by less than 30°: the estimate, bit for bit
            assert_eq!(g, u);
            kept += 1;
        } else if u.dot(p).min(u.dot(q)) < 0.5 * half {
            turned += 1;
        }
        if p.dot(q) <= CORNER_COS[1] {
            // a corner of 60° or more: its bisector
            assert!((g - (p + q).normalize()).length() < 1e-12, "{g}");
        }
        // against both chords by at least half the bisector's margin
        assert!(
            g.dot(p).min(g.dot(q)) >= 0.5 * half - 1e-12,
            "{ci} {co} {u} -> {g}"
        );
    }
    assert!(kept > 100 && turned > 1000, "{kept} {turned}");
}

#[test]
fn chord_guard_is_continuous() {
    // an estimate swung round through the whole circle, chords turning by 150°
    let (ci, co) = (DVec3::X, DVec3::new(-0.866, 0.5, 0.0));
    let steps = 100_000;
    let at = |k: usize| {
        let a = std::f64::consts::TAU * k as f64 / steps as f64;
        guard_chords(ci, co, DVec3::new(a.cos(), a.sin(), 0.3).normalize())
    };
    let step = std::f64::consts::TAU / steps as f64;
    let worst = (0..steps)
        .map(|k| (at(k + 1) - at(k)).length())
        .fold(0.0, f64::max);
    // the guard stretches the estimate's motion by a bounded factor, never jumps
    assert!(worst < 20.0 * step, "{worst} against a step of {step}");
}

#[test]
fn jagged_polylines_get_tangents_along_their_chords() {
    // Gaussian-like random walks: turns of every size, up to near reversals
    let mut r = stream(11);
    for rule in [
        TangentRule::FivePointBounded,
        TangentRule::FivePoint,
        TangentRule::FivePointUniform,
        TangentRule::Circle,
    ] {
        for n in 3..60 {
            for closed in [false, true] {
                let mut x = vec![DVec3::ZERO];
                for _ in 1..n {
                    let d = DVec3::new(r() + r(), r() + r(), r() + r());
                    x.push(*x.last().unwrap() + d);
                }
                let t = estimate(
                    &x,
                    &ch_closed(&x, closed),
                    closed,
                    rule,
                    "points",
                    &cancel::never,
                )
                .unwrap();
                let m = if closed { n } else { n - 1 };
                // the unbounded rules leave their end tangents as the quartic gives them
                let unbounded =
                    matches!(rule, TangentRule::FivePoint | TangentRule::FivePointUniform);
                let skip_ends = unbounded && !closed && n >= 5;
                let inner = if skip_ends { 1..m - 1 } else { 0..m };
                for i in inner {
                    let j = (i + 1) % n;
                    let c = (x[j] - x[i]).normalize();
                    let d = c.dot(t[i] + t[j]);
                    assert!(d > 1e-6, "{rule:?} n={n} closed={closed} segment {i}: {d}");
                }
                if rule == TangentRule::FivePointBounded && !closed && n >= 5 {
                    for (e, c) in [(0, x[1] - x[0]), (n - 1, x[n - 1] - x[n - 2])] {
                        let lean = t[e].angle_between(c);
                        assert!(lean <= std::f64::consts::FRAC_PI_4 + 1e-12, "{lean}");
                    }
                }
            }
        }
    }
}

fn ch_closed(x: &[DVec3], closed: bool) -> Vec<f64> {
    crate::frames::validate::chords(x, closed, "points", &cancel::never).unwrap()
}

#[test]
fn exact_reversals_get_a_tangent_normal_to_the_chord() {
    // three points: the circle rule's estimate vanishes at the reversal
    let x = [DVec3::ZERO, DVec3::X, DVec3::ZERO];
    let t = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePointBounded,
        "points",
        &cancel::never,
    )
    .unwrap();
    assert_eq!(t[1].dot(DVec3::X), 0.0);
    assert!((t[1].length() - 1.0).abs() < 1e-15);
    assert!(t[0].dot(DVec3::X) > 0.7 && t[2].dot(DVec3::X) < -0.7);
    // a symmetric reversal inside a longer curve: the five-point estimate vanishes too;
    // normal to the chord, as the bisectors of near reversals are (in their plane: the
    // collinear exact one has no side to lean to)
    let y = |e: f64| {
        let x = [
            DVec3::new(-2.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.5, 0.0),
            DVec3::ZERO,
            DVec3::new(-1.0, 0.5 + e, 0.0),
            DVec3::new(-2.0, 1.0 + e, 0.0),
        ];
        estimate(
            &x,
            &ch(&x),
            false,
            TangentRule::FivePointBounded,
            "points",
            &cancel::never,
        )
        .unwrap()[2]
    };
    let (exact, near) = (y(0.0), y(1e-9));
    assert!(
        exact.dot(DVec3::new(-1.0, 0.5, 0.0)).abs() < 1e-15,
        "{exact}"
    );
    assert!((exact.length() - 1.0).abs() < 1e-15);
    // (the bisector of chords 1e-9 from opposite carries their rounding, ε/1e-9 ≈ 1e-7)
    assert!(near.dot(DVec3::new(-1.0, 0.5, 0.0)).abs() < 1e-6, "{near}");
    assert!(near.z == 0.0 && near.y > 0.0, "{near}");
    // two reversals in a row leave a segment with no forward tangent: refused
    let x = [DVec3::ZERO, DVec3::X, DVec3::ZERO, DVec3::X];
    let t = estimate(
        &x,
        &ch(&x),
        false,
        TangentRule::FivePoint,
        "points",
        &cancel::never,
    )
    .unwrap();
    let c = x[2] - x[1];
    assert!(c.dot(t[1] + t[2]) <= 1e-6);
}
