//! The other long calls stopped at each of their polls: PH rows, splines and frames,
//! quaternion rows, fields and tools, spine and surface models, mesh measures, frames in
//! time and the tangents of many curves.

use super::*;

#[test]
fn ph_rows_stop_anywhere() {
    use crate::ph::{self, Cubic};
    // a spatial PH cubic (from a quaternion preimage), 200,000 times
    let c = Cubic::from_quaternions([0.3, -1.2, 0.7, 0.4], [-0.5, 0.2, 1.1, -0.9], DVec3::ZERO);
    let cubics = vec![c; 200_000];
    let m = cubics.len();
    let (is_ph, polls) = stop_everywhere(|k| ph::check::is_ph_rows(&cubics, 1e-9, k));
    assert!(
        polls >= m / crate::run::alloc::CANCEL_ITEMS,
        "{polls} polls"
    );
    assert_eq!(is_ph.expect("valid"), vec![true; m]);
    let (inv, polls) = stop_everywhere(|k| ph::check::invariant_rows(&cubics, k));
    assert!(
        polls >= m / crate::run::alloc::CANCEL_ITEMS,
        "{polls} polls"
    );
    assert_eq!(inv.expect("valid").len(), m);
    let (pre, _) = stop_everywhere(|k| ph::preimage_rows(&cubics, 1e-9, true, k));
    let pre = pre.expect("valid");
    assert_eq!(pre.len(), m);
    // and back, from (x, y, z, w) rows and one start for all
    let xyzw = |r: &[f64]| [r[1], r[2], r[3], r[0]];
    let a0: Vec<ph::Quat> = pre.iter().map(|r| xyzw(&r[0..4])).collect();
    let a1: Vec<ph::Quat> = pre.iter().map(|r| xyzw(&r[4..8])).collect();
    let run = |k: Cancel<'_>| {
        let mut out = vec![[0.0; 12]; m];
        ph::from_quaternion_rows_into(&a0, &a1, &[DVec3::ZERO], false, &mut out, k).expect("valid");
        out
    };
    let (back, _) = stop_everywhere(run);
    let want: Vec<f64> = c.b.iter().flat_map(|p| p.to_array()).collect();
    assert!(
        back.iter()
            .all(|r| r.iter().zip(&want).all(|(x, y)| (x - y).abs() < 1e-12))
    );
}

#[test]
fn ph_spline_frames_stop_anywhere() {
    use crate::ph::{Cubic, frame};
    // two joined PH cubics, frames at 500,000 parameters over both
    let a = Cubic::from_quaternions([0.3, -1.2, 0.7, 0.4], [-0.5, 0.2, 1.1, -0.9], DVec3::ZERO);
    let b = Cubic::from_quaternions([-0.5, 0.2, 1.1, -0.9], [0.6, 0.1, -0.8, 0.3], a.b[3]);
    let cubics = [a, b];
    let n = 500_000;
    let s: Vec<f64> = (0..n).map(|i| 2.0 * i as f64 / (n - 1) as f64).collect();
    for mode in [frame::Mode::Exact, frame::Mode::Rational] {
        let run = |k: Cancel<'_>| {
            let (mut f, mut om) = (vec![[0.0; 9]; n], vec![0.0; n]);
            let start = frame::Start::Angle(0.0);
            let r = frame::frames_at(&cubics, &s, start, None, mode, &mut f, &mut om, k);
            unless_stopped(r).map(|()| (f.concat(), om))
        };
        let (got, polls) = stop_everywhere(run);
        let (f, om) = got.expect("not stopped");
        assert!(polls >= n / (1 << 16), "{polls} polls");
        // the uninterrupted call matches the one with `cancel::never`
        let (want_f, want_om) = run(&cancel::never).expect("not stopped");
        assert!(same_bits(&f, &want_f) && same_bits(&om, &want_om));
    }
}

/// A chain of `m` G¹ PH cubics: the Hermite interpolants of a helix.
fn ph_chain(m: usize) -> Vec<crate::ph::Cubic> {
    let at = |u: f64| {
        let (s, c) = u.sin_cos();
        (DVec3::new(c, s, 0.3 * u), DVec3::new(-s, c, 0.3))
    };
    (0..m)
        .map(|i| {
            let ((p0, t0), (p1, t1)) = (at(0.4 * i as f64), at(0.4 * (i + 1) as f64));
            crate::ph::hermite::hermite(p0, t0.normalize(), p1, t1.normalize()).cubics[0]
        })
        .collect()
}

