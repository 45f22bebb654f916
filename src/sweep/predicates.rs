//! Exact geometric predicates on the profile plane, shared by the profile check and its
//! triangulation: the orientation test `orient` (Shewchuk's orient2d: a floating-point
//! filter, then an exact expansion), and sums accurate to the last bit for the tests.

use glam::DVec2;

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
pub(super) fn orient(a: DVec2, b: DVec2, c: DVec2) -> std::cmp::Ordering {
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
    // Shewchuk's Grow-Expansion with zero elimination, in place: a non-overlapping
    // expansion in increasing magnitude (each term adds at most one component), whose sign
    // is that of its last non-zero component
    let mut h = [0.0; 16];
    let mut n = 0;
    for t in orient_terms(a, b, c) {
        let mut q = t;
        let mut k = 0;
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
        n = k;
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
pub(super) fn accurate_sum(xs: impl IntoIterator<Item = f64>) -> f64 {
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
pub(super) fn accurate_det(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    accurate_sum(orient_terms(a, b, c))
}

/// Twice the signed area of a closed polygon to about the last bit (the shoelace formula
/// with accurate terms and sum).
#[cfg(test)]
pub(super) fn accurate_area2(p: &[DVec2]) -> f64 {
    let m = p.len();
    accurate_sum((0..m).map(|j| accurate_det(p[j], p[(j + 1) % m], DVec2::ZERO)))
}

/// Twice the area covered by the triangles `tris` of the points `p`, to about the last bit.
#[cfg(test)]
pub(super) fn accurate_cover2(p: &[DVec2], tris: &[[usize; 3]]) -> f64 {
    accurate_sum(tris.iter().map(|t| accurate_det(p[t[0]], p[t[1]], p[t[2]])))
}
