//! Every long call, stopped at each of its polls in turn, returns without a panic (no stage
//! reads the incomplete output of a stage before it), and the same call with a hook that
//! never stops gives the bits of the call with [`cancel::never`].

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;

use super::cancel::{self, Cancel};
use crate::error::InputError;

use crate::flesh::surface::{self, Surface};
use crate::frames::constraints::TwistRule;
use crate::frames::guide::Guide;
use crate::frames::steer::{self, Steering};
use crate::frames::{self, Method, Orientation, Request};
use crate::mesh::measure;
use crate::quaternion::camera;

/// A hook that counts its polls and says stop from poll `after` on.
struct After {
    polls: AtomicUsize,
    after: usize,
}

impl After {
    fn new(after: usize) -> After {
        After {
            polls: AtomicUsize::new(0),
            after,
        }
    }
    fn stop(&self) -> bool {
        self.polls.fetch_add(1, Ordering::Relaxed) >= self.after
    }
}

/// Run `call` with a hook that never stops (its result is returned, with the number of
/// polls), then stopped at about 12 of those polls spread over the whole call.
fn stop_everywhere<T>(call: impl Fn(&(dyn Fn() -> bool + Sync)) -> T) -> (T, usize) {
    let never = After::new(usize::MAX);
    let full = call(&|| never.stop());
    let polls = never.polls.load(Ordering::Relaxed);
    assert!(polls > 3, "the call polls only {polls} times");
    for after in (0..polls).step_by(polls.div_ceil(12)).chain([polls - 1]) {
        let hook = After::new(after);
        call(&|| hook.stop());
    }
    (full, polls)
}

/// A closed curve of `n` samples (a circle with a wave, curvature nowhere zero).
fn curve(n: usize) -> Vec<DVec3> {
    (0..n)
        .map(|i| {
            let s = std::f64::consts::TAU * 50.0 * i as f64 / n as f64;
            DVec3::new(s.cos(), s.sin(), 0.3 * (3.0 * s).sin())
        })
        .collect()
}

fn frames_of(req: &Request, cancel: Cancel<'_>) -> (Vec<f64>, f64) {
    let mut out = vec![0.0; 9 * req.points.map_or(0, <[DVec3]>::len)];
    let angle = frames::compute_into(req, &mut out, cancel).expect("valid");
    (out, angle)
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn general_frames_stop_anywhere() {
    let x = curve(70_000);
    let t: Vec<DVec3> = x
        .iter()
        .enumerate()
        .map(|(i, p)| (x[(i + 1) % x.len()] - *p).normalize())
        .collect();
    let base = Request {
        points: Some(&x),
        ..Request::default()
    };
    let requests = [
        Request {
            closed: true,
            ..base
        },
        Request {
            closed: true,
            tangents: Some(&t),
            ..base
        },
        Request {
            method: Method::Frenet,
            ..base
        },
        Request {
            end: Some(Orientation::Vector(DVec3::Z)),
            ..base
        },
        Request {
            method: Method::Projection,
            ..base
        },
    ];
    for req in &requests {
        let ((out, angle), _) = stop_everywhere(|c| frames_of(req, c));
        let mut plain = vec![0.0; out.len()];
        let a = frames::compute_into(req, &mut plain, &cancel::never).expect("valid");
        assert!(same_bits(&out, &plain) && angle.to_bits() == a.to_bits());
    }
}

#[test]
fn steered_frames_stop_anywhere() {
    let x = curve(70_000);
    let req = Request {
        points: Some(&x),
        ..Request::default()
    };
    let up = [DVec3::Z];
    let pins = [steer::Constraint {
        row: 35_000,
        orientation: Orientation::Vector(DVec3::Z),
    }];
    let guided = Steering {
        constraints: &[],
        rule: TwistRule::ArcLength,
        turns: &[],
        guide: Some(Guide {
            vectors: &up,
            weight: 1.0,
            tolerance: 1e-3,
            axis: false,
            previous: &[],
            previous_weight: 1.0,
        }),
        previous: None,
    };
    let pinned = Steering {
        constraints: &pins,
        guide: None,
        ..guided
    };
    for st in [guided, pinned] {
        let run = |c: Cancel<'_>| {
            let mut out = vec![0.0; 9 * x.len()];
            steer::compute_steered(&req, &st, &mut out, c).expect("valid");
            out
        };
        let (out, _) = stop_everywhere(run);
        let mut plain = vec![0.0; out.len()];
        steer::compute_steered(&req, &st, &mut plain, &cancel::never).expect("valid");
        assert!(same_bits(&out, &plain));
    }
}

