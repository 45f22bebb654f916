//! Timings of the grid tool's evaluation (run on request, `--ignored`).

use super::*;
use crate::run::cancel;

#[test]
#[ignore]
fn time_grid_eval() {
    let n = [64, 64, 64];
    let mut coef = Vec::new();
    for i in 0..n[0] + 2 {
        for j in 0..n[1] + 2 {
            for k in 0..n[2] + 2 {
                let p = DVec3::new(i as f64, j as f64, k as f64) - DVec3::splat(32.5);
                coef.push(p.length() * 0.03 - 0.3);
            }
        }
    }
    let g = GridTool::new(
        DVec3::splat(-1.0),
        0.03,
        n,
        coef,
        (DVec3::X, DVec3::ZERO, 0.3, false, false),
        &cancel::never,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let pts: Vec<DVec3> = (0..1_000_000)
        .map(|i| {
            let a = i as f64 * 0.001;
            DVec3::new(a.sin(), a.cos(), (a * 0.37).sin()) * 0.45
        })
        .collect();
    let t = std::time::Instant::now();
    let mut s = DVec3::ZERO;
    for p in &pts {
        s += g.eval(*p, 0.0);
    }
    println!(
        "grid eval: {} ns/point ({s})",
        t.elapsed().as_secs_f64() / pts.len() as f64 * 1e9
    );
}
