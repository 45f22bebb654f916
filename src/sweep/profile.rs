//! The swept profile: a polygon in the normal plane, coordinates `(a, b)` along the frame's
//! `(r, s)` axes.
//!
//! * A closed profile is a simple polygon (no self-intersection); its orientation is read
//!   from the signed area `A = ½ Σ (a_j b_{j+1} − a_{j+1} b_j)` (shoelace formula) and the
//!   faces are wound so that they face outwards whichever way the user listed the vertices.
//! * The `v` texture coordinate of vertex `j` is its arc length along the profile divided by
//!   the perimeter (closed) or by the total length (open).
//! * Caps are a triangulation of the polygon on its own vertices (every simple polygon of
//!   `m` vertices splits into `m − 2` triangles by diagonals), so non-convex profiles
//!   (mouldings, stars, letters) are capped correctly and no vertex is added.
//!
//! **Cost.** A strictly convex polygon (every turn the same way, total turning ±2π) is
//! simple and is fanned from its first vertex: O(m). Other polygons are checked for
//! self-intersection by the sweep line of Shamos and Hoey in O(m log m) with exact
//! orientation tests (adjacent edges that fold back onto each other count as meeting), and
//! triangulated in O(m log m) with the same tests: a second sweep cuts them into y-monotone
//! pieces, each triangulated with a stack in linear time (de Berg et al., *Computational
//! Geometry: Algorithms and Applications*, §3.2–3.3; see `monotone.rs`).

use glam::DVec2;

use crate::error::{InputError, Result};
use crate::math::predicates::orient;
use crate::run::alloc;
use crate::run::cancel::{self, BLOCK, Cancel};

/// A validated profile.
#[derive(Debug, Clone)]
pub struct Profile {
    /// Profile vertices `(a, b)` along the frame's `(r, s)` columns.
    pub points: Vec<DVec2>,
    /// The profile is a closed polygon (else an open polyline).
    pub closed: bool,
    /// Signed area (closed profiles; 0 for open ones).
    pub area: f64,
    /// `v` coordinate of every vertex, in `[0, 1)` (closed) or `[0, 1]` (open).
    pub v: Vec<f64>,
    /// A closed, strictly convex polygon (its caps are a fan).
    pub convex: bool,
}

/// Most vertices a profile may have.
pub const MAX_VERTICES: usize = 1 << 24;

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Signed area of a closed polygon (positive when counter-clockwise).
pub fn signed_area(p: &[DVec2]) -> f64 {
    let m = p.len();
    0.5 * (0..m).map(|j| cross(p[j], p[(j + 1) % m])).sum::<f64>()
}

/// Do the closed segments `p q` and `r s` intersect (touching counts)? Exact.
fn segments_meet(p: DVec2, q: DVec2, r: DVec2, s: DVec2) -> bool {
    use std::cmp::Ordering::Equal;
    let d1 = orient(p, q, r);
    let d2 = orient(p, q, s);
    let d3 = orient(r, s, p);
    let d4 = orient(r, s, q);
    if d1 != Equal && d2 != Equal && d1 != d2 && d3 != Equal && d4 != Equal && d3 != d4 {
        return true;
    }
    // an endpoint on the other segment (collinear and within its box)
    let on = |a: DVec2, b: DVec2, c: DVec2, d| {
        d == Equal
            && c.x >= a.x.min(b.x)
            && c.x <= a.x.max(b.x)
            && c.y >= a.y.min(b.y)
            && c.y <= a.y.max(b.y)
    };
    on(p, q, r, d1) || on(p, q, s, d2) || on(r, s, p, d3) || on(r, s, q, d4)
}

/// `a` before `b` in the sweep's order: by `x`, then by `y`.
fn lex(a: DVec2, b: DVec2) -> std::cmp::Ordering {
    use std::cmp::Ordering::{Equal, Greater, Less};
    if a.x < b.x || (a.x == b.x && a.y < b.y) {
        Less
    } else if a == b {
        Equal
    } else {
        Greater
    }
}

/// An edge in the sweep's active set: its endpoints in sweep order (`l` before `r`).
#[derive(Clone, Copy, Debug)]
struct Active {
    l: DVec2,
    r: DVec2,
    id: usize,
}