/// The frame set-up of a long spline (the reference vector carried in one pass, the
/// angle fits in parallel) stops anywhere, and its fits are those of each segment fitted
/// on its own.
#[test]
fn ph_spline_setup_stops_anywhere() {
    use crate::ph::frame::{self, Start};
    let cubics = ph_chain(3000);
    let run = |k: Cancel<'_>| unless_stopped(frame::setup(&cubics, Start::Angle(0.2), None, k));
    let (got, polls) = stop_everywhere(run);
    let segs = got.expect("not stopped");
    assert!(polls > 3000 / 16, "{polls} polls");
    assert_eq!(
        segs,
        frame::setup(&cubics, Start::Angle(0.2), None, &cancel::never).expect("valid")
    );
    for (c, seg) in cubics.iter().zip(&segs) {
        let alone = frame::segment(c, seg.omega0, None).expect("bent");
        assert_eq!(alone.fit, seg.fit);
    }
}

/// The PH rows (Hermite interpolation, evaluation) stop anywhere and give the bits of the
/// calls with `cancel::never`.
#[test]
fn ph_hermite_and_evaluation_stop_anywhere() {
    use crate::ph::{self, hermite};
    let cubics = ph_chain(70_000);
    let p0: Vec<DVec3> = cubics.iter().map(|c| c.b[0]).collect();
    let p1: Vec<DVec3> = cubics.iter().map(|c| c.b[3]).collect();
    let t0: Vec<DVec3> = cubics.iter().map(|c| c.b[1] - c.b[0]).collect();
    let t1: Vec<DVec3> = cubics.iter().map(|c| c.b[3] - c.b[2]).collect();
    let run =
        |k: Cancel<'_>| unless_stopped(hermite::hermite_rows(&p0, &t0, &p1, &t1, false, true, k));
    let (got, _) = stop_everywhere(run);
    let got = got.expect("not stopped");
    let plain =
        hermite::hermite_rows(&p0, &t0, &p1, &t1, false, true, &cancel::never).expect("valid");
    assert!(same_bits(&got.candidates, &plain.candidates) && got.counts == plain.counts);
    let m = cubics.len() as f64;
    let s: Vec<f64> = (0..100_000).map(|i| m * i as f64 / 99_999.0).collect();
    for d in 0..4 {
        let run = |k: Cancel<'_>| {
            let mut out = vec![DVec3::ZERO; s.len()];
            ph::eval_into(&cubics, &s, d, &mut out, k).expect("valid");
            out
        };
        let (got, _) = stop_everywhere(run);
        assert!(got == ph::eval_at(&cubics, &s, d).expect("valid"));
    }
}

