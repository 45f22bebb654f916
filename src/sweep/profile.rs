//! The swept profile: a polygon in the normal plane, coordinates `(a, b)` along the frame's
//! `(r, s)` axes.
//!
//! * A closed profile is a simple polygon (no self-intersection); its orientation is read
//!   from the signed area `A = ½ Σ (a_j b_{j+1} − a_{j+1} b_j)` (shoelace formula) and the
//!   faces are wound so that they face outwards whichever way the user listed the vertices.
//! * The `v` texture coordinate of vertex `j` is its arc length along the profile divided by
//!   the perimeter (closed) or by the total length (open).
//! * Caps are the ear-clipping triangulation of the polygon (Meisters 1975: every simple
//!   polygon with more than three vertices has two non-overlapping ears), so non-convex
//!   profiles (mouldings, stars, letters) are capped correctly and no vertex is added.
//!
//! **Cost.** A strictly convex polygon (every turn the same way, total turning ±2π) is
//! simple and is fanned from its first vertex: O(m). Other polygons are checked for
//! self-intersection on a uniform grid of about `m` cells (only segments sharing a cell are
//! compared) and ear-clipped on a doubly linked list, testing only the reflex vertices near
//! the candidate ear (a convex vertex whose triangle contains no reflex vertex is an ear;
//! O'Rourke, *Computational Geometry in C*, §1.6; the grid as in Mapbox's earcut). Both are
//! close to linear on ordinary profiles; O(m²) remains the worst case of adversarial ones.

use glam::DVec2;

use crate::error::{InputError, Result};

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

/// Do the closed segments `p q` and `r s` intersect (touching counts)?
fn segments_meet(p: DVec2, q: DVec2, r: DVec2, s: DVec2) -> bool {
    let d1 = cross(q - p, r - p);
    let d2 = cross(q - p, s - p);
    let d3 = cross(s - r, p - r);
    let d4 = cross(s - r, q - r);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |a: DVec2, b: DVec2, c: DVec2, d: f64| {
        d == 0.0
            && c.x >= a.x.min(b.x)
            && c.x <= a.x.max(b.x)
            && c.y >= a.y.min(b.y)
            && c.y <= a.y.max(b.y)
    };
    on(p, q, r, d1) || on(p, q, s, d2) || on(r, s, p, d3) || on(r, s, q, d4)
}

