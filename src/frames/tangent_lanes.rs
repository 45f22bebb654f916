//! The interior rows of the five-point chord-length tangent (the default rule of
//! [`super::tangents`]), four rows per operation.
//!
//! At a centred row `i` (`2 ≤ i < n − 2` of an open curve) the scalar estimate is
//! `u = v/|v|` with `v = Σ_j w_j (x_j − x_i)` (the Lagrange weights of the quartic through
//! the five samples at their cumulative chord lengths, [`centred_weights`]; Wang, Jüttler,
//! Zheng & Liu, ACM TOG 2008, §6.1, at chord-length parameters), kept where it passes two
//! cheap tests: within 60° of the circle estimate `|c_i|² c_{i−1} + |c_{i−1}|² c_i`
//! (`guard_overshoot`) and, with the chords `c_{i−1}, c_i` turning by less than 30°, within
//! 60° of both (the test of `guard_chords`). A smooth sampling passes them at every row. Here
//! the same IEEE operations in the same order run on four consecutive rows at once ([`F4`]:
//! lane for lane the bits of the scalar formula), so the chords are loaded once per group
//! and the tests cost a few vector comparisons; a group in which a lane fails a test (or sits
//! next to an end) is left to the scalar function, which decides as before. The result is
//! the scalar estimate bit for bit on every input.

use glam::DVec3;

use super::lanes::{Arith, F4, L, V4};

/// The unit tangents of the rows `g … g + 3` (all four centred: `2 ≤ g`, `g + 6 ≤ n`) when
/// each passes the scalar rule's tests, else `None` (the caller then asks the scalar
/// function for each row). `h` are the chords `|x_{j+1} − x_j|` of `validate::chords`.
#[inline(always)]
pub fn centred_group(x: &[DVec3], h: &[f64], g: usize) -> Option<[DVec3; L]> {
    // the eight samples g − 2 … g + 5 as coordinate arrays
    let pts = &x[g - 2..g + 6];
    let px: [f64; 8] = std::array::from_fn(|j| pts[j].x);
    let py: [f64; 8] = std::array::from_fn(|j| pts[j].y);
    let pz: [f64; 8] = std::array::from_fn(|j| pts[j].z);
    let at = |o: usize| V4 {
        x: F4::load(&px, o),
        y: F4::load(&py, o),
        z: F4::load(&pz, o),
    };
    let wt = centred_weights(
        F4::load(h, g - 2),
        F4::load(h, g - 1),
        F4::load(h, g),
        F4::load(h, g + 1),
    );
    let (p0, p1, pc, p3, p4) = (at(0), at(1), at(2), at(3), at(4));
    let v = (p0 - pc).scale(wt[0])
        + (p1 - pc).scale(wt[1])
        + (p3 - pc).scale(wt[2])
        + (p4 - pc).scale(wt[3]);
    let l = v.dot(v).sqrt();
    let u = v.scale(F4::splat(1.0) / l);
    // the chords either side (`x_i − x_{i−1}`, `x_{i+1} − x_i`) and their squares
    let (ci, co) = (pc - p1, p3 - pc);
    let (qi, qo) = (ci.dot(ci), co.dot(co));
    // the circle estimate (`circle_raw`): |c_i|² c_{i−1} + |c_{i−1}|² c_i
    let cw = ci.scale(qo) + co.scale(qi);
    let d = u.dot(cw);
    let (a, b, turn) = (u.dot(ci), u.dot(co), ci.dot(co));
    let zero = F4::splat(0.0);
    let margin2 = F4::splat(CHORD_MARGIN * CHORD_MARGIN);
    let good = l.mask(zero, |p, q| p > q)
        & u.finite_mask()
        & d.mask(zero, |p, q| p >= q)
        & (d * d).mask(
            F4::splat(OVERSHOOT_COS * OVERSHOOT_COS) * cw.dot(cw),
            |p, q| p >= q,
        )
        & turn.mask(zero, |p, q| p >= q)
        & (turn * turn).mask(F4::splat(CORNER_COS2) * (qi * qo), |p, q| p >= q)
        & a.mask(zero, |p, q| p >= q)
        & b.mask(zero, |p, q| p >= q)
        & (a * a).mask(margin2 * qi, |p, q| p >= q)
        & (b * b).mask(margin2 * qo, |p, q| p >= q);
    if good != 0b1111 {
        return None;
    }
    Some(std::array::from_fn(|k| {
        DVec3::new(u.x.0[k], u.y.0[k], u.z.0[k])
    }))
}

/// The rows of [`centred_group`] that rows `i` belong to (groups start at multiples of 4),
/// or `None` where that group is not centred on a curve of `n` samples.
#[inline(always)]
pub fn group_of(i: usize, n: usize) -> Option<usize> {
    let g = i & !(L - 1);
    (g >= 2 && g + 6 <= n).then_some(g)
}

