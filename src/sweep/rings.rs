//! The rings of one spine: vertices `x_i + M_i (a′_j r_i + b′_j s_i)` with the mitre stretch,
//! normals of the smooth surface (three-point derivatives in arc length), uv, fold and twist tests.

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::ops::Range;
use std::sync::OnceLock;

use super::faces::FacePattern;
use super::kernel::{Axes, Cols, Columns, Geo, RingScratch};
use super::layout::Plan;
use super::scale::{Index, Real, put3, unscaled};
use super::{MeshMut, Profile, Spine, columns};
use crate::run::cancel::Cancel;

/// The unit vector along a chord of the spine (zero for a zero chord), scaled by the largest
/// component before squaring: any finite spine size.
#[inline(always)]
fn unit_chord(v: DVec3) -> DVec3 {
    crate::math::scale::normalize(v).unwrap_or(DVec3::ZERO)
}

/// Mitre stretch at a ring between the unit chords `din` (in) and `dout` (out) of the spine
/// ([`unit_chord`]) with tangent `t`: `(factor − 1, unit direction)`, or zero where the
/// spine is straight.
pub(super) fn mitre(din: DVec3, dout: DVec3, t: DVec3, limit: f64) -> (f64, DVec3) {
    let half_cos = 0.5 * (1.0 + din.dot(dout)); // cos²(φ/2)
    let k = din - dout;
    let k = k - k.dot(t) * t;
    let kl = k.length();
    if !(kl > 1e-12) || !(half_cos > 0.0) {
        return (0.0, DVec3::ZERO);
    }
    let factor = (1.0 / half_cos.sqrt()).min(limit);
    (factor - 1.0, k / kl)
}

/// Three-point derivative weights at the middle of samples spaced `h1`, `h2`.
#[inline]
fn central_weights(h1: f64, h2: f64) -> [f64; 3] {
    [
        -h2 / (h1 * (h1 + h2)),
        (h2 - h1) / (h1 * h2),
        h1 / (h2 * (h1 + h2)),
    ]
}

/// Derivative along the spine at ring `i`: three rings and their weights (three-point rule
/// in arc length; one-sided at open ends; two points for a two-sample spine).
fn spine_weights(arc: &[f64], i: usize, r_n: usize, closed: bool) -> ([usize; 3], [f64; 3]) {
    if closed {
        let a = if i == 0 { r_n - 1 } else { i - 1 };
        let b = if i + 1 == r_n { 0 } else { i + 1 };
        let h1 = if i == 0 {
            arc[r_n] - arc[r_n - 1]
        } else {
            arc[i] - arc[i - 1]
        };
        let h2 = arc[i + 1] - arc[i];
        ([a, i, b], central_weights(h1, h2))
    } else if r_n == 2 {
        let h = arc[1] - arc[0];
        ([0, 1, 1], [-1.0 / h, 1.0 / h, 0.0])
    } else if i == 0 || i + 1 == r_n {
        let (i0, i1, i2) = if i == 0 {
            (0, 1, 2)
        } else {
            (r_n - 1, r_n - 2, r_n - 3)
        };
        let h1 = (arc[i1] - arc[i0]).abs();
        let h2 = (arc[i2] - arc[i1]).abs();
        let sg = if i == 0 { 1.0 } else { -1.0 };
        (
            [i0, i1, i2],
            [
                -sg * (2.0 * h1 + h2) / (h1 * (h1 + h2)),
                sg * (h1 + h2) / (h1 * h2),
                -sg * h1 / (h2 * (h1 + h2)),
            ],
        )
    } else {
        let h1 = arc[i] - arc[i - 1];
        let h2 = arc[i + 1] - arc[i];
        ([i - 1, i, i + 1], central_weights(h1, h2))
    }
}

/// One block of rings' share of the outputs (`f`: the faces of its segments): whole rings,
/// or one piece of the columns of one ring (see [`Rings::write`]).
pub(super) struct Block<'a, R, I> {
    /// The block's first stored ring.
    pub(super) i0: usize,
    /// The block's columns of every ring (`0..cols`: whole rings).
    pub(super) j: Range<usize>,
    /// The split of every segment (true: along `b d`) when the block holds a piece of a
    /// ring, indexed by segment (`None`: whole rings, which test their segments here).
    pub(super) bd: Option<&'a [bool]>,
    pub(super) v: &'a mut [[R; 3]],
    pub(super) n: Option<&'a mut [[R; 3]]>,
    pub(super) u: Option<&'a mut [[R; 2]]>,
    pub(super) f: &'a mut [[I; 3]],
}