/// The quaternion rows (spin, slerp between key frames, path length, signs) stop
/// anywhere and give the bits of the calls with `cancel::never`.
#[test]
fn quaternion_rows_stop_anywhere() {
    use crate::quaternion::{self as q, spin};
    let x = curve(100_000);
    let req = Request {
        points: Some(&x),
        ..Request::default()
    };
    let mut flat = vec![0.0; 9 * x.len()];
    frames::compute_into(&req, &mut flat, &cancel::never).expect("valid");
    let a: Vec<[f64; 9]> = flat
        .chunks_exact(9)
        .map(|c| c.try_into().expect("9"))
        .collect();
    // b: a turned about each tangent by 0.3 rad
    let b: Vec<[f64; 9]> = a
        .iter()
        .map(|f| {
            let m = glam::DMat3::from_cols_array(f).transpose();
            let turned = m * glam::DMat3::from_rotation_z(0.3);
            turned.transpose().to_cols_array()
        })
        .collect();
    let run = |k: Cancel<'_>| {
        let mut out = vec![0.0; x.len()];
        spin::spin_into(&a, &b, &mut out, k).expect("valid");
        out
    };
    let (got, _) = stop_everywhere(run);
    assert!(same_bits(&got, &spin::spin(&a, &b).expect("valid")));
    assert!(got.iter().all(|v| (v - 0.3).abs() < 1e-12));

    let quats = q::from_frames(&a, false, &cancel::never).expect("rotations");
    let run = |k: Cancel<'_>| q::continuous(&quats, k).expect("valid");
    let (got, _) = stop_everywhere(run);
    assert!(got == q::continuous(&quats, &cancel::never).expect("valid"));
    let run = |k: Cancel<'_>| q::path_length(&quats, true, k);
    let (got, _) = stop_everywhere(run);
    let want = q::path_length(&quats, true, &cancel::never).expect("valid");
    assert_eq!(got.expect("valid").to_bits(), want.to_bits());

    let keys = &a[..1000];
    let ku: Vec<f64> = (0..1000).map(f64::from).collect();
    let nu: Vec<f64> = (0..100_000).map(|i| 999.0 * i as f64 / 99_999.0).collect();
    let run = |k: Cancel<'_>| {
        let mut out = vec![[0.0; 9]; nu.len()];
        let r = q::slerp_frames(keys, &ku, &nu, &mut out, k);
        unless_stopped(r).map(|()| out.concat())
    };
    let (got, _) = stop_everywhere(run);
    let mut want = vec![[0.0; 9]; nu.len()];
    q::slerp_frames(keys, &ku, &nu, &mut want, &cancel::never).expect("valid");
    assert!(same_bits(&got.expect("not stopped"), &want.concat()));
}

/// A field evaluated at many points, and a rod tool built from many axis samples, stop
/// anywhere; the uninterrupted calls give the bits of those with `cancel::never`.
#[test]
fn field_evaluation_and_rod_stop_anywhere() {
    use crate::deform::{Field, advect, fields::Translation, rod::Rod};
    let tool = Translation::new(DVec3::new(0.0, 0.0, 1.0), 0.5, DVec3::X, None, 3, false);
    let field = Field::single(tool.expect("valid"));
    let p = curve(50_000);
    let run = |k: Cancel<'_>| {
        let mut out = vec![DVec3::ZERO; p.len()];
        advect::eval_into(&field, &p, 0.0, &mut out, k).expect("sizes match");
        out
    };
    let (got, _) = stop_everywhere(run);
    assert!(got.iter().zip(&p).all(|(v, x)| *v == field.eval(*x, 0.0)));
    let axis: Vec<DVec3> = (0..50_000)
        .map(|i| {
            let s = i as f64 * 0.01;
            DVec3::new(s.cos(), s.sin(), 0.3 * s)
        })
        .collect();
    let run = |k: Cancel<'_>| unless_stopped(Rod::from_points(&axis, 0.05, None, None, k));
    let (got, _) = stop_everywhere(run);
    let rod = got.expect("not stopped");
    let plain = Rod::from_points(&axis, 0.05, None, None, &cancel::never).expect("valid");
    assert_eq!(rod.center, plain.center);
    let x = DVec3::new(1.02, 0.0, 0.0);
    assert_eq!(rod.closest(x), plain.closest(x));
}

/// A long spine's model (checks, curvatures, Hermite pieces) and the compass walk of a
/// posed spine stop anywhere, and give the results of the calls with `cancel::never`.
#[test]
fn spine_model_and_compass_walk_stop_anywhere() {
    use crate::flesh::{SpineModel, spine};
    // a closed wavy circle with its frames: r along z, t along the circle
    let n = 70_000;
    let x = curve(n);
    let mut pts: Vec<DVec3> = x.clone();
    pts.push(x[0]);
    let mut frames = Vec::with_capacity(9 * (n + 1));
    for i in 0..=n {
        let t = (pts[(i + 1) % n] - pts[(i + n - 1) % n]).normalize();
        let r = (DVec3::Z - t * t.z).normalize();
        let q = t.cross(r);
        frames.extend_from_slice(&[r.x, q.x, t.x, r.y, q.y, t.y, r.z, q.z, t.z]);
    }
    let run = |k: Cancel<'_>| unless_stopped(SpineModel::new("rest_spine", &pts, &frames, true, k));
    let (got, polls) = stop_everywhere(run);
    let got = got.expect("not stopped");
    assert!(polls >= 4 * n / cancel::BLOCK, "{polls} polls");
    let plain = SpineModel::new("rest_spine", &pts, &frames, true, &cancel::never).expect("valid");
    for (k, a) in [(0, 0.3), (n / 2, 0.7), (n - 1, 1.0)] {
        let (g, p) = (got.eval(k, a), plain.eval(k, a));
        assert!(g.q == p.q && g.t == p.t && g.u == p.u && g.kappa == p.kappa);
    }
    // the walk with chords of a third of the edges: three steps to an edge
    let chords: Vec<f64> = pts
        .windows(2)
        .flat_map(|w| [w[0].distance(w[1]) / 3.0; 3])
        .collect();
    let run = |k: Cancel<'_>| unless_stopped(spine::compass_walk_located(&pts, &chords, k));
    let (got, _) = stop_everywhere(run);
    let (walked, at) = got.expect("not stopped");
    let (plain, plain_at) = spine::compass_walk_located(&pts, &chords, &cancel::never).expect("ok");
    assert!(walked == plain && same_bits(&at, &plain_at));
    assert_eq!(walked, spine::compass_walk(&pts, &chords).expect("ok"));
}

