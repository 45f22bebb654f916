//! Self-intersections of a triangle mesh: the pairs of faces that cross or overlap, decided
//! with exact orientation predicates ([`crate::math::predicates`]), in `O(F log F)` for
//! meshes of evenly sized faces.
//!
//! * **Candidates** from a bounding-volume hierarchy over the faces' boxes (median splits
//!   of the face centroids along the longest axis, [`crate::math::bvh`]): every
//!   face descends the hierarchy with its box and meets the faces after it whose boxes
//!   overlap its own (closed intervals of exact coordinates: no tolerance).
//! * **Two faces with no common vertex** intersect exactly when an edge of one meets the
//!   other (closed sets): for faces in different planes the intersection segment ends on
//!   the boundary of one of them, and for faces in one plane either their edges cross or
//!   one holds a vertex of the other. An edge meets a triangle when its ends are not
//!   strictly on one side of the triangle's plane and the three tetrahedra (edge, side of
//!   the triangle) agree in sign (`orient3d`); an edge in the plane is tested in 2-D on the
//!   coordinate plane where the triangle's projection is largest (`orient2d`).
//! * **Faces that share a vertex** `v` meet elsewhere only if the edge opposite `v` of one
//!   meets the other, or an edge from `v` of one runs inside the other's angle at `v` in its
//!   plane. **Faces that share an edge** meet elsewhere only if they lie in one plane on the
//!   same side of that edge (a fold onto itself). Faces sharing all three vertices
//!   (duplicates) are reported; faces with coincident corners or collinear corners
//!   (zero area) are left out (they are degenerate, not crossing).
//!
//! The pairs `(i, j)`, `i < j`, come back sorted; the work is cut into fixed blocks of
//! faces, so the result does not depend on the number of threads.

use std::cmp::Ordering;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::measure::{Index, Point, corners};
use crate::error::{InputError, Result};
use crate::math::bvh::{Aabb, Bvh};
use crate::math::predicates::{orient, orient3d};
use crate::run::cancel::Cancel;

/// Faces per block of the candidate search (a Ctrl-C poll each).
const BLOCK: usize = 1 << 12;

/// The name of the call in out-of-memory errors.
pub const CALL: &str = "self_intersections";

/// The pairs of faces of `(v, f)` that intersect other than along shared vertices and
/// edges (see the module documentation), sorted, and whether the list stopped at `limit`
/// pairs. Indices are checked (errors name `faces`). `Ok(None)` when `cancel` said stop.
pub fn self_intersections<P: Point, I: Index>(
    v: &[P],
    f: &[[I; 3]],
    limit: usize,
    cancel: Cancel<'_>,
) -> Result<Option<(Vec<[usize; 2]>, bool)>> {
    super::measure::check_faces(f, v.len(), cancel)?;
    let tri: Vec<[usize; 3]> = crate::run::alloc::collect(CALL, f.iter().map(corners))?;
    let at = |i: usize| v[i].dvec3();
    let pts = |t: &[usize; 3]| [at(t[0]), at(t[1]), at(t[2])];
    let boxes: Vec<Aabb> =
        crate::run::alloc::collect(CALL, tri.iter().map(|t| Aabb::of_points(&pts(t))))?;
    if cancel() {
        return Ok(None);
    }
    let bvh = Bvh::build(&boxes);
    if cancel() {
        return Ok(None);
    }
    let blocks: Vec<Option<Vec<[usize; 2]>>> = (0..tri.len().div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            if cancel() {
                return None;
            }
            let mut out = Vec::new();
            for i in b * BLOCK..((b + 1) * BLOCK).min(tri.len()) {
                bvh.query(&boxes[i], |j| {
                    if j > i && faces_meet(&tri[i], &tri[j], &at) {
                        out.push([i, j]);
                    }
                });
                if out.len() > limit {
                    break;
                }
            }
            out.sort_unstable();
            Some(out)
        })
        .collect();
    if cancel() || blocks.iter().any(Option::is_none) {
        return Ok(None);
    }
    let mut pairs = Vec::new();
    let mut truncated = false;
    for b in blocks.into_iter().flatten() {
        let room = limit - pairs.len();
        if b.len() > room {
            truncated = true;
        }
        pairs
            .try_reserve(b.len().min(room))
            .map_err(|_| InputError::out_of_memory(CALL, b.len(), size_of::<[usize; 2]>()))?;
        pairs.extend(b.into_iter().take(room));
        if truncated {
            break;
        }
    }
    Ok(Some((pairs, truncated)))
}