/// The first vertex with a coordinate that is not finite.
#[inline(always)]
fn first_non_finite<R: Real>(rv: &[[R; 3]]) -> Option<usize> {
    let ok = rv.as_flattened().iter().fold(true, |a, x| a & x.finite());
    match ok {
        true => None,
        false => rv.iter().position(|v| !v.iter().all(|x| x.finite())),
    }
}

/// The vertices, normals and uv of one spine's rings, and its fold-over test.
///
/// One pass over the stored rings: positions (mitred), normals of the smooth surface
/// (un-mitred: the mitre is a discretisation correction and would tilt them), uv, and the
/// fold-over test of the segment starting there. Stored ring `i` is spine sample
/// `i mod rings`, stored column `j` is profile vertex `j mod m` (the duplicates of split
/// seams carry u = L and v = 1). Nothing is read back from the outputs but the ring just
/// written; rings go in blocks so that each ring's geometry is computed once (a ring of more
/// than [`BLOCK_BYTES`] goes in pieces of its columns, each with its ring's geometry).
///
/// [`BLOCK_BYTES`]: super::run::BLOCK_BYTES
pub(super) struct Rings<'a> {
    pub(super) s: &'a Spine<'a>,
    /// The distinct spine samples.
    pub(super) x: &'a [DVec3],
    pub(super) plan: &'a Plan,
    pub(super) p: &'a Profile,
    pub(super) column: &'a OnceLock<Columns>,
    pub(super) closed: bool,
    pub(super) miter_limit: f64,
    /// −1 where the faces are wound the other way (clockwise closed profiles).
    pub(super) sign: f64,
    /// Global row of spine sample 0 (for the fold reports).
    pub(super) rowbase: usize,
    /// The column shift at a closed spine's seam (0, or `m/2` for a half turn: the rings
    /// across the seam are then seen turned by π, [`Rings::across`]).
    pub(super) seam: usize,
}

