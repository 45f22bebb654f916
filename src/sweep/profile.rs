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

    /// A star of `m` spikes: vertices at equal angles, alternately at radius 1 and `inner`.
    pub fn spiked_star(m: usize, inner: f64) -> Vec<DVec2> {
        (0..m)
            .map(|k| {
                let r = if k % 2 == 0 { 1.0 } else { inner };
                r * DVec2::from_angle(std::f64::consts::TAU * k as f64 / m as f64)
            })
            .collect()
    }

    /// A comb of `k` teeth of height 1 on a bar of height 0.1 along `[0, 1]`.
    pub fn comb(k: usize) -> Vec<DVec2> {
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
    }
}

#[cfg(test)]
mod tests;
