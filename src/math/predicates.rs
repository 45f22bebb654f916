//! Exact geometric predicates (Shewchuk, "Adaptive precision floating-point arithmetic and
//! fast robust geometric predicates", 1997): the orientation of three points in the plane
//! ([`orient`], orient2d; the profile check and its triangulation) and of four points in
//! space ([`orient3d`]; the self-intersection test of meshes). Each computes the
//! determinant in floating point and returns its sign when the error bound of §4.3 proves
//! it; otherwise it sums the determinant's terms exactly, each product of coordinates
//! split into floating-point numbers that add up to it exactly (Dekker's two-product by a
//! fused multiply-add, Knuth's two-sum), into a non-overlapping expansion whose largest
//! component has the sign of the determinant. Exact barring underflow (coordinates
//! within about 1e±100). Also sums accurate to the last bit, for the tests.

use std::cmp::Ordering;

use glam::{DVec2, DVec3};

/// `a + b` as `(sum, error)`, exactly (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

/// `a − b` as `(difference, error)`, exactly.
fn two_diff(a: f64, b: f64) -> (f64, f64) {
    two_sum(a, -b)
}

/// `a b` as `(product, error)`, exactly (a fused multiply-add gives the error).
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    (x, a.mul_add(b, -x))
}

/// The side of `c` from the directed line `a → b`: `Greater` on its left, `Less` on its
/// right, `Equal` on it; the sign of `(a − c) × (b − c)` computed exactly (barring
/// underflow) — a floating-point filter first, then the exact sum of an expansion (Shewchuk,
/// "Adaptive precision floating-point arithmetic and fast robust geometric predicates",
/// 1997, §4.3 "orient2d").
pub(crate) fn orient(a: DVec2, b: DVec2, c: DVec2) -> std::cmp::Ordering {
    let sign = |x: f64| x.partial_cmp(&0.0).unwrap_or(std::cmp::Ordering::Equal);
    let detl = (a.x - c.x) * (b.y - c.y);
    let detr = (a.y - c.y) * (b.x - c.x);
    let det = detl - detr;
    // the two products of opposite signs, or one of them zero (a rounded difference is zero
    // only when exact, and keeps its sign): `det` has the sign of the exact value (Shewchuk's
    // orient2d, which this follows)
    if (detl > 0.0 && detr <= 0.0) || (detl < 0.0 && detr >= 0.0) || detl == 0.0 {
        return sign(det);
    }
    // Shewchuk's ccwerrboundA = (3 + 16ε) ε, ε = 2^-53
    let bound =
        (3.0 + 16.0 * f64::EPSILON / 2.0) * (f64::EPSILON / 2.0) * (detl.abs() + detr.abs());
    if det > bound || -det > bound {
        return sign(det);
    }
    // the exact terms summed into a non-overlapping expansion (Shewchuk's Grow-Expansion
    // with zero elimination), whose sign is that of its last non-zero component
    let mut h = [0.0; 17];
    let mut n = 0;
    for t in orient_terms(a, b, c) {
        n = grow(&mut h, n, t);
    }
    sign(if n == 0 { 0.0 } else { h[n - 1] })
}

/// Add `q` to the non-overlapping expansion `h[..n]` (increasing magnitude), eliminating
/// zero components (Shewchuk's Grow-Expansion); returns the new length. `h` must have room
/// for one more component.
fn grow(h: &mut [f64], n: usize, q: f64) -> usize {
    let (mut q, mut k) = (q, 0);
    for i in 0..n {
        let (sum, err) = two_sum(q, h[i]);
        if err != 0.0 {
            h[k] = err;
            k += 1;
        }
        q = sum;
    }
    if q != 0.0 {
        h[k] = q;
        k += 1;
    }
    k
}

