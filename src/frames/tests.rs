//! Tests of the driver against closed forms (helices, circles), the method orders, the
//! boundary conditions, bundles and the input errors.

use super::*;
use crate::run::cancel;
use std::f64::consts::{PI, TAU};

use glam::{DMat3, DVec3};

use super::double_reflection::DoubleReflection;
use super::geometry::signed_angle;
use super::transport::Step;
use crate::error::Result;

/// Column `k` (0: r, 1: s, 2: t) of frame `i` of a row-major frames buffer.
fn col(out: &[f64], i: usize, k: usize) -> DVec3 {
    DVec3::new(out[9 * i + k], out[9 * i + 3 + k], out[9 * i + 6 + k])
}

/// An angle brought into `[−π, π)`.
fn wrap(a: f64) -> f64 {
    (a + PI).rem_euclid(TAU) - PI
}

fn frames(req: &Request) -> Result<(Vec<f64>, f64)> {
    let rows = req.points.or(req.tangents).map_or(0, <[DVec3]>::len);
    let mut out = vec![0.0; 9 * rows];
    let angle = compute_into(req, &mut out, &cancel::never)?;
    Ok((out, angle))
}

/// Every frame orthonormal and right-handed (`s = t × r`) to `tol`.
fn assert_rotations(out: &[f64], tol: f64) {
    for i in 0..out.len() / 9 {
        let (r, s, t) = (col(out, i, 0), col(out, i, 1), col(out, i, 2));
        let worst = [
            r.length() - 1.0,
            s.length() - 1.0,
            t.length() - 1.0,
            r.dot(s),
            r.dot(t),
            s.dot(t),
            r.cross(s).dot(t) - 1.0,
            (t.cross(r) - s).length(),
        ]
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()));
        assert!(worst < tol, "frame {i} is off a rotation by {worst:e}");
    }
}

/// The helix `x(u) = (a cos u, a sin u, b u)`: speed `c = √(a² + b²)`, torsion `b/c²`,
/// principal normal `N = (−cos u, −sin u, 0)`.
struct Helix {
    a: f64,
    b: f64,
}

impl Helix {
    fn x(&self, u: f64) -> DVec3 {
        DVec3::new(self.a * u.cos(), self.a * u.sin(), self.b * u)
    }
    fn d1(&self, u: f64) -> DVec3 {
        DVec3::new(-self.a * u.sin(), self.a * u.cos(), self.b)
    }
    fn d2(&self, u: f64) -> DVec3 {
        DVec3::new(-self.a * u.cos(), -self.a * u.sin(), 0.0)
    }
    fn normal(&self, u: f64) -> DVec3 {
        DVec3::new(-u.cos(), -u.sin(), 0.0)
    }
    /// Rate `dθ/du` of the RMF against the Frenet frame. With `r = cos θ N + sin θ B`
    /// and the Frenet–Serret formulas, `r′ = −sin θ (θ′ + τ) N + cos θ (θ′ + τ) B − κ cos θ T`
    /// (per arc length), which is along `T` (rotation minimising) iff `θ′ = −τ`; per unit
    /// of `u` that is `−τ c = −b/c`.
    fn rate(&self) -> f64 {
        -self.b / self.a.hypot(self.b)
    }
}