/// Smallest accepted margin of an estimated tangent against the chords at its sample,
/// relative to the bisector's (see [`guard_chords`](super::tangents::guard_chords)).
pub const CHORD_MARGIN: f64 = 0.5;

/// Cosine of the turn between two chords below which an estimate is left alone (30°), and
/// of the turn from which the bisector replaces it (60°); see [`guard_chords`](super::tangents::guard_chords).
pub const CORNER_COS: [f64; 2] = [0.866_025_403_784_438_6, 0.5];

/// `cos² 30° = 3/4`, for [`guard_chords`](super::tangents::guard_chords)' test without square roots.
pub const CORNER_COS2: f64 = 0.75;

/// Smallest accepted cosine between the five-point estimate and the circle (3-point)
/// estimate; below it the quartic overshoots (a kink, or wildly uneven spacing) and the
/// circle estimate is used.
pub const OVERSHOOT_COS: f64 = 0.5;

/// The weights of `centred_five_point` in [`super::tangents`] for `x₀, x₁, x₃, x₄` (relative to `x₂`); generic so
/// that the fused path evaluates the same formula four samples at a time.
#[inline(always)]
pub(super) fn centred_weights<T: Arith>(h0: T, h1: T, h2: T, h3: T) -> [T; 4] {
    // Positions relative to x₂, scaled by 1/(h₁ + h₂): the direction does not depend on the
    // scale, and O(1) values keep the products below far from under/overflow.
    let k = T::splat(1.0) / (h1 + h2);
    let (t0, t1, t3, t4) = (-(h0 + h1) * k, -h1 * k, h2 * k, (h2 + h3) * k);
    // Lagrange weights w_j = n_j / d_j; multiplying all by d₀d₁d₃d₄ (> 0 for
    // t₀ < t₁ < 0 < t₃ < t₄) leaves the direction and needs no division.
    let d0 = (t0 - t1) * t0 * (t0 - t3) * (t0 - t4);
    let d1 = (t1 - t0) * t1 * (t1 - t3) * (t1 - t4);
    let d3 = (t3 - t0) * (t3 - t1) * t3 * (t3 - t4);
    let d4 = (t4 - t0) * (t4 - t1) * t4 * (t4 - t3);
    let (d01, d34) = (d0 * d1, d3 * d4);
    [
        -(t1 * t3 * t4) * (d1 * d34),
        -(t0 * t3 * t4) * (d0 * d34),
        -(t0 * t1 * t4) * (d01 * d4),
        -(t0 * t1 * t3) * (d01 * d3),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::tangents::five_point_unit_open;
    use crate::run::cancel;

    /// Every group's rows against the scalar function, bit for bit; returns (groups taken
    /// four at a time, groups left to the scalar function).
    fn compare(x: &[DVec3]) -> (usize, usize) {
        let h = crate::frames::validate::chords(x, false, "points", &cancel::never).unwrap();
        let (mut fast, mut slow) = (0, 0);
        for g in (0..x.len()).step_by(L) {
            let Some(g) = group_of(g, x.len()) else {
                continue;
            };
            match centred_group(x, &h, g) {
                Some(t) => {
                    fast += 1;
                    for (k, tk) in t.iter().enumerate() {
                        let s = five_point_unit_open(x, g + k, |j| h[j]).unwrap();
                        assert_eq!(
                            tk.to_array().map(f64::to_bits),
                            s.to_array().map(f64::to_bits)
                        );
                    }
                }
                None => slow += 1,
            }
        }
        (fast, slow)
    }

    #[test]
    fn groups_are_the_scalar_tangents_bit_for_bit() {
        // a smooth helix: every centred group four at a time
        let x: Vec<DVec3> = (0..4003)
            .map(|i| {
                let u = i as f64 * 0.01;
                DVec3::new(u.cos(), u.sin(), 0.05 * u)
            })
            .collect();
        let (fast, slow) = compare(&x);
        assert!(fast > 990 && slow == 0, "{fast} {slow}");
        // a random walk (a linear congruential stream): most groups turn, some pass
        let mut s = 12345u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        let mut x = vec![DVec3::ZERO];
        for k in 1..20_000 {
            // smooth stretches between rough ones
            let d = if (k / 40) % 2 == 0 {
                DVec3::new(1.0, 0.3 * (k as f64 * 0.05).sin(), 0.0)
            } else {
                DVec3::new(r(), r(), r())
            };
            x.push(*x.last().unwrap() + d);
        }
        let (fast, slow) = compare(&x);
        assert!(fast > 100 && slow > 100, "{fast} {slow}");
    }
}
