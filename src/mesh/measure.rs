//! Measures of a triangle mesh of any size, in time linear in the faces and with no
//! temporaries beyond `O(F)` integers, in parallel.
//!
//! * **Volume** by the divergence theorem, `V = Σ (a − m)·((b − m) × (c − m)) / 6` about the
//!   mean vertex `m` (see [`crate::math::mesh::signed_volume`]); **area** `Σ |(b − a) × (c − a)| / 2`.
//!   Both are summed in fixed blocks of faces with Neumaier's compensation, and the block
//!   sums again, so the result does not depend on the number of threads.
//! * **Edges** by a counting sort of the `3F` face slots on their smaller vertex (Knuth, *The
//!   Art of Computer Programming* vol. 3, §5.2, "distribution counting"): every vertex `v`
//!   gets the bucket of the slots `v → w` and `w → v` with `w > v`, stored as `2w + [v → w]`;
//!   each bucket (of the size of the vertex degree) is then sorted on its own. An edge `{v, w}`
//!   of a closed 2-manifold has exactly two slots, traversed in opposite directions when the
//!   faces are consistently oriented ("winding"); one slot is a boundary edge, more a
//!   non-manifold edge. The sort runs in two parallel distributions (blocks of vertices, then
//!   vertices within a block), each face chunk writing its own part of every block, so no
//!   two threads write the same place and no lock is needed.

use glam::DVec3;
use rayon::prelude::*;

use crate::cancel::{self, Cancel};
use crate::error::{InputError, Result};
use crate::math::mesh::compensated_sum;

/// Faces per block of the compensated sums (fixed, so results do not depend on threads).
const BLOCK: usize = 1 << 14;

/// Face slots per block of the sequential passes of the edge sort, between two polls of the
/// cancel hook.
const SCAN: usize = 1 << 16;

/// A vertex row as stored by NumPy (`float64` or `float32`).
pub trait Point: Copy + Send + Sync {
    fn dvec3(self) -> DVec3;
}

impl Point for [f64; 3] {
    #[inline(always)]
    fn dvec3(self) -> DVec3 {
        DVec3::from_array(self)
    }
}

impl Point for [f32; 3] {
    #[inline(always)]
    fn dvec3(self) -> DVec3 {
        DVec3::new(self[0] as f64, self[1] as f64, self[2] as f64)
    }
}

/// A face index as stored by NumPy (`int64` or `int32`).
pub trait Index: Copy + Send + Sync {
    fn get(self) -> i64;
}

impl Index for i64 {
    #[inline(always)]
    fn get(self) -> i64 {
        self
    }
}

impl Index for i32 {
    #[inline(always)]
    fn get(self) -> i64 {
        self as i64
    }
}

#[inline(always)]
fn corners<I: Index>(t: &[I; 3]) -> [usize; 3] {
    // only after `check_faces`: every index is in `0..n`
    t.map(|i| i.get() as usize)
}

/// Refuse faces with an index outside `0..n` (the first such face; errors name `faces`).
pub fn check_faces<I: Index>(f: &[[I; 3]], n: usize) -> Result<()> {
    check_faces_cancellable(f, n, &cancel::never)
}

/// [`check_faces`] that polls `cancel` before every block of faces; a cancelled check passes
/// the blocks it skips (the caller discards the result, see [`crate::cancel`]).
pub fn check_faces_cancellable<I: Index>(f: &[[I; 3]], n: usize, cancel: Cancel<'_>) -> Result<()> {
    let bad = f
        .par_chunks(BLOCK)
        .position_first(|b| !cancel() && !b.iter().all(|t| valid(t, n)));
    match bad {
        None => Ok(()),
        Some(c) => Err(out_of_range(f, c * BLOCK, n)),
    }
}

#[inline(always)]
fn valid<I: Index>(t: &[I; 3], n: usize) -> bool {
    t.iter()
        .all(|i| usize::try_from(i.get()).is_ok_and(|x| x < n))
}

/// The error about the first face from `from` on with an index outside `0..n`.
fn out_of_range<I: Index>(f: &[[I; 3]], from: usize, n: usize) -> InputError {
    let i = from + f[from..].iter().position(|t| !valid(t, n)).unwrap_or(0);
    let x = f[i]
        .iter()
        .map(|i| i.get())
        .find(|&x| !usize::try_from(x).is_ok_and(|x| x < n))
        .unwrap_or(-1);
    InputError::new(
        "faces",
        format!(
            "face {i} refers to vertex {x}, but there are {n} vertices (indices must lie in \
             0..{n})"
        ),
    )
}

