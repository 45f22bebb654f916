//! Points carried along a slip surface of a field: the surface of a curl tool, across which
//! only the normal velocity is continuous (Zheng, thesis §12.1).
//!
//! On the surface `d = 0` of a curl tool (`n = ∇d/|∇d|`, negative `d` inside) the velocity has
//! two one-sided limits `v₊` (outside) and `v₋` (inside) with the same normal part, that of the
//! tool's own surface: for the translation tool `v₊ + v₋ = 2u` and the tangential parts are
//! `(1 ∓ ρ/R) u_t` (a ball of radius `ρ`, reach `R`). A point on the surface moved by the blend
//!
//! `v_s = (1 − s) v₊ + s v₋`,  `s ∈ [0, 1]`,
//!
//! stays on the surface for every `s`: `s = 0` follows the material just outside, `s = 1` the
//! material just inside and `s = ½` the surface's own motion (the tool's velocity `u` for a
//! translation). Started from a point `p` of the surface at rest, `Ψ(p, s)` sweeps, as `s`
//! goes from 0 to 1, the strip of the tool's surface between the two images `Φ₊(p)` and
//! `Φ₋(p)` into which the slip tears `p`: the part of a deformed body's boundary that runs
//! along the tool ([`super::refine`] places the vertices of that strip with it).
//!
//! The one-sided limits are the field evaluated a distance `δ = 10⁻¹¹ ×` the field's length
//! scale off the surface on either side (the curl fields are smooth on each side, so the
//! error is `O(δ |∇v|)`), at the point projected onto the surface by two Newton steps on `d`.

use glam::DVec3;
use rayon::prelude::*;

use super::Field;
use super::advect::{Method, Run, advect_steps, rk4_batch};

/// Offset of the one-sided evaluations, relative to the field's length scale.
const SIDE: f64 = 1e-11;

/// `x` moved onto the nearest slip surface of `field` at time `t` (two Newton steps on its
/// distance) and the surface's unit normal there; `None` where the field has no slip surface.
pub fn project(field: &Field, x: DVec3, t: f64) -> Option<(DVec3, DVec3)> {
    let mut y = x;
    let mut n = DVec3::ZERO;
    for _ in 0..2 {
        let (d, g) = field.slip_surface(y, t)?;
        let g2 = g.length_squared();
        if !(g2 > 0.0 && d.is_finite()) {
            return None;
        }
        y -= g * (d / g2);
        n = g / g2.sqrt();
    }
    Some((y, n))
}

/// How a point is carried.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Carry {
    /// By the field (no slip surface at its rest position).
    Free,
    /// By the material of one side of the nearest slip surface: 0 outside, 1 inside.
    Side(f64),
    /// On the slip surface, by the blend `s` of its two sides.
    Surface(f64),
}

/// The velocity of a point carried by `c`: `v_s = (1 − s) v₊ + s v₋` at the projection of
/// `x` onto the nearest slip surface for a surface point; for a material point the field on
/// its own side, extended past the surface where an integration stage has crossed it (to
/// second order: `v(a) ≈ 2 v(0) − v(−a)` along the normal, from the side's own values).
#[inline]
pub fn velocity(field: &Field, x: DVec3, t: f64, tm: f64, c: Carry, delta: f64) -> DVec3 {
    let s = match c {
        Carry::Free => return field.eval_in(x, t, tm),
        Carry::Side(side) => {
            let inside = side > 0.5;
            let Some((d, _)) = field.slip_surface(x, t) else {
                return field.eval_in(x, t, tm);
            };
            if (d < 0.0) == inside && d.abs() > delta {
                return field.eval_in(x, t, tm);
            }
            let Some((y, n)) = project(field, x, t) else {
                return field.eval_in(x, t, tm);
            };
            let n = if inside { -n } else { n }; // towards the point's own side
            let a = d.abs().max(delta);
            return 2.0 * field.eval_in(y + delta * n, t, tm) - field.eval_in(y + a * n, t, tm);
        }
        Carry::Surface(s) => s,
    };
    match project(field, x, t) {
        Some((y, n)) => {
            let out = field.eval_in(y + delta * n, t, tm);
            let inside = field.eval_in(y - delta * n, t, tm);
            out + s * (inside - out)
        }
        None => field.eval_in(x, t, tm),
    }
}

/// `q` kept where its carry puts it: a surface point on the surface, a material point on its
/// side (the exact flow never crosses the surface, whose normal velocity both sides share).
fn keep(field: &Field, q: DVec3, t: f64, c: Carry, delta: f64) -> DVec3 {
    match c {
        Carry::Free => q,
        Carry::Surface(_) => project(field, q, t).map_or(q, |(y, _)| y),
        Carry::Side(side) => match field.slip_surface(q, t) {
            Some((d, _)) if (d < 0.0) != (side > 0.5) || d == 0.0 => project(field, q, t)
                .map_or(q, |(y, n)| y + n * if side > 0.5 { -delta } else { delta }),
            _ => q,
        },
    }
}

