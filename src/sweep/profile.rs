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
}

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
        // Self-intersection: non-adjacent edges must not meet (O(m²), profiles are small).
        for a in 0..edges {
            for b in a + 2..edges {
                if closed && a == 0 && b == m - 1 {
                    continue; // adjacent through the closing vertex
                }
                if segments_meet(p[a], p[(a + 1) % m], p[b], p[(b + 1) % m]) {
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
        let p = &self.points;
        let m = p.len();
        // Work on a counter-clockwise index list.
        let mut idx: Vec<usize> = if self.area > 0.0 {
            (0..m).collect()
        } else {
            (0..m).rev().collect()
        };
        let mut tris = Vec::with_capacity(m.saturating_sub(2));
        let inside = |a: DVec2, b: DVec2, c: DVec2, q: DVec2| {
            cross(b - a, q - a) >= 0.0 && cross(c - b, q - b) >= 0.0 && cross(a - c, q - c) >= 0.0
        };
        let mut guard = 0;
        let mut k = 0;
        while idx.len() > 3 {
            let n = idx.len();
            let (ia, ib, ic) = (idx[(k + n - 1) % n], idx[k % n], idx[(k + 1) % n]);
            let (a, b, c) = (p[ia], p[ib], p[ic]);
            let convex = cross(b - a, c - b) > 0.0;
            let ear = convex
                && !idx
                    .iter()
                    .any(|&q| q != ia && q != ib && q != ic && inside(a, b, c, p[q]));
            if ear {
                tris.push([ia, ib, ic]);
                idx.remove(k % n);
                guard = 0;
            } else {
                k += 1;
                guard += 1;
                if guard > n {
                    // Only reachable through round-off on nearly collinear runs: clip the
                    // flattest convex-or-straight vertex.
                    let j = (0..n)
                        .max_by(|&x, &y| {
                            let f = |i: usize| {
                                let (a, b, c) =
                                    (p[idx[(i + n - 1) % n]], p[idx[i]], p[idx[(i + 1) % n]]);
                                cross(b - a, c - b)
                            };
                            f(x).total_cmp(&f(y))
                        })
                        .unwrap_or(0);
                    tris.push([idx[(j + n - 1) % n], idx[j], idx[(j + 1) % n]]);
                    idx.remove(j);
                    guard = 0;
                }
            }
            if !idx.is_empty() {
                k %= idx.len();
            }
        }
        tris.push([idx[0], idx[1], idx[2]]);
        tris
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_of(p: &[DVec2], tris: &[[usize; 3]]) -> f64 {
        tris.iter()
            .map(|t| 0.5 * cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]))
            .sum()
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