impl Profile {
    /// Validate `points` (an `(m, 2)` polygon). A closed profile may repeat its first vertex
    /// at the end; it is dropped.
    pub fn new(points: &[DVec2], closed: bool) -> Result<Profile> {
        const ARG: &str = "profile";
        if let Some(j) = points.iter().position(|p| !p.is_finite()) {
            return Err(InputError::new(ARG, format!("non-finite value at row {j}")));
        }
        let mut p = points.to_vec();
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
        let k = if scale > 0.0 {
            -crate::math::scale::exponent(scale)
        } else {
            0
        };
        let unit = |v: &DVec2| {
            DVec2::new(
                crate::math::scale::ldexp(v.x, k),
                crate::math::scale::ldexp(v.y, k),
            )
        };
        let q: Vec<DVec2> = p.iter().map(unit).collect();
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
        let convex = closed && strictly_convex(&p);
        if !convex {
            if let Some((a, b)) = first_crossing(&p, closed) {
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
        let mut v = Vec::with_capacity(m);
        let mut acc = 0.0;
        for j in 0..m {
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
    pub fn triangulate(&self) -> Vec<[usize; 3]> {
        let m = self.points.len();
        // Counter-clockwise vertex order.
        let ccw: Vec<usize> = if self.area > 0.0 {
            (0..m).collect()
        } else {
            (0..m).rev().collect()
        };
        if self.convex {
            return (1..m - 1).map(|k| [ccw[0], ccw[k], ccw[k + 1]]).collect();
        }
        ear_clip(&self.points, &ccw)
    }
}

/// Is the closed polygon strictly convex: every turn of the same sign and the total turning
/// ±2π (a convex polygon wound once is simple)?
fn strictly_convex(p: &[DVec2]) -> bool {
    let m = p.len();
    let (mut pos, mut neg, mut turning) = (false, false, 0.0);
    for j in 0..m {
        let e1 = p[(j + 1) % m] - p[j];
        let e2 = p[(j + 2) % m] - p[(j + 1) % m];
        let c = cross(e1, e2);
        pos |= c > 0.0;
        neg |= c < 0.0;
        if !(c != 0.0) || (pos && neg) {
            return false;
        }
        turning += c.atan2(e1.dot(e2));
    }
    (turning.abs() - std::f64::consts::TAU).abs() < 1.0
}

/// Square cells of side `side` (the median edge length, but at least a quarter of the mean, so
/// that a few edges far longer than the rest cross O(m) cells in all) holding items (edges or
/// vertices), sorted by cell: memory and time follow the items, not the bounding box.
struct Cells {
    lo: DVec2,
    inv: f64,
    /// `(cell key, item)`, sorted.
    items: Vec<(u64, usize)>,
}

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

    fn add_point(&mut self, q: DVec2, item: usize) {
        let (x, y) = self.xy(q);
        self.items.push((Self::key(x, y), item));
    }

    fn sort(&mut self) {
        self.items.sort_unstable();
        self.items.dedup();
    }

    /// Items of the cell `(x, y)`.
    fn at(&self, x: u64, y: u64) -> &[(u64, usize)] {
        let k = Self::key(x, y);
        let i = self.items.partition_point(|e| e.0 < k);
        let j = i + self.items[i..].partition_point(|e| e.0 == k);
        &self.items[i..j]
    }
}

/// The first pair of non-adjacent edges `(a, b)`, `a < b`, that meet, or `None` for a simple
/// polyline/polygon. Edges are binned in cells; only edges sharing a cell are compared.
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

/// Ear clipping of the simple polygon `p` listed counter-clockwise by `ccw`, on a doubly
/// linked list; the reflex vertices are binned on a grid so that an ear test looks only at
/// those near the ear.
fn ear_clip(p: &[DVec2], ccw: &[usize]) -> Vec<[usize; 3]> {
    let m = ccw.len();
    let q: Vec<DVec2> = ccw.iter().map(|&i| p[i]).collect();
    let mut next: Vec<usize> = (0..m).map(|k| (k + 1) % m).collect();
    let mut prev: Vec<usize> = (0..m).map(|k| (k + m - 1) % m).collect();
    let mut alive = vec![true; m];
    let turn = |prev: &[usize], next: &[usize], k: usize| {
        let (a, b, c) = (q[prev[k]], q[k], q[next[k]]);
        cross(b - a, c - b)
    };
    let mut cells = Cells::new(&q, true);
    let mut reflex = Vec::new();
    for (k, &v) in q.iter().enumerate() {
        if turn(&prev, &next, k) <= 0.0 {
            cells.add_point(v, k);
            reflex.push(k);
        }
    }
    cells.sort();
    let inside = |a: DVec2, b: DVec2, c: DVec2, v: DVec2| {
        cross(b - a, v - a) >= 0.0 && cross(c - b, v - b) >= 0.0 && cross(a - c, v - c) >= 0.0
    };
    let mut tris = Vec::with_capacity(m.saturating_sub(2));
    let (mut left, mut k, mut guard) = (m, 0, 0);
    while left > 3 {
        let (ia, ic) = (prev[k], next[k]);
        let (a, b, c) = (q[ia], q[k], q[ic]);
        let mut ear = cross(b - a, c - b) > 0.0;
        if ear {
            // a reflex vertex (still reflex, not a corner of the ear) inside blocks it
            let blocks = |v: usize| {
                alive[v]
                    && v != ia
                    && v != k
                    && v != ic
                    && turn(&prev, &next, v) <= 0.0
                    && inside(a, b, c, q[v])
            };
            let ((x0, y0), (x1, y1)) = (cells.xy(a.min(b).min(c)), cells.xy(a.max(b).max(c)));
            ear = if (x1 - x0 + 1).saturating_mul(y1 - y0 + 1) > reflex.len() as u64 {
                !reflex.iter().any(|&v| blocks(v))
            } else {
                !(y0..=y1)
                    .any(|y| (x0..=x1).any(|x| cells.at(x, y).iter().any(|&(_, v)| blocks(v))))
            };
        }
        if !ear {
            k = ic;
            guard += 1;
            if guard <= left {
                continue;
            }
            // Only reachable through round-off on nearly collinear runs: clip the flattest
            // convex-or-straight vertex.
            let (mut j, mut best, mut flat) = (k, k, turn(&prev, &next, k));
            for _ in 1..left {
                j = next[j];
                let t = turn(&prev, &next, j);
                if t > flat {
                    (best, flat) = (j, t);
                }
            }
            k = best;
        }
        let (ia, ic) = (prev[k], next[k]);
        tris.push([ccw[ia], ccw[k], ccw[ic]]);
        alive[k] = false;
        next[ia] = ic;
        prev[ic] = ia;
        left -= 1;
        guard = 0;
        if reflex.len() > 64 && 2 * reflex.iter().filter(|&&v| alive[v]).count() < reflex.len() {
            reflex.retain(|&v| alive[v]);
        }
        k = ic;
    }
    let a = next[k];
    tris.push([ccw[k], ccw[a], ccw[next[a]]]);
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_of(p: &[DVec2], tris: &[[usize; 3]]) -> f64 {
        tris.iter()
            .map(|t| 0.5 * cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]))
            .sum()
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
        assert!(Profile::new(&p, false).is_ok());
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
                let prof = Profile::new(&p, true).unwrap();
                let tris = prof.triangulate();
                assert_eq!(tris.len(), p.len() - 2);
                // every triangle counter-clockwise, total = |area|
                for t in &tris {
                    assert!(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]) > 0.0);
                }
                assert!((area_of(&p, &tris) - prof.area.abs()).abs() < 1e-12);
            }
        }
    }

    /// A regular 1000-gon is convex (a fan); a gear of 400 teeth is not (ear clipping);
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
                let prof = Profile::new(&p, true).unwrap();
                assert_eq!(prof.convex, convex);
                let tris = prof.triangulate();
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
        assert!(Profile::new(&bad, true).is_err());
    }

    #[test]
    fn bad_profiles_are_refused() {
        let bowtie: Vec<DVec2> = [(0., 0.), (1., 1.), (1., 0.), (0., 1.)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        assert!(Profile::new(&bowtie, true).is_err());
        let line: Vec<DVec2> = [(0., 0.), (1., 1.), (2., 2.)]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect();
        assert!(Profile::new(&line, true).is_err());
        assert!(Profile::new(&line, false).is_ok());
    }
}
