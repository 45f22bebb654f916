//! Measures of a triangle mesh of any size, in time linear in the faces and with no
//! temporaries beyond `O(F)` integers, in parallel.
//!
//! * **Volume** by the divergence theorem, `V = Σ (a − m)·((b − m) × (c − m)) / 6` about the
//!   mean vertex `m` (see [`crate::math::mesh::signed_volume`]); **area** `Σ |(b − a) × (c − a)| / 2`.
//!   Both are summed in fixed blocks of faces with Neumaier's compensation, and the block
//!   sums again, so the result does not depend on the number of threads; both are taken on
//!   the vertices times the power of two that brings the largest coordinate into `[1, 2)`
//!   and scaled back ([`crate::math::mesh::pow2_scale`]): the same bits wherever the plain
//!   sums are finite and normal, and a finite result for coordinates anywhere in `1e±300`.
//! * **Edges** by distributing the `3F` face slots to buckets on their smaller vertex (Knuth,
//!   *The Art of Computer Programming* vol. 3, §5.2, "distribution counting"): every vertex
//!   `v` gets the bucket of the slots `v → w` and `w → v` with `w > v`, stored as
//!   `2w + [v → w]`; each bucket (of the size of the vertex degree) is then sorted on its own
//!   (insertion sort). An edge `{v, w}` of a closed 2-manifold has exactly two slots,
//!   traversed in opposite directions when the faces are consistently oriented ("winding");
//!   one slot is a boundary edge, more a non-manifold edge. The vertices are cut into parts
//!   of `2^10..2^14` (a part's buckets stay in the cache), one part per task, with `CAP`
//!   places per vertex and an overflow list for the rare vertex of higher degree. A face is
//!   ordered once (`lo < mid < hi` and its parity give its three keys). When the faces join
//!   nearby vertices (sweeps, most meshers), every part reads just the chunks of faces whose
//!   vertex range reaches into it, so the faces are read about twice in all (ranges, then
//!   buckets) and nothing of size `O(F)` is allocated; otherwise every chunk of faces first
//!   groups its slots by part (a first distribution, each chunk writing its own lists) and
//!   every part gathers its lists. Either way no two threads write the same place.
use glam::DVec3;
use rayon::prelude::*;

use crate::error::{InputError, Result};
use crate::math::mesh::{compensated_sum, pow2_scale, scale_back};
use crate::run::cancel::Cancel;

/// Faces per block of the compensated sums (fixed, so results do not depend on threads).
pub(crate) const BLOCK: usize = 1 << 14;

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

