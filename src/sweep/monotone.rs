//! Triangulation of a simple polygon in O(m log m): a plane sweep cuts it into y-monotone
//! pieces by diagonals, and each piece is triangulated with a stack in linear time (de Berg,
//! Cheong, van Kreveld and Overmars, *Computational Geometry: Algorithms and Applications*,
//! 3rd ed., §3.2 "Partitioning a polygon into monotone pieces", §3.3 "Triangulating a
//! monotone polygon").
//!
//! Every decision is an exact orientation test ([`orient`]) or a comparison of coordinates,
//! so collinear vertices and equal heights need no tolerance. Ties in height are broken by
//! `x` — a point is *above* another when it is higher, or as high and further left (the
//! book's convention: the sweep line turned by an infinitesimal angle) — so no two vertices
//! are level and no edge is horizontal. A vertex whose edges run straight on (an interior
//! angle of π) has one neighbour above it and one below, so it is a regular vertex; the stack
//! pops a vertex only across a strictly convex turn, so no triangle is flat.
//!
//! The pieces are the faces of the polygon cut by its diagonals, walked with the edges
//! around every vertex in angular order (a vertex with no diagonal has just its two edges).

use std::cmp::Ordering::{self, Equal, Greater, Less};
use std::collections::BTreeMap;

use glam::DVec2;

use crate::error::{InputError, Result};
use crate::math::predicates::orient;
use crate::run::cancel::{self, BLOCK, Cancel};

/// Is `a` above `b` in the sweep order (higher, or as high and further left)?
fn above(a: DVec2, b: DVec2) -> bool {
    a.y > b.y || (a.y == b.y && a.x < b.x)
}

/// The sweep order, top first.
fn sweep_order(a: DVec2, b: DVec2) -> Ordering {
    if above(a, b) {
        Less
    } else if a == b {
        Equal
    } else {
        Greater
    }
}

/// The kinds of vertices of the sweep (de Berg et al., §3.2), on a counter-clockwise polygon.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    /// Both neighbours below, interior angle < π.
    Start,
    /// Both neighbours below, interior angle > π.
    Split,
    /// Both neighbours above, interior angle < π.
    End,
    /// Both neighbours above, interior angle > π.
    Merge,
    /// Regular, on a left boundary (the previous vertex above, the interior to its right).
    Left,
    /// Regular, on a right boundary (the interior to its left).
    Right,
}

fn kind(prev: DVec2, v: DVec2, next: DVec2) -> Kind {
    let convex = orient(prev, v, next) == Greater;
    match (above(prev, v), above(next, v)) {
        (false, false) if convex => Kind::Start,
        (false, false) => Kind::Split,
        (true, true) if convex => Kind::End,
        (true, true) => Kind::Merge,
        (true, false) => Kind::Left,
        (false, true) => Kind::Right,
    }
}

/// The search key of a point in the status.
const PROBE: usize = usize::MAX;

/// An edge in the sweep's status: the polygon edge from vertex `id` (its upper end `hi`) to
/// vertex `id + 1` (`lo`, below), with the interior to its right; or, for `id == PROBE`, the
/// point `hi` (a search key).
#[derive(Clone, Copy, Debug)]
struct Status {
    hi: DVec2,
    lo: DVec2,
    id: usize,
}

impl Status {
    /// The side of `p`, at a height the edge spans: `Less` west of it (left), `Greater` east.
    fn side(&self, p: DVec2) -> Ordering {
        orient(self.lo, self.hi, p).reverse()
    }

    /// West to east, for `self` entering the status no earlier than `o`: `self`'s upper end
    /// then lies at a height `o` spans, off `o` (edges of a simple polygon do not meet but at
    /// shared vertices, and two edges at one vertex are never in the status together).
    fn later(&self, o: &Status) -> Ordering {
        o.side(self.hi)
            .then_with(|| o.side(self.lo))
            .then(self.id.cmp(&o.id))
    }
}

impl PartialEq for Status {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Equal
    }
}

impl Eq for Status {}

