//! Carrying a reference vector along the samples, with an optional twist distributed
//! linearly in arc length, written straight into the output frames.
//!
//! **Parallel prefix scan.** For double reflection and the rotation method a step is a
//! rotation `Q_i` that depends only on the curve data, so `r_k = Q_{k−1} ⋯ Q_0 r_0`. The
//! samples are cut into chunks; every chunk is transported in parallel from a provisional
//! start vector; because each `Q` is a rotation taking `t_a` to `t_b`, the true vector at the
//! end of a chunk is the provisional one turned about `t_b` by the same angle that separates
//! the true and provisional start vectors. A serial pass over the chunk boundaries fixes
//! these angles, and a second parallel pass writes the frames from the true start vectors.
//!
//! **Twist** (Wang et al. §6.3, Zheng §7.3). Among all frames `g = cos α r + sin α (t × r)`
//! that meet a condition at the far end, `∫(κ² + α′²) ds` is least for `α` linear in arc
//! length: `α(s) = α_L s / L`. `α_L` is the signed angle from the transported reference
//! vector at the end to the target (`r_0` itself for a closed curve), plus `2π·turns`.

use glam::DVec3;
use rayon::prelude::*;

use super::geometry::{any_perpendicular, rotate_about, signed_angle};

/// A transport step from sample `i` to sample `i + 1` (mod n for the closing segment).
pub trait Step: Sync {
    fn step(&self, i: usize, r: DVec3) -> DVec3;
    /// True when the step is a rotation independent of `r` (enables the parallel scan).
    fn is_rotation(&self) -> bool;
}

/// Condition at the far end.
#[derive(Debug, Clone, Copy)]
pub enum Twist {
    /// No condition: the plain transported frames.
    None,
    /// Closed curve: the frame after the closing segment must equal the first one.
    Closed { turns: i64 },
    /// The reference vector at the last sample must be `target` (unit, ⟂ last tangent).
    End { target: DVec3, turns: i64 },
}

/// Minimum number of frames per chunk before a curve is split across threads.
pub const PAR_CHUNK: usize = 1 << 15;

#[inline(always)]
pub fn write_frame(buf: &mut [f64], r: DVec3, t: DVec3) {
    let s = t.cross(r);
    buf[0] = r.x;
    buf[1] = s.x;
    buf[2] = t.x;
    buf[3] = r.y;
    buf[4] = s.y;
    buf[5] = t.y;
    buf[6] = r.z;
    buf[7] = s.z;
    buf[8] = t.z;
}

/// Turn the `(r, s)` columns of a written frame about its `t` column.
#[inline(always)]
fn turn_frame(f: &mut [f64], cos: f64, sin: f64) {
    for row in 0..3 {
        let (r, s) = (f[3 * row], f[3 * row + 1]);
        f[3 * row] = cos * r + sin * s;
        f[3 * row + 1] = cos * s - sin * r;
    }
}

/// How a curve of `ext` extended frames is cut into chunks for the parallel scan: `(chunks,
/// chunk size)`. One chunk unless the step is a rotation, there are several threads and the
/// curve is long.
pub fn plan(ext: usize, is_rotation: bool) -> (usize, usize) {
    let threads = rayon::current_num_threads();
    let chunks = if is_rotation && threads > 1 && ext >= 2 * PAR_CHUNK {
        (2 * threads).min(ext / PAR_CHUNK).max(1)
    } else {
        1
    };
    let cs = ext.div_ceil(chunks).max(1);
    (ext.div_ceil(cs), cs)
}

/// What phase 1 of the scan reports per chunk: the start vector it used (the true one for
/// chunk 0, a provisional one otherwise), its last vector, and the chunk's arc length.
pub type ChunkEnds = (DVec3, DVec3, f64);

/// The curve data phases 2 and 3 of the scan need, whatever produced phase 1.
pub struct Finish<B, T, L> {
    /// Transport across the chunk boundary `i → i + 1` (the step of the method).
    pub boundary_step: B,
    /// Unit tangent at extended index `i` (`i = n` is sample 0 of a closed curve).
    pub tangent: T,
    /// Length of segment `i` (clamped to the last segment), for the twist.
    pub seg: L,
    pub n: usize,
    pub closed: bool,
    pub r0: DVec3,
    pub twist: Twist,
    pub cs: usize,
    pub ext: usize,
}

