//! Corner joins: where a spine turns too sharply for one ring per sample, the corner is built
//! from the two straight sweeps that meet there, as a 2D stroker joins two segments: the
//! inner side cut where the two sweeps meet, the outer side round, bevelled or mitred.
//!
//! At a corner sample `c` with unit chords `d₋` (in) and `d₊` (out), turning by `φ` about
//! `b = d₋ × d₊ / |d₋ × d₊|`, the outgoing ring `B` is the profile in the plane normal to
//! `d₊` (the sample's axes turned by the minimal rotation from its tangent to `d₊`), profile
//! vertex `j` at offset `q_j` from `c`, and the incoming ring is `A = Rot(b, −φ) B`.
//!
//! * **Inner side** (`q·m < 0`, with `m = (d₋ + d₊) / |d₋ + d₊|` the normal of the bisector
//!   plane): the two straight sweeps meet on the bisector plane, at the crease points
//!   `c + q + (−q·m / d₊·m) d₊` (the exact intersection of the two prisms; a point of the
//!   profile at distance `ρ` from the spine moves at most `ρ tan(φ/2)` along the leg).
//!   Every ring of the join, and every ring of a neighbouring sample whose vertex lies
//!   past the bisector plane, uses the crease vertex of its column: the rail edges there
//!   collapse (vertex by vertex, so the mesh stays a closed manifold) and the faces they
//!   flatten are left out, so that no face crosses the bisector plane on the inner side.
//! * **Outer side**: `join="round"` turns ring `A` into `B` about the axis `b` through `c`,
//!   in steps of at most `2π / m` (`m` profile vertices: the profile's own angular
//!   sampling), the surface of revolution of the profile about `b` (for a circle, the
//!   spherical wedge of the union of the two cylinders); `"bevel"` joins `A` to `B`
//!   directly; `"miter"` keeps the one ring in the bisector plane, with the crease formula
//!   on every column (the exact mitre of the two prisms), and bevels where the mitre would
//!   exceed `miter_limit`.
//!
//! A sample gets a join where its chords turn by 15° or more and its plain mitred ring
//! would either need more than `miter_limit` or cross the ring of a neighbouring sample
//! (their planes meet within the profile's reach, see [`corners`]), and where it is a
//! corner of the polyline whatever the profile: a turn of 60° or more, or of 28° or more
//! between samples that turn by a quarter of it at most. Everywhere else, and so on every
//! smooth, well-sampled spine, the rings are those of the plain sweep, bit for bit.
//!
//! **Layout.** The join's extra rings (ring `A` and the rings turning towards `B`, which is
//! the sample's own ring) are stored after the spine's rings, in the order of the corners;
//! vertex `(ring, column)` stays where the layout puts it. A vertex welded to a crease
//! keeps the crease's position and normal but is not referenced. Where the legs between
//! two corners are shorter than the crease needs, it is held to half of each leg, and the
//! fold-over test reports the segments that still cross.
//!
//! Normals at the crease are the mean of the two sweeps' normals there; on the rings of the
//! join those of the surface of revolution; on the rings next to a corner those of the
//! ring's own plane (their three-point derivative would reach across the corner).

use super::MeshMut;
pub use super::corners::{Corner, Join, corners};
use super::faces::FacePattern;
use super::kernel::{Cols, Geo};
use super::rings::Rings;
use super::scale::{Index, Real, put3, unscaled};
use crate::math::rotation::{minimal_rotation_matrix, rodrigues};
use glam::DVec3;

/// No weld (see [`write_joins`]).
const NONE: usize = usize::MAX;

/// Relative distance from the bisector plane within which a column counts as inner (on the
/// join's axis: welded rather than turned in place).
const ON_AXIS: f64 = 1e-9;

/// The turn of a corner: unit chords in and out, the unit axis `b` and the angle `φ`.
#[derive(Clone, Copy)]
struct Turn {
    din: DVec3,
    dout: DVec3,
    axis: DVec3,
    phi: f64,
}

