//! The default step count, measured on the path lines that are to be integrated.
//!
//! The a priori rule ([`Field::step_bound`]) takes `n = ⌈8 |T| v_max / ℓ⌉` steps, so that a
//! step moves a point by at most `ℓ/8` (`ℓ` the field's length scale, `v_max` a bound of
//! its speed). For a tool whose shape is sampled (a distance grid from a mesh) `v_max` comes
//! from the grid's coefficient differences, `|∇d| ≤ max|Δc|/h`, which near a thin feature
//! can exceed the speed any point actually reaches by two orders of magnitude: a cow-shaped
//! tool at 64 nodes asks for 4,608 steps where 128 give the same vertices to 1e-8 of the
//! fandisk's diagonal.
//!
//! The measured rule integrates the given points themselves with RK4 at `n = 4, 8, 16, …`
//! steps and stops at the first `2n` whose run agrees with the run at `n` on every point to
//! within `TOLERANCE · ℓ` (max norm). For RK4 of global order `p` the difference
//! `X_n − X_2n = (2^p − 1) e_2n` is a multiple of the error `e_2n` of the finer run
//! (Richardson; `p = 4` on smooth path lines, about 2 where a path line crosses the `C⁰`
//! edge of a falloff or the `C²` knots of a distance spline), so the accepted run's error is
//! at most a third of the tolerance and usually a fifteenth. The count never exceeds the a
//! priori bound: the search gives up, returning the bound, as soon as the next run would
//! take the total work past it, so measuring costs at most as many point-steps as the
//! integration it precedes. Runs of equal steps only, so the count `n` returned gives the
//! same bits as an explicit `steps = n` (the count, not the positions, is what is measured);
//! the maximum over the points is independent of their order and of the thread count.
//!
//! A run is accepted only if, besides, no point moved more than `ℓ/8` in one of its steps
//! (the a priori rule with the speeds the points reached instead of the bound) and the
//! tool's support moved no more than that ([`super::Tool::support_speed`]), so that neither a
//! point nor the tool can step over the other.
//!
//! Fields with breakpoints (tools along a path, keyframed tools) keep the a priori rule:
//! their steps end at the breakpoints, so equal runs over the whole duration do not apply.

use glam::DVec3;

use super::Field;
use super::advect::{Run, advect_measuring};
use crate::error::{InputError, Result};
use crate::run::alloc;
use crate::run::cancel::Cancel;

/// Largest accepted difference between the runs at `n` and `2n` steps, as a fraction of the
/// field's length scale.
pub const TOLERANCE: f64 = 1e-5;

/// The fewest steps tried.
const FIRST: usize = 4;

/// The default step count for integrating `points` over `duration` from `t0` with RK4: the
/// measured count (see the module documentation), at most [`Field::default_steps`]. Errors
/// as [`Field::default_steps`] when neither rule gives a count of at most
/// [`super::MAX_STEPS`]; `cancel` is polled between blocks of steps.
pub fn measured_steps(
    field: &Field,
    points: &[DVec3],
    t0: f64,
    duration: f64,
    cancel: Cancel<'_>,
) -> Result<usize> {
    let bound = field.step_bound(duration);
    let length = field.length_scale();
    let trivial = points.is_empty()
        || duration == 0.0
        || !length.is_finite()
        || !(bound > (2 * FIRST) as f64)
        || !field.breakpoints("advect")?.is_empty();
    if trivial {
        return field.default_steps(duration);
    }
    let cap = bound.min(super::MAX_STEPS as f64);
    // no point may miss the tool between two samples of time
    let floor = (duration.abs() * 8.0 * field.support_speed() / length).ceil();
    let mut coarse = alloc::collect("advect", points.iter().copied())?;
    let mut fine = alloc::collect("advect", points.iter().copied())?;
    let mut n = FIRST;
    run(field, &mut coarse, t0, duration, n, cancel)?;
    let mut work = n as f64;
    // the next run (2n steps) must not take the measuring past the work of the integration
    // at the bound
    while work + (2 * n) as f64 <= cap {
        let m = 2 * n;
        fine.copy_from_slice(points);
        let stride = run(field, &mut fine, t0, duration, m, cancel)?;
        work += m as f64;
        let mut gap = 0.0f64;
        for (a, b) in coarse.iter().zip(&fine) {
            gap = gap.max((*a - *b).abs().max_element());
        }
        if !(gap.is_finite() && stride.is_finite()) {
            break;
        }
        // accepted: the runs agree, no point moved more than ℓ/8 in a step (the a priori
        // rule with the speeds the points reached instead of the bound), and the tool
        // moved no more than that either
        if gap <= TOLERANCE * length && stride <= 0.125 * length && m as f64 >= floor {
            return Ok(m);
        }
        std::mem::swap(&mut coarse, &mut fine);
        n = m;
    }
    field.default_steps(duration)
}