/// The side of `d` from the plane through `a`, `b`, `c`: the sign of the determinant of
/// the rows `a − d`, `b − d`, `c − d`, exactly (barring underflow); `Equal` when the four
/// points are coplanar. Swapping two of the points flips it, so only the agreement of
/// signs carries meaning (two points on the same side get the same sign).
pub(crate) fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Ordering {
    let sign = |x: f64| x.partial_cmp(&0.0).unwrap_or(Ordering::Equal);
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let bc = bd.y * cd.z - bd.z * cd.y;
    let ca = cd.y * ad.z - cd.z * ad.y;
    let ab = ad.y * bd.z - ad.z * bd.y;
    let det = ad.x * bc + bd.x * ca + cd.x * ab;
    let permanent = ((bd.y * cd.z).abs() + (bd.z * cd.y).abs()) * ad.x.abs()
        + ((cd.y * ad.z).abs() + (cd.z * ad.y).abs()) * bd.x.abs()
        + ((ad.y * bd.z).abs() + (ad.z * bd.y).abs()) * cd.x.abs();
    // Shewchuk's o3derrboundA = (7 + 56ε) ε, ε = 2^-53
    let eps = f64::EPSILON / 2.0;
    let bound = (7.0 + 56.0 * eps) * eps * permanent;
    if det > bound || -det > bound {
        return sign(det);
    }
    let mut h = [0.0; 97];
    let mut n = 0;
    // differences that are exact (as between nearby points, by Sterbenz's lemma): the 3×3
    // determinant of those, as 6 signed triple products of four floating-point numbers each
    let exact = [ad, bd, cd].iter().zip([a, b, c]).all(|(e, p)| {
        (0..3).all(|k| two_diff(p[k], d[k]).1 == 0.0 && two_diff(p[k], d[k]).0 == e[k])
    });
    if exact {
        let triples = [
            (ad.x, bd.y, cd.z, 1.0),
            (ad.x, bd.z, cd.y, -1.0),
            (bd.x, cd.y, ad.z, 1.0),
            (bd.x, cd.z, ad.y, -1.0),
            (cd.x, ad.y, bd.z, 1.0),
            (cd.x, ad.z, bd.y, -1.0),
        ];
        for (x, y, z, sgn) in triples {
            let (yz, yz_err) = two_product(y, z);
            for part in [yz, yz_err] {
                let (t, t_err) = two_product(part, x);
                n = grow(&mut h, n, sgn * t);
                n = grow(&mut h, n, sgn * t_err);
            }
        }
        return sign(if n == 0 { 0.0 } else { h[n - 1] });
    }
    by_rows(a, b, c, d)
}