/// A distance-grid tool's set-up (coefficient checks, copy, the cell minima) stops
/// anywhere and gives the tool made with `cancel::never`.
#[test]
fn grid_tool_stops_anywhere() {
    use crate::deform::grid;
    let (n, h) = (60usize, 1.0 / 59.0);
    let p = n + 2;
    let origin = DVec3::splat(-0.5);
    let coef: Vec<f64> = (0..p * p * p)
        .map(|q| {
            let (i, j, k) = (q / (p * p), (q / p) % p, q % p);
            let x = origin + DVec3::new(i as f64, j as f64, k as f64) * h - DVec3::splat(h);
            x.length() - 0.3
        })
        .collect();
    let build = |k: Cancel<'_>| {
        let (u, c) = (DVec3::X, DVec3::ZERO);
        grid::grid_tool(origin, h, [p; 3], &coef, u, c, 0.1, false, true, k)
    };
    let (got, polls) = stop_everywhere(|k| unless_stopped(build(k)));
    let got = got.expect("not stopped");
    assert!(polls >= 4 * (n - 1), "{polls} polls");
    let plain = build(&cancel::never).expect("valid");
    for x in [
        DVec3::ZERO,
        DVec3::new(0.31, 0.0, 0.0),
        DVec3::new(0.2, -0.25, 0.1),
    ] {
        assert_eq!(got.distance(x), plain.distance(x));
    }
    assert_eq!(got.support_extent(), plain.support_extent());
}

#[test]
fn mesh_measures_stop_anywhere() {
    // 200,000 pseudo-random faces over 5,000 vertices (a linear congruential sequence)
    let mut state = 12345u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        state >> 33
    };
    let v: Vec<[f64; 3]> = (0..5000)
        .map(|_| [next(), next(), next()].map(|k| k as f64 / 2e9))
        .collect();
    let f: Vec<[i64; 3]> = (0..200_000)
        .map(|_| [next(), next(), next()].map(|k| (k % 5000) as i64))
        .collect();
    let (vol, _) = stop_everywhere(|c| measure::volume(&v, &f, c).expect("ok"));
    assert_eq!(
        vol.to_bits(),
        measure::volume(&v, &f, &cancel::never)
            .expect("ok")
            .to_bits()
    );
    let (area, _) = stop_everywhere(|c| measure::area(&v, &f, c).expect("ok"));
    assert_eq!(
        area.to_bits(),
        measure::area(&v, &f, &cancel::never).expect("ok").to_bits()
    );
    let (e, _) = stop_everywhere(|c| measure::edges(&f, 5000, c).expect("ok"));
    assert_eq!(e, measure::edges(&f, 5000, &cancel::never).expect("ok"));
}