/// The largest error of the frames of `n` helix samples over two turns: of the angle
/// between `r` and the principal normal against the closed form, and of `t` against the
/// unit tangent. `given`: exact tangents are passed; `analytic`: exact derivatives.
fn helix_errors(method: Method, given: bool, analytic: bool, n: usize) -> (f64, f64) {
    let h = Helix { a: 1.0, b: 0.5 };
    let span = 4.0 * PI;
    let u: Vec<f64> = (0..n).map(|i| span * i as f64 / (n - 1) as f64).collect();
    let half: Vec<f64> = (0..2 * n - 1)
        .map(|i| span * i as f64 / (2 * n - 2) as f64)
        .collect();
    let x: Vec<DVec3> = u.iter().map(|&u| h.x(u)).collect();
    let t: Vec<DVec3> = u.iter().map(|&u| h.d1(u)).collect();
    let d1: Vec<DVec3> = half.iter().map(|&u| h.d1(u)).collect();
    let d2: Vec<DVec3> = half.iter().map(|&u| h.d2(u)).collect();
    let req = Request {
        points: Some(&x),
        tangents: given.then_some(&t[..]),
        analytic: analytic.then_some(Analytic {
            u: &u,
            d1: &d1,
            d2: &d2,
            d3: &[],
        }),
        method,
        ..Default::default()
    };
    let (out, _) = frames(&req).expect("a regular helix");
    assert_rotations(&out, 1e-12);
    let theta = |i: usize| signed_angle(h.normal(u[i]), col(&out, i, 0), col(&out, i, 2));
    let theta0 = theta(0);
    let (mut angle, mut tangent) = (0.0_f64, 0.0_f64);
    for i in 0..n {
        let want = theta0 + h.rate() * u[i];
        angle = angle.max(wrap(theta(i) - want).abs());
        tangent = tangent.max((col(&out, i, 2) - t[i].normalize()).length());
    }
    (angle, tangent)
}

/// The RMF of a helix turns against its Frenet frame at the constant rate `−b/c` per
/// unit of `u`; every method approaches it at its order (the error falls by about `2^p`
/// when the spacing halves).
#[test]
fn helix_rmf_matches_the_closed_form_at_the_method_order() {
    for (method, given, analytic, order, n) in [
        (Method::DoubleReflection, true, false, 4, 40),
        (Method::DoubleReflection, false, false, 4, 40),
        (Method::Rotation, true, false, 2, 40),
        (Method::Rotation, false, false, 2, 40),
        (Method::Projection, true, false, 2, 40),
        (Method::Rk4, false, true, 4, 40),
        (Method::Rk4Phi, false, true, 4, 40),
    ] {
        let (e1, t1) = helix_errors(method, given, analytic, n);
        let (e2, t2) = helix_errors(method, given, analytic, 2 * n - 1);
        let (e3, _) = helix_errors(method, given, analytic, 4 * n - 3);
        let what = format!("{method:?}, given {given}: errors {e1:e} {e2:e} {e3:e}");
        // halving the spacing divides the error by 2^p (a margin of half an order)
        let least = 2f64.powf(order as f64 - 0.5);
        assert!(e1 < 0.1 && e1 / e2 > least && e2 / e3 > least, "{what}");
        if given || analytic {
            assert!(t1 < 1e-15 && t2 < 1e-15, "{what}: t is the unit tangent");
        } else {
            // five-point tangents: 4th order
            assert!(
                t1 / t2 > 2f64.powf(3.5),
                "{what}: tangent errors {t1:e} {t2:e}"
            );
        }
    }
}

/// The Frenet method's `r` is the principal normal, to the order of the circle through
/// three samples it is estimated from: 2 for the centred circle inside, 1 at the ends.
#[test]
fn frenet_frame_follows_the_principal_normal() {
    let h = Helix { a: 1.0, b: 0.5 };
    let err = |n: usize| {
        let u: Vec<f64> = (0..n)
            .map(|i| 4.0 * PI * i as f64 / (n - 1) as f64)
            .collect();
        let x: Vec<DVec3> = u.iter().map(|&u| h.x(u)).collect();
        let (out, _) = frames(&Request {
            points: Some(&x),
            method: Method::Frenet,
            ..Default::default()
        })
        .expect("a regular helix");
        assert_rotations(&out, 1e-12);
        let at = |i: usize| (col(&out, i, 0) - h.normal(u[i])).length();
        let inside = (1..n - 1).map(at).fold(0.0, f64::max);
        (inside, at(0).max(at(n - 1)))
    };
    let ((e1, f1), (e2, f2)) = (err(100), err(199));
    assert!(
        e1 < 0.01 && e1 / e2 > 2f64.powf(1.5),
        "inside: {e1:e} {e2:e}"
    );
    assert!(f1 < 0.1 && f1 / f2 > 2f64.powf(0.5), "ends: {f1:e} {f2:e}");
}

/// An uneven, non-planar open curve.
fn wiggle(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let u = 0.05 * (i as f64 + 0.3 * (1.7 * i as f64).sin());
            DVec3::new(
                3.0 * u.cos(),
                2.0 * u.sin(),
                0.4 * u + 0.2 * (3.0 * u).sin(),
            )
        })
        .collect()
}

