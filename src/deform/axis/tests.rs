//! Unit tests of the axis: the grid search against brute force, the clamped spline, the
//! foot-point quintic, the block boxes and the `%.4g` formatting of messages.

use super::*;

/// `n` samples of a circular arc of radius `r` and angle `a`.
pub(in crate::deform) fn arc(n: usize, r: f64, a: f64) -> Vec<AxisSample> {
    (0..n)
        .map(|i| {
            let th = a * i as f64 / (n - 1) as f64;
            AxisSample {
                x: DVec3::new(r * th.cos(), r * th.sin(), 0.0),
                m: DVec3::new(-th.sin(), th.cos(), 0.0),
                s: r * th,
            }
        })
        .collect()
}

/// A brute-force check of [`self_approach`] on a hairpin and on random walks.
#[test]
fn the_grid_search_finds_the_first_pair_of_the_brute_force_search() {
    let brute = |p: &[DVec3], t: &[f64], outer: f64| {
        for i in 0..p.len() {
            for j in 0..p.len() {
                let d = (p[i] - p[j]).length();
                if d < 2.0 * outer && (t[i] - t[j]).abs() > std::f64::consts::PI * outer {
                    return Some((i, j, d));
                }
            }
        }
        None
    };
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for case in 0..40 {
        let n = 50 + 10 * case;
        let mut p = vec![DVec3::ZERO];
        for _ in 1..n {
            let step = DVec3::new(rnd(), rnd(), rnd()) * 0.2 + DVec3::X * 0.05;
            p.push(*p.last().unwrap() + step);
        }
        let t: Vec<f64> = (0..n).map(|i| 0.15 * i as f64).collect();
        for outer in [0.01, 0.05, 0.1, 0.3] {
            assert_eq!(
                self_approach(&p, &t, outer, &cancel::never),
                brute(&p, &t, outer)
            );
        }
    }
    // a hairpin: two straight legs 0.5 apart, joined by a half circle
    let mut p = Vec::new();
    for i in 0..=200 {
        p.push(DVec3::new(i as f64 * 0.01, 0.0, 0.0));
    }
    for i in 1..50 {
        let a = std::f64::consts::PI * i as f64 / 50.0;
        p.push(DVec3::new(2.0 + 0.25 * a.sin(), 0.25 - 0.25 * a.cos(), 0.0));
    }
    for i in 0..=200 {
        p.push(DVec3::new(2.0 - i as f64 * 0.01, 0.5, 0.0));
    }
    let mut t = vec![0.0];
    for w in p.windows(2) {
        t.push(t.last().unwrap() + (w[1] - w[0]).length());
    }
    for outer in [0.2, 0.249, 0.251, 0.3] {
        assert_eq!(
            self_approach(&p, &t, outer, &cancel::never),
            brute(&p, &t, outer)
        );
    }
    assert!(self_approach(&p, &t, 0.249, &cancel::never).is_none());
    assert!(self_approach(&p, &t, 0.251, &cancel::never).is_some());
}

#[test]
fn the_clamped_spline_of_a_cubic_is_the_cubic() {
    // γ(S) = (S, S² − S, S³/4) at uneven parameters, with its own end derivatives
    let g = |t: f64| DVec3::new(t, t * t - t, 0.25 * t * t * t);
    let dg = |t: f64| DVec3::new(1.0, 2.0 * t - 1.0, 0.75 * t * t);
    let s = [0.0, 0.3, 0.5, 1.1, 1.2, 2.0, 2.7];
    let x: Vec<DVec3> = s.iter().map(|&t| g(t)).collect();
    let m = clamped_spline_slopes(&x, &s, dg(0.0), dg(2.7)).unwrap();
    for (mk, &t) in m.iter().zip(&s) {
        assert!((*mk - dg(t)).length() < 1e-13, "{mk} {}", dg(t));
    }
    let two = clamped_spline_slopes(&x[..2], &s[..2], DVec3::X, DVec3::Y).unwrap();
    assert_eq!(two, vec![DVec3::X, DVec3::Y]);
    let three = clamped_spline_slopes(&x[..3], &s[..3], dg(0.0), dg(0.5)).unwrap();
    assert!((three[1] - dg(0.3)).length() < 1e-13);
}