/// Whether the faces `s` and `t` (vertex indices, positions from `at`) intersect anywhere
/// but along the vertices and edges they share.
fn faces_meet(s: &[usize; 3], t: &[usize; 3], at: &impl Fn(usize) -> DVec3) -> bool {
    let a = [at(s[0]), at(s[1]), at(s[2])];
    let b = [at(t[0]), at(t[1]), at(t[2])];
    if degenerate(&a) || degenerate(&b) {
        return false;
    }
    let shared: Vec<(usize, usize)> = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .filter(|&(i, j)| s[i] == t[j])
        .collect();
    match shared.len() {
        0 => triangles_meet(&a, &b),
        1 => {
            let (i, j) = shared[0];
            share_vertex(&a, i, &b, j) || share_vertex(&b, j, &a, i)
        }
        2 => {
            // the corners not on the shared edge
            let i = 3 - shared[0].0 - shared[1].0;
            let j = 3 - shared[0].1 - shared[1].1;
            let (p, q) = (a[shared[0].0], a[shared[1].0]);
            orient3d(a[0], a[1], a[2], b[j]) == Ordering::Equal && {
                let k = drop_axis(&a);
                let side = |x: DVec3| orient(flat(p, k), flat(q, k), flat(x, k));
                side(a[i]) == side(b[j])
            }
        }
        _ => true, // the same three vertices: a duplicate face
    }
}

/// Whether, of two faces sharing only the vertex `a[i] = b[j]`, face `b` meets face `a`
/// elsewhere: the edge of `b` opposite the shared vertex meets `a`, or an edge of `b` from
/// it lies in `a`'s plane inside `a`'s angle there.
fn share_vertex(a: &[DVec3; 3], i: usize, b: &[DVec3; 3], j: usize) -> bool {
    let (w1, w2) = (b[(j + 1) % 3], b[(j + 2) % 3]);
    if segment_meets_triangle(w1, w2, a) {
        return true;
    }
    let k = drop_axis(a);
    let o = flat(a[i], k);
    let (u, w) = (flat(a[(i + 1) % 3], k), flat(a[(i + 2) % 3], k));
    [w1, w2].into_iter().any(|x| {
        orient3d(a[0], a[1], a[2], x) == Ordering::Equal && {
            // x − o strictly inside the angle (u − o, w − o), or along one of its sides
            let p = flat(x, k);
            let turn = orient(o, u, w);
            let s1 = orient(o, u, p);
            let s2 = orient(o, p, w);
            (s1 == turn || s1 == Ordering::Equal) && (s2 == turn || s2 == Ordering::Equal) && {
                // along a side: in the same direction, not the opposite one
                (s1 != Ordering::Equal || (p - o).dot(u - o) > 0.0)
                    && (s2 != Ordering::Equal || (p - o).dot(w - o) > 0.0)
            }
        }
    })
}

/// Whether the closed triangles `a` and `b` (no shared vertices) intersect.
fn triangles_meet(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    // all of one triangle strictly on one side of the other's plane: apart
    let apart = |t: &[DVec3; 3], u: &[DVec3; 3]| {
        let o = u.map(|x| orient3d(t[0], t[1], t[2], x));
        o.iter().all(|&s| s == Ordering::Greater) || o.iter().all(|&s| s == Ordering::Less)
    };
    if apart(a, b) || apart(b, a) {
        return false;
    }
    (0..3).any(|k| segment_meets_triangle(a[k], a[(k + 1) % 3], b))
        || (0..3).any(|k| segment_meets_triangle(b[k], b[(k + 1) % 3], a))
}

