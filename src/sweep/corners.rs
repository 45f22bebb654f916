//! Where a sweep's spine gets a corner join: the samples whose chords turn too sharply for
//! one ring per sample (the joins themselves are built by [`super::join`]).
//!
//! A sample is a corner where its chords turn by 60° or more, or by 28° or more between
//! samples that turn by a quarter of it at most (a corner of the polyline whatever the
//! profile), or by 15° or more where its plain mitred ring would need more than
//! `miter_limit` or cross the ring of a neighbouring sample. For ring planes through `x_a`,
//! `x_b` with unit normals `n_a`, `n_b` (the chords' bisectors), the line where they meet lies
//! `|(x_b − x_a)·n_a| / |n_a × n_b|` from `x_b` within its plane, and the ring reaches
//! `ρ_b min(1 / cos(φ_b/2), miter_limit)` there (`ρ_b`: the largest distance of a profile
//! vertex from the spine, scaled).

use super::{Options, Profile};
use glam::{DVec2, DVec3};

/// How the outer side of a corner is built (see [`super::join`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Join {
    /// Rings turning about the corner, at most `2π / m` apart.
    #[default]
    Round,
    /// One flat band from the incoming ring to the outgoing one.
    Bevel,
    /// One ring in the bisector plane; a bevel where the mitre exceeds `miter_limit`.
    Miter,
}

/// `cos²` of the smallest turn that gets a join (15°).
const MIN_TURN_COS2: f64 = 0.933_012_701_892_219_3;

/// The smallest turn of a corner between straighter runs that gets a join however long its
/// legs (28°, in radians): the gentler kinks of a smooth curve keep their mitred ring.
const LONE_TURN: f64 = 0.488_692_190_558_412_2;

/// A corner of a spine that gets a join.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Corner {
    /// The spine sample.
    pub k: usize,
    /// Rings stored for the join besides the sample's own (0: a mitre).
    pub extra: usize,
}

/// The corners of the spine with distinct samples `x` (`scale`: one row per sample, or one
/// for all), in the order of the samples, given to `f`. A sample is a corner where its
/// chords turn by 60° or more, or by 28° or more while its neighbours turn by a quarter of
/// that at most, or by 15° or more where its mitred ring would need more than
/// `miter_limit`, or where its ring plane and a neighbour's meet within reach of either
/// ring: for ring planes
/// through `x_a`, `x_b` with unit normals `n_a`, `n_b` (the chords' bisectors; the chord at
/// an open end), the line where they meet lies `|(x_b − x_a)·n_a| / |n_a × n_b|` from `x_b`
/// within its plane, and the ring reaches `ρ_b min(1 / cos(φ_b/2), miter_limit)` there
/// (`ρ`: the largest distance of a profile vertex from the spine, scaled). Values that are
/// not finite make no corner (the spine's checks refuse them).
pub fn corners(
    x: &[DVec3],
    scale: &[DVec2],
    closed: bool,
    p: &Profile,
    opts: &Options,
    mut f: impl FnMut(Corner),
) {
    let n = x.len();
    if n < 3 {
        return;
    }
    let next = |k: usize| if k + 1 == n { 0 } else { k + 1 };
    let prev = |k: usize| if k == 0 { n - 1 } else { k - 1 };
    let interior = |k: usize| closed || (k > 0 && k + 1 < n);
    // the raw chord out of sample k (the closing chord on a closed spine)
    let raw = |k: usize| x[next(k)] - x[k];
    // a turn of 15° or more between chords `a` and `b` (squared lengths `la`, `lb`):
    // cos φ < cos 15°, decided without a square root
    let sharp = |a: DVec3, b: DVec3, la: f64, lb: f64| {
        let c = a.dot(b);
        c < 0.0 || c * c < MIN_TURN_COS2 * (la * lb)
    };
    // most spines have no such turn: one pass over the chords, each computed once
    let mut din = x[1] - x[0];
    let mut lin = din.length_squared();
    let mut candidates = false;
    for w in x[1..].windows(2) {
        let dout = w[1] - w[0];
        let lout = dout.length_squared();
        if sharp(din, dout, lin, lout) {
            candidates = true;
            break;
        }
        (din, lin) = (dout, lout);
    }
    if closed && !candidates {
        // the two turns at the closing chord
        let (a, b, c) = (raw(n - 2), raw(n - 1), raw(0));
        let (la, lb, lc) = (a.length_squared(), b.length_squared(), c.length_squared());
        candidates = sharp(a, b, la, lb) || sharp(b, c, lb, lc);
    }
    if !candidates {
        return;
    }
    let reach = p.points.iter().fold(0.0_f64, |m, q| m.max(q.length()));
    let rho = |k: usize| reach * scale[if scale.len() == 1 { 0 } else { k }].max_element();
    let unit = |k: usize| crate::math::scale::normalize(raw(k)).unwrap_or(DVec3::ZERO);
    // the ring plane's unit normal at sample k, and the ring's reach in it (with its mitre)
    let plane = |k: usize| -> (DVec3, f64) {
        if !interior(k) {
            return (unit(if k == 0 { 0 } else { n - 2 }), rho(k));
        }
        let (a, b) = (unit(prev(k)), unit(k));
        let half_cos = 0.5 * (a + b).length();
        let stretch = match half_cos * opts.miter_limit > 1.0 {
            true => 1.0 / half_cos,
            false => opts.miter_limit,
        };
        ((a + b).try_normalize().unwrap_or(a), rho(k) * stretch)
    };
    let crosses = |a: usize, b: usize| -> bool {
        let ((na, ea), (nb, eb)) = (plane(a), plane(b));
        let sin = na.cross(nb).length();
        let d = x[b] - x[a];
        sin > 1e-9 && (eb * sin >= d.dot(na).abs() || ea * sin >= d.dot(nb).abs())
    };
    let step = std::f64::consts::TAU / p.len() as f64;
    for k in (0..n).filter(|&k| interior(k)) {
        let (din, dout) = (unit(prev(k)), unit(k));
        let c = din.dot(dout);
        if din == DVec3::ZERO || dout == DVec3::ZERO || !(c * c.abs() < MIN_TURN_COS2) {
            continue;
        }
        let half_cos = (0.5 * (1.0 + c)).max(0.0).sqrt();
        let over = !(half_cos * opts.miter_limit >= 1.0);
        let phi = din.cross(dout).length().atan2(c);
        // a corner between straighter runs: its neighbours turn by a quarter of it at most
        let turn = |j: usize| match interior(j) {
            true => unit(prev(j)).angle_between(unit(j)),
            false => 0.0,
        };
        let lone = phi >= LONE_TURN && turn(prev(k)) <= 0.25 * phi && turn(next(k)) <= 0.25 * phi;
        let sharp = c <= 0.5; // 60° or more: the frames' tangent is the chords' bisector
        if !(over || lone || sharp || crosses(prev(k), k) || crosses(k, next(k))) {
            continue;
        }
        let extra = match opts.join {
            Join::Round => ((phi / step).ceil() as usize).max(1),
            Join::Bevel => 1,
            Join::Miter => usize::from(over),
        };
        f(Corner { k, extra });
    }
}
