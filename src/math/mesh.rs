//! Triangle-mesh measures.
//!
//! * **Signed volume** of a closed, consistently oriented triangle mesh by the divergence
//!   theorem: `V = Σ (a − m)·((b − m) × (c − m)) / 6` over the faces `(a, b, c)`, positive
//!   when the faces are counter-clockwise seen from outside. Any reference point `m` gives
//!   the same `V` for a closed mesh; the mean vertex keeps the digits of a small mesh far
//!   from the origin (the terms stay of the size of the mesh, not of its distance).
//! * **Edges**: the undirected edges `{i, j}` (`i < j`, sorted) and, for every face slot `k`
//!   (the edge `F[k] → F[k+1]`), its edge id; an edge of a closed 2-manifold has exactly two
//!   slots, a boundary edge one, a non-manifold edge more.

use glam::DVec3;

/// Signed volume of the closed triangle mesh `(v, f)`, summed about the mean vertex (0 for
/// no vertices). Face indices must be valid.
pub fn signed_volume(v: &[DVec3], f: &[[usize; 3]]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let m = v.iter().sum::<DVec3>() / v.len() as f64;
    compensated_sum(
        f.iter()
            .map(|t| (v[t[0]] - m).dot((v[t[1]] - m).cross(v[t[2]] - m))),
    ) / 6.0
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
    let slots = crate::alloc::product(what, 3, f.len(), size_of::<([usize; 2], usize)>())?;
    let mut keyed: Vec<([usize; 2], usize)> = crate::alloc::with_capacity(what, slots)?;
    for (i, c) in f.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            keyed.push(([a.min(b), a.max(b)], 3 * i + k));
        }
    }
    keyed.sort_unstable();
    let mut list: Vec<[usize; 2]> = Vec::new();
    let mut slot = crate::alloc::filled(what, f.len(), [0usize; 3])?;
    for (e, s) in keyed {
        if list.last() != Some(&e) {
            crate::alloc::push(what, &mut list, e)?;
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
    let mut count = crate::alloc::filled(what, n, 0usize)?;
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