/// Whether the closed segment `p q` meets the closed triangle `t`.
fn segment_meets_triangle(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> bool {
    let op = orient3d(t[0], t[1], t[2], p);
    let oq = orient3d(t[0], t[1], t[2], q);
    if op == oq && op != Ordering::Equal {
        return false; // strictly on one side
    }
    if op == Ordering::Equal && oq == Ordering::Equal {
        // in the plane: 2-D on the coordinate plane of the largest projection
        let k = drop_axis(t);
        let (p, q) = (flat(p, k), flat(q, k));
        let u = t.map(|x| flat(x, k));
        return inside(p, &u)
            || inside(q, &u)
            || (0..3).any(|e| segments_meet(p, q, u[e], u[(e + 1) % 3]));
    }
    // the line through p, q crosses the plane: through the triangle when the three
    // tetrahedra over its sides agree in sign (zeros allowed: an edge or a corner hit)
    let s = [
        orient3d(p, q, t[0], t[1]),
        orient3d(p, q, t[1], t[2]),
        orient3d(p, q, t[2], t[0]),
    ];
    let pos = s.contains(&Ordering::Greater);
    let neg = s.contains(&Ordering::Less);
    if pos && neg {
        return false;
    }
    if !pos && !neg {
        // the segment's line lies in a plane with every side: a degenerate triangle
        return false;
    }
    true
}

/// Whether a triangle's corners are collinear (or coincide), exactly.
fn degenerate(t: &[DVec3; 3]) -> bool {
    // collinear iff every coordinate-plane projection is collinear
    (0..3).all(|k| orient(flat(t[0], k), flat(t[1], k), flat(t[2], k)) == Ordering::Equal)
}

/// The coordinate axis along which the triangle's normal is largest: dropping it keeps
/// the triangle's orientation and area as much as possible (and, for points in its plane,
/// the in-plane predicates exact).
fn drop_axis(t: &[DVec3; 3]) -> usize {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).abs();
    if n.x >= n.y && n.x >= n.z {
        0
    } else if n.y >= n.z {
        1
    } else {
        2
    }
}

/// `x` without its coordinate `k`.
fn flat(x: DVec3, k: usize) -> DVec2 {
    match k {
        0 => DVec2::new(x.y, x.z),
        1 => DVec2::new(x.z, x.x),
        _ => DVec2::new(x.x, x.y),
    }
}

/// Whether `p` lies in the closed triangle `u` (either orientation).
fn inside(p: DVec2, u: &[DVec2; 3]) -> bool {
    let s = [
        orient(u[0], u[1], p),
        orient(u[1], u[2], p),
        orient(u[2], u[0], p),
    ];
    !(s.contains(&Ordering::Greater) && s.contains(&Ordering::Less))
}