impl Active {
    /// The order of `self` and `t` along a sweep line that crosses both, when `self` enters
    /// the sweep first: `Less` when `t` lies above (to the left of `l → r`).
    fn below(&self, t: &Active) -> std::cmp::Ordering {
        use std::cmp::Ordering::Equal;
        match orient(self.l, self.r, t.l) {
            Equal => match orient(self.l, self.r, t.r) {
                Equal => self.id.cmp(&t.id), // collinear: by index
                o => o.reverse(),
            },
            o => o.reverse(),
        }
    }
}

impl PartialEq for Active {
    fn eq(&self, o: &Self) -> bool {
        self.id == o.id
    }
}

impl Eq for Active {}

impl PartialOrd for Active {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Active {
    /// Bottom to top along the sweep line (consistent while no two active edges cross,
    /// which is all the sweep needs: it stops at the first crossing).
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        if self.id == o.id {
            std::cmp::Ordering::Equal
        } else if lex(self.l, o.l) != std::cmp::Ordering::Greater {
            self.below(o)
        } else {
            o.below(self).reverse()
        }
    }
}

/// Do the edges `a b` and `b c` overlap (`c` back along `b a`: a turn of exactly 180°)?
/// Exact: collinearity by [`orient`], the side by comparing coordinates.
fn folds_back(a: DVec2, b: DVec2, c: DVec2) -> bool {
    orient(a, b, c) == std::cmp::Ordering::Equal && lex(a, b) == lex(c, b)
}

/// A pair of edges `(a, b)`, `a < b`, that meet other than adjacent edges at their shared
/// vertex (touching counts; adjacent edges that fold back onto each other meet), or `None`
/// for a simple polyline/polygon: the sweep line of Shamos and Hoey ("Geometric intersection
/// problems", FOCS 1976) over the endpoints in `(x, y)` order, the edges crossing the line
/// kept in order in a B-tree, every edge tested against its neighbours when it enters and
/// the two edges it separated when it leaves. O(m log m), with exact predicates. Several
/// edges ending at one point and edges folding back are found before the sweep, so that
/// the ordered edges meet only where the sweep tests them. Polls `cancel` between its
/// passes and every [`BLOCK`] events within them ([`InputError::stopped`] when it says stop).
fn sweep_crossing(p: &[DVec2], closed: bool, cancel: Cancel<'_>) -> Result<Option<(usize, usize)>> {
    let stop = || match cancel() {
        true => Err(InputError::stopped()),
        false => Ok(()),
    };
    use std::collections::BTreeSet;
    use std::ops::Bound::{Excluded, Unbounded};
    let m = p.len();
    let edges = if closed { m } else { m - 1 };
    let seg: Vec<Active> = (0..edges)
        .map(|e| {
            let (a, b) = (p[e], p[(e + 1) % m]);
            let (l, r) = if lex(a, b) == std::cmp::Ordering::Greater {
                (b, a)
            } else {
                (a, b)
            };
            Active { l, r, id: e }
        })
        .collect();
    // (point, 0 = enter / 1 = leave, edge): at a shared point every edge enters before
    // any leaves, so edges that touch there are in the set together
    let mut events: Vec<(DVec2, u8, usize)> = Vec::with_capacity(2 * edges);
    for s in &seg {
        events.push((s.l, 0, s.id));
        events.push((s.r, 1, s.id));
    }
    stop()?;
    // the keys are distinct (an edge enters and leaves once)
    let by = |x: &(DVec2, u8, usize), y: &(DVec2, u8, usize)| {
        lex(x.0, y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2))
    };
    if !cancel::sort_by(&mut events, by, cancel) {
        return Err(InputError::stopped());
    }
    let adjacent = |a: usize, b: usize| {
        let (a, b) = (a.min(b), a.max(b));
        b == a + 1 || (closed && a == 0 && b == m - 1)
    };
    let meet = |a: &Active, b: &Active| {
        (!adjacent(a.id, b.id) && segments_meet(a.l, a.r, b.l, b.r))
            .then(|| (a.id.min(b.id), a.id.max(b.id)))
    };
    let first = usize::from(!closed);
    if let Some(j) =
        (first..m - first).find(|&j| folds_back(p[(j + m - 1) % m], p[j], p[(j + 1) % m]))
    {
        let a = (j + m - 1) % m;
        return Ok(Some((a.min(j), a.max(j))));
    }
    stop()?;
    // edges that end at the same point: around a vertex only its two edges may, so three
    // (of which two are not adjacent) or two non-adjacent ones meet there
    for (g, group) in events.chunk_by(|x, y| x.0 == y.0).enumerate() {
        if g % BLOCK == 0 {
            stop()?;
        }
        let ids: Vec<usize> = group.iter().take(3).map(|e| e.2).collect();
        for (i, &a) in ids.iter().enumerate() {
            for &b in &ids[i + 1..] {
                if !adjacent(a, b) {
                    return Ok(Some((a.min(b), a.max(b))));
                }
            }
        }
    }
    let mut set = BTreeSet::new();
    for (i, &(_, kind, e)) in events.iter().enumerate() {
        if i % BLOCK == 0 {
            stop()?;
        }
        let s = seg[e];
        let below = set.range(..s).next_back().copied();
        let above = set.range((Excluded(s), Unbounded)).next().copied();
        if kind == 0 {
            set.insert(s);
            for t in [below, above].into_iter().flatten() {
                if let Some(hit) = meet(&s, &t) {
                    return Ok(Some(hit));
                }
            }
        } else {
            set.remove(&s);
            if let (Some(b), Some(a)) = (below, above) {
                if let Some(hit) = meet(&b, &a) {
                    return Ok(Some(hit));
                }
            }
        }
    }
    Ok(None)
}