/// The turn of every corner and the axes of its outgoing ring `B` (the profile's `(a, b)`
/// axes, normal to the outgoing chord). A corner alone takes them from its sample's frame
/// (turned by the minimal rotation from the frame's tangent to the chord). Along a chain of
/// corners at consecutive samples the rings are carried exactly instead, as the polyline's
/// own rotation-minimising frame: `A` of a corner has the axes of `B` before it (a straight
/// segment has no twist) and `B = Rot(b, φ) A`; the roll by which the chain's last `B`
/// then misses the frame of its sample (on a loop of corners, the first `B` carried once
/// round) is spread over the chain in proportion to arc length, `ψ_i = δ s_i / S`, each
/// ring rolled about its own tangent. So a coarse polyline's straight segments between
/// joins stay untwisted prisms (a twisted one loses volume and can fold at a sharp join).
fn corner_axes(rings: &Rings, corners: &[Corner]) -> (Vec<Turn>, Vec<(DVec3, DVec3)>) {
    let turns: Vec<Turn> = corners
        .iter()
        .map(|c| {
            let (din, dout) = (rings.chord(rings.before(c.k)), rings.chord(c.k));
            let cr = din.cross(dout);
            let axis = cr
                .try_normalize()
                .unwrap_or_else(|| super::super::frames::geometry::any_perpendicular(dout));
            Turn {
                din,
                dout,
                axis,
                phi: cr.length().atan2(din.dot(dout)),
            }
        })
        .collect();
    let from_frame = |ci: usize| {
        let k = corners[ci].k;
        let (_, a1, a2) = rings.base(k);
        let turn = minimal_rotation_matrix(rings.tangent(k), turns[ci].dout);
        (turn * a1, turn * a2)
    };
    let n = corners.len();
    let linked = |i: usize, j: usize| rings.after(corners[i].k) == corners[j].k;
    let arc = &rings.plan.arc;
    let nr = rings.plan.rings;
    let dist = |a: usize, b: usize| match (b > a, rings.closed) {
        (true, _) => arc[b] - arc[a],
        (false, true) => arc[nr] - arc[a] + arc[b],
        (false, false) => 0.0,
    };
    let mut axes = vec![(DVec3::ZERO, DVec3::ZERO); n];
    let starts: Vec<usize> = (0..n)
        .filter(|&i| match i {
            0 => !(n > 1 && linked(n - 1, 0)),
            _ => !linked(i - 1, i),
        })
        .collect();
    let looped = starts.is_empty(); // every sample of a loop is a corner
    let roll =
        |v: (DVec3, DVec3), t: DVec3, psi: f64| (rodrigues(v.0, t, psi), rodrigues(v.1, t, psi));
    for &s in if looped { &[0][..] } else { &starts[..] } {
        // the chain s, s + 1, … (indices of corners, wrapping on a loop)
        let mut chain = vec![s];
        while chain.len() < n {
            let (i, j) = (chain[chain.len() - 1], (chain[chain.len() - 1] + 1) % n);
            if !linked(i, j) || (!looped && j == s) {
                break;
            }
            chain.push(j);
        }
        axes[s] = from_frame(s);
        for w in chain.windows(2) {
            let (i, j) = (w[0], w[1]);
            axes[j] = roll(axes[i], turns[j].axis, turns[j].phi);
        }
        let last = chain[chain.len() - 1];
        if chain.len() < 2 {
            continue;
        }
        let (target, carried, at, total) = match looped {
            true => {
                let once = roll(axes[last], turns[s].axis, turns[s].phi);
                (axes[s], once, turns[s].dout, arc[nr])
            }
            false => (from_frame(last), axes[last], turns[last].dout, {
                dist(corners[s].k, corners[last].k)
            }),
        };
        let delta = crate::math::rotation::signed_angle(carried.0, target.0, at);
        if !(total > 0.0) || !delta.is_finite() {
            continue;
        }
        let k0 = corners[s].k;
        for &i in &chain[1..] {
            let psi = delta * dist(k0, corners[i].k) / total;
            axes[i] = roll(axes[i], turns[i].dout, psi);
        }
    }
    (turns, axes)
}

/// The unit tangent at `b` of the circle through `a`, `b`, `c` (`|v|² u + |u|² v` with
/// `u = b − a`, `v = c − b`; the chords' direction on a straight run).
fn circle_tangent(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    let (u, v) = (b - a, c - b);
    (v.length_squared() * u + u.length_squared() * v).try_normalize()
}

/// One vertex written by the joins: position (in the swept coordinates, see
/// [`unscaled`]), normal, and `u`.
fn put<R: Real>(
    out: &mut MeshMut<R, impl Index>,
    i: usize,
    (x, n): (DVec3, DVec3),
    unscale: Option<i32>,
) -> bool {
    let v = [
        unscaled::<R>(x.x, unscale),
        unscaled::<R>(x.y, unscale),
        unscaled::<R>(x.z, unscale),
    ];
    out.vertices[i] = v;
    if let Some(nr) = out.normals.as_deref_mut() {
        nr[i] = put3(n);
    }
    v.iter().all(|c| c.finite())
}