/// The compensated sum of `term(face)` over all faces, in fixed blocks, checking the
/// indices on the way (errors name `faces`). Polls `cancel` before every block; the blocks
/// it skips count as zero (the caller discards the result).
fn face_sum<I: Index>(
    f: &[[I; 3]],
    n: usize,
    term: impl Fn([usize; 3]) -> f64 + Sync,
    cancel: Cancel<'_>,
) -> Result<f64> {
    let blocks: Vec<Option<f64>> = f
        .par_chunks(BLOCK)
        .map(|b| {
            if cancel() {
                return Some(0.0);
            }
            if !b.iter().all(|t| valid(t, n)) {
                return None;
            }
            Some(compensated_sum(b.iter().map(|t| term(corners(t)))))
        })
        .collect();
    if let Some(c) = blocks.iter().position(Option::is_none) {
        return Err(out_of_range(f, c * BLOCK, n));
    }
    Ok(compensated_sum(blocks.into_iter().flatten()))
}

/// The mean of the vertices (zero for none), summed in fixed blocks (polling `cancel`
/// before each; skipped blocks count as zero).
fn mean<P: Point>(v: &[P], cancel: Cancel<'_>) -> DVec3 {
    if v.is_empty() {
        return DVec3::ZERO;
    }
    let blocks: Vec<DVec3> = v
        .par_chunks(BLOCK)
        .map(|b| {
            if cancel() {
                return DVec3::ZERO;
            }
            b.iter().map(|p| p.dvec3()).sum::<DVec3>()
        })
        .collect();
    blocks.into_iter().sum::<DVec3>() / v.len() as f64
}

/// Signed volume of the mesh `(v, f)` about its mean vertex (faces checked, errors name
/// `faces`); positive for a closed mesh wound counter-clockwise seen from outside.
pub fn volume<P: Point, I: Index>(v: &[P], f: &[[I; 3]]) -> Result<f64> {
    volume_cancellable(v, f, &cancel::never)
}

/// [`volume`] that polls `cancel` before every block of faces (a cancelled call returns a
/// partial sum, see [`crate::cancel`]).
pub fn volume_cancellable<P: Point, I: Index>(
    v: &[P],
    f: &[[I; 3]],
    cancel: Cancel<'_>,
) -> Result<f64> {
    let m = mean(v, cancel);
    let s = face_sum(
        f,
        v.len(),
        |[a, b, c]| {
            let (a, b, c) = (v[a].dvec3() - m, v[b].dvec3() - m, v[c].dvec3() - m);
            a.dot(b.cross(c))
        },
        cancel,
    )?;
    Ok(s / 6.0)
}

/// Total area of the triangles (faces checked, errors name `faces`).
pub fn area<P: Point, I: Index>(v: &[P], f: &[[I; 3]]) -> Result<f64> {
    area_cancellable(v, f, &cancel::never)
}

/// [`area`] that polls `cancel` before every block of faces (a cancelled call returns a
/// partial sum, see [`crate::cancel`]).
pub fn area_cancellable<P: Point, I: Index>(
    v: &[P],
    f: &[[I; 3]],
    cancel: Cancel<'_>,
) -> Result<f64> {
    let s = face_sum(
        f,
        v.len(),
        |[a, b, c]| {
            let a = v[a].dvec3();
            (v[b].dvec3() - a).cross(v[c].dvec3() - a).length()
        },
        cancel,
    )?;
    Ok(0.5 * s)
}

/// Edge statistics of a triangle mesh, from [`edges`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EdgeStats {
    /// Distinct undirected edges (of distinct vertices).
    pub edges: usize,
    /// Edges in exactly one face.
    pub boundary: usize,
    /// Edges in more than two faces.
    pub non_manifold: usize,
    /// Edges in exactly two faces that traverse it in the same direction.
    pub inconsistent: usize,
    /// Face slots whose two vertices are the same (degenerate faces).
    pub degenerate: usize,
}

impl EdgeStats {
    /// Every edge in exactly two faces, no degenerate face.
    pub fn closed(&self) -> bool {
        self.boundary == 0 && self.non_manifold == 0 && self.degenerate == 0
    }

    /// Every edge shared by two faces is traversed by them in opposite directions.
    pub fn winding_consistent(&self) -> bool {
        self.inconsistent == 0
    }

