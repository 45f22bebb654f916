//! Unit tests of advection: RK4's order, the spatial order's bits, and ticked advection.

use super::super::{Swirl, SwirlKind, Translation};
use super::*;
use crate::math::rotation::rodrigues;
use crate::run::cancel;

#[test]
fn rk4_on_a_swirl_is_fourth_order() {
    let s = Swirl {
        pivot: DVec3::ZERO,
        axis: DVec3::Z,
        rate: 4.0,
        reach: 2.0,
        kind: SwirlKind::Twist,
        curl_form: false,
    };
    let f = Field::single(s);
    let x0 = DVec3::new(0.6, 0.2, 0.7);
    let exact = rodrigues(x0, DVec3::Z, s.angular(x0.z, x0.length()));
    let err = |n: usize| (integrate(&f, x0, 0.0, 1.0 / n as f64, n, Method::Rk4) - exact).length();
    let ratio = err(8) / err(16);
    assert!((14.0..18.0).contains(&ratio), "ratio {ratio}");
}

#[test]
fn spatial_order_keeps_the_bits() {
    // a strip along a curved axis asks for locality: the sorted run must equal the
    // unsorted one bit for bit, and the order must be a permutation
    let axis: Vec<DVec3> = (0..40)
        .map(|i| {
            let a = i as f64 * 0.05;
            DVec3::new(a.cos(), a.sin(), 0.1 * a)
        })
        .collect();
    let strip = super::super::tube::strip_curve(&axis, 0.1, 1.0, Some(0.15), false, &cancel::never)
        .unwrap();
    // and so does a rod curl tool (its axis is a table of segments too)
    let rod =
        super::super::rod::Rod::from_points(&axis, 0.1, Some(0.15), None, &cancel::never).unwrap();
    let rod = super::super::curl::CurlTool::new(
        std::sync::Arc::new(rod),
        super::super::curl::Motion::Translate(DVec3::new(0.0, 0.0, -1.0)),
        2,
        true,
    )
    .unwrap();
    assert!(super::super::Tool::wants_locality(&rod));
    let x0: Vec<DVec3> = (0..6000)
        .map(|i| {
            let a = i as f64;
            DVec3::new((a * 0.7).sin(), (a * 1.3).cos(), (a * 0.11).sin()) * 1.2
        })
        .collect();
    let keys = spatial_order(&x0).unwrap();
    assert!(keys.windows(2).all(|w| w[0] < w[1])); // by cell, ties in the given order
    let mut order: Vec<u64> = keys.iter().map(|k| k & u64::from(u32::MAX)).collect();
    order.sort_unstable();
    assert!(order.iter().enumerate().all(|(i, &j)| i as u64 == j));
    for f in [Field::single(strip), Field::single(rod)] {
        let mut sorted = x0.clone();
        advect_in_place(&f, &mut sorted, 0.0, 0.02, 8, Method::Rk4);
        let mut plain = x0.clone();
        advect_steps(&f, &mut plain, 0.0, 0.02, 0..8, Method::Rk4);
        assert_eq!(sorted, plain);
        assert_ne!(plain, x0);
    }
}

#[test]
fn ticked_advection_has_the_bits_of_one_call_and_stops_when_told() {
    let f = Field::single(
        Translation::new(DVec3::new(0.0, 0.0, 1.2), 0.5, DVec3::NEG_Z, None, 2, true).unwrap(),
    );
    let x0: Vec<DVec3> = (0..500)
        .map(|i| DVec3::new((i as f64 * 0.1).sin(), (i as f64 * 0.37).cos(), 0.9))
        .collect();
    let mut once = x0.clone();
    advect_in_place(&f, &mut once, 0.0, 0.01, 300, Method::Rk4);
    let mut ticked = x0.clone();
    let mut calls = Vec::new();
    assert!(advect_ticked(
        &f,
        &mut ticked,
        Run {
            t0: 0.0,
            h: 0.01,
            count: 300,
        },
        Method::Rk4,
        7,
        &mut |d, n| {
            calls.push((d, n));
            true
        }
    ));
    assert_eq!(ticked, once);
    assert_eq!(calls.last(), Some(&(300, 300)));
    assert!(calls.windows(2).all(|w| w[0].0 < w[1].0));
    // every multiple of 7 is reported
    assert!((7..300).step_by(7).all(|k| calls.iter().any(|c| c.0 == k)));
    let mut stopped = x0.clone();
    let mut seen = 0;
    assert!(!advect_ticked(
        &f,
        &mut stopped,
        Run {
            t0: 0.0,
            h: 0.01,
            count: 300,
        },
        Method::Rk4,
        0,
        &mut |d, _| {
            seen = d;
            false
        }
    ));
    assert_eq!(seen, 1); // the first block is one step
}