#[test]
fn camera_inputs_stop_anywhere() {
    let x = curve(100_000);
    for mode in [
        camera::Mode::Transport,
        camera::Mode::Level {
            singular_angle: 0.1,
        },
    ] {
        let run =
            |c: Cancel<'_>| camera::inputs(&x, None, None, None, true, mode, c).expect("valid");
        let (got, _) = stop_everywhere(run);
        let plain =
            camera::inputs(&x, None, None, None, true, mode, &cancel::never).expect("valid");
        assert!(got.tangents == plain.tangents && got.regular == plain.regular);
    }
}

/// A sweep stopped anywhere in its set-up or its writing (each spine's frames, checks
/// and rings), with given frames and with the frames computed spine by spine; the
/// computed ones give the bits of the frames computed first (`spinal.frames`).
#[test]
fn sweep_stops_anywhere() {
    use crate::sweep::{FrameSource, MeshMut, Options, Prepared, Spine};
    use glam::DVec2;
    let opts = Options {
        closed: false,
        caps: true,
        miter_limit: 4.0,
        split_seams: true,
        join: crate::sweep::Join::Round,
        turns: 0.0,
        scale_name: "scale",
    };
    let profile = [DVec2::X, DVec2::Y, -DVec2::X, -DVec2::Y];
    // near unit size, and far from it (the set-up scales the input first)
    for size in [1.0, 1e200] {
        let x: Vec<DVec3> = curve(70_000).into_iter().map(|p| p * size).collect();
        // three curves: the first two short, the third long
        let offsets = [0, 100, 200, x.len()];
        let req = Request {
            points: Some(&x),
            ..Request::default()
        };
        let mut flat = vec![0.0; 9 * x.len()];
        frames::compute_many(&req, &offsets, &[], &[], &mut flat, &cancel::never, None)
            .expect("valid");
        let frames: Vec<[f64; 9]> = flat
            .chunks_exact(9)
            .map(|c| c.try_into().expect("9"))
            .collect();
        let scale = [glam::DVec2::splat(0.01 * size)];
        let spine = Spine {
            points: &x,
            frames: &frames,
            scale: &scale,
            twist: &[],
        };
        let vertices = |p: &Prepared<'_>, c: Cancel<'_>| {
            let (nv, nf) = (p.layout.vertices, p.layout.faces);
            let (mut v, mut f) = (vec![[0.0f64; 3]; nv], vec![[0i64; 3]; nf]);
            let out = MeshMut {
                vertices: &mut v,
                faces: &mut f,
                normals: None,
                uv: None,
            };
            // a stopped sweep's result is discarded, whatever it holds
            let folds = p.write_into(out, c, None);
            (folds, v.concat(), f)
        };
        let plain = Prepared::new(
            spine,
            &offsets,
            &profile,
            true,
            opts,
            FrameSource::Given,
            &cancel::never,
        )
        .expect("valid");
        let (folds, pv, pf) = vertices(&plain, &cancel::never);
        assert!(folds.is_ok());
        let computed = Spine {
            frames: &[],
            ..spine
        };
        let rmf = FrameSource::Rmf { tangents: None };
        for (s, source) in [(spine, FrameSource::Given), (computed, rmf)] {
            let run = |c: Cancel<'_>| {
                unless_stopped(Prepared::new(s, &offsets, &profile, true, opts, source, c))
                    .map(|p| vertices(&p, c))
            };
            let (got, _) = stop_everywhere(run);
            let (folds, v, f) = got.expect("not stopped");
            assert!(folds.is_ok());
            assert!(same_bits(&v, &pv) && f == pf, "{source:?}");
        }
    }
}