impl Point for DVec3 {
    #[inline(always)]
    fn dvec3(self) -> DVec3 {
        self
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

impl Index for usize {
    /// Indices past `i64::MAX` (never valid) read as `i64::MAX`, which is out of range.
    #[inline(always)]
    fn get(self) -> i64 {
        i64::try_from(self).unwrap_or(i64::MAX)
    }
}

impl Index for i32 {
    #[inline(always)]
    fn get(self) -> i64 {
        self as i64
    }
}

#[inline(always)]
pub(crate) fn corners<I: Index>(t: &[I; 3]) -> [usize; 3] {
    // only after `check_faces`: every index is in `0..n`
    t.map(|i| i.get() as usize)
}

/// The first row of `values` (rows of `width` numbers, `f32` or `f64`) that holds a NaN or an
/// infinity, blocks scanned in parallel; polls `cancel` before each block (a cancelled scan
/// finds nothing in the blocks it skips, see [`crate::run::cancel`]).
pub fn first_non_finite_row<T: Copy + Sync + Into<f64>>(
    values: &[T],
    width: usize,
    cancel: Cancel<'_>,
) -> Option<usize> {
    let rows = values.len() / width.max(1);
    crate::run::cancel::first_bad_index(rows, cancel, |i| {
        values[i * width..(i + 1) * width]
            .iter()
            .all(|&v| v.into().is_finite())
    })
}

/// Refuse faces with an index outside `0..n` (the first such face; errors name `faces`).
///
/// Polls `cancel` before every block of faces; a cancelled check passes the blocks it skips (the
/// caller discards the result, see [`crate::run::cancel`]).
pub fn check_faces<I: Index>(f: &[[I; 3]], n: usize, cancel: Cancel<'_>) -> Result<()> {
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
pub(crate) fn face_sum<I: Index>(
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

/// The largest absolute coordinate of the vertices (0 for none; NaN rows are skipped),
/// polling `cancel` before each block.
pub(crate) fn largest<P: Point>(v: &[P], cancel: Cancel<'_>) -> f64 {
    v.par_chunks(BLOCK)
        .map(|b| {
            if cancel() {
                return 0.0;
            }
            b.iter()
                .fold(0.0f64, |a, p| a.max(p.dvec3().abs().max_element()))
        })
        .reduce(|| 0.0, f64::max)
}

/// The vertices as the measures read them: times the power of two `s` of
/// [`pow2_scale`] and, for the volume, about their (scaled) mean `m`.
#[derive(Clone, Copy)]
pub(crate) struct Scaled {
    /// The scale `2^-e` applied to every coordinate.
    pub s: f64,
    /// Its inverse `2^e`, to scale results back with [`scale_back`].
    pub back: f64,
    /// The mean of the scaled vertices (zero when not asked for).
    pub m: DVec3,
}

impl Scaled {
    /// The scale of `v`, and its scaled mean when `centred`.
    pub(crate) fn of<P: Point>(v: &[P], centred: bool, cancel: Cancel<'_>) -> Scaled {
        let (s, back) = pow2_scale(largest(v, cancel));
        let m = if centred {
            mean(v, s, cancel)
        } else {
            DVec3::ZERO
        };
        Scaled { s, back, m }
    }

    /// Vertex `i` scaled and moved by the mean.
    #[inline]
    pub(crate) fn at<P: Point>(&self, v: &[P], i: usize) -> DVec3 {
        v[i].dvec3() * self.s - self.m
    }
}

/// The mean of the vertices times `s` (zero for none), summed in fixed blocks (polling
/// `cancel` before each; skipped blocks count as zero).
pub(crate) fn mean<P: Point>(v: &[P], s: f64, cancel: Cancel<'_>) -> DVec3 {
    if v.is_empty() {
        return DVec3::ZERO;
    }
    let blocks: Vec<DVec3> = v
        .par_chunks(BLOCK)
        .map(|b| {
            if cancel() {
                return DVec3::ZERO;
            }
            b.iter().map(|p| p.dvec3() * s).sum::<DVec3>()
        })
        .collect();
    blocks.into_iter().sum::<DVec3>() / v.len() as f64
}

/// Signed volume of the mesh `(v, f)` about its mean vertex (faces checked, errors name
/// `faces`); positive for a closed mesh wound counter-clockwise seen from outside.
///
/// Polls `cancel` before every block of faces (a cancelled call returns a partial sum, see
/// [`crate::run::cancel`]).
pub fn volume<P: Point, I: Index>(v: &[P], f: &[[I; 3]], cancel: Cancel<'_>) -> Result<f64> {
    let sc = Scaled::of(v, true, cancel);
    let six = face_sum(
        f,
        v.len(),
        |[a, b, c]| sc.at(v, a).dot(sc.at(v, b).cross(sc.at(v, c))),
        cancel,
    )?;
    Ok(scale_back(six / 6.0, sc.back, 3))
}

/// Total area of the triangles (faces checked, errors name `faces`).
///
/// Polls `cancel` before every block of faces (a cancelled call returns a partial sum, see
/// [`crate::run::cancel`]).
pub fn area<P: Point, I: Index>(v: &[P], f: &[[I; 3]], cancel: Cancel<'_>) -> Result<f64> {
    let sc = Scaled::of(v, false, cancel);
    let twice = face_sum(
        f,
        v.len(),
        |[a, b, c]| {
            let a = sc.at(v, a);
            (sc.at(v, b) - a).cross(sc.at(v, c) - a).length()
        },
        cancel,
    )?;
    Ok(scale_back(0.5 * twice, sc.back, 2))
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
///
/// Polls `cancel` before every chunk of faces and every part of the vertices (a cancelled call
/// returns incomplete counts, see [`crate::run::cancel`]).
pub fn edges<I: Index>(f: &[[I; 3]], n: usize, cancel: Cancel<'_>) -> Result<EdgeStats> {
    if (2 * n as u64) < u32::MAX as u64 {
        edges_keyed::<I, u32>(f, n, cancel)
    } else {
        edges_keyed::<I, u64>(f, n, cancel)
    }
}

/// The slots of one chunk of faces, grouped by part of the vertices (part `p` in
/// `start[p]..start[p + 1]`): a slot `v → w` or `w → v` (`v < w`) on its way to the bucket
/// of `v` is `v` within its part (`v`) and the key `2w + [v → w]` (`key`).
struct Distributed<K> {
    start: Vec<usize>,
    v: Vec<u32>,
    key: Vec<K>,
    degenerate: Vec<usize>,
}

/// The slots `(a, b)` of a face (the corner pairs `c[k] → c[k + 1]`).
#[inline(always)]
fn slots(c: [usize; 3]) -> [(usize, usize); 3] {
    [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])]
}

/// A face `(a, b, c)` of distinct corners as `(lo, mid, hi, s)`: its corners in increasing
/// order and `s = 1` when it runs `lo → mid → hi` (an even permutation), 0 when it runs
/// `lo → hi → mid`. Its slots are then `lo: 2 mid + s`, `lo: 2 hi + 1 − s` and
/// `mid: 2 hi + s` (bucket: key `2w + [v → w]`).
#[inline(always)]
fn ordered([a, b, c]: [usize; 3]) -> (usize, usize, usize, u64) {
    let lo = a.min(b).min(c);
    let hi = a.max(b).max(c);
    // the cyclic order descends once (at `hi → lo`) when it is `lo → mid → hi`, twice
    // otherwise
    let descents = u64::from(a > b) + u64::from(b > c) + u64::from(c > a);
    (lo, a ^ b ^ c ^ lo ^ hi, hi, u64::from(descents == 1))
}

/// First distribution of one chunk of faces (indices checked): its slots grouped by part
/// of their smaller vertex (parts of `2^bits` vertices). The chunk is read twice (count,
/// then scatter), the second time from the cache.
fn distribute<K: Key, I: Index>(f: &[[I; 3]], bits: u32, parts: usize) -> Distributed<K> {
    let mut count = vec![0usize; parts + 1];
    // the degenerate slots of each part (by the smallest corner of their face)
    let mut degenerate = vec![0usize; parts];
    for t in f {
        let c = corners(t);
        for (a, b) in slots(c) {
            if a != b {
                count[(a.min(b) >> bits) + 1] += 1;
            } else {
                degenerate[c[0].min(c[1]).min(c[2]) >> bits] += 1;
            }
        }
    }
    for p in 1..=parts {
        count[p] += count[p - 1];
    }
    let start = count;
    let mut cursor = start[..parts].to_vec();
    let mut vs = vec![0u32; start[parts]];
    let mut keys = vec![K::default(); start[parts]];
    let mask = (1usize << bits) - 1;
    for t in f {
        for (a, b) in slots(corners(t)) {
            if a != b {
                let v = a.min(b);
                let at = &mut cursor[v >> bits];
                vs[*at] = (v & mask) as u32;
                keys[*at] = K::new(2 * a.max(b) as u64 + u64::from(a < b));
                *at += 1;
            }
        }
    }
    Distributed {
        start,
        v: vs,
        key: keys,
        degenerate,
    }
}

/// The edges of one bucket (the keys `2w + [v → w]` of one vertex `v`), sorted in place.
#[inline(always)]
fn bucket_stats<K: Key>(b: &mut [K], st: &mut EdgeStats) {
    sort_small(b);
    // a closed, consistently wound neighbourhood: pairs `2w, 2w + 1` of increasing `w`
    if b.len() % 2 == 0 {
        let (mut ok, mut after) = (true, 0);
        for pair in b.chunks_exact(2) {
            let (k, l) = (pair[0].get(), pair[1].get());
            ok &= (k & 1 == 0) & (l == k + 1) & (k >= after);
            after = l + 1;
        }
        if ok {
            st.edges += b.len() / 2;
            return;
        }
    }
    let mut i = 0;
    while i < b.len() {
        let k = b[i].get();
        let w = k >> 1;
        let mut j = i + 1;
        while j < b.len() && b[j].get() >> 1 == w {
            j += 1;
        }
        st.edges += 1;
        match j - i {
            1 => st.boundary += 1,
            // sorted: `w → v` (even key) then `v → w` (odd)
            2 if k & 1 == 1 || b[i + 1].get() & 1 == 0 => st.inconsistent += 1,
            2 => {}
            _ => st.non_manifold += 1,
        }
        i = j;
    }
}

/// Bucket capacity per vertex in the second distribution (a vertex with more slots, rare
/// in a mesh of degree about 6, sends the others to an overflow list).
const CAP: usize = 8;

fn edges_keyed<I: Index, K: Key>(f: &[[I; 3]], n: usize, cancel: Cancel<'_>) -> Result<EdgeStats> {
    let threads = rayon::current_num_threads().max(1);
    // parts of 2^10 ..= 2^14 vertices (a part's buckets stay in the cache), at least four
    // per thread when there are enough vertices, at most 2^12 parts (each chunk holds a
    // start per part)
    let log2 = |x: usize| x.max(1).next_power_of_two().trailing_zeros();
    let bits = log2(n.div_ceil(4 * threads))
        .clamp(10, 14)
        .max(log2(n >> 12));
    let parts = (n >> bits) + 1;
    // chunks of faces a few times smaller than a part, so that a chunk of a mesh that joins
    // nearby vertices mostly reaches into one part
    let chunk = f.len().div_ceil(4 * threads).clamp(1 << 10, 1 << 12);
    // the vertex range of every chunk of faces, checking the indices
    let spans: Vec<Option<(usize, usize)>> = f
        .par_chunks(chunk)
        .map(|b| {
            let (mut lo, mut hi) = (usize::MAX, 0);
            if cancel() {
                return Some((lo, hi)); // an empty span: the chunk is not read
            }
            for t in b {
                if !valid(t, n) {
                    return None;
                }
                let [a, b, c] = corners(t);
                lo = lo.min(a.min(b).min(c));
                hi = hi.max(a.max(b).max(c));
            }
            Some((lo, hi))
        })
        .collect();
    if let Some(c) = spans.iter().position(Option::is_none) {
        return Err(out_of_range(f, c * chunk, n));
    }
    let spans: Vec<(usize, usize)> = spans.into_iter().flatten().collect();
    // faces that join nearby vertices (as sweeps and most meshers write them): every part
    // reads the chunks whose vertices reach into it, straight into its buckets; otherwise
    // the slots are first distributed by part
    let reads: usize = spans
        .iter()
        .filter(|s| s.0 <= s.1)
        .map(|s| (s.1 >> bits) - (s.0 >> bits) + 1)
        .sum();
    let local = reads <= 2 * spans.len();
    // local: the chunks that reach into every part; else the slots of (larger) chunks of
    // faces by part
    let mut reach: Vec<Vec<u32>> = Vec::new();
    let mut dist: Vec<Distributed<K>> = Vec::new();
    if local {
        reach.resize(parts, Vec::new());
        for (c, s) in spans.iter().enumerate().filter(|(_, s)| s.0 <= s.1) {
            for r in &mut reach[s.0 >> bits..=s.1 >> bits] {
                r.push(c as u32);
            }
        }
    } else {
        dist = f
            .par_chunks(chunk << 3)
            .map(|b| match cancel() {
                true => distribute::<K, I>(&[], bits, parts),
                false => distribute::<K, I>(b, bits, parts),
            })
            .collect();
    }
    let st = (0..parts)
        .into_par_iter()
        .map_init(Buckets::<K>::default, |bk, p| {
            let lo = p << bits;
            let m = n.saturating_sub(lo).min(1 << bits);
            let mut st = EdgeStats::default();
            if m == 0 || cancel() {
                return st;
            }
            bk.count.clear();
            bk.count.resize(m, 0);
            bk.table.resize(m * CAP, K::default());
            bk.over.clear();
            if local {
                for &c in &reach[p] {
                    let c = c as usize;
                    let b = &f[c * chunk..f.len().min((c + 1) * chunk)];
                    st.degenerate += bk.gather(b, lo, m);
                }
            } else {
                let (count, table, over) = bk.parts();
                for d in &dist {
                    let r = d.start[p]..d.start[p + 1];
                    for (&v, &key) in d.v[r.clone()].iter().zip(&d.key[r]) {
                        put(count, table, over, v as usize, key);
                    }
                    st.degenerate += d.degenerate[p];
                }
            }
            bk.read(m, &mut st);
            st
        })
        .reduce(EdgeStats::default, EdgeStats::add);
    Ok(st)
}

/// Put `key` in the bucket of the vertex `v` of a part: `CAP` places per vertex in `table`,
/// the further slots in `over`.
#[inline(always)]
fn put<K: Key>(count: &mut [u32], table: &mut [K], over: &mut Vec<(u32, K)>, v: usize, key: K) {
    let c = count[v] as usize;
    if c < CAP {
        table[v * CAP + c] = key;
    } else {
        over.push((v as u32, key));
    }
    count[v] += 1;
}

/// The buckets of one part of the vertices: `CAP` places per vertex in `table`, the
/// further slots of a vertex in `over`; scratch space reused from part to part.
struct Buckets<K> {
    count: Vec<u32>,
    table: Vec<K>,
    over: Vec<(u32, K)>,
    big: Vec<K>,
}

impl<K> Default for Buckets<K> {
    fn default() -> Self {
        Buckets {
            count: Vec::new(),
            table: Vec::new(),
            over: Vec::new(),
            big: Vec::new(),
        }
    }
}

impl<K: Key> Buckets<K> {
    /// The counts, places and overflow, borrowed apart.
    fn parts(&mut self) -> (&mut [u32], &mut [K], &mut Vec<(u32, K)>) {
        (&mut self.count, &mut self.table, &mut self.over)
    }

    /// Put the slots of the faces `f` whose smaller vertex lies in `lo..lo + m` (the part);
    /// the degenerate slots of the faces whose smallest corner lies there.
    fn gather<I: Index>(&mut self, f: &[[I; 3]], lo: usize, m: usize) -> usize {
        let (count, table, over) = self.parts();
        let inside = |x: usize| x.wrapping_sub(lo) < m;
        let mut degenerate = 0;
        for t in f {
            let c = corners(t);
            if c[0] == c[1] || c[1] == c[2] || c[2] == c[0] {
                if inside(c[0].min(c[1]).min(c[2])) {
                    degenerate += 1 + usize::from(c[0] == c[1] && c[1] == c[2]) * 2;
                }
                for (a, b) in slots(c) {
                    let v = a.min(b);
                    if a != b && inside(v) {
                        let key = K::new(2 * a.max(b) as u64 + u64::from(a < b));
                        put(count, table, over, v - lo, key);
                    }
                }
            } else {
                let (l, mid, h, s) = ordered(c);
                let (m2, h2) = (2 * mid as u64, 2 * h as u64);
                if inside(l) {
                    put(count, table, over, l - lo, K::new(m2 + s));
                    put(count, table, over, l - lo, K::new(h2 + 1 - s));
                }
                if inside(mid) {
                    put(count, table, over, mid - lo, K::new(h2 + s));
                }
            }
        }
        degenerate
    }

    /// Add the edges of the buckets of the `m` vertices of the part to `st`.
    fn read(&mut self, m: usize, st: &mut EdgeStats) {
        self.over.sort_unstable();
        let mut next = 0; // the overflow of the vertices from here on
        for v in 0..m {
            let c = self.count[v] as usize;
            let b = &mut self.table[v * CAP..(v + 1) * CAP];
            if c <= CAP {
                bucket_stats(&mut b[..c], st);
            } else {
                let end = next + (c - CAP);
                self.big.clear();
                self.big.extend_from_slice(b);
                self.big
                    .extend(self.over[next..end].iter().map(|&(_, k)| k));
                next = end;
                bucket_stats(&mut self.big, st);
            }
        }
    }
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
mod tests;