#[test]
fn frames_in_time_stop_anywhere() {
    use crate::frames::time;
    let (steps, rows) = (8, 20_000);
    let x: Vec<DVec3> = (0..steps)
        .flat_map(|k| {
            curve(rows)
                .into_iter()
                .map(move |p| p * (1.0 + 0.01 * k as f64))
        })
        .collect();
    let req = Request {
        points: Some(&x),
        ..Request::default()
    };
    let prev = {
        let mut f = vec![0.0; 9 * rows];
        let one = Request {
            points: Some(&x[..rows]),
            ..req
        };
        frames::compute_into(&one, &mut f, &cancel::never).expect("valid");
        time::turn_all(&mut f, 0.3, &cancel::never);
        let f: Vec<[f64; 9]> = f
            .chunks_exact(9)
            .map(|c| c.try_into().expect("9"))
            .collect();
        f
    };
    for previous in [None, Some(&prev[..])] {
        let run = |c: Cancel<'_>| {
            let mut out = vec![0.0; 9 * x.len()];
            time::frames_in_time(&req, steps, rows, None, previous, &mut out, c, None)
                .expect("valid");
            out
        };
        let (out, _) = stop_everywhere(run);
        let mut plain = vec![0.0; out.len()];
        time::frames_in_time(
            &req,
            steps,
            rows,
            None,
            previous,
            &mut plain,
            &cancel::never,
            None,
        )
        .expect("valid");
        assert!(same_bits(&out, &plain));
    }
}

#[test]
fn tangents_of_many_curves_stop_anywhere() {
    use crate::frames::{TangentRule, tangents};
    let x = curve(70_000);
    let offsets = [0, 100, 200, 35_000, 70_000];
    for closed in [false, true] {
        let rule = TangentRule::FivePointBounded;
        let run =
            |c: Cancel<'_>| tangents::estimate_many(&x, &offsets, closed, rule, c).expect("valid");
        let (got, _) = stop_everywhere(run);
        assert!(
            got == tangents::estimate_many(&x, &offsets, closed, rule, &cancel::never)
                .expect("valid")
        );
    }
}

#[test]
fn closed_tool_stops_anywhere() {
    use crate::mesh::closed::{self, tests::torus};
    let (v, f) = torus(400, 200);
    let (full, _) = stop_everywhere(|c| closed::closed_volume_centroid(&v, &f, c).expect("ok"));
    let plain = closed::closed_volume_centroid(&v, &f, &cancel::never).expect("ok");
    assert!(full.0.to_bits() == plain.0.to_bits() && full.1 == plain.1);
    let broken = &f[1..];
    let (e, _) = stop_everywhere(|c| closed::closed_volume_centroid(&v, broken, c));
    assert_eq!(
        e,
        closed::closed_volume_centroid(&v, broken, &cancel::never)
    );
}

#[test]
fn surface_deform_stops_anywhere() {
    let (nu, nv) = (6, 7);
    let grid = |bend: f64| -> Vec<DVec3> {
        (0..nu * nv)
            .map(|k| {
                let (i, j) = ((k / nv) as f64 / 5.0, (k % nv) as f64 / 6.0);
                DVec3::new(i, j, bend * (3.0 * i).sin())
            })
            .collect()
    };
    let rest = Surface::new("rest", &grid(0.0), nu, nv).expect("grid");
    let posed = Surface::new("posed", &grid(0.2), nu, nv).expect("grid");
    let vertices: Vec<DVec3> = (0..20_000)
        .map(|k| {
            let s = k as f64;
            DVec3::new(
                (s * 0.618).fract(),
                (s * 0.414).fract(),
                0.1 * (s * 0.732).fract(),
            )
        })
        .collect();
    let (cell, coords) = surface::bind_surface(&rest, &vertices, &cancel::never).expect("bound");
    let n = vertices.len();
    let run = |c: Cancel<'_>| {
        let (mut out, mut flags) = (vec![DVec3::ZERO; n], vec![0u8; n]);
        surface::deform_surface(
            &posed,
            rest.scale.exp(),
            &cell,
            &coords,
            true,
            &mut out,
            &mut flags,
            c,
        )
        .expect("valid");
        (out, flags)
    };
    let ((out, flags), _) = stop_everywhere(run);
    let (mut plain, mut pflags) = (vec![DVec3::ZERO; n], vec![0u8; n]);
    surface::deform_surface(
        &posed,
        rest.scale.exp(),
        &cell,
        &coords,
        true,
        &mut plain,
        &mut pflags,
        &cancel::never,
    )
    .expect("valid");
    assert!(out == plain && flags == pflags);
}