impl PartialOrd for Status {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Status {
    /// West to east along the sweep line (consistent for edges that cross the sweep line
    /// together, which are the only ones the status holds at once).
    fn cmp(&self, o: &Self) -> Ordering {
        if self.id == o.id {
            Equal
        } else if self.id == PROBE {
            o.side(self.hi).then(Greater)
        } else if o.id == PROBE {
            o.cmp(self).reverse()
        } else if above(o.hi, self.hi) || o.hi == self.hi {
            self.later(o)
        } else {
            o.later(self).reverse()
        }
    }
}

/// The diagonals that cut the counter-clockwise simple polygon `q` into y-monotone pieces,
/// `order` being its vertices in sweep order: MakeMonotone of de Berg et al., §3.2. Every
/// split and merge vertex gets a diagonal to the *helper* of the edge directly left of it
/// (the lowest vertex above it seen horizontally from that edge), found in a B-tree of the
/// edges crossing the sweep line with the interior to their right. O(m log m).
fn diagonals(q: &[DVec2], order: &[usize], cancel: Cancel<'_>) -> Result<Vec<[usize; 2]>> {
    let m = q.len();
    let next = |v: usize| if v + 1 == m { 0 } else { v + 1 };
    let prev = |v: usize| if v == 0 { m - 1 } else { v - 1 };
    let kinds: Vec<Kind> = (0..m).map(|v| kind(q[prev(v)], q[v], q[next(v)])).collect();
    let edge = |i: usize| Status {
        hi: q[i],
        lo: q[next(i)],
        id: i,
    };
    let mut status: BTreeMap<Status, usize> = BTreeMap::new();
    let mut out = Vec::new();
    for (i, &v) in order.iter().enumerate() {
        if i % BLOCK == 0 && cancel() {
            return Err(InputError::stopped());
        }
        // the edge that ends at v leaves the status; its helper, if a merge vertex, joins v
        let close = |status: &mut BTreeMap<Status, usize>, out: &mut Vec<[usize; 2]>| {
            if let Some(h) = status.remove(&edge(prev(v))) {
                if kinds[h] == Kind::Merge {
                    out.push([v, h]);
                }
            }
        };
        // the edge directly left of v takes v as its helper; the old helper joins v when
        // `always` (v a split vertex) or when it is a merge vertex
        let left = |status: &mut BTreeMap<Status, usize>, out: &mut Vec<[usize; 2]>, always| {
            let probe = Status {
                hi: q[v],
                lo: q[v],
                id: PROBE,
            };
            if let Some((_, h)) = status.range_mut(..probe).next_back() {
                if always || kinds[*h] == Kind::Merge {
                    out.push([v, *h]);
                }
                *h = v;
            }
        };
        match kinds[v] {
            Kind::Start => {
                status.insert(edge(v), v);
            }
            Kind::End => close(&mut status, &mut out),
            Kind::Split => {
                left(&mut status, &mut out, true);
                status.insert(edge(v), v);
            }
            Kind::Merge => {
                close(&mut status, &mut out);
                left(&mut status, &mut out, false);
            }
            Kind::Left => {
                close(&mut status, &mut out);
                status.insert(edge(v), v);
            }
            Kind::Right => left(&mut status, &mut out, false),
        }
    }
    debug_assert!(status.is_empty());
    Ok(out)
}

/// `a` before `b` counter-clockwise around `c`, starting from the direction `+x`: by half
/// plane (angles in `[0, π)` first, compared exactly), then by orientation.
fn around(c: DVec2, a: DVec2, b: DVec2) -> Ordering {
    let lower = |p: DVec2| !(p.y > c.y || (p.y == c.y && p.x > c.x));
    lower(a)
        .cmp(&lower(b))
        .then_with(|| orient(c, a, b).reverse())
}

/// Triangulate the y-monotone polygon `cyc` (vertices of `q`, counter-clockwise) with a
/// stack: TriangulateMonotonePolygon of de Berg et al., §3.3. The two chains from the top to
/// the bottom are merged in sweep order; a vertex on the other chain from the stack's top
/// sees the whole stack, one on the same chain cuts off the vertices behind strictly convex
/// turns. `k − 2` counter-clockwise triangles into `out`; `seq` and `stack` are scratch.
fn monotone_piece(
    q: &[DVec2],
    cyc: &[usize],
    seq: &mut Vec<(usize, bool)>,
    stack: &mut Vec<(usize, bool)>,
    out: &mut Vec<[usize; 3]>,
) {
    let k = cyc.len();
    if k < 3 {
        return;
    }
    let (mut t, mut b) = (0, 0);
    for i in 1..k {
        if above(q[cyc[i]], q[cyc[t]]) {
            t = i;
        }
        if above(q[cyc[b]], q[cyc[i]]) {
            b = i;
        }
    }
    // (vertex, on the left chain): the left chain runs forward from the top (counter-
    // clockwise goes down on the left), the right chain backward
    seq.clear();
    seq.push((cyc[t], true));
    let (mut l, mut r) = ((t + 1) % k, (t + k - 1) % k);
    while l != b || r != b {
        if r == b || (l != b && above(q[cyc[l]], q[cyc[r]])) {
            seq.push((cyc[l], true));
            l = (l + 1) % k;
        } else {
            seq.push((cyc[r], false));
            r = (r + k - 1) % k;
        }
    }
    seq.push((cyc[b], true));
    // triangles of u and every pair of consecutive stack vertices, u on the other chain
    let fan = |stack: &[(usize, bool)], u: usize, left: bool, out: &mut Vec<[usize; 3]>| {
        for w in stack.windows(2) {
            let (older, newer) = (w[0].0, w[1].0);
            out.push(if left {
                [u, newer, older]
            } else {
                [u, older, newer]
            });
        }
    };
    stack.clear();
    stack.extend_from_slice(&seq[..2]);
    for &(u, left) in &seq[2..k - 1] {
        let Some(&top) = stack.last() else { return };
        if top.1 != left {
            fan(stack, u, left, out);
            stack.clear();
            stack.push(top);
        } else {
            stack.pop();
            let mut last = top;
            while let Some(&s) = stack.last() {
                let tri = if left {
                    [s.0, last.0, u]
                } else {
                    [u, last.0, s.0]
                };
                if orient(q[tri[0]], q[tri[1]], q[tri[2]]) != Greater {
                    break;
                }
                out.push(tri);
                last = s;
                stack.pop();
            }
            stack.push(last);
        }
        stack.push((u, left));
    }
    // the bottom joins every stack vertex, on the other chain from the top of the stack
    if let Some(&(_, left)) = stack.last() {
        fan(stack, seq[k - 1].0, !left, out);
    }
}

/// Triangles `[a, b, c]`, counter-clockwise, indices into `q`, covering the simple polygon
/// `q` listed counter-clockwise: `m − 2` triangles on its own vertices, each of positive
/// area, every edge of `q` in one triangle (in its direction) and every diagonal in two (in
/// opposite directions). O(m log m). Polls `cancel` between its passes and every
/// [`BLOCK`] vertices within them, and fails with [`InputError::stopped`] when it says stop.
pub fn triangulate(q: &[DVec2], cancel: Cancel<'_>) -> Result<Vec<[usize; 3]>> {
    let m = q.len();
    let mut out = Vec::with_capacity(m.saturating_sub(2));
    if m < 3 {
        return Ok(out);
    }
    let stop = || match cancel() {
        true => Err(InputError::stopped()),
        false => Ok(()),
    };
    let mut order: Vec<usize> = (0..m).collect();
    // the vertices of a simple polygon are distinct
    if !cancel::sort_by(&mut order, |&a, &b| sweep_order(q[a], q[b]), cancel) {
        return Err(InputError::stopped());
    }
    let diag = diagonals(q, &order, cancel)?;
    drop(order);
    let (mut seq, mut stack) = (Vec::new(), Vec::new());
    if diag.is_empty() {
        let all: Vec<usize> = (0..m).collect();
        monotone_piece(q, &all, &mut seq, &mut stack, &mut out);
        return Ok(out);
    }
    // the edges around every vertex: the block off[v]..off[v + 1] of `adj` holds their far
    // ends, the two polygon edges first; blocks with diagonals are then sorted
    // counter-clockwise (two edges need no order: each is the other's neighbour both ways)
    let next = |v: usize| if v + 1 == m { 0 } else { v + 1 };
    let prev = |v: usize| if v == 0 { m - 1 } else { v - 1 };
    let mut off = vec![2usize; m + 1];
    off[m] = 0;
    for &[a, b] in &diag {
        off[a] += 1;
        off[b] += 1;
    }
    let mut acc = 0;
    for o in off.iter_mut() {
        (*o, acc) = (acc, acc + *o);
    }
    let mut fill: Vec<usize> = off[..m].iter().map(|&o| o + 2).collect();
    let mut adj = vec![0usize; off[m]];
    for v in 0..m {
        adj[off[v]] = next(v);
        adj[off[v] + 1] = prev(v);
    }
    for &[a, b] in &diag {
        adj[fill[a]] = b;
        fill[a] += 1;
        adj[fill[b]] = a;
        fill[b] += 1;
    }
    drop(fill);
    stop()?;
    for v in 0..m {
        if v % BLOCK == 0 {
            stop()?;
        }
        let block = &mut adj[off[v]..off[v + 1]];
        if block.len() > 2 {
            block.sort_unstable_by(|&a, &b| around(q[v], q[a], q[b]));
        }
    }
    // walk the faces with the interior on the left: after the half-edge u → v comes
    // v → w, w the edge around v clockwise next from u; the half-edges v → prev(v) bound the
    // outside and start no walk
    let mut seen = vec![false; adj.len()];
    let mut cyc = Vec::new();
    for v in 0..m {
        if v % BLOCK == 0 {
            stop()?;
        }
        for s in off[v]..off[v + 1] {
            if seen[s] || adj[s] == prev(v) {
                continue;
            }
            cyc.clear();
            let (mut u, mut h) = (v, s);
            while !seen[h] {
                seen[h] = true;
                cyc.push(u);
                let w = adj[h];
                let block = &adj[off[w]..off[w + 1]];
                let d = block.len();
                let at = if d == 2 {
                    usize::from(block[0] != u)
                } else {
                    block
                        .binary_search_by(|&x| around(q[w], q[x], q[u]))
                        .unwrap_or_else(|i| i.min(d - 1))
                };
                (u, h) = (w, off[w] + (at + d - 1) % d);
            }
            monotone_piece(q, &cyc, &mut seq, &mut stack, &mut out);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::predicates::{accurate_area2, accurate_cover2};
    use crate::sweep::profile::Profile;
    use crate::sweep::profile::fixtures::{Rng, comb, spiked_star as star, star_shaped};
    use std::collections::HashMap;

    /// Check that `tris` triangulates the counter-clockwise simple polygon `q`: `m − 2`
    /// triangles on valid vertex indices, each counter-clockwise by the exact predicate, the
    /// areas adding up to the polygon's, every polygon edge once in its direction and every
    /// other edge (a diagonal) twice, in opposite directions, and never along the outside.
    fn check(q: &[DVec2], tris: &[[usize; 3]]) {
        let m = q.len();
        assert_eq!(tris.len(), m - 2, "{q:?}");
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        for t in tris {
            assert!(t.iter().all(|&i| i < m), "{t:?}");
            assert_eq!(orient(q[t[0]], q[t[1]], q[t[2]]), Greater, "{t:?} in {q:?}");
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "half-edge {a} → {b} twice in {q:?}");
            if b == (a + 1) % m {
                continue; // a polygon edge
            }
            assert_ne!(a, (b + 1) % m, "the outside of edge {b} → {a} in {q:?}");
            assert!(
                edges.contains_key(&(b, a)),
                "diagonal {a} → {b} once in {q:?}"
            );
        }
        for a in 0..m {
            assert!(
                edges.contains_key(&(a, (a + 1) % m)),
                "edge {a} missing in {q:?}"
            );
        }
        let (poly, cover) = (accurate_area2(q), accurate_cover2(q, tris));
        assert!(
            (cover - poly).abs() <= 1e-12 * poly.abs(),
            "{cover} vs {poly}"
        );
    }

    /// Triangulate `p` as the caps do (counter-clockwise order) and check it, starting the
    /// vertex list at three places.
    fn check_polygon(p: &[DVec2]) {
        let m = p.len();
        let area = accurate_area2(p);
        let ccw: Vec<DVec2> = if area > 0.0 {
            p.to_vec()
        } else {
            p.iter().rev().copied().collect()
        };
        for s in [0, m / 3, 2 * m / 3] {
            let mut q = ccw.clone();
            q.rotate_left(s);
            check(&q, &triangulate(&q, &cancel::never).unwrap());
        }
    }

    /// Random simple polygons on an `n × n` grid (shared heights and abscissae, collinear
    /// vertices and edges, straight angles), kept when the profile check accepts them (it
    /// runs the Shamos–Hoey sweep on every non-convex one): random vertex lists, and random
    /// grid points in angular order about a point off the grid (star-shaped, larger).
    #[test]
    fn random_grid_polygons() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        let mut tested = [0usize; 41];
        let mut straight = 0;
        let mut try_one = |p: &[DVec2], tested: &mut [usize; 41]| {
            let Ok(prof) = Profile::new(p, true, &cancel::never) else {
                return;
            };
            let q = &prof.points;
            let m = q.len();
            check_polygon(q);
            tested[m] += 1;
            if (0..m).any(|j| orient(q[(j + m - 1) % m], q[j], q[(j + 1) % m]) == Equal) {
                straight += 1;
            }
        };
        for n in [3u64, 4, 5, 8] {
            for _ in 0..6000 {
                let m = 3 + rng.below(6) as usize;
                let mut p: Vec<DVec2> = Vec::new();
                while p.len() < m {
                    let v = DVec2::new(rng.below(n) as f64, rng.below(n) as f64);
                    if p.last() != Some(&v) {
                        p.push(v);
                    }
                }
                try_one(&p, &mut tested);
            }
        }
        for n in [4u64, 6, 10] {
            for _ in 0..2000 {
                let m = 3 + rng.below(38) as usize;
                let c = DVec2::new(
                    rng.below(n) as f64 + 0.5 * rng.unit(),
                    rng.below(n) as f64 + 0.5 * rng.unit(),
                );
                let mut p: Vec<DVec2> = (0..m)
                    .map(|_| DVec2::new(rng.below(n) as f64, rng.below(n) as f64))
                    .collect();
                p.sort_by(|a, b| {
                    let (u, v) = (*a - c, *b - c);
                    u.y.atan2(u.x).total_cmp(&v.y.atan2(v.x))
                });
                p.dedup();
                try_one(&p, &mut tested);
            }
        }
        // every size from 3 to 30 is tested, and many polygons have straight angles
        assert!(tested[3..=30].iter().all(|&k| k >= 20), "{tested:?}");
        assert!(straight > 1000, "{straight}");
    }

    /// Polygons grown on a grid by random walks of their boundary: a square cut by random
    /// axis-parallel notches has many equal heights, straight angles and merge and split
    /// vertices on one line.
    #[test]
    fn rectilinear_polygons() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        let mut tested = 0;
        for _ in 0..2000 {
            // a histogram polygon: bars of random heights on a base, turned by 0/90/180/270°
            let k = 1 + rng.below(30) as usize;
            let h: Vec<f64> = (0..k).map(|_| 1.0 + rng.below(5) as f64).collect();
            let mut p = vec![DVec2::new(0.0, 0.0), DVec2::new(k as f64, 0.0)];
            for i in (0..k).rev() {
                p.push(DVec2::new(i as f64 + 1.0, h[i]));
                p.push(DVec2::new(i as f64, h[i]));
            }
            // keep the straight angles between bars of equal height, sometimes
            let turn = rng.below(4);
            let p: Vec<DVec2> = p
                .iter()
                .map(|&v| match turn {
                    0 => v,
                    1 => DVec2::new(-v.y, v.x),
                    2 => -v,
                    _ => DVec2::new(v.y, -v.x),
                })
                .collect();
            let mut q: Vec<DVec2> = Vec::new();
            for v in p {
                if q.last() != Some(&v) {
                    q.push(v);
                }
            }
            if q.first() == q.last() {
                q.pop();
            }
            if let Ok(prof) = Profile::new(&q, true, &cancel::never) {
                check_polygon(&prof.points);
                tested += 1;
            }
        }
        assert!(tested > 1900, "{tested}");
    }