/// A trefoil knot sampled unevenly (no repeated end point).
fn trefoil(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let u = TAU * (i as f64 + 0.2 * (3.0 * TAU * i as f64 / n as f64).sin()) / n as f64;
            let r = 2.0 + (3.0 * u).cos();
            DVec3::new(r * (2.0 * u).cos(), r * (2.0 * u).sin(), (3.0 * u).sin())
        })
        .collect()
}

/// All methods, with and without given tangents: rotations whose `t` is the unit tangent.
#[test]
fn frames_are_rotations_with_t_the_unit_tangent() {
    let x = wiggle(300);
    let t: Vec<DVec3> = (0..x.len())
        .map(|i| {
            let u = 0.05 * (i as f64 + 0.3 * (1.7 * i as f64).sin());
            DVec3::new(-3.0 * u.sin(), 2.0 * u.cos(), 0.4 + 0.6 * (3.0 * u).cos()) * 7.0
        })
        .collect();
    for method in [
        Method::DoubleReflection,
        Method::Rotation,
        Method::Projection,
        Method::Frenet,
    ] {
        for (closed, x) in [(false, x.clone()), (true, trefoil(257))] {
            let (out, _) = frames(&Request {
                points: Some(&x),
                method,
                closed,
                ..Default::default()
            })
            .expect("valid curve");
            assert_rotations(&out, 1e-12);
            let est =
                tangents::estimate_rows(&x, closed, TangentRule::FivePointBounded, &cancel::never)
                    .expect("regular curve");
            for (i, e) in est.iter().enumerate() {
                assert!(
                    (col(&out, i, 2) - *e).length() < 1e-15,
                    "{method:?} row {i}"
                );
            }
        }
        let (out, _) = frames(&Request {
            points: Some(&x),
            tangents: Some(&t),
            method,
            ..Default::default()
        })
        .expect("valid curve");
        assert_rotations(&out, 1e-12);
        for (i, ti) in t.iter().enumerate() {
            assert!((col(&out, i, 2) - ti.normalize()).length() < 1e-15);
        }
    }
}

/// Carry frame `i`'s `r` one step and measure the angle to frame `i + 1`'s (mod n).
fn step_angles<S: Step>(step: &S, out: &[f64], n: usize, closed: bool) -> Vec<f64> {
    let m = if closed { n } else { n - 1 };
    (0..m)
        .map(|i| {
            let j = (i + 1) % n;
            let carried = step.step(i, col(out, i, 0));
            signed_angle(carried, col(out, j, 0), col(out, j, 2))
        })
        .collect()
}

/// A closed curve's frames meet at the seam: the frames turn away from the transported
/// ones by the closing twist spread linearly in arc length, and after the closing
/// segment they are back at frame 0; a repeated end point gets frame 0's copy.
#[test]
fn closed_curve_frames_meet_at_the_seam() {
    let n = 400;
    let x = trefoil(n);
    let h: Vec<f64> = (0..n).map(|i| (x[(i + 1) % n] - x[i]).length()).collect();
    let length: f64 = h.iter().sum();
    for method in [Method::DoubleReflection, Method::Rotation] {
        for turns in [0.0, 1.0, -2.0] {
            let (out, raw) = frames(&Request {
                points: Some(&x),
                closed: true,
                method,
                turns,
                ..Default::default()
            })
            .expect("a closed curve");
            assert!(raw.abs() <= PI && raw.abs() > 1e-3, "{raw}");
            let t: Vec<DVec3> = (0..n).map(|i| col(&out, i, 2)).collect();
            let angles = if method == Method::Rotation {
                step_angles(&rotation::Rotation { t: &t }, &out, n, true)
            } else {
                let dr = DoubleReflection {
                    x: &x,
                    t: &t,
                    closed: true,
                    tangent_chords: false,
                };
                step_angles(&dr, &out, n, true)
            };
            let total = raw + TAU * turns;
            for (i, a) in angles.iter().enumerate() {
                let want = wrap(total * h[i] / length);
                assert!(
                    (a - want).abs() < 1e-10,
                    "{method:?} step {i}: {a} vs {want}"
                );
            }
            // with the repeated end point: the same frames and a copy of frame 0
            let mut y = x.clone();
            y.push(x[0]);
            let (again, raw2) = frames(&Request {
                points: Some(&y),
                closed: true,
                method,
                turns,
                ..Default::default()
            })
            .expect("a closed curve");
            assert_eq!(raw.to_bits(), raw2.to_bits());
            assert_eq!(&again[..9 * n], &out[..]);
            assert_eq!(&again[9 * n..], &out[..9]);
        }
    }
    // a plane curve closes without a twist (double reflection is exact on planes)
    let circle: Vec<DVec3> = (0..50)
        .map(|i| {
            let u = TAU * (i as f64 + 0.3 * (i as f64).sin()) / 50.0;
            DVec3::new(u.cos(), u.sin(), 0.0)
        })
        .collect();
    let (_, raw) = frames(&Request {
        points: Some(&circle),
        closed: true,
        ..Default::default()
    })
    .expect("a circle");
    assert!(raw.abs() < 1e-12, "closing angle of a circle: {raw}");
}