/// The offset of the one-sided evaluations for `field`.
pub fn offset(field: &Field) -> f64 {
    let l = field.length_scale();
    if l.is_finite() { SIDE * l } else { 0.0 }
}

/// Step `j` of the run `r` (RK4) for the points `x` carried by `carry`: all of them by the
/// field, then again from where they were, with [`velocity`], the surface points and the
/// material points within one step's travel (`|h| ×` the speed bound) of a slip surface,
/// whose integration stages may cross it.
pub fn step(field: &Field, x: &mut [DVec3], carry: &[Carry], r: &Run, j: usize) {
    let t = r.t0 + r.h * j as f64;
    let band = r.h.abs() * field.max_speed();
    let redo: Vec<(usize, DVec3)> = x
        .par_iter()
        .zip(carry.par_iter())
        .enumerate()
        .filter_map(|(i, (p, c))| {
            let near = match c {
                Carry::Free => false,
                Carry::Surface(_) => true,
                Carry::Side(_) => field
                    .slip_surface(*p, t)
                    .is_some_and(|(d, g)| d.abs() < band * g.length().max(1.0)),
            };
            near.then_some((i, *p))
        })
        .collect();
    advect_steps(field, x, r.t0, r.h, j..j + 1, Method::Rk4);
    let delta = offset(field);
    let again: Vec<DVec3> = redo
        .par_iter()
        .map(|&(i, p)| {
            let mut q = p;
            let c = carry[i];
            rk4_batch(
                |y, t, tm| velocity(field, y, t, tm, c, delta),
                std::slice::from_mut(&mut q),
                r.t0,
                r.h,
                j..j + 1,
            );
            // RK4 drifts off a curved surface by O(h⁵)
            keep(field, q, t + r.h, c, delta)
        })
        .collect();
    for ((i, _), q) in redo.into_iter().zip(again) {
        x[i] = q;
    }
}

/// The rest points `p` carried by `carry` through the first `upto` steps of `runs` (the
/// surface points first projected onto the slip surface at the start): `Φ` of the material
/// points, `Ψ(p, s)` of the surface points.
pub fn flow(field: &Field, p: &mut [DVec3], carry: &[Carry], runs: &[Run], upto: usize) {
    let Some(start) = runs.first() else {
        return;
    };
    p.par_iter_mut().zip(carry.par_iter()).for_each(|(x, c)| {
        if let Carry::Surface(_) = c
            && let Some((y, _)) = project(field, *x, start.t0)
        {
            *x = y;
        }
    });
    let mut left = upto;
    for r in runs {
        for j in 0..r.count.min(left) {
            step(field, p, carry, r, j);
        }
        left -= r.count.min(left);
        if left == 0 {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deform::Translation;
    use crate::deform::refine::schedule;

    fn tool() -> Field {
        Field::single(Translation {
            center: DVec3::new(0.0, 0.0, 0.9),
            velocity: DVec3::new(0.5, 0.0, 0.0),
            radius: 0.9,
            reach: 0.9,
            power: 2,
            moving: true,
        })
    }

    #[test]
    fn blends_stay_on_the_surface_and_half_follows_the_tool() {
        // ρ = R: the mean of the one-sided velocities is the tool's velocity u, so Ψ(p, ½)
        // moves rigidly with the tool; s = 0 and s = 1 part to either side of it
        let f = tool();
        let runs = schedule(&f, 0.0, 1.0, 10).unwrap();
        let u = DVec3::new(0.5, 0.0, 0.0);
        let c = DVec3::new(0.0, 0.0, 0.9) + u; // the centre at t = 1
        let p0 = [DVec3::new(0.9, 0.0, 0.9), DVec3::new(0.0, 0.9, 0.9)];
        let mut at = Vec::new();
        for s in [0.0, 0.5, 1.0] {
            let mut p = p0;
            flow(&f, &mut p, &[Carry::Surface(s); 2], &runs, 10);
            for x in p {
                assert!(((x - c).length() - 0.9).abs() < 1e-9, "{s}: {x}");
            }
            at.push(p);
        }
        for k in 0..2 {
            // to O(δ |∇v|), δ the offset of the one-sided evaluations
            assert!((at[1][k] - (p0[k] + u)).length() < 1e-9, "{:?}", at[1][k]);
        }
        // where u is tangential the two sides part by about 2|u| t
        let gap = at[2][1].x - at[0][1].x;
        assert!(gap > 0.8 && gap < 1.0, "{gap}");
    }
}
