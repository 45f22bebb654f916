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

    let threads = rayon::current_num_threads();
    let chunks = if step.is_rotation() && threads > 1 && ext >= 2 * PAR_CHUNK {
        (2 * threads).min(ext / PAR_CHUNK).max(1)
    } else {
        1
    };
    let cs = ext.div_ceil(chunks);
    let chunks = ext.div_ceil(cs);
    let bounds = |c: usize| (c * cs, ((c + 1) * cs).min(ext));

    // Phase 1: provisional transport of every chunk (skipped when nothing needs it).
    let need_scan = chunks > 1 || !matches!(twist, Twist::None);
    let mut start = vec![r0; chunks];
    let mut len_prefix = vec![0.0; chunks + 1];
    let mut end_r = r0;
    if need_scan {
        let prov: Vec<(DVec3, DVec3, f64)> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let (a, b) = bounds(c);
                let s0 = if c == 0 { r0 } else { any_perpendicular(tt(a)) };
                let mut r = s0;
                let mut len = 0.0;
                for (i, l) in seg.iter().enumerate().take(b - 1).skip(a) {
                    r = step.step(i, r);
                    len += l;
                }
                if b < ext {
                    len += seg[b - 1];
                }
                (s0, r, len)
            })
            .collect();
        // Phase 2: serial fix-up of the chunk start vectors.
        let mut theta = 0.0;
        for c in 0..chunks {
            let (a, b) = bounds(c);
            len_prefix[c + 1] = len_prefix[c] + prov[c].2;
            if c > 0 {
                let (_, pb) = bounds(c - 1);
                let last = rotate_about(prov[c - 1].1, tt(pb - 1), theta);
                let true_start = step.step(a - 1, last);
                theta = signed_angle(prov[c].0, true_start, tt(a));
                start[c] = true_start;
            }
            if c + 1 == chunks {
                end_r = rotate_about(prov[c].1, tt(b - 1), theta);
            }
        }
    }
    // Without a scan there is one chunk and no twist: the arc-length prefix is not needed.

    let (raw, total) = match twist {
        Twist::None => (0.0, 0.0),
        Twist::Closed { turns } => {
            let a = signed_angle(end_r, r0, t[0]);
            (a, a + std::f64::consts::TAU * turns as f64)
        }
        Twist::End { target, turns } => {
            let a = signed_angle(end_r, target, t[n - 1]);
            (a, a + std::f64::consts::TAU * turns as f64)
        }
    };
    let length = len_prefix[chunks];
    let rate = if total != 0.0 && length > 0.0 {
        total / length
    } else {
        0.0
    };

    // Phase 3: write the frames from the true chunk starts.
    let write_rows = rows.min(ext);
    out[..9 * write_rows]
        .par_chunks_mut(9 * cs)
        .enumerate()
        .for_each(|(c, buf)| {
            let (a, _) = bounds(c);
            let k = buf.len() / 9;
            let mut r = start[c];
            let mut s = len_prefix[c];
            for (off, f) in buf.chunks_exact_mut(9).enumerate() {
                let i = a + off;
                let ti = tt(i);
                write_frame(f, rotate_about(r, ti, rate * s), ti);
                if off + 1 < k {
                    r = step.step(i, r);
                    s += seg[i];
                }
            }
        });
    if closed && rows == n + 1 {
        let (head, tail) = out.split_at_mut(9 * n);
        tail[..9].copy_from_slice(&head[..9]);
    }
    raw
}