    /// A square spiral of `turns` turns and corridor width 1 (every vertex on a grid).
    fn spiral(turns: usize) -> Vec<DVec2> {
        // the centre line visits the corners of growing squares; the polygon is its
        // outline, the outer wall out and the inner wall back
        let mut line = vec![DVec2::ZERO];
        let dirs = [
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(-1.0, 0.0),
            DVec2::new(0.0, -1.0),
        ];
        let mut at = DVec2::ZERO;
        for k in 0..4 * turns {
            at += dirs[k % 4] * (2 * (k / 2 + 1)) as f64;
            line.push(at);
        }
        // offset by ±1/2 to the left and right of the centre line, corner by corner
        let side = |s: f64| -> Vec<DVec2> {
            let n = line.len();
            (0..n)
                .map(|i| {
                    let d_in = if i > 0 {
                        (line[i] - line[i - 1]).normalize()
                    } else {
                        (line[1] - line[0]).normalize()
                    };
                    let d_out = if i + 1 < n {
                        (line[i + 1] - line[i]).normalize()
                    } else {
                        d_in
                    };
                    let (l_in, l_out) = (d_in.perp(), d_out.perp());
                    if i == 0 || i + 1 == n || l_in == l_out {
                        line[i] + s * 0.5 * l_in
                    } else {
                        line[i] + s * 0.5 * (l_in + l_out)
                    }
                })
                .collect()
        };
        let mut p = side(-1.0);
        p.extend(side(1.0).into_iter().rev());
        p
    }