/// The joins of one spine, written over the plain sweep of its rings (`out`: the spine's
/// part of the buffers; `side_and_caps`: its faces before the joins' faces; `folds`: the
/// plain sweep's fold-over rows, corrected here). Returns the number of faces kept (the
/// faces left out are those the welds flatten, the kept ones moved to the front) and the
/// first vertex (local) out of the output type's range. Polls `cancel` between blocks of
/// corners; a stopped call leaves its part of the output incomplete.
// Kept whole: the corners, their welds and the rewrite of the faces they touch share a dozen
// flat stores (`weld_of`, `row_of`, `touched`, `bands`, …) and the closures over them.
#[allow(clippy::too_many_arguments)]
pub(super) fn write_joins<R: Real, I: Index>(
    rings: &Rings,
    corners: &[Corner],
    column: &Cols,
    pattern: &FacePattern,
    mut out: MeshMut<R, I>,
    side_and_caps: usize,
    vbase: usize,
    unscale: Option<i32>,
    folds: &mut Vec<usize>,
    cancel: crate::run::cancel::Cancel<'_>,
) -> (usize, Option<usize>) {
    let plan = rings.plan;
    let (cols, nr, stored) = (plan.cols, plan.rings, plan.stored_rings);
    let (closed, arc) = (rings.closed, &plan.arc);
    let split = closed && stored > nr;
    let per_seg = pattern.per_segment();
    let mut bad = None;
    // flat stores, indexed by ring (slot: the spine's rings, then the joins' rings) or by a
    // row that a slot points to (NONE: none), so that no ring has an allocation of its own
    let slots = stored + plan.extra;
    // per ring: the row of `welds` holding the crease vertex (local) each column is welded
    // to, or NONE
    let (mut weld_of, mut welds) = (vec![NONE; slots], Vec::<usize>::new());
    // per ring written here: the row of `pos` (its vertices' positions, swept coordinates)
    // and of `tangents` (its tangents as the end and as the start of a segment)
    let mut row_of = vec![NONE; slots];
    let (mut pos, mut tangents) = (Vec::<DVec3>::new(), Vec::<(DVec3, DVec3)>::new());
    // side segments whose faces the welds change → the ring their faces end on (NONE: not
    // changed)
    let mut touched = vec![NONE; stored];
    // join segments: (first face, from ring, to ring, corner sample)
    let mut bands: Vec<(usize, usize, usize, usize)> = Vec::new();
    let mut is_corner = vec![false; nr];
    for c in corners {
        is_corner[c.k] = true;
    }
    let mut claimed = is_corner.clone();
    let dist = |a: usize, b: usize| match b > a {
        true => arc[b] - arc[a],
        false => arc[nr] - arc[a] + arc[b],
    };
    let end_slot = |s: usize| if s + 1 == stored { 0 } else { s + 1 };
    // a segment's faces are changed (ending on the ring they end on unless already moved)
    let touch = |touched: &mut [usize], s: usize| {
        if touched[s] == NONE {
            touched[s] = end_slot(s);
        }
    };
    // the rings next to a round or bevelled corner, square to their own run (a tangent
    // estimate reaching across the corner would tilt them): tangent to the circle through
    // the ring's sample and its neighbours on that side, or along the chord where the run
    // ends there (a mitre keeps the frames' rings, whose bisector planes it joins)
    let (mut turned_of, mut turned) = (vec![NONE; nr], Vec::<Geo>::new());
    for c in corners.iter().filter(|c| c.extra > 0) {
        for ahead in [false, true] {
            let r = if ahead {
                rings.after(c.k)
            } else {
                rings.before(c.k)
            };
            if is_corner[r] || turned_of[r] != NONE {
                continue;
            }
            let x = rings.x;
            let t = match ahead {
                true if closed || r + 1 < nr => circle_tangent(x[c.k], x[r], x[rings.after(r)]),
                false if closed || r > 0 => circle_tangent(x[rings.before(r)], x[r], x[c.k]),
                true => (x[r] - x[c.k]).try_normalize(),
                false => (x[c.k] - x[r]).try_normalize(),
            };
            let Some(t) = t else { continue };
            let g = rings.geo_turned(r, t);
            turned_of[r] = turned.len();
            turned.push(g);
            let slots = match r == 0 && split {
                true => vec![0, nr],
                false => vec![r],
            };
            for slot in slots {
                for j in 0..cols {
                    let x = (g.b.0 + column.px[j] * g.ma) + column.py[j] * g.mb;
                    let w = (column.w[0][j], column.w[1][j]);
                    let n = rings.plane_normal(w, (g.b.1, g.b.2), g.t);
                    if !put(&mut out, slot * cols + j, (x, n), unscale) && bad.is_none() {
                        bad = Some(slot * cols + j);
                    }
                }
            }
            if closed || r > 0 {
                touch(&mut touched, rings.before(r));
            }
            if closed || r + 1 < nr {
                touch(&mut touched, r);
            }
        }
    }
    let geo_at = |slot: usize| {
        let k = if slot >= nr { slot - nr } else { slot };
        match turned_of.get(k) {
            Some(&i) if i != NONE => turned[i],
            _ => rings.geo(k),
        }
    };
    let (turns, axes) = corner_axes(rings, corners);
    // per column of the corner at hand: inner?, the outgoing ring B's vertex and normal,
    // the crease point and normal; the columns welded in the ring before and at hand
    let (mut inner, mut ring_b, mut crease) = (Vec::new(), Vec::new(), Vec::new());
    let (mut cur, mut now) = (Vec::new(), Vec::new());
    let (mut next_ring, mut jf) = (stored, side_and_caps);
    for (ci, c) in corners.iter().enumerate() {
        // a long rough spine has a corner at most samples: poll the stop between blocks of
        // them (a stopped sweep's output is discarded)
        if ci % 4096 == 0 && cancel() {
            return (side_and_caps, bad);
        }
        let k = c.k;
        // how far the crease may run along either leg: half the way to the next corner
        let back = match (ci, closed) {
            (0, false) => arc[k] - arc[0],
            (0, true) => 0.5 * dist(corners[corners.len() - 1].k, k),
            _ => 0.5 * dist(corners[ci - 1].k, k),
        };
        let ahead = match (corners.get(ci + 1), closed) {
            (Some(nc), _) => 0.5 * dist(k, nc.k),
            (None, true) => 0.5 * dist(k, corners[0].k),
            (None, false) => arc[nr - 1] - arc[k],
        };
        let run = back.min(ahead);
        let cx = rings.x[k];
        let Turn {
            din,
            dout,
            axis,
            phi,
        } = turns[ci];
        let (a1, a2) = axes[ci];
        let m = (din + dout).try_normalize();
        let den = m.map_or(0.0, |m| dout.dot(m));
        // per column: inner?, outgoing vertex, crease point, outgoing and crease normals
        inner.clear();
        ring_b.clear();
        crease.clear();
        for j in 0..cols {
            let q = column.px[j] * a1 + column.py[j] * a2;
            let side = m.map_or(0.0, |m| q.dot(m));
            let is_inner = den > 0.0 && side < ON_AXIS * q.length();
            inner.push(is_inner);
            let shift = match den > 0.0 {
                true if is_inner => (-side / den).clamp(0.0, run),
                true => (-side / den).clamp(-run, 0.0),
                false => 0.0,
            };
            let nb = rings.plane_normal((column.w[0][j], column.w[1][j]), (a1, a2), dout);
            let na = rodrigues(nb, axis, -phi);
            ring_b.push((cx + q, nb));
            crease.push((
                cx + q + shift * dout,
                (na + nb).try_normalize().unwrap_or(nb),
            ));
        }
        // the sample's own ring: B (its inner side on the crease), or the mitre
        let kb = k * cols;
        let rk = tangents.len();
        for j in 0..cols {
            let v = match c.extra == 0 || inner[j] {
                true => crease[j],
                false => ring_b[j],
            };
            if !put(&mut out, kb + j, v, unscale) && bad.is_none() {
                bad = Some(kb + j);
            }
            pos.push(v.0);
        }
        let into = match closed && k == 0 {
            true => nr - 1,
            false => k - 1,
        };
        row_of[k] = rk;
        tangents.push((if c.extra == 0 { din } else { dout }, dout));
        if k == 0 && split {
            // the seam's copy of the ring, which the segment into the corner ends on
            for j in 0..cols {
                let v = if c.extra == 0 || inner[j] {
                    crease[j]
                } else {
                    ring_b[j]
                };
                if !put(&mut out, nr * cols + j, v, unscale) && bad.is_none() {
                    bad = Some(nr * cols + j);
                }
            }
            // (the same positions and tangents as the ring's)
            row_of[nr] = rk;
        }
        // (a segment's end ring already moved to a corner's A stays moved)
        touch(&mut touched, k);
        touch(&mut touched, into);
        // the rings turning from A towards B, after the spine's rings
        let first = next_ring;
        let u = match k == 0 && split {
            true => arc[nr],
            false => arc[k],
        };
        for e in 0..c.extra {
            let (slot, ang) = (first + e, phi * e as f64 / c.extra as f64 - phi);
            let t = rodrigues(dout, axis, ang);
            let wr = welds.len();
            welds.resize(wr + cols, NONE);
            for j in 0..cols {
                let li = slot * cols + j;
                let v = match inner[j] {
                    true => {
                        welds[wr + j] = kb + j;
                        crease[j]
                    }
                    false => {
                        let (x, nb) = ring_b[j];
                        let x = cx + rodrigues(x - cx, axis, ang);
                        (x, rodrigues(nb, axis, ang))
                    }
                };
                if !put(&mut out, li, v, unscale) && bad.is_none() {
                    bad = Some(li);
                }
                pos.push(v.0);
                if let Some(uv) = out.uv.as_deref_mut() {
                    uv[li] = [unscaled(u, unscale), R::of(column.v[j])];
                }
            }
            weld_of[slot] = wr / cols;
            row_of[slot] = tangents.len();
            tangents.push((t, t));
            let to = if e + 1 < c.extra { slot + 1 } else { k };
            let faces = &mut out.faces[jf..jf + per_seg];
            pattern.write(faces, e % 2 == 1, vbase + slot * cols, vbase + to * cols, 0);
            bands.push((jf, slot, to, k));
            jf += per_seg;
        }
        next_ring += c.extra;
        if c.extra > 0 {
            // the segment into the corner ends on A
            let from = (end_slot(into) * cols, first * cols);
            for fc in &mut out.faces[into * per_seg..(into + 1) * per_seg] {
                for i in fc.iter_mut() {
                    let l = i.get() - vbase;
                    if (from.0..from.0 + cols).contains(&l) {
                        *i = I::of(vbase + l - from.0 + from.1);
                    }
                }
            }
            touched[into] = first;
        }
        // the neighbours' vertices past the bisector plane: welded to the crease, the rings
        // walked away from the corner while some column is welded (a column only where the
        // ring before it in the walk has it welded)
        let Some(m) = m else { continue };
        for ahead in [false, true] {
            cur.clone_from(&inner);
            let mut i = k;
            loop {
                let nx = if ahead {
                    rings.after(i)
                } else {
                    rings.before(i)
                };
                let end = match ahead {
                    true => nx + 1 == nr,
                    false => nx == 0,
                };
                if nx == k || claimed[nx] || (end && !closed) || (split && nx == 0) {
                    break;
                }
                let g = geo_at(nx);
                now.clear();
                now.resize(cols, false);
                for j in (0..cols).filter(|&j| cur[j]) {
                    let x = (g.b.0 + column.px[j] * g.ma) + column.py[j] * g.mb;
                    let past = (x - cx).dot(m);
                    if (ahead && past < 0.0) || (!ahead && past > 0.0) {
                        now[j] = true;
                        if weld_of[nx] == NONE {
                            weld_of[nx] = welds.len() / cols;
                            welds.resize(welds.len() + cols, NONE);
                        }
                        welds[weld_of[nx] * cols + j] = kb + j;
                        if !put(&mut out, nx * cols + j, crease[j], unscale) && bad.is_none() {
                            bad = Some(nx * cols + j);
                        }
                    }
                }
                if !now.iter().any(|&w| w) {
                    break;
                }
                claimed[nx] = true;
                touch(&mut touched, nx);
                touch(&mut touched, rings.before(nx));
                std::mem::swap(&mut cur, &mut now);
                i = nx;
            }
        }
    }
    // the vertex (local) that the faces use for vertex `l`, column `j` of a ring whose
    // welds are `w` (its crease vertex where it is welded)
    let welded = |l: usize, j: usize, w: Option<&[usize]>| match w.map(|w| w[j]) {
        Some(c) if c != NONE => c,
        _ => l,
    };
    // a ring's welds, and its positions where it was written here
    let weld = |s: usize| match weld_of[s] {
        NONE => None,
        r => Some(&welds[r * cols..(r + 1) * cols]),
    };
    let written = |s: usize| match row_of[s] {
        NONE => None,
        r => Some(&pos[r * cols..(r + 1) * cols]),
    };
    // the welds on the faces they touch (each segment's faces use two rings), and the faces
    // they flatten
    let changed = || (0..stored).filter(|&s| touched[s] != NONE);
    let ranges = changed()
        .map(|s| (s * per_seg..(s + 1) * per_seg, s, touched[s]))
        .chain(bands.iter().map(|&(f, a, b, _)| (f..f + per_seg, a, b)));
    let mut dropped = Vec::new();
    for (si, (r, a, b)) in ranges.enumerate() {
        if si % 4096 == 0 && cancel() {
            return (side_and_caps, bad);
        }
        let (wa, wb) = (weld(a), weld(b));
        let (la, lb) = (vbase + a * cols, vbase + b * cols);
        for fi in r {
            let f = &mut out.faces[fi];
            if wa.is_some() || wb.is_some() {
                for i in f.iter_mut() {
                    let g = i.get();
                    let t = match (g.wrapping_sub(la), g.wrapping_sub(lb)) {
                        (j, _) if j < cols => welded(g - vbase, j, wa),
                        (_, j) if j < cols => welded(g - vbase, j, wb),
                        _ => g - vbase,
                    };
                    if t + vbase != g {
                        *i = I::of(vbase + t);
                    }
                }
            }
            let [a, b, c] = f.map(|i| i.get());
            if a == b || b == c || a == c {
                dropped.push(fi);
            }
        }
    }
    // fold-over on the segments the joins changed, on the vertices as written
    let row = |s: usize| rings.rowbase + s;
    folds.retain(|&r| touched[r - rings.rowbase] == NONE);
    // a vertex of ring `slot` as the faces use it (its weld) and its position (`w`, `p`,
    // `g`: the ring's welds, written positions or plain geometry)
    let at = |slot: usize, j: usize, w: Option<&[usize]>, p: Option<&[DVec3]>, g: &Option<Geo>| {
        let l = slot * cols + j;
        let t = welded(l, j, w);
        let x = match (t == l, p) {
            (true, Some(p)) => p[j],
            (false, _) => pos[row_of[t / cols] * cols + t % cols],
            (true, None) => {
                let g = g.unwrap_or_else(|| geo_at(slot));
                (g.b.0 + column.px[j] * g.ma) + column.py[j] * g.mb
            }
        };
        (t, x)
    };
    let tangent = |slot: usize, start: bool| match row_of[slot] {
        NONE => geo_at(slot).t,
        r => match start {
            true => tangents[r].1,
            false => tangents[r].0,
        },
    };
    let folded = |a: usize, b: usize| {
        let plain = |slot: usize| match slot < stored && row_of[slot] == NONE {
            true => Some(geo_at(slot)),
            false => None,
        };
        let (ga, gb) = (plain(a), plain(b));
        // (a ring not written here has the tangent of its geometry)
        let ta = ga.map_or_else(|| tangent(a, true), |g| g.t);
        let tb = gb.map_or_else(|| tangent(b, false), |g| g.t);
        let (wa, wb, pa, pb) = (weld(a), weld(b), written(a), written(b));
        (0..cols).any(|j| {
            let (ia, xa) = at(a, j, wa, pa, &ga);
            let (ib, xb) = at(b, j, wb, pb, &gb);
            let e = xb - xa;
            ia != ib && !(e.dot(ta) > 0.0 && e.dot(tb) > 0.0)
        })
    };
    let segments = changed().map(|s| (s, touched[s], s));
    let mut new_folds = Vec::new();
    for (i, (a, b, at)) in segments
        .chain(bands.iter().map(|&(_, a, b, k)| (a, b, k)))
        .enumerate()
    {
        if i % 4096 == 0 && cancel() {
            return (side_and_caps, bad);
        }
        if folded(a, b) {
            new_folds.push(row(at));
        }
    }
    folds.extend(new_folds);
    folds.sort_unstable();
    folds.dedup();
    // the faces kept, moved to the front
    dropped.sort_unstable();
    let total = jf;
    let Some(&start) = dropped.first() else {
        return (total, bad);
    };
    let mut w = start;
    for (di, &d) in dropped.iter().enumerate() {
        let end = dropped.get(di + 1).copied().unwrap_or(total);
        out.faces.copy_within(d + 1..end, w);
        w += end - d - 1;
    }
    (w, bad)
}
