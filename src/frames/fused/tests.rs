//! Unit tests of the fused frames: the bits of the general path on smooth curves, jagged
//! walks, given tangents and AVX2 builds, the chunked scan, and what it declines.

use super::super::{Orientation, compute_general};
use super::*;
use crate::run::cancel;

fn both(req: &Request) -> (Vec<f64>, Vec<f64>, f64, f64) {
    let n = req.points.map_or(0, <[DVec3]>::len);
    let (mut a, mut b) = (vec![0.0; 9 * n], vec![0.0; 9 * n]);
    let fa = try_open_points(req, &mut a, &crate::run::cancel::never).expect("fast path taken");
    let fb = compute_general(req, &mut b, &cancel::never).expect("valid input");
    (a, b, fa, fb)
}

/// The same values, bit for bit.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits())
}

/// A curve with uneven spacing, a straight start (the default initial vector is found
/// past the serial search) and a bend.
fn curve(n: usize, straight: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let u = i as f64 + 0.3 * (i as f64 * 0.7).sin();
            if i < straight {
                DVec3::new(u, 0.0, 0.0)
            } else {
                let v = (u - straight as f64) * 0.01;
                DVec3::new(
                    straight as f64 + v.sin() * 100.0,
                    100.0 * (1.0 - v.cos()),
                    v * v,
                )
            }
        })
        .collect()
}

#[test]
fn fused_equals_general_bit_for_bit() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| {
        for (n, straight) in [(5, 0), (6, 0), (1100, 0), (3000, 600), (70_001, 10)] {
            let x = curve(n, straight);
            for (initial, end, method) in [
                (None, None, Method::DoubleReflection),
                (None, None, Method::Rotation),
                (
                    Some(Orientation::Vector(DVec3::new(0.0, 0.3, 1.0))),
                    None,
                    Method::DoubleReflection,
                ),
                (
                    None,
                    Some(Orientation::Vector(DVec3::new(0.2, 1.0, 0.5))),
                    Method::DoubleReflection,
                ),
                (
                    None,
                    Some(Orientation::Vector(DVec3::new(0.2, 1.0, 0.5))),
                    Method::Rotation,
                ),
            ] {
                let req = Request {
                    points: Some(&x),
                    initial,
                    end,
                    turns: 1.0,
                    method,
                    ..Default::default()
                };
                let (a, b, fa, fb) = both(&req);
                assert_eq!(fa.to_bits(), fb.to_bits(), "n {n}");
                assert!(
                    same_bits(&a, &b),
                    "n {n}, initial {initial:?}, end {end:?}, {method:?}"
                );
            }
        }
        // a straight line: no bend anywhere
        let x: Vec<DVec3> = (0..2000)
            .map(|i| DVec3::new(1.0, 2.0, 3.0) * i as f64)
            .collect();
        let (a, b, _, _) = both(&Request {
            points: Some(&x),
            ..Default::default()
        });
        assert_eq!(a, b);
    });
}

/// Jagged random walks, whose estimated tangents the chord guard turns at many rows:
/// the fused path takes them and gives the general path's bits.
#[test]
fn fused_equals_general_on_jagged_walks() {
    let mut s = 5u64;
    let mut r = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    for n in [5, 6, 9, 40, 1100, 5000] {
        let mut x = vec![DVec3::ZERO];
        for _ in 1..n {
            let d = DVec3::new(r() + r(), r() + r(), r() + r());
            x.push(*x.last().unwrap() + d);
        }
        for method in [Method::DoubleReflection, Method::Rotation] {
            let req = Request {
                points: Some(&x),
                method,
                ..Default::default()
            };
            let (a, b, fa, fb) = both(&req);
            assert_eq!(fa.to_bits(), fb.to_bits(), "n {n}");
            assert!(same_bits(&a, &b), "n {n}, {method:?}");
        }
    }
}