/// Whether the closed segments `p q` and `r s` meet.
fn segments_meet(p: DVec2, q: DVec2, r: DVec2, s: DVec2) -> bool {
    let (o1, o2) = (orient(p, q, r), orient(p, q, s));
    let (o3, o4) = (orient(r, s, p), orient(r, s, q));
    let strict = |x: Ordering, y: Ordering| x != Ordering::Equal && y != Ordering::Equal && x != y;
    if strict(o1, o2) && strict(o3, o4) {
        return true; // a proper crossing
    }
    // otherwise they meet only where an end of one lies on the other
    let on = |a: DVec2, b: DVec2, x: DVec2| {
        x.x >= a.x.min(b.x) && x.x <= a.x.max(b.x) && x.y >= a.y.min(b.y) && x.y <= a.y.max(b.y)
    };
    (o1 == Ordering::Equal && on(p, q, r))
        || (o2 == Ordering::Equal && on(p, q, s))
        || (o3 == Ordering::Equal && on(r, s, p))
        || (o4 == Ordering::Equal && on(r, s, q))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::mesh::fixtures::{cube, octahedron};
    use crate::run::cancel;

    fn pairs(v: &[DVec3], f: &[[usize; 3]]) -> Vec<[usize; 2]> {
        self_intersections(v, f, usize::MAX, &cancel::never)
            .unwrap()
            .unwrap()
            .0
    }

    #[test]
    fn closed_convex_meshes_have_none() {
        let (v, f) = octahedron();
        assert!(pairs(&v, &f).is_empty());
        let (v, f) = cube();
        assert!(pairs(&v, &f).is_empty());
    }

    #[test]
    fn two_octahedra_cross_where_they_overlap() {
        // a second octahedron moved by half its size crosses the first; moved by 3 it does
        // not
        let (v, f) = octahedron();
        for (shift, crossing) in [(0.5, true), (3.0, false), (1.8, true), (2.1, false)] {
            let mut w = v.clone();
            w.extend(v.iter().map(|p| *p + DVec3::new(shift, 0.1, 0.05)));
            let mut g = f.clone();
            g.extend(f.iter().map(|t| t.map(|i| i + 6)));
            let p = pairs(&w, &g);
            assert_eq!(!p.is_empty(), crossing, "shift {shift}: {p:?}");
            assert!(p.iter().all(|&[i, j]| i < 8 && j >= 8));
        }
    }

    #[test]
    fn shared_vertices_and_edges_are_not_crossings_but_folds_are() {
        let v = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.3, 0.3, 0.0),
            DVec3::Z,
            -DVec3::Y,
            DVec3::new(1.0, 1.0, 0.0),
        ];
        // sharing the edge 0-1, on opposite sides of it in one plane: fine
        assert!(pairs(&v, &[[0, 1, 2], [1, 0, 5]]).is_empty());
        // folded onto each other in the plane (both on the side of 2): a crossing
        assert_eq!(pairs(&v, &[[0, 1, 2], [1, 0, 3]]), vec![[0, 1]]);
        // sharing vertex 0 only, the other in the plane x = 0 touching the first only there
        assert!(pairs(&v, &[[0, 1, 2], [0, 4, 5]]).is_empty());
        // sharing vertex 0, with an edge running inside the first's angle in its plane
        assert_eq!(pairs(&v, &[[0, 1, 2], [0, 6, 4]]), vec![[0, 1]]);
        // sharing vertex 0, the other piercing the first's interior through its far edge
        let pierce = vec![
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(3.0, 3.0, -1.0),
            DVec3::new(3.0, 3.0, 1.0),
        ];
        assert_eq!(pairs(&pierce, &[[0, 1, 2], [0, 3, 4]]), vec![[0, 1]]);
        // a duplicate face
        assert_eq!(pairs(&v, &[[0, 1, 2], [2, 0, 1]]), vec![[0, 1]]);
    }

    #[test]
    fn touching_and_coplanar_cases_are_exact() {
        let v = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            // a triangle touching the first at the point (0.5, 0.5, 0) with a corner
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(1.5, 0.5, 1.0),
            // a coplanar triangle strictly inside the first
            DVec3::new(0.2, 0.2, 0.0),
            DVec3::new(0.4, 0.2, 0.0),
            DVec3::new(0.2, 0.4, 0.0),
            // one just above the plane (1e-300 away: exact arithmetic sees it)
            DVec3::new(0.2, 0.2, 1e-300),
            DVec3::new(0.4, 0.2, 1e-300),
            DVec3::new(0.2, 0.4, 1e-300),
        ];
        assert_eq!(pairs(&v, &[[0, 1, 2], [3, 4, 5]]), vec![[0, 1]]);
        assert_eq!(pairs(&v, &[[0, 1, 2], [6, 7, 8]]), vec![[0, 1]]);
        assert!(pairs(&v, &[[0, 1, 2], [9, 10, 11]]).is_empty());
    }
}