impl Rings<'_> {
    #[inline(always)]
    pub(super) fn tangent(&self, k: usize) -> DVec3 {
        columns(&self.s.frames[k]).2
    }

    /// Ring `k` of the smooth swept surface: centre and the images of the profile axes.
    #[inline(always)]
    pub(super) fn base(&self, k: usize) -> (DVec3, DVec3, DVec3) {
        let s = self.s;
        let (r, q, _) = columns(&s.frames[k]);
        let sc = s.scale[if s.scale.len() == 1 { 0 } else { k }];
        let (sn, cs) = if s.twist.is_empty() {
            (0.0, 1.0)
        } else {
            s.twist[k].sin_cos()
        };
        (
            self.x[k],
            sc.x * (cs * r + sn * q),
            sc.y * (cs * q - sn * r),
        )
    }

    /// The unit chord from spine sample `k` to the next ([`unit_chord`]; on a closed spine
    /// the last wraps to the first, on an open one it is zero).
    #[inline(always)]
    pub(super) fn chord(&self, k: usize) -> DVec3 {
        let n = self.x.len();
        match k + 1 == n {
            false => unit_chord(self.x[k + 1] - self.x[k]),
            true if self.closed => unit_chord(self.x[0] - self.x[k]),
            true => DVec3::ZERO,
        }
    }

    /// Spine sample `k ± 1` (`k < rings`), wrapping around.
    #[inline(always)]
    pub(super) fn after(&self, k: usize) -> usize {
        if k + 1 == self.x.len() { 0 } else { k + 1 }
    }

    #[inline(always)]
    pub(super) fn before(&self, k: usize) -> usize {
        if k == 0 { self.x.len() - 1 } else { k - 1 }
    }

    /// Ring `g` as seen from a ring on the other side of a seam with a half turn
    /// (`crossed`): its axes turned by π about the tangent, so that its column `j` is the
    /// neighbour of the other ring's column `j` (see [`super::seam`]); else as it is.
    #[inline(always)]
    pub(super) fn across(&self, g: Geo, crossed: bool) -> Geo {
        match crossed && self.seam > 0 {
            false => g,
            true => Geo {
                b: (g.b.0, -g.b.1, -g.b.2),
                ma: -g.ma,
                mb: -g.mb,
                ..g
            },
        }
    }

    #[inline(always)]
    pub(super) fn geo(&self, k: usize) -> Geo {
        self.geo_between(k, self.chord(self.before(k)), self.chord(k))
    }

    /// Ring `k` of the mitred sweep, from the unit chords into and out of sample `k`
    /// ([`Rings::chord`] of `k − 1` and `k`: a pass along the spine computes each chord
    /// once).
    #[inline(always)]
    pub(super) fn geo_between(&self, k: usize, din: DVec3, dout: DVec3) -> Geo {
        self.geo_of(k, din, dout, self.base(k), self.tangent(k))
    }

    /// Ring `k` of the mitred sweep with the centre and axes `b` and the tangent `t`.
    #[inline(always)]
    fn geo_of(&self, k: usize, din: DVec3, dout: DVec3, b: Axes, t: DVec3) -> Geo {
        let end = !self.closed && (k == 0 || k + 1 == self.x.len());
        let (mf, mk) = match end {
            true => (0.0, DVec3::ZERO),
            false => mitre(din, dout, t, self.miter_limit),
        };
        Geo {
            k,
            b,
            ma: b.1 + (mf * b.1.dot(mk)) * mk,
            mb: b.2 + (mf * b.2.dot(mk)) * mk,
            t,
        }
    }

    /// Ring `k` of the mitred sweep turned to the tangent `t` (its axes turned by the
    /// minimal rotation from the frame's tangent to `t`).
    pub(super) fn geo_turned(&self, k: usize, t: DVec3) -> Geo {
        let (x, a, b) = self.base(k);
        let turn = crate::math::rotation::minimal_rotation_matrix(self.tangent(k), t);
        let (din, dout) = (self.chord(self.before(k)), self.chord(k));
        self.geo_of(k, din, dout, (x, turn * a, turn * b), t)
    }

    /// All stored rings and the side faces of their segments, `grain` rings per parallel
    /// task (or, for a ring larger than `piece` columns, pieces of `piece` columns of one
    /// ring per task), each output element written once; returns the fold-over rows and the
    /// first vertex (local) out of the output type's range. `vbase`: the spine's first
    /// vertex; `unscale`: see [`unscaled`]; `ring`: scratch for a spine of one block (the
    /// short streamlines of a bundle), which is written here without setting up parallel
    /// tasks.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn write<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        (grain, piece): (usize, usize),
        ring: &mut RingScratch,
        cancel: Cancel<'_>,
    ) -> (Vec<usize>, Option<usize>) {
        let cols = self.plan.cols;
        if piece < cols {
            return self.write_pieces(out, pattern, vbase, unscale, piece, cancel);
        }
        let all = self.column.get_or_init(|| Columns::of(self.p, cols));
        let column = &all.view(0..cols);
        let block = grain * cols;
        if out.vertices.len() <= block {
            if cancel() {
                return (Vec::new(), None);
            }
            let b = Block {
                i0: 0,
                j: 0..cols,
                bd: None,
                v: out.vertices,
                n: out.normals,
                u: out.uv,
                f: out.faces,
            };
            return self.block(b, column, pattern, vbase, unscale, ring);
        }
        let blocks = out.vertices.len().div_ceil(block);
        let mut nb: Vec<Option<&mut [[R; 3]]>> = match out.normals {
            Some(a) => a.chunks_mut(block).map(Some).collect(),
            None => Vec::new(),
        };
        nb.resize_with(blocks, || None);
        let mut ub: Vec<Option<&mut [[R; 2]]>> = match out.uv {
            Some(a) => a.chunks_mut(block).map(Some).collect(),
            None => Vec::new(),
        };
        ub.resize_with(blocks, || None);
        let per_block = grain * pattern.per_segment();
        let mut fb: Vec<&mut [[I; 3]]> = out.faces.chunks_mut(per_block).collect();
        fb.resize_with(blocks, || &mut []);
        let jobs: Vec<_> = out
            .vertices
            .chunks_mut(block)
            .zip(nb)
            .zip(ub)
            .zip(fb)
            .enumerate()
            .map(|(bi, (((v, n), u), f))| Block {
                i0: bi * grain,
                j: 0..cols,
                bd: None,
                v,
                n,
                u,
                f,
            })
            .collect();
        let per_block: Vec<(Vec<usize>, Option<usize>)> = jobs
            .into_par_iter()
            .map_init(
                || RingScratch::new(cols),
                |ring, b| match cancel() {
                    true => (Vec::new(), None),
                    false => self.block(b, column, pattern, vbase, unscale, ring),
                },
            )
            .collect();
        let bad = per_block.iter().find_map(|b| b.1);
        (per_block.into_iter().flat_map(|b| b.0).collect(), bad)
    }

    /// [`Rings::write`] for rings of more than `piece` columns: first the split of every
    /// odd segment (is any quad twisted?) piece by piece, then every ring piece by piece,
    /// each piece a parallel task that polls `cancel`, so that no task writes much more
    /// than [`BLOCK_BYTES`] however large the profile. The same operations per column as a
    /// whole ring, so the same bits.
    ///
    /// [`BLOCK_BYTES`]: super::run::BLOCK_BYTES
    fn write_pieces<R: Real, I: Index>(
        &self,
        out: MeshMut<R, I>,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        piece: usize,
        cancel: Cancel<'_>,
    ) -> (Vec<usize>, Option<usize>) {
        let (cols, segments) = (self.plan.cols, self.plan.segments);
        let edges = pattern.edges;
        let pieces = cols.div_ceil(piece);
        // the odd segments' splits: (segment, piece) tasks
        let twisted: Vec<bool> = (0..segments / 2 * pieces)
            .into_par_iter()
            .map(|t| {
                let (i, c) = (2 * (t / pieces) + 1, t % pieces);
                let e = (c * piece).min(edges)..((c + 1) * piece).min(edges);
                let next = self.across(self.geo(self.after(i)), i + 1 >= self.plan.rings);
                !cancel() && self.twisted(&self.geo(i), &next, e)
            })
            .collect();
        if cancel() {
            return (Vec::new(), None);
        }
        let bd: Vec<bool> = (0..segments)
            .map(|i| i % 2 == 1 && twisted[i / 2 * pieces..][..pieces].iter().any(|&t| t))
            .collect();
        // the output of every (ring, piece), in the order of the rings
        let stored = self.plan.stored_rings;
        let mut jobs = Vec::with_capacity(stored * pieces);
        let mut v = out.vertices.chunks_mut(cols);
        let mut n = out.normals.map(|a| a.chunks_mut(cols));
        let mut u = out.uv.map(|a| a.chunks_mut(cols));
        let mut f = out.faces.chunks_mut(pattern.per_segment());
        for i in 0..stored {
            let (Some(rv), rn, ru) = (
                v.next(),
                n.as_mut().and_then(|a| a.next()),
                u.as_mut().and_then(|a| a.next()),
            ) else {
                break;
            };
            let rf = if i < segments { f.next() } else { None };
            let mut rv = rv.chunks_mut(piece);
            let mut rn = rn.map(|a| a.chunks_mut(piece));
            let mut ru = ru.map(|a| a.chunks_mut(piece));
            let mut rf = rf.map(|a| a.chunks_mut(2 * piece));
            for c in 0..pieces {
                let (Some(pv), pn, pu) = (
                    rv.next(),
                    rn.as_mut().and_then(|a| a.next()),
                    ru.as_mut().and_then(|a| a.next()),
                ) else {
                    break;
                };
                let pf = rf.as_mut().and_then(|a| a.next()).unwrap_or(&mut []);
                jobs.push(Block {
                    i0: i,
                    j: c * piece..((c + 1) * piece).min(cols),
                    bd: Some(&bd),
                    v: pv,
                    n: pn,
                    u: pu,
                    f: pf,
                });
            }
        }
        let per_piece: Vec<(Vec<usize>, Option<usize>)> = jobs
            .into_par_iter()
            .map_init(
                || (RingScratch::new(piece), Columns::of(self.p, 0)),
                |(ring, column), b| match cancel() {
                    true => (Vec::new(), None),
                    false => {
                        column.fill(self.p, b.j.clone());
                        let view = &column.view(0..b.j.len());
                        self.block(b, view, pattern, vbase, unscale, ring)
                    }
                },
            )
            .collect();
        let bad = per_piece.iter().find_map(|b| b.1);
        // a folded segment is reported by each of its pieces that folds
        let mut folds: Vec<usize> = per_piece.into_iter().flat_map(|b| b.0).collect();
        folds.dedup();
        (folds, bad)
    }

    /// One block of rings, [`Rings::block_body`]; on x86-64 processors with AVX2 the same
    /// code compiled for 256-bit vectors (four columns per instruction in the column loops
    /// of [`RingScratch`]; the same IEEE operations, so the same bits), chosen at run time
    /// like the frames' scan (`crate::frames::fused`). Measured with one thread on a
    /// 10⁵-point float32 tube: 110 instead of 204 instructions per vertex in this kernel,
    /// 71–76 ms instead of 82–88 ms for the core call (best of 25, a loaded machine).
    pub(super) fn block<R: Real, I: Index>(
        &self,
        b: Block<R, I>,
        column: &Cols,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        ring: &mut RingScratch,
    ) -> (Vec<usize>, Option<usize>) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: `block_avx2` only needs the processor to support AVX2, checked just
            // above.
            return unsafe { self.block_avx2(b, column, pattern, vbase, unscale, ring) };
        }
        self.block_body(b, column, pattern, vbase, unscale, ring)
    }

    /// [`Rings::block_body`] compiled for AVX2. Safety: call only where AVX2 is available.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn block_avx2<R: Real, I: Index>(
        &self,
        b: Block<R, I>,
        column: &Cols,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        ring: &mut RingScratch,
    ) -> (Vec<usize>, Option<usize>) {
        self.block_body(b, column, pattern, vbase, unscale, ring)
    }

    /// The rings of a block and the faces of their segments: per ring, the vertices and
    /// normals column by column into [`RingScratch`], then stored (with the unscaling and
    /// the range check), uv, the fold-over test and the faces of the block's columns.
    #[inline(always)]
    pub(super) fn block_body<R: Real, I: Index>(
        &self,
        b: Block<R, I>,
        column: &Cols,
        pattern: &FacePattern,
        vbase: usize,
        unscale: Option<i32>,
        ring: &mut RingScratch,
    ) -> (Vec<usize>, Option<usize>) {
        let (r_n, cols, stored) = (self.plan.rings, self.plan.cols, self.plan.stored_rings);
        let arc = &self.plan.arc[..];
        let Block {
            i0,
            j: js,
            bd: given_bd,
            v: bv,
            n: mut bn,
            u: mut bu,
            f: bf,
        } = b;
        let width = js.len();
        ring.fit(width);
        // the block's edges of every segment and their faces
        let edges = js.start.min(pattern.edges)..js.end.min(pattern.edges);
        let per_segment = 2 * edges.len();
        let (mut folds, mut bad) = (Vec::new(), None);
        // the unit chords out of the previous, current and next ring's samples
        let k0 = if i0 >= r_n { i0 - r_n } else { i0 };
        let (kp, kn) = (self.before(k0), self.after(k0));
        let (cp, mut cc) = (self.chord(kp), self.chord(k0));
        // stored ring i is sample i mod r_n; rings before 0 and from r_n on (a split seam's
        // copy of ring 0) lie across the seam
        let prev = self.geo_between(kp, self.chord(self.before(kp)), cp);
        let mut prev = self.across(prev, i0 == 0 || i0 > r_n);
        let mut cur = self.across(self.geo_between(k0, cp, cc), i0 >= r_n);
        let mut kn = kn;
        for (di, rv) in bv.chunks_mut(width).enumerate() {
            let i = i0 + di;
            let cn = self.chord(kn);
            let next = self.across(self.geo_between(kn, cc, cn), i + 1 >= r_n);
            let span = di * width..(di + 1) * width;
            ring.vertices(column, &cur);
            ring.put_vertices(rv, unscale);
            if let Some(bn) = bn.as_deref_mut() {
                ring.normals(column, &self.normal_crosses([&prev, &cur, &next]));
                let rn = &mut bn[span.clone()];
                if !ring.put_normals(rn) {
                    // a degenerate spine derivative: the normal of the ring plane
                    for (j, n) in rn.iter_mut().enumerate() {
                        if !ring.usable(j) {
                            let w = (column.w[0][j], column.w[1][j]);
                            *n = put3(self.plane_normal(w, (cur.b.1, cur.b.2), cur.t));
                        }
                    }
                }
            }
            if bad.is_none() {
                bad = first_non_finite(rv).map(|j| i * cols + js.start + j);
            }
            if let Some(bu) = bu.as_deref_mut() {
                let u = unscaled::<R>(arc[i], unscale);
                for (w, &v) in bu[span].iter_mut().zip(column.v) {
                    *w = [u, R::of(v)];
                }
            }
            if i < self.plan.segments {
                if self.folds_over(&cur, &next, column) {
                    folds.push(self.rowbase + i);
                }
                // split along b d on the odd twisted segments
                let bd = match given_bd {
                    Some(bd) => bd[i],
                    None => i % 2 == 1 && self.twisted_ring(&cur, &next, column, pattern.edges),
                };
                let faces = &mut bf[di * per_segment..(di + 1) * per_segment];
                match i + 1 == stored {
                    // the closing segment, to ring 0 (with the seam's column shift)
                    true => pattern.write_seam(faces, bd, vbase + i * cols, vbase, edges.start),
                    false => {
                        let (b0, b1) = (vbase + i * cols, vbase + (i + 1) * cols);
                        pattern.write(faces, bd, b0, b1, edges.start);
                    }
                }
            }
            (prev, cur, cc) = (cur, next, cn);
            kn = self.after(kn);
        }
        (folds, bad)
    }

    /// The outward unit normal of a ring's own plane at a column whose profile derivative
    /// has weights `w` on the ring's axes `(a, b)`: `±(w₀ a + w₁ b) × t` (the tangent `t`
    /// where that vanishes), the normal of a prism on the ring.
    #[inline]
    pub(super) fn plane_normal(&self, w: (f64, f64), (a, b): (DVec3, DVec3), t: DVec3) -> DVec3 {
        let e = w.0 * a + w.1 * b;
        (self.sign * e.cross(t)).try_normalize().unwrap_or(t)
    }

    /// d/ds of ring `cur` (three-point rule in arc length): the same weights on centres and
    /// axes; the neighbouring rings are at hand.
    #[inline(always)]
    fn spine_derivative(&self, [prev, cur, next]: [&Geo; 3]) -> (DVec3, DVec3, DVec3) {
        let k = cur.k;
        let (idx, w) = spine_weights(&self.plan.arc, k, self.plan.rings, self.closed);
        let (mut dx, mut da, mut db) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        if idx == [prev.k, k, next.k] {
            // the rule on the neighbours at hand (inside the spine, or closed), in the same
            // order as below
            for (wi, bi) in w.into_iter().zip([prev.b, cur.b, next.b]) {
                dx += wi * bi.0;
                da += wi * bi.1;
                db += wi * bi.2;
            }
            return (dx, da, db);
        }
        for (&ii, &wi) in idx.iter().zip(&w) {
            let bi = match ii {
                _ if ii == k => cur.b,
                _ if ii == next.k => next.b,
                _ if ii == prev.k => prev.b,
                _ => self.base(ii),
            };
            dx += wi * bi.0;
            da += wi * bi.1;
            db += wi * bi.2;
        }
        (dx, da, db)
    }

    /// The normal S_v × S_u of ring `cur` with S_v ∝ e = dp.x b₁ + dp.y b₂ (around the
    /// profile) and S_u = dx + p.x da + p.y db (along the spine) is bilinear in a column's
    /// (dp, p): six cross products per ring (returned here), six weights per column.
    #[inline(always)]
    fn normal_crosses(&self, geo: [&Geo; 3]) -> [DVec3; 6] {
        let (b, sign) = (geo[1].b, self.sign);
        let (dx, da, db) = self.spine_derivative(geo);
        [
            sign * b.1.cross(dx),
            sign * b.2.cross(dx),
            sign * b.1.cross(da),
            sign * b.1.cross(db),
            sign * b.2.cross(da),
            sign * b.2.cross(db),
        ]
    }

    /// Are the quads of profile edges `edges` of the segment from `cur` to `next` twisted (not
    /// planar)? The quad of
    /// profile edge `p → p + e` has `b − a = A e`, `c − d = A′ e` and
    /// `d − a = Δx + (A′ − A) p`, with `A = (ma, mb)`; `τ = det(b − a, d − a, c − d)`.
    #[inline(always)]
    fn twisted(&self, cur: &Geo, next: &Geo, edges: Range<usize>) -> bool {
        let (dx, dma, dmb) = (next.b.0 - cur.b.0, next.ma - cur.ma, next.mb - cur.mb);
        let pts = &self.p.points;
        let m = pts.len();
        edges.into_iter().any(|j| {
            let (p, e) = (pts[j], pts[if j + 1 == m { 0 } else { j + 1 }] - pts[j]);
            let u = e.x * cur.ma + e.y * cur.mb;
            let w = e.x * next.ma + e.y * next.mb;
            let v = dx + p.x * dma + p.y * dmb;
            let tau = u.cross(v).dot(w);
            // |τ| > 10⁻⁹ |u| |v| |w| decided on the squares (no square roots) where they are
            // clear of it by 10⁻¹², far more than the few roundings of either side
            let (t2, s2) = (tau * tau, 1e-18 * (u.dot(u) * v.dot(v) * w.dot(w)));
            if s2 > 1e-290 && s2.is_finite() {
                if t2 > s2 * (1.0 + 1e-12) {
                    return true;
                }
                if t2 < s2 * (1.0 - 1e-12) {
                    return false;
                }
            }
            tau.abs() > 1e-9 * (u.length() * v.length() * w.length())
        })
    }

    /// [`Rings::twisted`] on edges `0..edges` of whole rings (`column`: all the stored
    /// columns): the same test on every edge without branches (a loop the compiler turns
    /// into vector instructions), deciding where every edge is clear of the threshold on
    /// the squares; where one is not, [`Rings::twisted`] decides (the test is an or over
    /// the edges, so the same answer).
    #[inline(always)]
    fn twisted_ring(&self, cur: &Geo, next: &Geo, column: &Cols, edges: usize) -> bool {
        let (dx, dma, dmb) = (next.b.0 - cur.b.0, next.ma - cur.ma, next.mb - cur.mb);
        let n = edges.min(column.px.len());
        let (px, py) = (&column.px[..n], &column.py[..n]);
        let (ex, ey) = (&column.ex[..n], &column.ey[..n]);
        let (mut yes, mut unsure) = (false, false);
        for j in 0..n {
            let u = ex[j] * cur.ma + ey[j] * cur.mb;
            let w = ex[j] * next.ma + ey[j] * next.mb;
            let v = dx + px[j] * dma + py[j] * dmb;
            let tau = u.cross(v).dot(w);
            let (t2, s2) = (tau * tau, 1e-18 * (u.dot(u) * v.dot(v) * w.dot(w)));
            let clear = (s2 > 1e-290) & s2.is_finite();
            let (hi, lo) = (t2 > s2 * (1.0 + 1e-12), t2 < s2 * (1.0 - 1e-12));
            yes |= clear & hi;
            unsure |= !(clear & (hi | lo));
        }
        yes || (unsure && self.twisted(cur, next, 0..edges))
    }

    /// Fold-over of the segment from `cur` to `next`: rail edges must advance along both
    /// tangents. The rail edge of profile vertex p is (x′ − x) + p_a (ma′ − ma) + p_b (mb′ − mb),
    /// so its components along t and t′ are affine in p.
    #[inline(always)]
    fn folds_over(&self, cur: &Geo, next: &Geo, column: &Cols) -> bool {
        let (dx0, dma, dmb) = (next.b.0 - cur.b.0, next.ma - cur.ma, next.mb - cur.mb);
        let along = |t: DVec3| (dx0.dot(t), DVec2::new(dma.dot(t), dmb.dot(t)));
        let ((c1, g1), (c2, g2)) = (along(cur.t), along(next.t));
        // over the stored columns (the profile's vertices; a seam's copy repeats the first),
        // without branches
        let (px, py) = (column.px, &column.py[..column.px.len()]);
        let ok = px.iter().zip(py).fold(true, |a, (&x, &y)| {
            a & (c1 + (x * g1.x + y * g1.y) > 0.0) & (c2 + (x * g2.x + y * g2.y) > 0.0)
        });
        !ok
    }
}