/// With `initial` and `end` the first and last `r` are the given vectors projected onto
/// the normal planes, and the twist in between is linear in arc length.
#[test]
fn open_curve_meets_initial_and_end() {
    let x = wiggle(200);
    let n = x.len();
    let h: Vec<f64> = (0..n - 1).map(|i| (x[i + 1] - x[i]).length()).collect();
    let length: f64 = h.iter().sum();
    let (v0, v1) = (DVec3::new(0.3, -1.0, 2.0), DVec3::new(1.0, 0.5, -0.2));
    for turns in [0.0, 3.0] {
        let (out, raw) = frames(&Request {
            points: Some(&x),
            initial: Some(Orientation::Vector(v0)),
            end: Some(Orientation::Vector(v1)),
            turns,
            ..Default::default()
        })
        .expect("valid curve");
        let proj = |v: DVec3, t: DVec3| (v - v.dot(t) * t).normalize();
        assert!((col(&out, 0, 0) - proj(v0, col(&out, 0, 2))).length() < 1e-15);
        assert!((col(&out, n - 1, 0) - proj(v1, col(&out, n - 1, 2))).length() < 1e-12);
        let t: Vec<DVec3> = (0..n).map(|i| col(&out, i, 2)).collect();
        let dr = DoubleReflection {
            x: &x,
            t: &t,
            closed: false,
            tangent_chords: false,
        };
        let total = raw + TAU * turns;
        for (i, a) in step_angles(&dr, &out, n, false).iter().enumerate() {
            assert!((a - wrap(total * h[i] / length)).abs() < 1e-10, "step {i}");
        }
    }
}

/// A bundle gives, bit for bit, the frames and angles of its curves computed one by one
/// (also a curve long enough for the chunked scan, on two threads).
#[test]
fn compute_many_equals_each_curve_alone() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool");
    pool.install(|| {
        let lengths = [5, 2, 300, 2 * transport::PAR_CHUNK + 11, 7];
        let mut offsets = vec![0];
        for l in lengths {
            offsets.push(offsets[offsets.len() - 1] + l);
        }
        let x = wiggle(offsets[lengths.len()]);
        let initial: Vec<Orientation> = (0..lengths.len())
            .map(|c| Orientation::Vector(DVec3::new(1.0, c as f64, 0.5)))
            .collect();
        let end = [Orientation::Vector(DVec3::new(0.2, 0.1, 1.0))];
        for method in [Method::DoubleReflection, Method::Rotation] {
            let template = Request {
                points: Some(&x),
                method,
                turns: 1.0,
                ..Default::default()
            };
            let mut all = vec![0.0; 9 * x.len()];
            let angles = compute_many(
                &template,
                &offsets,
                &initial,
                &end,
                &mut all,
                &cancel::never,
                None,
            )
            .expect("valid bundle");
            for (c, w) in offsets.windows(2).enumerate() {
                let one = Request {
                    points: Some(&x[w[0]..w[1]]),
                    initial: Some(initial[c]),
                    end: Some(end[0]),
                    ..template
                };
                let (out, angle) = frames(&one).expect("valid curve");
                assert_eq!(angle.to_bits(), angles[c].to_bits(), "curve {c}");
                assert!(
                    out.iter()
                        .zip(&all[9 * w[0]..9 * w[1]])
                        .all(|(p, q)| p.to_bits() == q.to_bits()),
                    "{method:?}, curve {c}"
                );
            }
        }
        // an error names the argument and the curve
        let mut y = x.clone();
        y[offsets[2] + 17].y = f64::NAN;
        let template = Request {
            points: Some(&y),
            ..Default::default()
        };
        let mut all = vec![0.0; 9 * y.len()];
        let err = compute_many(
            &template,
            &offsets,
            &[],
            &[],
            &mut all,
            &cancel::never,
            None,
        )
        .unwrap_err();
        assert_eq!(err.arg, "points");
        let rows = format!("curve 2 (rows {} to {})", offsets[2], offsets[3] - 1);
        assert!(err.msg.starts_with(&rows), "{err}");
        assert!(err.msg.contains("row 17"), "{err}");
    });
}