/// The checks of a large convex profile (its copy, scaling, convexity and arc lengths)
/// poll within their passes, not only between them, and give the bits of the checks with `cancel::never`.
#[test]
fn convex_profile_checks_stop_anywhere() {
    use crate::sweep::Profile;
    use glam::DVec2;
    let m = 200_000;
    let profile: Vec<DVec2> = (0..m)
        .map(|j| DVec2::from_angle(std::f64::consts::TAU * j as f64 / m as f64) * 3.0)
        .collect();
    let run = |c: Cancel<'_>| match Profile::new(&profile, true, c) {
        Ok(p) => Some(p),
        Err(e) => {
            assert_eq!(e, InputError::stopped());
            None
        }
    };
    let (got, polls) = stop_everywhere(run);
    let got = got.expect("not stopped");
    let plain = Profile::new(&profile, true, &cancel::never).expect("valid");
    // the convexity test and the arc lengths, each polling every block of vertices
    assert!(polls >= 2 * m / cancel::BLOCK, "{polls} polls");
    assert!(got.convex && plain.convex && got.area.to_bits() == plain.area.to_bits());
    assert!(same_bits(&got.v, &plain.v));
}

#[test]
fn non_convex_profile_sweep_stops_anywhere() {
    use crate::sweep::{FrameSource, MeshMut, Options, Prepared, Spine};
    use glam::DVec2;
    // a star of 50,000 points: tested for self-intersection and triangulated for its
    // caps by sweeps that poll every few thousand events
    let m = 50_000;
    let profile: Vec<DVec2> = (0..m)
        .map(|j| {
            let a = std::f64::consts::TAU * j as f64 / m as f64;
            DVec2::from_angle(a) * if j % 2 == 0 { 1.0 } else { 0.7 }
        })
        .collect();
    let x = [DVec3::ZERO, DVec3::new(0.0, 0.1, 1.0)];
    let opts = Options {
        closed: false,
        caps: true,
        miter_limit: 4.0,
        split_seams: true,
        join: crate::sweep::Join::Round,
        turns: 0.0,
        scale_name: "scale",
    };
    let spine = Spine {
        points: &x,
        frames: &[],
        scale: &[DVec2::ONE],
        twist: &[],
    };
    let run = |c: Cancel<'_>| {
        let rmf = FrameSource::Rmf { tangents: None };
        let prep = Prepared::new(spine, &[0, 2], &profile, true, opts, rmf, c);
        unless_stopped(prep).map(|p| {
            let (nv, nf) = (p.layout.vertices, p.layout.faces);
            let (mut v, mut f) = (vec![[0.0f64; 3]; nv], vec![[0i64; 3]; nf]);
            let out = MeshMut {
                vertices: &mut v,
                faces: &mut f,
                normals: None,
                uv: None,
            };
            // a stopped sweep's result is discarded, whatever it holds
            let done = p.write_into(out, c, None).is_ok();
            (done, v.concat(), f)
        })
    };
    let (got, polls) = stop_everywhere(run);
    let (done, v, f) = got.expect("not stopped");
    // the two sweeps over 2m events, in blocks
    assert!(done && polls > 2 * 2 * m / cancel::BLOCK, "{polls} polls");
    // the coordinates of two rings of m + 1 points (the seam column twice), their side
    // faces and two caps of m − 2 triangles
    assert_eq!((v.len(), f.len()), (3 * 2 * (m + 1), 2 * m + 2 * (m - 2)));
}

/// The result of a cancellable call, `None` when it was stopped (any other error fails).
fn unless_stopped<T>(r: crate::error::Result<T>) -> Option<T> {
    match r {
        Ok(v) => Some(v),
        Err(e) => {
            assert_eq!(e, InputError::stopped());
            None
        }
    }
}

mod others;
