//! Triangle-mesh measures.
//!
//! * **Signed volume** of a closed, consistently oriented triangle mesh by the divergence
//!   theorem: `V = Σ (a − m)·((b − m) × (c − m)) / 6` over the faces `(a, b, c)`, positive
//!   when the faces are counter-clockwise seen from outside. Any reference point `m` gives
//!   the same `V` for a closed mesh; the mean vertex keeps the digits of a small mesh far
//!   from the origin (the terms stay of the size of the mesh, not of its distance).
//! * **Scale**: both measures are taken on the vertices times a power of two `2^-e` that
//!   brings the largest coordinate into `[1, 2)` ([`pow2_scale`]) and scaled back by
//!   `2^(2e)` (area) or `2^(3e)` (volume). Multiplying by a power of two is exact, so the
//!   result has the same bits as the unscaled sum wherever that one neither overflows nor
//!   underflows, and stays finite (or `inf` only when the true value is not representable)
//!   for coordinates anywhere in `1e±300`.
//! * **Edges**: the undirected edges `{i, j}` (`i < j`, sorted) and, for every face slot `k`
//!   (the edge `F[k] → F[k+1]`), its edge id; an edge of a closed 2-manifold has exactly two
//!   slots, a boundary edge one, a non-manifold edge more.

use glam::DVec3;

/// Signed volume of the closed triangle mesh `(v, f)`, summed about the mean vertex (0 for
/// no vertices), on the vertices scaled by [`pow2_scale`]. Face indices must be valid.
pub fn signed_volume(v: &[DVec3], f: &[[usize; 3]]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let (s, back) = pow2_scale(v.iter().fold(0.0f64, |a, p| a.max(p.abs().max_element())));
    let m = v.iter().map(|p| *p * s).sum::<DVec3>() / v.len() as f64;
    let p = |i: usize| v[i] * s - m;
    let six = compensated_sum(f.iter().map(|t| p(t[0]).dot(p(t[1]).cross(p(t[2])))));
    scale_back(six / 6.0, back, 3)
}

/// The power of two `s = 2^-e` that brings `largest` (the largest absolute coordinate, finite,
/// ≥ 0) into `[1, 2)`, and its inverse `2^e`; both normal numbers (`e` within ±1022), and
/// `(1, 1)` for `largest = 0`. Products of coordinates scaled by `s` neither overflow nor
/// underflow for any mesh whose vertices are distinct in floating point.
pub fn pow2_scale(largest: f64) -> (f64, f64) {
    if !(largest > 0.0 && largest.is_finite()) {
        return (1.0, 1.0);
    }
    // the binary exponent of `largest` (of its leading bit for subnormals)
    let bits = largest.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i64;
    let e = if biased == 0 {
        -1011 - (bits & ((1u64 << 52) - 1)).leading_zeros() as i64
    } else {
        biased - 1023
    }
    .clamp(-1022, 1022);
    let pow = |k: i64| f64::from_bits(((k + 1023) as u64) << 52);
    (pow(-e), pow(e))
}

/// `x · back^power`, one factor at a time (each step exact until the true value leaves the
/// range of `f64`, which then gives `±inf` or `0`, never NaN).
pub fn scale_back(x: f64, back: f64, power: u32) -> f64 {
    (0..power).fold(x, |acc, _| acc * back)
}

/// The sum of `terms` with Neumaier's compensation (Neumaier 1974, "Rundungsfehleranalyse
/// einiger Verfahren zur Summation endlicher Summen"): the rounding error stays of the order
/// of one ulp of the sum instead of growing with the number of terms, which matters for a
/// volume change of 1e-9 measured as the difference of two sums over 10⁵ faces.
pub fn compensated_sum(terms: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut c) = (0.0f64, 0.0f64);
    for x in terms {
        let t = sum + x;
        c += if sum.abs() >= x.abs() {
            (sum - t) + x
        } else {
            (x - t) + sum
        };
        sum = t;
    }
    sum + c
}

/// The sorted undirected edges of a mesh and the edge id of every face slot.
pub type EdgeList = (Vec<[usize; 2]>, Vec<[usize; 3]>);

/// The undirected edges of the faces `f`, sorted (`[i, j]` with `i < j`), and the edge id
/// of every face slot (slot `k` of a face is its edge from corner `k` to corner `k + 1`).
/// Buffers are allocated fallibly; the out-of-memory error names `what`.
pub fn edges(what: &'static str, f: &[[usize; 3]]) -> crate::error::Result<EdgeList> {
    let slots = crate::run::alloc::product(what, 3, f.len(), size_of::<([usize; 2], usize)>())?;
    let mut keyed: Vec<([usize; 2], usize)> = crate::run::alloc::with_capacity(what, slots)?;
    for (i, c) in f.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            keyed.push(([a.min(b), a.max(b)], 3 * i + k));
        }
    }
    keyed.sort_unstable();
    let mut list: Vec<[usize; 2]> = Vec::new();
    let mut slot = crate::run::alloc::filled(what, f.len(), [0usize; 3])?;
    for (e, s) in keyed {
        if list.last() != Some(&e) {
            crate::run::alloc::push(what, &mut list, e)?;
        }
        slot[s / 3][s % 3] = list.len() - 1;
    }
    Ok((list, slot))
}