impl<B, T, L> Finish<B, T, L>
where
    B: Fn(usize, DVec3) -> DVec3,
    T: Fn(usize) -> DVec3,
    L: Fn(usize) -> f64 + Sync,
{
    /// Phases 2 and 3: fix the chunk angles serially, add the twist, turn the written rows
    /// (`out`: `9·rows` values, provisional frames from phase 1) and return the raw end angle.
    pub fn run(&self, prov: &[ChunkEnds], out: &mut [f64]) -> f64 {
        let (n, cs, ext) = (self.n, self.cs, self.ext);
        let chunks = prov.len();
        let rows = out.len() / 9;
        let write_rows = rows.min(ext);
        let tt = &self.tangent;

        // Phase 2 (serial): the angle that turns each chunk's provisional vectors into the
        // true ones, the arc length at each chunk start, and the true vector at the far end.
        let mut theta = vec![0.0; chunks];
        let mut len_prefix = vec![0.0; chunks + 1];
        for c in 0..chunks {
            len_prefix[c + 1] = len_prefix[c] + prov[c].2;
            if c > 0 {
                let a = c * cs;
                let last = rotate_about(prov[c - 1].1, tt(a - 1), theta[c - 1]);
                let true_start = (self.boundary_step)(a - 1, last);
                theta[c] = signed_angle(prov[c].0, true_start, tt(a));
            }
        }
        let end_r = rotate_about(prov[chunks - 1].1, tt(ext - 1), theta[chunks - 1]);

        let (raw, total) = match self.twist {
            Twist::None => (0.0, 0.0),
            Twist::Closed { turns } => {
                let a = signed_angle(end_r, self.r0, tt(0));
                (a, a + std::f64::consts::TAU * turns as f64)
            }
            Twist::End { target, turns } => {
                let a = signed_angle(end_r, target, tt(n - 1));
                (a, a + std::f64::consts::TAU * turns as f64)
            }
        };
        let length = len_prefix[chunks];
        let rate = if total != 0.0 && length > 0.0 {
            total / length
        } else {
            0.0
        };

        // Phase 3 (parallel): turn every row about its tangent by the chunk's correction plus
        // the twist `rate · s`: (r, s) ← (cos φ r + sin φ s, cos φ s − sin φ r). Chunks with
        // nothing to turn (chunk 0 without a twist) are left as they are.
        if rate == 0.0 && theta.iter().any(|&a| a != 0.0) {
            // a constant turn per chunk: split the chunks finely so that all threads share
            // the rows to turn (chunk 0 has none)
            const SUB: usize = 1 << 12;
            let turns: Vec<(f64, f64)> = theta.iter().map(|a| a.sin_cos()).collect();
            out[9 * cs.min(write_rows)..9 * write_rows]
                .par_chunks_mut(9 * SUB)
                .enumerate()
                .for_each(|(k, buf)| {
                    // rows cs + k·SUB …; a sub-chunk may straddle two chunks
                    let first = cs + k * SUB;
                    for (off, f) in buf.chunks_exact_mut(9).enumerate() {
                        let (sin, cos) = turns[(first + off) / cs];
                        turn_frame(f, cos, sin);
                    }
                });
        } else if rate != 0.0 {
            let seg = &self.seg;
            out[..9 * write_rows]
                .par_chunks_mut(9 * cs)
                .enumerate()
                .filter(|(c, _)| rate != 0.0 || theta[*c] != 0.0)
                .for_each(|(c, buf)| {
                    let a = c * cs;
                    let mut arc = len_prefix[c];
                    let (mut sin, mut cos) = theta[c].sin_cos();
                    for (off, f) in buf.chunks_exact_mut(9).enumerate() {
                        if rate != 0.0 {
                            (sin, cos) = (theta[c] + rate * arc).sin_cos();
                            arc += seg(a + off);
                        }
                        turn_frame(f, cos, sin);
                    }
                });
        }
        if self.closed && rows == n + 1 {
            let (head, tail) = out.split_at_mut(9 * n);
            tail[..9].copy_from_slice(&head[..9]);
        }
        raw
    }
}

/// Transport `r0` (unit, ⟂ `t[0]`) along the curve and write the frames.
///
/// * `t`: unit tangents of the `n` distinct samples; `closed` adds the segment `n−1 → 0`.
/// * `seg`: length of every segment (`n−1`, or `n` when closed), for the twist weights.
/// * `out`: `9·rows` values, `rows = n` (or `n + 1` for a closed curve whose input repeated
///   its first point; that row is set to a copy of frame 0).
///
/// Returns the raw end angle `α` (closing angle, or angle to the end target), before adding
/// `2π·turns`; 0 when there is no end condition.
pub fn transport_into<S: Step>(
    step: &S,
    t: &[DVec3],
    seg: &[f64],
    closed: bool,
    r0: DVec3,
    twist: Twist,
    out: &mut [f64],
) -> f64 {
    let n = t.len();
    let m = if closed { n } else { n - 1 }; // segments; extended frames 0..=m
    let ext = m + 1;
    let rows = out.len() / 9;
    debug_assert!(rows == n || (closed && rows == n + 1));
    let tt = |i: usize| t[if i == n { 0 } else { i }];
    let (chunks, cs) = plan(ext, step.is_rotation());
    let bounds = |c: usize| (c * cs, ((c + 1) * cs).min(ext));
    let write_rows = rows.min(ext);

    // Phase 1 (parallel): every chunk transports a provisional start vector (the true one for
    // chunk 0), writes its rows into `buf`, and reports its start, its last vector and its
    // length.
    let provisional = |c: usize, buf: &mut [f64]| {
        let (a, b) = bounds(c);
        let s0 = if c == 0 { r0 } else { any_perpendicular(tt(a)) };
        let mut rows = buf.chunks_exact_mut(9);
        let mut r = s0;
        for i in a..b {
            if let Some(f) = rows.next() {
                write_frame(f, r, tt(i));
            }
            if i + 1 < b {
                r = step.step(i, r);
            }
        }
        (s0, r, seg[a.min(m)..b.min(m)].iter().sum::<f64>())
    };
    let mut prov: Vec<ChunkEnds> = out[..9 * write_rows]
        .par_chunks_mut(9 * cs)
        .enumerate()
        .map(|(c, buf)| provisional(c, buf))
        .collect();
    // A closed curve's extended frame may form a last chunk with no row to write.
    for c in prov.len()..chunks {
        prov.push(provisional(c, &mut []));
    }
    Finish {
        boundary_step: |i: usize, r: DVec3| step.step(i, r),
        tangent: tt,
        seg: |i: usize| seg[i.min(seg.len() - 1)],
        n,
        closed,
        r0,
        twist,
        cs,
        ext,
    }
    .run(&prov, out)
}