/// The call named in out-of-memory errors.
const CALL: &str = "sweep";

/// Bytes per profile vertex that the self-intersection test and the cap triangulation of a
/// non-convex profile take at most (their sorted events, sweep-line trees and edge lists;
/// about 40 measured on a 2²²-vertex star).
const WORKING_BYTES_PER_VERTEX: usize = 64;

/// Fails with the out-of-memory error unless the working memory of the sweep-line passes
/// over `m` profile vertices can be had now (their trees allocate infallibly); the probe is
/// freed at once.
fn probe(m: usize) -> Result<()> {
    let bytes = alloc::product(CALL, m, WORKING_BYTES_PER_VERTEX, 1)?;
    alloc::with_capacity::<u8>(CALL, bytes)
        .map_err(|_| InputError::out_of_memory(CALL, m, WORKING_BYTES_PER_VERTEX))?;
    Ok(())
}

impl Profile {
    /// Validate `points` (an `(m, 2)` polygon). A closed profile may repeat its first vertex
    /// at the end; it is dropped.
    ///
    /// Polls `cancel` in the self-intersection test of a non-convex profile (O(m log m)); fails
    /// with [`InputError::stopped`] when it says stop.
    pub fn new(points: &[DVec2], closed: bool, cancel: Cancel<'_>) -> Result<Profile> {
        const ARG: &str = "profile";
        // each pass over the vertices is followed by a poll, the slow ones (the convexity
        // test's arc tangents, the arc lengths) poll every [`BLOCK`] vertices as well
        let poll = || match cancel() {
            true => Err(InputError::stopped()),
            false => Ok(()),
        };
        if let Some(j) = crate::frames::validate::first_bad(points, |p| p.is_finite(), cancel) {
            return Err(InputError::new(ARG, format!("non-finite value at row {j}")));
        }
        poll()?;
        let mut p = alloc::copied(CALL, points)?;
        poll()?;
        let scale = p.iter().fold(0.0_f64, |a, q| a.max(q.abs().max_element()));
        let same = |a: DVec2, b: DVec2| (a - b).abs().max_element() <= 8.0 * f64::EPSILON * scale;
        if closed && p.len() >= 2 && same(p[0], p[p.len() - 1]) {
            p.pop();
        }
        let m = p.len();
        if m > MAX_VERTICES {
            return Err(InputError::new(
                ARG,
                format!("at most {MAX_VERTICES} vertices (2**24), got {m}"),
            ));
        }
        let min = if closed { 3 } else { 2 };
        if m < min {
            return Err(InputError::new(
                ARG,
                format!(
                    "a{} profile needs at least {min} distinct vertices, got {m}",
                    if closed { " closed" } else { "n open" }
                ),
            ));
        }
        let edges = if closed { m } else { m - 1 };
        // the area and intersection tests multiply coordinates: run them on the polygon
        // divided by the power of two of its largest coordinate (exact), so that any finite
        // size works
        let k = unit_exponent(scale);
        poll()?;
        let q: Vec<DVec2> = alloc::collect(CALL, p.iter().map(|&v| scaled(v, k)))?;
        poll()?;
        let (p_all, p) = (p, q);
        let scale = crate::math::scale::ldexp(scale, k);
        let same = |a: DVec2, b: DVec2| (a - b).abs().max_element() <= 8.0 * f64::EPSILON * scale;
        if let Some(j) = (0..edges).find(|&j| same(p[j], p[(j + 1) % m])) {
            return Err(InputError::new(
                ARG,
                format!(
                    "vertices {j} and {} coincide (a zero-length edge)",
                    (j + 1) % m
                ),
            ));
        }
        poll()?;
        let convex = closed && strictly_convex(&p, cancel)?;
        // a closed polygon on one line folds back on itself: its zero area is the clearer
        // message
        let on_a_line = || {
            closed
                && (0..m).all(|j| {
                    orient(p[(j + m - 1) % m], p[j], p[(j + 1) % m]) == std::cmp::Ordering::Equal
                })
        };
        if !convex && !on_a_line() {
            probe(m)?;
            if let Some((a, b)) = sweep_crossing(&p, closed, cancel)? {
                return Err(InputError::new(
                    ARG,
                    format!(
                        "the polygon intersects itself (edges {a}–{} and {b}–{}); a \
                         profile must be a simple polygon",
                        (a + 1) % m,
                        (b + 1) % m
                    ),
                ));
            }
        }
        poll()?;
        let area = if closed { signed_area(&p) } else { 0.0 };
        if closed && !(area.abs() > 1e-12 * scale * scale) {
            return Err(InputError::new(
                ARG,
                "the closed polygon has zero area (its vertices are collinear)",
            ));
        }
        // the area in the units of the input (it fits where the polygon does)
        let area = crate::math::scale::ldexp(area, -2 * k);
        let p = p_all;
        let mut v = alloc::with_capacity(CALL, m)?;
        let mut acc = 0.0;
        for j in 0..m {
            if j % BLOCK == 0 {
                poll()?;
            }
            v.push(acc);
            if j + 1 < m || closed {
                acc += crate::math::scale::length((p[(j + 1) % m] - p[j]).extend(0.0));
            }
        }
        for x in v.iter_mut() {
            *x /= acc;
        }
        Ok(Profile {
            points: p,
            closed,
            area,
            v,
            convex,
        })
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Triangles `[a, b, c]` covering the polygon, counter-clockwise in the profile plane
    /// (so their normal is `+t`, the direction of travel).
    ///
    /// Polls `cancel` in the triangulation of a non-convex profile (O(m log m)); fails with
    /// [`InputError::stopped`] when it says stop.
    pub fn triangulate(&self, cancel: Cancel<'_>) -> Result<Vec<[usize; 3]>> {
        let m = self.points.len();
        // Counter-clockwise vertex order.
        let ccw: Vec<usize> = if self.area > 0.0 {
            alloc::collect(CALL, 0..m)?
        } else {
            alloc::collect(CALL, (0..m).rev())?
        };
        if self.convex {
            return alloc::collect(CALL, (1..m - 1).map(|k| [ccw[0], ccw[k], ccw[k + 1]]));
        }
        probe(m)?;
        // the exact predicates on the polygon brought near unit size, as in the check of
        // [`Profile::new`]
        let scale = (self.points.iter()).fold(0.0_f64, |a, q| a.max(q.abs().max_element()));
        let k = unit_exponent(scale);
        let q: Vec<DVec2> = alloc::collect(CALL, ccw.iter().map(|&i| scaled(self.points[i], k)))?;
        let mut tris = super::monotone::triangulate(&q, cancel)?;
        for t in tris.iter_mut() {
            *t = t.map(|i| ccw[i]);
        }
        Ok(tris)
    }
}

/// The power of two `k` that brings the largest coordinate `scale` of a polygon into
/// `[1, 2)` (0 for a polygon at the origin).
fn unit_exponent(scale: f64) -> i32 {
    if scale > 0.0 {
        -crate::math::scale::exponent(scale)
    } else {
        0
    }
}

/// `v 2^k`, exactly while the result is normal.
fn scaled(v: DVec2, k: i32) -> DVec2 {
    DVec2::new(
        crate::math::scale::ldexp(v.x, k),
        crate::math::scale::ldexp(v.y, k),
    )
}

/// Is the closed polygon strictly convex: every turn of the same sign and the total turning
/// ±2π (a convex polygon wound once is simple)?
fn strictly_convex(p: &[DVec2], cancel: Cancel<'_>) -> Result<bool> {
    let m = p.len();
    let (mut pos, mut neg, mut turning) = (false, false, 0.0);
    for j in 0..m {
        if j % BLOCK == 0 && cancel() {
            return Err(InputError::stopped());
        }
        let e1 = p[(j + 1) % m] - p[j];
        let e2 = p[(j + 2) % m] - p[(j + 1) % m];
        let c = cross(e1, e2);
        pos |= c > 0.0;
        neg |= c < 0.0;
        if !(c != 0.0) || (pos && neg) {
            return Ok(false);
        }
        turning += c.atan2(e1.dot(e2));
    }
    Ok((turning.abs() - std::f64::consts::TAU).abs() < 1.0)
}

/// Square cells of side `side` (the median edge length, but at least a quarter of the mean, so
/// that a few edges far longer than the rest cross O(m) cells in all) holding items (edges or
/// vertices), sorted by cell: memory and time follow the items, not the bounding box.
#[cfg(test)]
struct Cells {
    lo: DVec2,
    inv: f64,
    /// `(cell key, item)`, sorted.
    items: Vec<(u64, usize)>,
}

#[cfg(test)]
impl Cells {
    fn new(p: &[DVec2], closed: bool) -> Cells {
        let m = p.len();
        let edges = if closed { m } else { m - 1 };
        let mut len: Vec<f64> = (0..edges)
            .map(|j| (p[(j + 1) % m] - p[j]).length())
            .collect();
        let total: f64 = len.iter().sum();
        let mid = len.len() / 2;
        let median = *len.select_nth_unstable_by(mid, f64::total_cmp).1;
        // Σ (2 len / side + 1) ≤ 8 edges + edges samples of 9 cells each
        let side = median.max(total / (4.0 * edges as f64));
        let lo = p.iter().fold(DVec2::INFINITY, |a, &q| a.min(q)) - DVec2::splat(side);
        Cells {
            lo,
            inv: if side > 0.0 { 1.0 / side } else { 0.0 },
            items: Vec::new(),
        }
    }