/// How many face slots use each of the `n` edges (`slot` as returned by [`edges`]).
pub fn edge_counts(
    what: &'static str,
    slot: &[[usize; 3]],
    n: usize,
) -> crate::error::Result<Vec<usize>> {
    let mut count = crate::run::alloc::filled(what, n, 0usize)?;
    for s in slot.iter().flatten() {
        count[*s] += 1;
    }
    Ok(count)
}

/// Test meshes shared by the unit tests of several modules.
#[cfg(test)]
pub(crate) mod fixtures {
    use glam::DVec3;

    /// The regular octahedron with vertices on the unit axes, faces wound outwards.
    pub fn octahedron() -> (Vec<DVec3>, Vec<[usize; 3]>) {
        let v = vec![
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ];
        let f = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (v, f)
    }

    /// The unit cube `[0, 1]³`, vertex `x + 2y + 4z`, faces wound outwards.
    pub fn cube() -> (Vec<DVec3>, Vec<[usize; 3]>) {
        let v: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1], // z = 0, normal −z
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        let f = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        (v, f)
    }

    /// [`cube`] with the face indices of a NumPy `int64` array.
    pub fn cube_i64() -> (Vec<DVec3>, Vec<[i64; 3]>) {
        let (v, f) = cube();
        (v, f.iter().map(|t| t.map(|i| i as i64)).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::cube;
    use super::*;

    #[test]
    fn pow2_scale_brings_the_largest_coordinate_into_one_two() {
        for x in [1e-310, 5e-324, 1e-300, 0.75, 1.0, 1.5, 3.0, 1e300, f64::MAX] {
            let (s, back) = pow2_scale(x);
            assert_eq!(s * back, 1.0);
            assert!(s.is_normal() && back.is_normal());
            if (1e-300..1e300).contains(&x) {
                assert!((1.0..2.0).contains(&(x * s)), "{x}: {}", x * s);
            }
        }
        assert_eq!(pow2_scale(0.0), (1.0, 1.0));
        assert_eq!(scale_back(3.0, 2.0, 3), 24.0);
        assert_eq!(scale_back(1e300, 1e10, 2), f64::INFINITY);
    }

    #[test]
    fn signed_volume_is_scale_invariant() {
        let (v, f) = cube();
        for k in [-600, -200, 0, 200, 300] {
            let s = 2f64.powi(k / 2) * 2f64.powi(k - k / 2);
            let w: Vec<DVec3> = v.iter().map(|p| *p * s).collect();
            let want = s * s * s;
            let got = signed_volume(&w, &f);
            assert!(
                got == want || (got / want - 1.0).abs() < 1e-15,
                "2^{k}: {got}"
            );
        }
    }

    #[test]
    fn compensated_sum_keeps_the_small_terms() {
        // 1 + 1e-16 · 10⁴ − 1: a plain sum loses every small term, the compensated one none
        let terms = std::iter::once(1.0)
            .chain(std::iter::repeat_n(1e-16, 10_000))
            .chain(std::iter::once(-1.0));
        let s = compensated_sum(terms.clone());
        assert!((s - 1e-12).abs() < 1e-24, "{s}");
        assert_eq!(terms.sum::<f64>(), 0.0);
    }

    #[test]
    fn unit_cube_volume_sign_and_translation() {
        let (v, f) = cube();
        assert!((signed_volume(&v, &f) - 1.0).abs() < 1e-15);
        let flipped: Vec<[usize; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert!((signed_volume(&v, &flipped) + 1.0).abs() < 1e-15);
        let far: Vec<DVec3> = v.iter().map(|p| *p + DVec3::new(1e6, -1e6, 1e6)).collect();
        assert!((signed_volume(&far, &f) - 1.0).abs() < 1e-12);
        assert_eq!(signed_volume(&[], &[]), 0.0);
    }

    #[test]
    fn cube_edges_are_manifold() {
        let (_, f) = cube();
        let (list, slot) = edges("x", &f).unwrap();
        // 12 cube edges and 6 face diagonals, each shared by two triangles
        assert_eq!(list.len(), 18);
        assert!(list.windows(2).all(|w| w[0] < w[1]));
        assert!(
            edge_counts("x", &slot, list.len())
                .unwrap()
                .iter()
                .all(|&c| c == 2)
        );
        for (t, s) in f.iter().zip(&slot) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                assert_eq!(list[s[k]], [a.min(b), a.max(b)]);
            }
        }
        // one triangle alone: three boundary edges
        let (list, slot) = edges("x", &f[..1]).unwrap();
        assert_eq!(edge_counts("x", &slot, list.len()).unwrap(), vec![1, 1, 1]);
    }
}
