//! The solid bounded by a closed triangle mesh (a free-form tool): the check that the mesh
//! bounds one (watertight, consistently and outward wound) and its volume and centroid.
//!
//! * The check is the edge pass of [`super::measure::edges`] (distribution counting by the
//!   smaller vertex, in parallel, no sort of all slots). Only a mesh that fails it is read
//!   again, its slots distributed to buckets in one array, to name the first bad edge.
//! * **Volume** `V = Σ 6V_f / 6` and **centroid** `m + Σ 6V_f (a + b + c − 3m)/4 / (6V)` over
//!   the tetrahedra `(m, a, b, c)` from the mean vertex `m` (the divergence theorem; the
//!   centroid of a tetrahedron is the mean of its corners), summed in fixed blocks of faces
//!   so the results do not depend on the number of threads.

use glam::DVec3;
use rayon::prelude::*;

use super::measure::{self, BLOCK, Index, Point, Scaled, corners, face_sum};
use crate::error::{InputError, Result};
use crate::math::mesh::scale_back;
use crate::run::cancel::Cancel;

/// The name of the call in out-of-memory errors.
pub const CALL: &str = "closed tool";

/// The signed volume and the centroid of the solid bounded by a closed, consistently
/// oriented, outward-wound triangle mesh (indices checked; errors name `mesh`): every edge in
/// exactly two faces, each directed edge once, a positive volume.
///
/// Polls `cancel` before every block of faces of each pass and returns at once (with a meaningless
/// result) when it says stop (see [`crate::run::cancel`]).
pub fn closed_volume_centroid<P: Point, I: Index>(
    v: &[P],
    f: &[[I; 3]],
    cancel: Cancel<'_>,
) -> Result<(f64, DVec3)> {
    let stopped = Ok((0.0, DVec3::ZERO));
    if f.is_empty() {
        return Err(InputError::new("mesh", "has no faces"));
    }
    let n = v.len();
    measure::check_faces(f, n, cancel).map_err(|e| InputError::new("mesh", e.msg))?;
    if cancel() {
        return stopped;
    }
    let st = measure::edges(f, n, cancel)?;
    if cancel() {
        return stopped;
    }
    if !st.watertight() {
        return match first_bad_edge(f, n, cancel)? {
            Some(e) => Err(e),
            None if cancel() => stopped,
            // the edge statistics and the slot table agree; this is not reached
            None => Err(InputError::new(
                "mesh",
                "faces are not consistently oriented",
            )),
        };
    }
    // on the scaled vertices (see `measure`): `vol` and `moment` scaled by `s³` and `s⁴`
    let sc = Scaled::of(v, true, cancel);
    let six = |[a, b, c]: [usize; 3]| {
        let (a, b, c) = (sc.at(v, a), sc.at(v, b), sc.at(v, c));
        (a.dot(b.cross(c)), a + b + c)
    };
    let vol = face_sum(f, n, |t| six(t).0, cancel)? / 6.0;
    if cancel() {
        return stopped;
    }
    if !(vol > 0.0) {
        return Err(InputError::new(
            "mesh",
            format!(
                "encloses a non-positive volume ({:.4}); faces must be oriented outwards",
                scale_back(vol, sc.back, 3)
            ),
        ));
    }
    let blocks: Vec<DVec3> = f
        .par_chunks(BLOCK)
        .map(|b| {
            if cancel() {
                return DVec3::ZERO;
            }
            b.iter().fold(DVec3::ZERO, |acc, t| {
                let (w, s) = six(corners(t));
                acc + w * s
            })
        })
        .collect();
    let moment = blocks.into_iter().sum::<DVec3>();
    let centroid = (sc.m + moment / (24.0 * vol)) * sc.back;
    Ok((scale_back(vol, sc.back, 3), centroid))
}