/// The sign of [`orient3d`]'s determinant in any case: the 4×4 determinant of the rows
/// `(x, y, z, 1)` of `a, b, c, d` (equal to the 3×3 one), as the 24 signed products
/// `x_p y_q z_r` of distinct rows, each split into four floating-point numbers, summed
/// exactly.
fn by_rows(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Ordering {
    let sign = |x: f64| x.partial_cmp(&0.0).unwrap_or(Ordering::Equal);
    let mut h = [0.0; 97];
    let mut n = 0;
    let rows = [a, b, c, d];
    for p in 0..4 {
        for q in 0..4 {
            for r in 0..4 {
                if p == q || q == r || p == r {
                    continue;
                }
                let s = 6 - p - q - r; // the row whose entry is the column of ones
                // the sign of the permutation (p, q, r, s) of (0, 1, 2, 3)
                let perm = [p, q, r, s];
                let inversions = (0..4)
                    .flat_map(|i| (i + 1..4).map(move |j| (i, j)))
                    .filter(|&(i, j)| perm[i] > perm[j])
                    .count();
                let sgn = if inversions % 2 == 0 { 1.0 } else { -1.0 };
                let (xy, xy_err) = two_product(rows[p].x, rows[q].y);
                for part in [xy, xy_err] {
                    let (t, t_err) = two_product(part, rows[r].z);
                    n = grow(&mut h, n, sgn * t);
                    n = grow(&mut h, n, sgn * t_err);
                }
            }
        }
    }
    sign(if n == 0 { 0.0 } else { h[n - 1] })
}

/// `(a − c) × (b − c)` as sixteen floating-point numbers that add up to it exactly (barring
/// underflow): each difference as two terms, each product of two-term factors as eight.
fn orient_terms(a: DVec2, b: DVec2, c: DVec2) -> [f64; 16] {
    let (ax, ex) = two_diff(a.x, c.x);
    let (by, ey) = two_diff(b.y, c.y);
    let (ay, fy) = two_diff(a.y, c.y);
    let (bx, fx) = two_diff(b.x, c.x);
    let mut terms = [0.0; 16];
    let pairs = [
        (ax, by, 1.0),
        (ax, ey, 1.0),
        (ex, by, 1.0),
        (ex, ey, 1.0),
        (ay, bx, -1.0),
        (ay, fx, -1.0),
        (fy, bx, -1.0),
        (fy, fx, -1.0),
    ];
    for (k, &(u, v, sign)) in pairs.iter().enumerate() {
        let (x, e) = two_product(u, v);
        terms[2 * k] = sign * x;
        terms[2 * k + 1] = sign * e;
    }
    terms
}

/// A sum with Neumaier's compensation (error about one rounding of the result plus
/// `ε²` times the sum of magnitudes).
#[cfg(test)]
pub(crate) fn accurate_sum(xs: impl IntoIterator<Item = f64>) -> f64 {
    let (mut s, mut c) = (0.0_f64, 0.0_f64);
    for x in xs {
        let t = s + x;
        c += if s.abs() >= x.abs() {
            (s - t) + x
        } else {
            (x - t) + s
        };
        s = t;
    }
    s + c
}

/// `(a − c) × (b − c)` (twice the signed area of the triangle `a b c`) to about the last
/// bit: the exact terms of [`orient`] added up with compensation.
#[cfg(test)]
pub(crate) fn accurate_det(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    accurate_sum(orient_terms(a, b, c))
}

/// Twice the signed area of a closed polygon to about the last bit (the shoelace formula
/// with accurate terms and sum).
#[cfg(test)]
pub(crate) fn accurate_area2(p: &[DVec2]) -> f64 {
    let m = p.len();
    accurate_sum((0..m).map(|j| accurate_det(p[j], p[(j + 1) % m], DVec2::ZERO)))
}

/// Twice the area covered by the triangles `tris` of the points `p`, to about the last bit.
#[cfg(test)]
pub(crate) fn accurate_cover2(p: &[DVec2], tris: &[[usize; 3]]) -> f64 {
    accurate_sum(tris.iter().map(|t| accurate_det(p[t[0]], p[t[1]], p[t[2]])))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The determinant of `orient3d` for points on the grid `k / 2^10`, exactly in integers.
    fn exact_sign(p: [[i64; 3]; 4]) -> Ordering {
        let d = |i: usize, k: usize| i128::from(p[i][k] - p[3][k]);
        let det = d(0, 0) * (d(1, 1) * d(2, 2) - d(1, 2) * d(2, 1))
            + d(1, 0) * (d(2, 1) * d(0, 2) - d(2, 2) * d(0, 1))
            + d(2, 0) * (d(0, 1) * d(1, 2) - d(0, 2) * d(1, 1));
        det.cmp(&0)
    }

    #[test]
    fn orient3d_is_exact_on_nearly_and_exactly_coplanar_points() {
        // a little generator (xorshift), no dependency
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = |m: i64| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % (2 * m as u64 + 1)) as i64 - m
        };
        let scale = 2f64.powi(-10);
        let mut zeros = 0;
        for k in 0..4000 {
            let mut p = [[0i64; 3]; 4];
            for row in p.iter_mut().take(3) {
                for c in row.iter_mut() {
                    *c = next(1 << 30); // triple products of differences stay below 2^100
                }
            }
            // the fourth point: an integer combination of the first three (coplanar), or
            // that moved by one grid step (the float filter cannot decide these)
            let (u, w) = (next(3), next(3));
            let [p0, p1, p2, _] = p;
            p[3] = std::array::from_fn(|c| {
                p0[c]
                    + u * (p1[c] - p0[c])
                    + w * (p2[c] - p0[c])
                    + if k % 2 == 0 { 0 } else { next(1) }
            });
            let q = p.map(|r| DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64) * scale);
            let want = exact_sign(p);
            zeros += usize::from(want == Ordering::Equal);
            assert_eq!(orient3d(q[0], q[1], q[2], q[3]), want, "{p:?}");
            // the general route (used where differences are inexact) on the same points
            assert_eq!(by_rows(q[0], q[1], q[2], q[3]), want, "{p:?}");
        }
        assert!(zeros > 1500, "{zeros}");
    }
}