/// The scan with many chunks on two threads: the same frames as one serial pass (to
/// rounding), the same bits on every run, and a failed check in any chunk (also the
/// first or last row of one) reported by the general path without hanging the others.
#[test]
fn chunked_scan_matches_serial_and_refuses_late_failures() {
    let n = 5 * super::super::transport::SCAN_CHUNK + 123;
    let x = curve(n, 10);
    let req = Request {
        points: Some(&x),
        ..Default::default()
    };
    let run = |threads: usize, req: &Request| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut out = vec![0.0; 9 * n];
        let got = pool.install(|| try_open_points(req, &mut out, &crate::run::cancel::never));
        (got, out)
    };
    let (serial, one) = run(1, &req);
    let (chunked, two) = run(2, &req);
    assert!(serial.is_some() && chunked.is_some());
    let worst = one
        .iter()
        .zip(&two)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "chunked scan differs from the serial one by {worst}"
    );
    for _ in 0..3 {
        let (_, again) = run(2, &req);
        assert!(same_bits(&again, &two));
    }
    let cs = super::super::transport::SCAN_CHUNK;
    for row in [cs - 1, cs, 3 * cs + 7, n - 1] {
        let mut y = x.clone();
        y[row].z = f64::NAN;
        let bad = Request {
            points: Some(&y),
            ..Default::default()
        };
        assert!(run(2, &bad).0.is_none(), "NaN at row {row}");
        let mut out = vec![0.0; 9 * n];
        let err = super::super::compute_into(&bad, &mut out, &cancel::never).unwrap_err();
        assert!(err.to_string().contains("points"), "{err}");
    }
}

/// Given tangents (of any length, slightly off the curve's): the fused path again gives
/// the bits of the general one, and declines what the general path refuses.
#[test]
fn fused_given_tangents_equal_general_bit_for_bit() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| {
        for n in [5, 7, 1100, 70_001] {
            let x = curve(n, 10);
            let t: Vec<DVec3> = (0..n)
                .map(|i| {
                    let d = x[(i + 1).min(n - 1)] - x[i.saturating_sub(1)];
                    d * (1.0 + 0.3 * (i as f64).sin()) + DVec3::splat(1e-3 * (i as f64).cos())
                })
                .collect();
            for method in [Method::DoubleReflection, Method::Rotation] {
                for end in [None, Some(Orientation::Vector(DVec3::new(0.2, 1.0, 0.5)))] {
                    let req = Request {
                        points: Some(&x),
                        tangents: Some(&t),
                        end,
                        method,
                        ..Default::default()
                    };
                    let (a, b, fa, fb) = both(&req);
                    assert_eq!(fa.to_bits(), fb.to_bits(), "n {n}");
                    assert!(same_bits(&a, &b), "n {n}, end {end:?}, {method:?}");
                }
            }
            let mut out = vec![0.0; 9 * n];
            for (row, bad) in [
                (n / 2, DVec3::ZERO),
                (n - 1, DVec3::new(f64::NAN, 0.0, 0.0)),
                (0, DVec3::new(f64::INFINITY, 1.0, 0.0)),
                (n / 3, -t[n / 3]),
            ] {
                let mut u = t.clone();
                u[row] = bad;
                let req = Request {
                    points: Some(&x),
                    tangents: Some(&u),
                    ..Default::default()
                };
                assert!(
                    try_open_points(&req, &mut out, &crate::run::cancel::never).is_none(),
                    "{bad} at {row}"
                );
                assert!(
                    compute_general(&req, &mut out, &cancel::never).is_err(),
                    "{bad} at {row}"
                );
            }
            // a NaN point with good tangents: only the chords next to it see it
            for row in [0, n / 2, n - 1] {
                let mut y = x.clone();
                y[row].y = f64::NAN;
                let req = Request {
                    points: Some(&y),
                    tangents: Some(&t),
                    ..Default::default()
                };
                assert!(
                    try_open_points(&req, &mut out, &crate::run::cancel::never).is_none(),
                    "NaN point at {row}"
                );
                assert!(
                    compute_general(&req, &mut out, &cancel::never).is_err(),
                    "NaN point at {row}"
                );
            }
        }
    });
}

/// The run-time choice of the AVX2 build changes no bit (on a processor without AVX2
/// both calls run the same code).
#[test]
fn avx2_build_equals_baseline_build() {
    let n = 3 * BLOCK + 77;
    let x = curve(n, 300);
    let t: Vec<DVec3> = (0..n)
        .map(|i| x[(i + 1).min(n - 1)] - x[i.saturating_sub(1)])
        .collect();
    for (given, rotation) in [(None, false), (Some(&t[..]), false), (None, true)] {
        let (mut p, mut q) = (vec![0.0; 9 * n], vec![0.0; 9 * n]);
        let start = Some(any_perpendicular(t[0].normalize()));
        let job = Job {
            x: &x,
            given,
            rotation,
            apart: 1e-300,
            a: 0,
            b: n,
            start,
        };
        let (a, b) = (chunk(job, &mut p), chunk_body(job, &mut q));
        assert!(a.is_some() && b.is_some());
        assert!(same_bits(&p, &q));
    }
}