    /// Regular and irregular stars, combs, spirals and random star-shaped polygons, with
    /// every vertex also on a rotated copy (no equal heights at all).
    #[test]
    fn stars_combs_spirals() {
        let mut rng = Rng(0xdead_beef_cafe_f00d);
        let mut polys = vec![
            star(10, 0.4),
            star(64, 0.2),
            star(1000, 0.9),
            star(20_000, 0.2),
        ];
        polys.extend([comb(1), comb(3), comb(50), comb(2500)]);
        polys.extend([spiral(1), spiral(2), spiral(5), spiral(40)]);
        for m in [3, 5, 20, 200, 5000] {
            polys.push(star_shaped(&mut rng, m));
        }
        for p in polys {
            let turned: Vec<DVec2> = p
                .iter()
                .map(|&v| DVec2::from_angle(0.3).rotate(v))
                .collect();
            for p in [p, turned] {
                let prof = Profile::new(&p, true, &cancel::never).expect("a simple polygon");
                check_polygon(&prof.points);
            }
        }
    }

    /// Vertices at equal heights in long runs: a zigzag band whose teeth all touch two
    /// lines, and a staircase; a spike field whose tips and valleys are level.
    #[test]
    fn level_runs() {
        let zig = |k: usize| -> Vec<DVec2> {
            let mut p: Vec<DVec2> = (0..=2 * k)
                .map(|i| DVec2::new(i as f64, if i % 2 == 0 { 0.0 } else { 1.0 }))
                .collect();
            p.extend(
                (0..=2 * k)
                    .rev()
                    .map(|i| DVec2::new(i as f64, if i % 2 == 0 { 2.0 } else { 3.0 })),
            );
            p
        };
        let stairs = |k: usize| -> Vec<DVec2> {
            let mut p = vec![DVec2::new(0.0, 0.0)];
            for i in 0..k {
                p.push(DVec2::new(i as f64 + 1.0, i as f64));
                p.push(DVec2::new(i as f64 + 1.0, i as f64 + 1.0));
            }
            p.push(DVec2::new(0.0, k as f64));
            p
        };
        for p in [zig(1), zig(7), zig(300), stairs(1), stairs(9), stairs(500)] {
            for turn in 0..4 {
                let q: Vec<DVec2> = p
                    .iter()
                    .map(|&v| {
                        DVec2::from_angle(std::f64::consts::FRAC_PI_2 * turn as f64)
                            .rotate(v)
                            .round()
                    })
                    .collect();
                let prof = Profile::new(&q, true, &cancel::never).expect("a simple polygon");
                check_polygon(&prof.points);
            }
        }
    }

    /// The kinds of the vertices of an "M" (a notch up from the bottom, one down from the
    /// top) and the single diagonal that the sweep draws for its split and merge vertices.
    #[test]
    fn kinds_and_diagonals_of_an_m() {
        let p: Vec<DVec2> = [(0., 0.), (2., 1.), (4., 0.), (4., 3.), (2., 2.), (0., 3.)]
            .map(|(x, y)| DVec2::new(x, y))
            .to_vec();
        let m = p.len();
        let k: Vec<Kind> = (0..m)
            .map(|v| kind(p[(v + m - 1) % m], p[v], p[(v + 1) % m]))
            .collect();
        use Kind::*;
        assert_eq!(k, [End, Split, End, Start, Merge, Start]);
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_unstable_by(|&a, &b| sweep_order(p[a], p[b]));
        // level vertices: the one further left first
        assert_eq!(order, [5, 3, 4, 1, 0, 2]);
        assert_eq!(diagonals(&p, &order, &cancel::never).unwrap(), [[1, 4]]);
        check(&p, &triangulate(&p, &cancel::never).unwrap());
    }
}
