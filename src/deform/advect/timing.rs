//! Timings of the batched integrators (run on request, `--ignored`).

use super::super::{Sphere, Swirl, SwirlKind, Translation};
use super::*;

/// ns per vertex per RK4 step: `cargo test --release -- --ignored --nocapture time_fields`.
#[test]
#[ignore]
fn time_fields() {
    let n = 200_000;
    let x0: Vec<DVec3> = (0..n)
        .map(|i| {
            let a = i as f64 * 0.001;
            DVec3::new(a.sin(), a.cos(), (a * 0.37).sin())
        })
        .collect();
    let down = DVec3::new(0.0, 0.0, -1.0);
    let fields = [
        (
            "translation",
            Field::single(
                Translation::new(DVec3::new(0., 0., 1.32), 0.3, down, None, 2, true).unwrap(),
            ),
        ),
        (
            "twist",
            Field::single(
                Swirl::new(DVec3::ZERO, DVec3::Z, 4.0, 2.0, SwirlKind::Twist, false).unwrap(),
            ),
        ),
        (
            "twist out",
            Field::single(
                Swirl::new(
                    DVec3::new(5., 0., 0.),
                    DVec3::Z,
                    4.0,
                    2.0,
                    SwirlKind::Twist,
                    false,
                )
                .unwrap(),
            ),
        ),
        (
            "translation in",
            Field::single(Translation::new(DVec3::ZERO, 0.6, down, Some(1.0), 2, true).unwrap()),
        ),
        (
            "sphere in",
            Field::single(Sphere::new(DVec3::ZERO, 0.6, down, Some(1.0), false, false).unwrap()),
        ),
    ];
    for (name, f) in fields {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let mut x = x0.clone();
            let t = std::time::Instant::now();
            for b in x.chunks_mut(LANES) {
                integrate_batch(&f, b, 0.0, 0.3 / 16.0, 0..16, Method::Rk4);
            }
            best = best.min(t.elapsed().as_secs_f64());
            std::hint::black_box(&x);
        }
        println!("{name}: ns/vertex/step {}", best / (n as f64 * 16.0) * 1e9);
    }
}