/// A closed curve of exactly two chunks: its closing frame forms a third chunk with no
/// row to write. Two threads give the frames and closing angle of one thread, and the
/// frames meet across the seam.
#[test]
fn closed_curve_with_an_empty_last_chunk() {
    use super::super::transport::SCAN_CHUNK;
    let n = 2 * SCAN_CHUNK;
    let x: Vec<DVec3> = (0..n)
        .map(|i| {
            let u = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 2.0 + (3.0 * u).cos();
            DVec3::new(r * (2.0 * u).cos(), r * (2.0 * u).sin(), (3.0 * u).sin())
        })
        .collect();
    let req = Request {
        points: Some(&x),
        closed: true,
        ..Default::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut out = vec![0.0; 9 * n];
        let angle = pool.install(|| super::super::compute_into(&req, &mut out, &cancel::never));
        (angle.expect("valid closed curve"), out)
    };
    let (a1, f1) = run(1);
    let (a2, f2) = run(2);
    assert!((a1 - a2).abs() < 1e-12, "closing angle {a1} vs {a2}");
    let worst = f1
        .iter()
        .zip(&f2)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "two threads differ by {worst}");
    // across the closing segment the last frame, transported, meets the first one
    // turned back by that segment's share of the closing twist: α·h/L
    let t = |i: usize| DVec3::new(f2[9 * i + 2], f2[9 * i + 5], f2[9 * i + 8]);
    let r = |i: usize| DVec3::new(f2[9 * i], f2[9 * i + 3], f2[9 * i + 6]);
    let back = dr_step(x[0] - x[n - 1], t(n - 1), t(0), r(n - 1));
    let length: f64 = (0..n).map(|i| (x[(i + 1) % n] - x[i]).length()).sum();
    let share = a2 * (x[0] - x[n - 1]).length() / length;
    let gap = signed_angle(back, r(0), t(0));
    assert!(share.abs() > 1e-6, "the test needs a closing twist");
    assert!((gap - share).abs() < 1e-9, "seam: {gap} against {share}");
}

#[test]
fn fused_declines_what_it_does_not_check() {
    let mut x = curve(3000, 0);
    let mut out = vec![0.0; 9 * x.len()];
    fn req(x: &[DVec3]) -> Request<'_> {
        Request {
            points: Some(x),
            ..Default::default()
        }
    }
    assert!(try_open_points(&req(&x), &mut out, &crate::run::cancel::never).is_some());
    x[1500] = x[1499]; // a repeated point
    assert!(try_open_points(&req(&x), &mut out, &crate::run::cancel::never).is_none());
    x[1500] = DVec3::new(f64::NAN, 0.0, 0.0);
    assert!(try_open_points(&req(&x), &mut out, &crate::run::cancel::never).is_none());
    for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        for row in [0, 1, 2, 1500, 2997, 2998, 2999] {
            let mut y = curve(3000, 0);
            y[row].y = bad;
            assert!(
                try_open_points(&req(&y), &mut out, &crate::run::cancel::never).is_none(),
                "{bad} at {row}"
            );
        }
    }
    x[1500] = x[1498]; // an exact reversal: framed, by both paths alike
    let (a, b, _, _) = both(&req(&x));
    assert!(same_bits(&a, &b));
    let x = curve(3000, 0);
    let bad = Request {
        points: Some(&x),
        initial: Some(Orientation::Vector(DVec3::ZERO)), // no normal-plane component
        ..Default::default()
    };
    assert!(try_open_points(&bad, &mut out, &crate::run::cancel::never).is_none());
    assert!(super::super::compute_into(&bad, &mut out, &cancel::never).is_err());
    let closed = Request {
        points: Some(&x),
        closed: true,
        ..Default::default()
    };
    assert!(try_open_points(&closed, &mut out, &crate::run::cancel::never).is_none());
}