    /// Closed and consistently oriented.
    pub fn watertight(&self) -> bool {
        self.closed() && self.winding_consistent()
    }

    fn add(self, o: EdgeStats) -> EdgeStats {
        EdgeStats {
            edges: self.edges + o.edges,
            boundary: self.boundary + o.boundary,
            non_manifold: self.non_manifold + o.non_manifold,
            inconsistent: self.inconsistent + o.inconsistent,
            degenerate: self.degenerate + o.degenerate,
        }
    }
}

/// A bucket entry `2w + [v → w]`: `u32` when it fits (half the memory), else `u64`.
trait Key: Copy + Ord + Send + Sync + Default {
    fn new(x: u64) -> Self;
    fn get(self) -> u64;
}

impl Key for u32 {
    #[inline(always)]
    fn new(x: u64) -> Self {
        x as u32
    }
    #[inline(always)]
    fn get(self) -> u64 {
        self as u64
    }
}

impl Key for u64 {
    #[inline(always)]
    fn new(x: u64) -> Self {
        x
    }
    #[inline(always)]
    fn get(self) -> u64 {
        self
    }
}

/// Edge statistics of the faces `f` over `n` vertices (faces checked, errors name `faces`).
pub fn edges<I: Index>(f: &[[I; 3]], n: usize) -> Result<EdgeStats> {
    edges_cancellable(f, n, &cancel::never)
}

/// [`edges`] that polls `cancel` between blocks of every pass (a cancelled call returns
/// incomplete counts, see [`crate::cancel`]).
pub fn edges_cancellable<I: Index>(
    f: &[[I; 3]],
    n: usize,
    cancel: Cancel<'_>,
) -> Result<EdgeStats> {
    check_faces_cancellable(f, n, cancel)?;
    if cancel() {
        return Ok(EdgeStats::default());
    }
    Ok(if (2 * n as u64) < u32::MAX as u64 {
        edges_keyed::<I, u32>(f, n, cancel)
    } else {
        edges_keyed::<I, u64>(f, n, cancel)
    })
}

fn edges_keyed<I: Index, K: Key>(f: &[[I; 3]], n: usize, cancel: Cancel<'_>) -> EdgeStats {
    let parts = rayon::current_num_threads().clamp(1, n.max(1));
    let bounds: Vec<usize> = (0..=parts).map(|p| p * n / parts).collect();
    // each part: the slot count of every vertex in its range, and its degenerate slots
    let counted: Vec<(Vec<u32>, usize)> = (0..parts)
        .into_par_iter()
        .map(|p| {
            let (lo, hi) = (bounds[p], bounds[p + 1]);
            let mut count = vec![0u32; hi - lo];
            let mut degenerate = 0;
            for t in f.chunks(SCAN).take_while(|_| !cancel()).flatten() {
                let c = corners(t);
                for k in 0..3 {
                    let (a, b) = (c[k], c[(k + 1) % 3]);
                    let v = a.min(b);
                    if (lo..hi).contains(&v) {
                        if a == b {
                            degenerate += 1;
                        } else {
                            count[v - lo] += 1;
                        }
                    }
                }
            }
            (count, degenerate)
        })
        .collect();
    // a cancelled count is incomplete: the scatter below would overrun its buckets
    if cancel() {
        return EdgeStats::default();
    }
    let sizes: Vec<usize> = counted
        .iter()
        .map(|(c, _)| c.iter().map(|&x| x as usize).sum())
        .collect();
    let mut keys = vec![K::default(); sizes.iter().sum()];
    let mut slices = Vec::with_capacity(parts);
    let mut rest = &mut keys[..];
    for &s in &sizes {
        let (a, b) = rest.split_at_mut(s);
        slices.push(a);
        rest = b;
    }
    counted
        .into_par_iter()
        .zip(slices)
        .enumerate()
        .map(|(p, ((count, degenerate), keys))| {
            let lo = bounds[p];
            // bucket starts (exclusive prefix sums), then cursors while scattering
            let mut start = Vec::with_capacity(count.len() + 1);
            let mut acc = 0usize;
            start.push(0);
            for &c in &count {
                acc += c as usize;
                start.push(acc);
            }
            let mut cursor = start[..count.len()].to_vec();
            drop(count);
            for t in f.chunks(SCAN).take_while(|_| !cancel()).flatten() {
                let c = corners(t);
                for k in 0..3 {
                    let (a, b) = (c[k], c[(k + 1) % 3]);
                    let v = a.min(b);
                    if a != b && (lo..bounds[p + 1]).contains(&v) {
                        let w = a.max(b) as u64;
                        keys[cursor[v - lo]] = K::new(2 * w + u64::from(a < b));
                        cursor[v - lo] += 1;
                    }
                }
            }
            let mut st = EdgeStats {
                degenerate,
                ..EdgeStats::default()
            };
            let buckets = start.windows(2).enumerate();
            for (_, win) in buckets.take_while(|(v, _)| v % SCAN != 0 || !cancel()) {
                let bucket = &mut keys[win[0]..win[1]];
                sort_small(bucket);
                let mut i = 0;
                while i < bucket.len() {
                    let w = bucket[i].get() >> 1;
                    let mut j = i;
                    let mut forward = 0;
                    while j < bucket.len() && bucket[j].get() >> 1 == w {
                        forward += (bucket[j].get() & 1) as usize;
                        j += 1;
                    }
                    let slots = j - i;
                    st.edges += 1;
                    match slots {
                        1 => st.boundary += 1,
                        2 if forward != 1 => st.inconsistent += 1,
                        2 => {}
                        _ => st.non_manifold += 1,
                    }
                    i = j;
                }
            }
            st
        })
        .reduce(EdgeStats::default, EdgeStats::add)
}