/// The error about the first bad edge of a mesh that is not watertight or not consistently
/// wound, in the order of the slots `0 → 1` of all faces, then `1 → 2`, then `2 → 0`: an
/// edge in other than two faces, else an edge traversed twice in the same direction. `None`
/// when stopped (or when every edge is good).
///
/// The slots are distributed to the buckets of their smaller vertex (distribution counting,
/// Knuth, *The Art of Computer Programming* vol. 3, §5.2), a slot `v → w` or `w → v`
/// (`v ≤ w`) as the key `2w + [v → w, v < w]`; each bucket is sorted, and every slot then
/// finds the slots of its edge by a binary search in its bucket. The buffers (a start per
/// vertex, a key per slot) are allocated fallibly.
fn first_bad_edge<I: Index>(
    f: &[[I; 3]],
    n: usize,
    cancel: Cancel<'_>,
) -> Result<Option<InputError>> {
    let total = crate::run::alloc::product(CALL, 3, f.len(), size_of::<u64>())?;
    let slots = |t: &[I; 3]| {
        let c = corners(t);
        [0, 1, 2].map(|k| {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            (a.min(b), 2 * a.max(b) as u64 + u64::from(a < b))
        })
    };
    // the end of every bucket, then (filled from the end) its start; `start[n]` = slots
    let mut start = crate::run::alloc::filled(CALL, n + 1, 0usize)?;
    for block in f.chunks(BLOCK) {
        if cancel() {
            return Ok(None);
        }
        for (v, _) in block.iter().flat_map(slots) {
            start[v] += 1;
        }
    }
    let mut sum = 0;
    for s in &mut start {
        sum += *s;
        *s = sum;
    }
    let mut keys = crate::run::alloc::filled(CALL, total, 0u64)?;
    for block in f.chunks(BLOCK) {
        if cancel() {
            return Ok(None);
        }
        for (v, key) in block.iter().flat_map(slots) {
            start[v] -= 1;
            keys[start[v]] = key;
        }
    }
    for (v, w) in start.windows(2).enumerate() {
        if v % BLOCK == 0 && cancel() {
            return Ok(None);
        }
        keys[w[0]..w[1]].sort_unstable();
    }
    // the slots of the edge `(v, w)`, `v ≤ w`, and those running `v → w`, `v < w`
    let edge = |v: usize, w: usize| {
        let b = &keys[start[v]..start[v + 1]];
        let k = 2 * w as u64;
        let (lo, hi) = (
            b.partition_point(|&x| x < k),
            b.partition_point(|&x| x < k + 2),
        );
        (hi - lo, b[lo..hi].iter().filter(|&&x| x & 1 == 1).count())
    };
    for consistent in [false, true] {
        for k in 0..3 {
            for block in f.chunks(BLOCK) {
                if cancel() {
                    return Ok(None);
                }
                for t in block {
                    let c = corners(t);
                    let (a, b) = (c[k], c[(k + 1) % 3]);
                    let (v, w) = (a.min(b), a.max(b));
                    let (count, forward) = edge(v, w);
                    if !consistent && count != 2 {
                        return Ok(Some(InputError::new(
                            "mesh",
                            format!(
                                "not watertight: edge ({v}, {w}) belongs to {count} faces (a \
                                 closed surface has exactly 2)"
                            ),
                        )));
                    }
                    // both slots of one direction (a slot `v → v` is its own reverse)
                    if consistent && (v == w || forward != 1) {
                        return Ok(Some(InputError::new(
                            "mesh",
                            "faces are not consistently oriented",
                        )));
                    }
                }
            }
        }
    }
    Ok(None)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::run::cancel;

    use crate::math::mesh::fixtures::cube_i64 as cube;

    #[test]
    fn closed_mesh_volume_centroid_and_refusals() {
        let (v, f) = cube();
        let (vol, c) = closed_volume_centroid(&v, &f, &cancel::never).unwrap();
        assert!((vol - 1.0).abs() < 1e-15 && (c - DVec3::splat(0.5)).length() < 1e-15);
        let e = closed_volume_centroid(&v, &f[1..], &cancel::never).unwrap_err();
        assert!(e.msg.starts_with("not watertight"), "{e}");
        let flipped: Vec<[i64; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
        let e = closed_volume_centroid(&v, &flipped, &cancel::never).unwrap_err();
        assert!(e.msg.starts_with("encloses a non-positive volume"), "{e}");
        let mut mixed = f.clone();
        mixed[0] = [f[0][0], f[0][2], f[0][1]];
        let e = closed_volume_centroid(&v, &mixed, &cancel::never).unwrap_err();
        assert_eq!(
            (&*e.arg, e.msg.as_str()),
            ("mesh", "faces are not consistently oriented")
        );
        let e = closed_volume_centroid(&v, &[[0, 1, 9]], &cancel::never).unwrap_err();
        assert_eq!(e.arg, "mesh");
        assert!(e.msg.starts_with("face 0 refers to vertex 9"), "{e}");
        assert!(closed_volume_centroid::<DVec3, i64>(&v, &[], &cancel::never).is_err());
    }

    #[test]
    fn the_first_bad_edge_in_slot_order() {
        let (v, f) = cube();
        // without the face (0, 2, 3), the face (0, 3, 1) comes first: its slot 0 → 1, the
        // diagonal (0, 3), lost its other face
        let e = closed_volume_centroid(&v, &f[1..], &cancel::never).unwrap_err();
        assert!(
            e.msg
                .starts_with("not watertight: edge (0, 3) belongs to 1 faces"),
            "{e}"
        );
        // a degenerate face (0, 0, 1) last: its slots 0 → 1 and 1 → 0 make the cube's edge
        // (0, 1) one of four slots, first met at the face (0, 1, 5)
        let mut d = f.clone();
        d.push([0, 0, 1]);
        let e = closed_volume_centroid(&v, &d, &cancel::never).unwrap_err();
        assert!(
            e.msg
                .starts_with("not watertight: edge (0, 1) belongs to 4 faces"),
            "{e}"
        );
    }

    /// A torus of `nu × nv` quads (two triangles each), outward wound.
    pub(crate) fn torus(nu: usize, nv: usize) -> (Vec<DVec3>, Vec<[i64; 3]>) {
        let v = (0..nu * nv)
            .map(|k| {
                let (u, w) = (
                    std::f64::consts::TAU * (k / nv) as f64 / nu as f64,
                    std::f64::consts::TAU * (k % nv) as f64 / nv as f64,
                );
                let r = 1.0 + 0.3 * w.cos();
                DVec3::new(r * u.cos(), r * u.sin(), 0.3 * w.sin())
            })
            .collect();
        let id = |i: usize, j: usize| ((i % nu) * nv + j % nv) as i64;
        let f = (0..nu * nv)
            .flat_map(|k| {
                let (i, j) = (k / nv, k % nv);
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                [[a, b, c], [a, c, d]]
            })
            .collect();
        (v, f)
    }

    #[test]
    fn torus_volume_and_centroid() {
        let (v, f) = torus(400, 100);
        let (vol, c) = closed_volume_centroid(&v, &f, &cancel::never).unwrap();
        // Pappus: 2π R · π r², less the faceting
        let exact = std::f64::consts::TAU * std::f64::consts::PI * 0.09;
        assert!((vol / exact - 1.0).abs() < 2e-3, "{vol} {exact}");
        assert!(c.length() < 1e-12, "{c}");
        let e = closed_volume_centroid(&v, &f[..f.len() - 1], &cancel::never).unwrap_err();
        assert!(e.msg.starts_with("not watertight"), "{e}");
    }
}