/// `points` carried by `steps` equal RK4 steps over `duration` from `t0`; the largest
/// distance a point moved in one step (max norm, NaN when a point left the finite numbers).
fn run(
    field: &Field,
    points: &mut [DVec3],
    t0: f64,
    duration: f64,
    steps: usize,
    cancel: Cancel<'_>,
) -> Result<f64> {
    let r = Run {
        t0,
        h: duration / steps as f64,
        count: steps,
    };
    advect_measuring(field, points, r, cancel).ok_or_else(InputError::stopped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deform::advect::Method;
    use crate::deform::{Swirl, SwirlKind, Translation};

    fn ball(n: usize, radius: f64) -> Vec<DVec3> {
        // points on a sphere (a Fibonacci lattice)
        (0..n)
            .map(|i| {
                let z = 1.0 - (2 * i + 1) as f64 / n as f64;
                let r = (1.0 - z * z).sqrt();
                let a = i as f64 * 2.399_963_229_728_653;
                radius * DVec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect()
    }

    const T: f64 = 2.0;

    #[test]
    fn the_measured_count_meets_the_tolerance_and_never_exceeds_the_bound() {
        let s = Swirl {
            pivot: DVec3::ZERO,
            axis: DVec3::Z,
            rate: 100.0,
            reach: 1.5,
            kind: SwirlKind::Twist,
            curl_form: false,
        };
        let f = Field::single(s);
        // points near the axis, slower than the bound allows for
        let p = ball(500, 0.05);
        // long enough that the search ends before the bound
        let n = measured_steps(&f, &p, 0.0, T, &crate::run::cancel::never).unwrap();
        assert!(n < f.default_steps(T).unwrap(), "{n}");
        // the error of the accepted run against a fine reference is within the tolerance
        let carried = |steps: usize| {
            let mut q = p.clone();
            crate::deform::advect::advect_in_place(
                &f,
                &mut q,
                0.0,
                T / steps as f64,
                steps,
                Method::Rk4,
            );
            q
        };
        let (a, r) = (carried(n), carried(4096));
        let err = a
            .iter()
            .zip(&r)
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0, f64::max);
        assert!(err <= TOLERANCE * f.length_scale(), "{err:e} at {n} steps");
        // and the count before it was not accepted (the runs at a quarter and half the
        // count differ by more than the tolerance)
        if n > 2 * FIRST {
            let (q, h) = (carried(n / 4), carried(n / 2));
            let gap = q
                .iter()
                .zip(&h)
                .map(|(a, b)| (*a - *b).abs().max_element())
                .fold(0.0, f64::max);
            assert!(gap > TOLERANCE * f.length_scale(), "{gap:e}");
        }
    }

    #[test]
    fn points_the_field_does_not_move_take_the_fewest_steps() {
        // a tool at rest far from every point: the runs agree exactly at 8 steps
        let t =
            Translation::new(DVec3::new(10.0, 0.0, 0.0), 0.5, DVec3::X, None, 2, false).unwrap();
        let f = Field::single(t);
        assert!(f.default_steps(3.0).unwrap() > 2 * FIRST);
        let n = measured_steps(&f, &ball(200, 0.8), 0.0, 3.0, &crate::run::cancel::never).unwrap();
        assert_eq!(n, 2 * FIRST);
    }

    #[test]
    fn a_moving_tool_is_not_stepped_over() {
        // a small tool passing the points at t ≈ 10.3, inside the window of ±0.2 no stage
        // time of 4, 8 or 16 steps falls: those runs never see it and agree exactly, yet it
        // passes through the points; the count must let it move at most ℓ/8 per step
        let t = Translation::new(
            DVec3::new(-10.3, 0.0, 0.0),
            0.1,
            DVec3::X,
            Some(0.1),
            2,
            true,
        )
        .unwrap();
        let f = Field::single(t);
        let n = measured_steps(&f, &ball(50, 0.01), 0.0, 20.0, &crate::run::cancel::never).unwrap();
        assert!(n as f64 >= 8.0 * 20.0 / 0.1, "{n}");
    }

    #[test]
    fn a_stop_request_is_an_error() {
        let t = Translation::new(DVec3::ZERO, 0.5, DVec3::X, None, 2, true).unwrap();
        let f = Field::single(t);
        let r = measured_steps(&f, &ball(200, 0.8), 0.0, 3.0, &|| true);
        assert!(r.is_err());
    }
}