/// The quintic of the foot-point equation is `(X − γ)·γ′` and its derivative
/// `−|γ′|² + (X − γ)·γ″`, evaluated directly.
#[test]
fn the_foot_quintic_is_the_foot_equation() {
    let axis = Axis::new(arc(9, 1.0, 1.5), 0.3, &cancel::never).unwrap();
    for (k, seg) in axis.segs.iter().enumerate() {
        for i in 0..20 {
            let q = (i * 7 + k) as f64 * 0.31;
            let x = seg.centre + 0.4 * DVec3::new(q.sin(), (1.3 * q).cos(), (0.7 * q).sin());
            let a = seg.quintic(x);
            for l in [0.0, 0.2, 0.55, 1.0] {
                let (g, g1, g2) = seg.at(l);
                let f = (x - g).dot(g1);
                let df = (x - g).dot(g2) - g1.length_squared();
                let p = a[0] + l * (a[1] + l * (a[2] + l * (a[3] + l * (a[4] + l * a[5]))));
                let dp =
                    a[1] + l * (2.0 * a[2] + l * (3.0 * a[3] + l * (4.0 * a[4] + l * 5.0 * a[5])));
                assert!((p - f).abs() < 1e-15, "{p} {f}");
                assert!((dp - df).abs() < 1e-15, "{dp} {df}");
            }
        }
    }
}

/// The block boxes only skip blocks that hold no foot: the closest point of a long axis
/// (several blocks) against a dense polyline of it.
#[test]
fn a_box_the_axis_cannot_reach_has_no_foot_at_any_point() {
    let axis = Axis::new(arc(60, 3.0, 4.0), 0.3, &cancel::never).unwrap();
    let (mut missed, mut reached) = (0, 0);
    for i in 0..3000 {
        let q = i as f64 * 0.173;
        let r = 3.0 + 0.7 * (0.3 * q).sin();
        let c = DVec3::new(
            r * (0.7 * q).cos(),
            r * (0.7 * q).sin(),
            0.4 * (1.3 * q).sin(),
        );
        let h = DVec3::new(0.05, 0.08, 0.03) * (1.0 + (2.1 * q).sin());
        let (lo, hi) = (c - h, c + h);
        if axis.may_reach(lo, hi, 0.3) {
            reached += 1;
            continue;
        }
        missed += 1;
        // the corners, the faces' centres and points inside
        for k in 0..64 {
            let t = DVec3::new(
                (k % 4) as f64 / 3.0,
                ((k / 4) % 4) as f64 / 3.0,
                (k / 16) as f64 / 3.0,
            );
            let x = lo + (hi - lo) * t;
            assert!(axis.closest_point(x, 0.3).is_none(), "{x}");
        }
    }
    assert!(missed > 300 && reached > 300, "{missed} {reached}");
}

#[test]
fn block_boxes_keep_every_foot() {
    let axis = Axis::new(arc(60, 3.0, 4.0), 0.3, &cancel::never).unwrap();
    assert!(axis.blocks.len() >= 3);
    let dense: Vec<DVec3> = (0..59 * 400 + 1)
        .map(|i| {
            let (k, l) = (
                (i / 400).min(58),
                (i - 400 * (i / 400).min(58)) as f64 / 400.0,
            );
            axis.segs[k].curve.value(l)
        })
        .collect();
    let mut found = 0;
    for i in 0..4000 {
        let q = i as f64 * 0.173;
        // about the arc and beyond its ends, in and out of reach
        let (a, r) = (-0.3 + 4.6 * i as f64 / 4000.0, 3.0 + 0.4 * (2.7 * q).sin());
        let x = DVec3::new(r * a.cos(), r * a.sin(), 0.25 * (1.9 * q).sin());
        let near = dense
            .iter()
            .map(|p| (x - *p).length())
            .fold(f64::INFINITY, f64::min);
        match axis.closest_point(x, 0.3) {
            Some((_, p)) => {
                found += 1;
                let r = (x - p).length();
                assert!(r <= near + 1e-12 && r > near - 1e-4, "{x} {r} {near}");
            }
            None => assert!(near > 0.3 - 1e-4, "{x} {near}"),
        }
    }
    assert!(found > 1000 && found < 3800, "{found}");
}

#[test]
fn g4_is_four_significant_digits() {
    assert_eq!(g4(0.7614), "0.7614");
    assert_eq!(g4(0.76142), "0.7614");
    assert_eq!(g4(0.8), "0.8");
    assert_eq!(g4(12.0), "12");
    assert_eq!(g4(1234.56), "1235");
    assert_eq!(g4(2.5e-7), "2.500e-7");
}