/// Sort a bucket: insertion sort for the few entries of a typical vertex (a library sort's
/// set-up costs more there), the library's otherwise.
#[inline]
fn sort_small<K: Key>(b: &mut [K]) {
    if b.len() > 24 {
        b.sort_unstable();
        return;
    }
    for i in 1..b.len() {
        let x = b[i];
        let mut j = i;
        while j > 0 && b[j - 1] > x {
            b[j] = b[j - 1];
            j -= 1;
        }
        b[j] = x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::mesh::fixtures::octahedron;

    fn oct() -> (Vec<[f64; 3]>, Vec<[i64; 3]>) {
        let (v, f) = octahedron();
        (
            v.iter().map(|p| p.to_array()).collect(),
            f.iter().map(|t| t.map(|i| i as i64)).collect(),
        )
    }

    #[test]
    fn octahedron_measures() {
        let (v, f) = oct();
        assert!((volume(&v, &f).unwrap() - 4.0 / 3.0).abs() < 1e-15);
        let a = 8.0 * 3f64.sqrt() / 2.0;
        assert!((area(&v, &f).unwrap() - a).abs() < 1e-14);
        let v32: Vec<[f32; 3]> = v.iter().map(|p| p.map(|x| x as f32)).collect();
        let f32i: Vec<[i32; 3]> = f.iter().map(|t| t.map(|i| i as i32)).collect();
        assert!((volume(&v32, &f32i).unwrap() - 4.0 / 3.0).abs() < 1e-6);
        let e = edges(&f, 6).unwrap();
        assert_eq!(e.edges, 12);
        assert!(e.watertight());
    }

    #[test]
    fn broken_meshes() {
        let (_, f) = oct();
        // a hole: three boundary edges
        let e = edges(&f[1..], 6).unwrap();
        assert_eq!((e.boundary, e.closed()), (3, false));
        // a flipped face: its three edges are traversed twice the same way
        let mut g = f.clone();
        g[0] = [g[0][0], g[0][2], g[0][1]];
        let e = edges(&g, 6).unwrap();
        assert!(e.closed() && !e.winding_consistent() && e.inconsistent == 3);
        // a fin: a third face on an edge
        let mut g = f.clone();
        g.push([0, 2, 3]);
        let e = edges(&g, 6).unwrap();
        assert_eq!((e.non_manifold, e.boundary), (2, 1)); // 0-2 and 3-0 thrice, 2-3 once
        assert!(!e.watertight());
        // degenerate and out-of-range faces
        let e = edges(&[[0i64, 0, 1]], 2).unwrap();
        assert_eq!((e.degenerate, e.edges, e.boundary), (1, 1, 0));
        assert!(e.winding_consistent() && !e.closed());
        let err = edges(&[[0i64, 1, -1]], 3).unwrap_err();
        assert_eq!(err.arg, "faces");
        assert!(err.msg.contains("face 0 refers to vertex -1"), "{err}");
        assert!(volume(&[[0.0; 3]; 3], &[[0i64, 1, 3]]).is_err());
        assert_eq!(edges::<i64>(&[], 0).unwrap(), EdgeStats::default());
    }
}