/// Every refusal names the argument at fault.
#[test]
fn errors_name_the_argument() {
    let x = wiggle(30);
    let t: Vec<DVec3> = (0..30)
        .map(|i| x[(i + 1).min(29)] - x[i.saturating_sub(1)])
        .collect();
    let (u, d): (Vec<f64>, Vec<DVec3>) = ((0..30).map(f64::from).collect(), vec![DVec3::X; 59]);
    let analytic = Analytic {
        u: &u,
        d1: &d,
        d2: &d,
        d3: &[],
    };
    let mut nan = x.clone();
    nan[4].z = f64::NAN;
    let mut tnan = t.clone();
    tnan[3].x = f64::INFINITY;
    let mut zero_t = t.clone();
    zero_t[5] = DVec3::ZERO;
    let mut repeated = x.clone();
    repeated[7] = repeated[6];
    let mut reversed = x.clone();
    reversed.swap(10, 11);
    let mut u_back = u.clone();
    u_back[3] = 1.0;
    let mut d_zero = d.clone();
    d_zero[6] = DVec3::ZERO;
    let line: Vec<DVec3> = (0..30).map(|i| DVec3::X * f64::from(i)).collect();
    let two_distinct = [x[0], x[1], x[0]];
    let skew = DMat3::from_cols(DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::Z);
    let base = Request {
        points: Some(&x),
        ..Default::default()
    };
    let cases: Vec<(&str, Request, usize)> = vec![
        (
            "points",
            Request {
                points: None,
                ..base
            },
            30,
        ),
        (
            "tangents",
            Request {
                tangents: Some(&t[..20]),
                ..base
            },
            30,
        ),
        (
            "points",
            Request {
                points: Some(&x[..1]),
                ..base
            },
            1,
        ),
        (
            "tangents",
            Request {
                points: None,
                tangents: Some(&t[..1]),
                tangent_chords: true,
                ..base
            },
            1,
        ),
        ("out", base, 29),
        (
            "points",
            Request {
                points: Some(&nan),
                ..base
            },
            30,
        ),
        (
            "tangents",
            Request {
                tangents: Some(&tnan),
                ..base
            },
            30,
        ),
        (
            "tangents",
            Request {
                tangents: Some(&zero_t),
                ..base
            },
            30,
        ),
        (
            "points",
            Request {
                points: Some(&repeated),
                ..base
            },
            30,
        ),
        (
            "points",
            Request {
                // given tangents that run against a segment (estimated ones never do: the
                // zig-zag of two swapped samples is a valid polyline, tested below)
                points: Some(&reversed),
                tangents: Some(&t),
                ..base
            },
            30,
        ),
        (
            "method",
            Request {
                method: Method::Rk4,
                ..base
            },
            30,
        ),
        (
            "reflection",
            Request {
                tangent_chords: true,
                method: Method::Rotation,
                ..base
            },
            30,
        ),
        (
            "points",
            Request {
                points: None,
                tangents: Some(&t),
                ..base
            },
            30,
        ),
        (
            "end",
            Request {
                closed: true,
                end: Some(Orientation::Vector(DVec3::Z)),
                ..base
            },
            30,
        ),
        (
            "points",
            Request {
                points: Some(&two_distinct),
                closed: true,
                ..base
            },
            3,
        ),
        (
            "initial",
            Request {
                initial: Some(Orientation::Vector(DVec3::ZERO)),
                ..base
            },
            30,
        ),
        (
            "initial",
            Request {
                initial: Some(Orientation::Frame(skew)),
                ..base
            },
            30,
        ),
        (
            "initial",
            Request {
                initial: Some(Orientation::Frame(DMat3::IDENTITY)),
                points: Some(&line),
                ..base
            },
            30,
        ),
        (
            "end",
            Request {
                end: Some(Orientation::Vector(DVec3::new(f64::NAN, 0.0, 0.0))),
                ..base
            },
            30,
        ),
        (
            "end",
            Request {
                points: Some(&line),
                end: Some(Orientation::Vector(DVec3::X)),
                ..base
            },
            30,
        ),
        (
            "initial",
            Request {
                method: Method::Frenet,
                initial: Some(Orientation::Vector(DVec3::Z)),
                ..base
            },
            30,
        ),
        (
            "turns",
            Request {
                method: Method::Frenet,
                turns: 1.0,
                ..base
            },
            30,
        ),
        (
            "u",
            Request {
                analytic: Some(Analytic {
                    u: &u[..29],
                    ..analytic
                }),
                ..base
            },
            30,
        ),
        (
            "u",
            Request {
                analytic: Some(Analytic {
                    u: &u_back,
                    ..analytic
                }),
                ..base
            },
            30,
        ),
        (
            "u",
            Request {
                points: Some(&line),
                analytic: Some(analytic),
                closed: true,
                ..base
            },
            30,
        ),
        (
            "points",
            Request {
                points: Some(&line),
                analytic: Some(Analytic {
                    d1: &d_zero,
                    ..analytic
                }),
                ..base
            },
            30,
        ),
        (
            "tangents",
            Request {
                points: None,
                tangents: Some(&t[..3]),
                tangent_chords: true,
                ..base
            },
            3,
        ),
    ];
    for (k, (arg, req, rows)) in cases.iter().enumerate() {
        let mut out = vec![0.0; 9 * rows];
        match compute_into(req, &mut out, &cancel::never) {
            Err(e) => assert_eq!(&e.arg, arg, "case {k}: {e}"),
            Ok(_) => panic!("case {k} ({arg}) was accepted"),
        }
    }
    // two swapped samples with estimated tangents: a zig-zag, framed (every method)
    for method in [
        Method::DoubleReflection,
        Method::Rotation,
        Method::Projection,
    ] {
        let mut out = vec![0.0; 9 * 30];
        let req = Request {
            points: Some(&reversed),
            method,
            ..base
        };
        compute_into(&req, &mut out, &cancel::never).unwrap_or_else(|e| panic!("{method:?}: {e}"));
        assert!(
            out.chunks_exact(9)
                .all(|f| validate::is_rotation(f.try_into().unwrap()))
        );
    }
    let mut out = vec![0.0; 9 * 30];
    let two = [Orientation::Vector(DVec3::Z); 2];
    let err = compute_many(
        &base,
        &[0, 10, 20, 30],
        &two,
        &[],
        &mut out,
        &cancel::never,
        None,
    )
    .unwrap_err();
    assert_eq!(err.arg, "initial");
    let err = compute_many(
        &base,
        &[0, 10, 20, 30],
        &[],
        &two,
        &mut out,
        &cancel::never,
        None,
    )
    .unwrap_err();
    assert_eq!(err.arg, "end");
    let err = compute_many(
        &base,
        &[0, 20, 10, 30],
        &[],
        &[],
        &mut out,
        &cancel::never,
        None,
    )
    .unwrap_err();
    assert_eq!(err.arg, "lengths");
    let err = compute_many(
        &base,
        &[0, 10, 29],
        &[],
        &[],
        &mut out,
        &cancel::never,
        None,
    )
    .unwrap_err();
    assert_eq!(err.arg, "lengths");
}
