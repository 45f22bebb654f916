//! Unit tests of the grid tool: the B-spline of quadratic coefficients and its gradient, and
//! the AVX2 spline's bits.

use super::*;
use crate::run::cancel;

/// Coefficients `c = |node − m|²`: the B-spline is `|X − m|² + 3·(1/3)` (its basis has
/// variance 1/3 per axis), gradient `2(X − m)`.
#[test]
fn quadratic_coefficients_give_the_shifted_paraboloid_and_its_gradient() {
    let n = [10, 11, 12];
    let m = DVec3::new(4.5, 5.0, 5.5);
    let mut coef = Vec::new();
    for i in 0..n[0] + 2 {
        for j in 0..n[1] + 2 {
            for k in 0..n[2] + 2 {
                let p = DVec3::new(i as f64, j as f64, k as f64) - DVec3::ONE;
                coef.push((p - m).length_squared());
            }
        }
    }
    let o = DVec3::new(0.1, -0.2, 0.3);
    let g = GridTool::new(
        o,
        1.0,
        n,
        coef.clone(),
        (DVec3::X, m, 2.0, false, false),
        &cancel::never,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    for x in [DVec3::new(4.3, 5.1, 5.2), DVec3::new(5.0, 4.5, 6.0)] {
        let (d, n) = g.distance(x + o).unwrap();
        assert!((d - ((x - m).length_squared() + 1.0)).abs() < 1e-13, "{d}");
        assert!((n - 2.0 * (x - m)).length() < 1e-13);
    }
    assert!(g.distance(o + DVec3::new(9.5, 0.0, 0.0)).is_none());
    assert!(g.distance(o - DVec3::new(0.01, 0.0, 0.0)).is_none());
    // a support reaching the boundary is refused
    assert!(
        GridTool::new(
            o,
            1.0,
            n,
            coef,
            (DVec3::X, m, 40.0, false, false),
            &cancel::never
        )
        .is_err()
    );
}

/// The AVX2 contraction gives the bits of the portable one (same operations per lane).
#[test]
fn the_avx2_spline_has_the_bits_of_the_portable_one() {
    let n = [9, 10, 11];
    // coefficients in [0.5, 1.5], above the reach: no cell is in the support (which the
    // constructor would refuse at the edge); the spline itself is what is compared
    let coef: Vec<f64> = (0..(n[0] + 2) * (n[1] + 2) * (n[2] + 2))
        .map(|i| 1.0 + 0.5 * ((i as f64) * 0.37).sin())
        .collect();
    let g = GridTool::new(
        DVec3::ZERO,
        0.1,
        n,
        coef,
        (DVec3::X, DVec3::ZERO, 0.3, false, false),
        &cancel::never,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut seen = 0;
    for i in 0..500 {
        let a = i as f64;
        let idx = [
            i % (g.n[0] - 1),
            (i / 3) % (g.n[1] - 1),
            (i / 7) % (g.n[2] - 1),
        ];
        let fr = [(a * 0.61).fract(), (a * 0.37).fract(), (a * 0.83).fract()];
        let plain = g.spline_body(idx, fr).unwrap();
        assert!(plain.0.is_finite());
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 is available, checked just above.
            let fast = unsafe { g.spline_avx2(idx, fr) }.unwrap();
            assert_eq!(plain.0.to_bits(), fast.0.to_bits());
            assert_eq!(
                plain.1.to_array().map(f64::to_bits),
                fast.1.to_array().map(f64::to_bits)
            );
            seen += 1;
        }
        assert_eq!(g.spline(idx, fr), Some(plain));
    }
    if cfg!(target_arch = "x86_64") && seen == 0 {
        eprintln!("no AVX2 on this processor: only the portable spline was run");
    }
}