    /// Cell coordinates of `q` (clamped: far cells merge, which only costs tests).
    fn xy(&self, q: DVec2) -> (u64, u64) {
        let c = ((q - self.lo) * self.inv)
            .max(DVec2::ZERO)
            .min(DVec2::splat(1e9));
        (c.x as u64, c.y as u64)
    }

    fn key(x: u64, y: u64) -> u64 {
        (y << 32) | x
    }

    /// Add `item` to every cell the segment `a b` passes through (and some neighbours):
    /// samples every half cell, each with its 3 × 3 block of cells.
    fn add_segment(&mut self, a: DVec2, b: DVec2, item: usize) {
        let steps = ((b - a).length() * self.inv * 2.0).ceil().min(4e9) as usize;
        let mut last = None;
        for k in 0..=steps {
            let (x, y) = self.xy(a.lerp(b, k as f64 / steps.max(1) as f64));
            if last == Some((x, y)) {
                continue;
            }
            last = Some((x, y));
            for dy in 0..3 {
                for dx in 0..3 {
                    let (cx, cy) = ((x + dx).saturating_sub(1), (y + dy).saturating_sub(1));
                    self.items.push((Self::key(cx, cy), item));
                }
            }
        }
    }

    fn sort(&mut self) {
        self.items.sort_unstable();
        self.items.dedup();
    }
}

/// The first pair of non-adjacent edges `(a, b)`, `a < b`, that meet, or `None` for a simple
/// polyline/polygon. Edges are binned in cells; only edges sharing a cell are compared
/// (quadratic when many edges share cells; a cross-check of [`sweep_crossing`]).
#[cfg(test)]
fn first_crossing(p: &[DVec2], closed: bool) -> Option<(usize, usize)> {
    let m = p.len();
    let edges = if closed { m } else { m - 1 };
    let mut cells = Cells::new(p, closed);
    for e in 0..edges {
        cells.add_segment(p[e], p[(e + 1) % m], e);
    }
    cells.sort();
    let mut best: Option<(usize, usize)> = None;
    for group in cells.items.chunk_by(|x, y| x.0 == y.0) {
        for (k, &(_, a)) in group.iter().enumerate() {
            for &(_, b) in &group[k + 1..] {
                let (a, b) = (a.min(b), a.max(b));
                if b <= a + 1 || (closed && a == 0 && b == m - 1) {
                    continue; // the same or adjacent edges (sharing a vertex)
                }
                if best.is_some_and(|q| q <= (a, b)) {
                    continue;
                }
                if segments_meet(p[a], p[(a + 1) % m], p[b], p[(b + 1) % m]) {
                    best = Some((a, b));
                }
            }
        }
    }
    best
}

/// Random polygons shared by the unit tests of the profile and its caps.
#[cfg(test)]
pub(crate) mod fixtures {
    use glam::DVec2;

    /// Xorshift64: a small reproducible generator for the randomised tests.
    pub struct Rng(pub u64);

    impl Rng {
        pub fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        /// Uniform in `0..n`.
        pub fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        /// Uniform in `[0, 1)`.
        pub fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A star-shaped polygon: up to `m` vertices at increasing angles, random radii
    /// (simple, counter-clockwise).
    pub fn star_shaped(rng: &mut Rng, m: usize) -> Vec<DVec2> {
        let mut t: Vec<f64> = (0..m).map(|_| rng.unit() * std::f64::consts::TAU).collect();
        t.sort_by(f64::total_cmp);
        t.dedup();
        t.iter()
            .map(|&a| (0.05 + rng.unit()) * DVec2::from_angle(a))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{Rng, star_shaped};
    use super::*;
    use crate::math::predicates::{accurate_area2, accurate_cover2};

    fn area_of(p: &[DVec2], tris: &[[usize; 3]]) -> f64 {
        0.5 * accurate_cover2(p, tris)
    }

    /// One edge 3e9 times longer than the others: the binning stays O(m) (it asked for
    /// 8 GiB once, aborting the process).
    #[test]
    fn one_long_edge_bins_into_few_cells() {
        let t = 2.99865106e-10;
        let p = [
            DVec2::new(t, 0.0),
            DVec2::new(0.0, t),
            DVec2::new(-t, 0.0),
            DVec2::new(-1.0, -t),
        ];
        for closed in [false, true] {
            let mut cells = Cells::new(&p, closed);
            let edges = if closed { p.len() } else { p.len() - 1 };
            for e in 0..edges {
                cells.add_segment(p[e], p[(e + 1) % p.len()], e);
            }
            assert!(cells.items.len() <= 9 * 10 * edges, "{}", cells.items.len());
        }
        assert!(Profile::new(&p, false, &cancel::never).is_ok());
    }

    #[test]
    fn triangulation_covers_non_convex_polygons() {
        // An L shape and a 5-pointed star, both orientations.
        let l = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 3.), (0., 3.)];
        let star: Vec<(f64, f64)> = (0..10)
            .map(|k| {
                let r = if k % 2 == 0 { 1.0 } else { 0.4 };
                let a = std::f64::consts::PI * k as f64 / 5.0;
                (r * a.cos(), r * a.sin())
            })
            .collect();
        for poly in [l.to_vec(), star] {
            for rev in [false, true] {
                let mut p: Vec<DVec2> = poly.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
                if rev {
                    p.reverse();
                }
                let prof = Profile::new(&p, true, &cancel::never).unwrap();
                let tris = prof.triangulate(&cancel::never).unwrap();
                assert_eq!(tris.len(), p.len() - 2);
                // every triangle counter-clockwise, total = |area|
                for t in &tris {
                    assert!(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]) > 0.0);
                }
                assert!((area_of(&p, &tris) - prof.area.abs()).abs() < 1e-12);
            }
        }
    }

    /// A regular 1000-gon is convex (a fan); a gear of 400 teeth is not (monotone pieces);
    /// both cover their area with counter-clockwise triangles, in either orientation.
    #[test]
    fn convex_and_many_vertex_profiles_are_covered() {
        let ngon: Vec<DVec2> = (0..1000)
            .map(|k| DVec2::from_angle(std::f64::consts::TAU * k as f64 / 1000.0))
            .collect();
        let gear: Vec<DVec2> = (0..1600)
            .map(|k| {
                let r = if (k / 2) % 2 == 0 { 1.0 } else { 0.9 };
                r * DVec2::from_angle(std::f64::consts::TAU * k as f64 / 1600.0)
            })
            .collect();
        for (poly, convex) in [(ngon, true), (gear, false)] {
            for rev in [false, true] {
                let mut p = poly.clone();
                if rev {
                    p.reverse();
                }
                let prof = Profile::new(&p, true, &cancel::never).unwrap();
                assert_eq!(prof.convex, convex);
                let tris = prof.triangulate(&cancel::never).unwrap();
                assert_eq!(tris.len(), p.len() - 2);
                for t in &tris {
                    assert!(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]) > 0.0);
                }
                let a = area_of(&p, &tris);
                assert!((a - prof.area.abs()).abs() < 1e-12 * a);
            }
        }
        // a dent through the middle of the gear makes it self-intersecting
        let mut bad: Vec<DVec2> = (0..1600)
            .map(|k| DVec2::from_angle(std::f64::consts::TAU * k as f64 / 1600.0))
            .collect();
        bad[800] = DVec2::new(1.5, 0.0);
        assert!(Profile::new(&bad, true, &cancel::never).is_err());
    }

    #[test]
    fn bad_profiles_are_refused() {
        let bowtie: Vec<DVec2> = [(0., 0.), (1., 1.), (1., 0.), (0., 1.)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        assert!(Profile::new(&bowtie, true, &cancel::never).is_err());
        let line: Vec<DVec2> = [(0., 0.), (1., 1.), (2., 2.)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        assert!(Profile::new(&line, true, &cancel::never).is_err());
        assert!(Profile::new(&line, false, &cancel::never).is_ok());
    }

    /// The definition: any two non-adjacent edges that meet, or adjacent ones that fold
    /// back, by testing all pairs.
    fn brute_crossing(p: &[DVec2], closed: bool) -> bool {
        let m = p.len();
        let edges = if closed { m } else { m - 1 };
        let fold = |a: usize| folds_back(p[a], p[(a + 1) % m], p[(a + 2) % m]);
        (0..edges).any(|a| (a + 1 < edges || closed) && fold(a))
            || (0..edges).any(|a| {
                (a + 2..edges).any(|b| {
                    !(closed && a == 0 && b == m - 1)
                        && segments_meet(p[a], p[(a + 1) % m], p[b], p[(b + 1) % m])
                })
            })
    }

    #[test]
    fn orientation_is_exact() {
        // nearly collinear points where the plain cross product rounds the wrong way or
        // to zero (Shewchuk's example: points near (0.5, 0.5) on y = x)
        let (a, b) = (DVec2::new(12.0, 12.0), DVec2::new(24.0, 24.0));
        let ulp = f64::EPSILON / 2.0;
        for i in 0..64 {
            for j in 0..64 {
                let c = DVec2::new(0.5 + i as f64 * ulp, 0.5 + j as f64 * ulp);
                // c lies left of a → b exactly when c.y > c.x
                let want = c.y.partial_cmp(&c.x).unwrap();
                assert_eq!(orient(a, b, c), want, "{c:?}");
            }
        }
    }

    /// The orientation of points with integer coordinates up to 2^52 (products beyond the
    /// 53 bits of a double) against exact integer arithmetic: random points, points
    /// repeated (products of zero) and nearly collinear triples.
    #[test]
    fn orientation_matches_integer_arithmetic() {
        let mut rng = Rng(0x5851f42d4c957f2d);
        let exact = |a: DVec2, b: DVec2, c: DVec2| {
            let i = |x: f64| x as i128;
            let d = (i(a.x) - i(c.x)) * (i(b.y) - i(c.y)) - (i(a.y) - i(c.y)) * (i(b.x) - i(c.x));
            d.cmp(&0)
        };
        for bits in [3u32, 20, 40, 52] {
            let big = 1u64 << bits;
            let pt = |rng: &mut Rng| {
                let s = |rng: &mut Rng| rng.below(big) as f64 - (big / 2) as f64;
                DVec2::new(s(rng), s(rng))
            };
            for _ in 0..20_000 {
                let (a, b) = (pt(&mut rng), pt(&mut rng));
                // c random, repeated, or on the line a b moved by a unit
                let c = match rng.below(3) {
                    0 => pt(&mut rng),
                    1 => [a, b][rng.below(2) as usize],
                    _ => {
                        let t = rng.below(1 << 10) as f64;
                        let on = a + (b - a) * t;
                        (on + DVec2::new(rng.below(3) as f64 - 1.0, 0.0)).round()
                    }
                };
                if [a, b, c]
                    .iter()
                    .any(|p| p.abs().max_element() >= 2f64.powi(61))
                {
                    continue;
                }
                for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b), (b, a, c)] {
                    assert_eq!(orient(x, y, z), exact(x, y, z), "{x:?} {y:?} {z:?}");
                }
            }
        }
    }

    #[test]
    fn sweep_finds_crossings_like_testing_all_pairs() {
        let mut rng = Rng(0x2545f4914f6cdd1d);
        // small polygons on a 5 × 5 grid: shared vertices, collinear and vertical edges,
        // touching at vertices, overlapping edges
        let mut found = [0usize; 2];
        for _ in 0..8_000 {
            let m = 3 + rng.below(8) as usize;
            let mut p: Vec<DVec2> = Vec::new();
            while p.len() < m {
                let q = DVec2::new(rng.below(5) as f64, rng.below(5) as f64);
                if p.last() != Some(&q) {
                    p.push(q);
                }
            }
            for closed in [false, true] {
                if closed && p[0] == p[m - 1] {
                    continue;
                }
                let want = brute_crossing(&p, closed);
                let got = sweep_crossing(&p, closed, &cancel::never).unwrap();
                assert_eq!(got.is_some(), want, "{p:?} closed {closed}");
                let grid = first_crossing(&p, closed).is_some();
                let fold = (0..m).any(|a| folds_back(p[a], p[(a + 1) % m], p[(a + 2) % m]));
                assert!(grid == want || fold, "{p:?}");
                if let Some((a, b)) = got {
                    let e = |k: usize| (p[k], p[(k + 1) % m]);
                    let ((w, x), (y, z)) = (e(a), e(b));
                    assert!(a < b && segments_meet(w, x, y, z));
                }
                found[usize::from(want)] += 1;
            }
        }
        assert!(found[0] > 500 && found[1] > 500, "{found:?}");
        // star-shaped polygons are simple; one vertex moved across makes most cross
        for m in [3, 10, 100, 2000] {
            for _ in 0..20 {
                let mut p = star_shaped(&mut rng, m);
                let n = p.len();
                assert_eq!(sweep_crossing(&p, true, &cancel::never).unwrap(), None);
                assert_eq!(sweep_crossing(&p, false, &cancel::never).unwrap(), None);
                let k = rng.below(n as u64) as usize;
                p[k] = -1.5 * p[k];
                if n <= 100 {
                    for closed in [false, true] {
                        assert_eq!(
                            sweep_crossing(&p, closed, &cancel::never)
                                .unwrap()
                                .is_some(),
                            brute_crossing(&p, closed)
                        );
                    }
                } else {
                    assert_eq!(
                        sweep_crossing(&p, true, &cancel::never).unwrap().is_some(),
                        first_crossing(&p, true).is_some()
                    );
                }
            }
        }
    }

    /// Stars and combs of many packed spikes: simple, capped by `m − 2` counter-clockwise
    /// triangles covering the area in either orientation, and one spike bent onto its
    /// neighbour is found.
    #[test]
    fn packed_spikes_are_checked_in_m_log_m() {
        let star = |m: usize| -> Vec<DVec2> {
            (0..m)
                .map(|k| {
                    let r = if k % 2 == 0 { 1.0 } else { 0.2 };
                    r * DVec2::from_angle(std::f64::consts::TAU * k as f64 / m as f64)
                })
                .collect()
        };
        let comb = |k: usize| -> Vec<DVec2> {
            let mut p = vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, 0.1),
            ];
            for i in (0..k).rev() {
                let x = i as f64 / k as f64;
                let w = 0.5 / k as f64;
                p.extend(
                    [(x + w, 0.1), (x + w, 1.1), (x, 1.1), (x, 0.1)].map(|(x, y)| DVec2::new(x, y)),
                );
            }
            p
        };
        for mut p in [star(100_000), comb(25_000)] {
            assert_eq!(sweep_crossing(&p, true, &cancel::never).unwrap(), None);
            for rev in [false, true] {
                let mut q = p.clone();
                if rev {
                    q.reverse();
                }
                let prof = Profile::new(&q, true, &cancel::never).unwrap();
                let tris = prof.triangulate(&cancel::never).unwrap();
                assert_eq!(tris.len(), q.len() - 2);
                use std::cmp::Ordering::Greater;
                assert!(
                    tris.iter()
                        .all(|t| orient(q[t[0]], q[t[1]], q[t[2]]) == Greater)
                );
                // the covered area against the polygon's, both to about the last bit
                let (a, want) = (area_of(&q, &tris), 0.5 * accurate_area2(&q).abs());
                assert!((a - want).abs() < 1e-12 * a, "{a} {want}");
            }
            let n = p.len();
            // two vertices of neighbouring spikes swapped: their edges cross
            let k = (n / 2) & !1;
            p.swap(k + 1, k + 5);
            assert!(sweep_crossing(&p, true, &cancel::never).unwrap().is_some());
        }
    }
}
