//! Carrying a reference vector along the samples, with an optional twist distributed
//! linearly in arc length, written straight into the output frames.
//!
//! **Parallel prefix scan.** For double reflection and the rotation method a step is a
//! rotation `Q_i` that depends only on the curve data, so `r_k = Q_{k−1} ⋯ Q_0 r_0`. The
//! samples are cut into chunks of [`SCAN_CHUNK`] frames; every chunk after the first is
//! transported from a provisional start vector; because each `Q` is a rotation taking `t_a`
//! to `t_b`, the true vector at the end of a chunk is the provisional one turned about `t_b`
//! by the angle that separates the true and provisional start vectors. The chunks go out in
//! order to one worker per thread; the angles are carried from chunk to chunk by whichever
//! worker delivers the chunk the carry needs next ([`super::carry`]), so that no worker waits
//! for another. Without an end condition a chunk's rows are turned as soon as its angle is
//! known, by its own worker while they are still in the cache when it can. With an end
//! condition the rows are turned once, by the chunk angle plus the twist, in a parallel pass
//! after the last chunk.
//!
//! **Twist** (Wang et al. §6.3, Zheng §7.3). Among all frames `g = cos α r + sin α (t × r)`
//! that meet a condition at the far end, `∫(κ² + α′²) ds` is least for `α` linear in arc
//! length: `α(s) = α_L s / L`. `α_L` is the signed angle from the transported reference
//! vector at the end to the target (`r_0` itself for a closed curve), plus `2π·turns`.

pub use super::carry::ChunkEnds;
use super::carry::turn_frame;
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
    Closed { turns: f64 },
    /// The reference vector at the last sample must be `target` (unit, ⟂ last tangent).
    End { target: DVec3, turns: f64 },
}

/// A curve is split across threads only from `2·PAR_CHUNK` frames on.
pub const PAR_CHUNK: usize = 1 << 15;

/// Frames per chunk of the parallel scan. A chunk's rows (72 bytes each, 2.25 MiB) are still
/// in the shared L3 cache when they are turned; chunks of 4096 frames, whose rows would stay
/// in a core's L2 cache, were not faster in `benchmarks/bench_frames.py` on a fresh output.
pub const SCAN_CHUNK: usize = 1 << 15;

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

/// How a curve of `ext` extended frames is cut into chunks for the parallel scan: `(chunks,
/// chunk size)`. One chunk unless the step is a rotation and the curve is long. The cut does
/// not depend on the number of threads (one thread scans the chunks in turn), so the frames
/// have the same bits however many threads run.
pub fn plan(ext: usize, is_rotation: bool) -> (usize, usize) {
    let cs = if is_rotation && ext >= 2 * PAR_CHUNK {
        SCAN_CHUNK
    } else {
        ext.max(1)
    };
    (ext.div_ceil(cs), cs)
}

/// The curve data the scan needs besides the transport of a chunk itself.
pub struct Scan<B, T, L> {
    /// Transport across the chunk boundary `i → i + 1` (the step of the method).
    pub boundary_step: B,
    /// Unit tangent at extended index `i` (`i = n` is sample 0 of a closed curve).
    pub tangent: T,
    /// Length of segment `i` (clamped to the last segment), for the twist.
    pub seg: L,
    /// Number of distinct samples of the curve.
    pub n: usize,
    /// The curve is a loop.
    pub closed: bool,
    /// Unit reference vector at sample 0 (⟂ its tangent).
    pub r0: DVec3,
    /// Boundary condition whose twist is spread in arc length.
    pub twist: Twist,
    /// Chunk size: extended frames per parallel task.
    pub cs: usize,
    /// Number of extended frames (`n`, plus one for a closed curve's return to sample 0).
    pub ext: usize,
}

impl<B, T, L> Scan<B, T, L>
where
    B: Fn(usize, DVec3) -> DVec3 + Sync,
    T: Fn(usize) -> DVec3 + Sync,
    L: Fn(usize) -> f64 + Sync,
{
    /// The scan: transport every chunk, fix the chunk angles, add the twist; returns the raw
    /// end angle, or `None` when `work` reported a failed check.
    ///
    /// `work(c, start, buf)` transports chunk `c` (extended frames `c·cs … (c+1)·cs − 1`)
    /// from `start` (`r0` for chunk 0; `None`: a provisional unit vector ⟂ its first
    /// tangent, of its own choice), writes its rows into `buf` (empty for the extra frame of
    /// a closed curve) and reports its [`ChunkEnds`].
    ///
    /// Chunks are handed out in order to one worker per thread, and the angle that turns a
    /// chunk's provisional start into the true one is carried in chunk order by whichever
    /// worker is free ([`super::carry`]): no worker waits for a chunk in another's hands.
    /// Without an end condition each chunk's rows are turned as soon as its angle is known;
    /// with one (an `end` or a closed curve) all rows are turned once, by the chunk angle plus
    /// the twist, in a parallel pass after the last chunk. The frames do not depend on the
    /// timing: chunk `c > 0` always starts from its provisional vector.
    ///
    /// `work`, `boundary_step` and `tangent` must not use rayon themselves: a worker that
    /// has nothing left to take sleeps until the carry passes the running chunks, and must
    /// not hold a task they need.
    ///
    /// Its final turning pass polls `cancel` every [`CANCEL_ROWS`] rows and stops once it says
    /// stop (`out` is then incomplete; `work` polls on its own).
    pub fn scan<W>(
        &self,
        work: W,
        out: &mut [f64],
        cancel: crate::run::cancel::Cancel<'_>,
    ) -> Option<f64>
    where
        W: Fn(usize, Option<DVec3>, &mut [f64]) -> Option<ChunkEnds> + Sync,
    {
        let (n, cs, ext) = (self.n, self.cs, self.ext);
        let chunks = ext.div_ceil(cs);
        let rows = out.len() / 9;
        let write_rows = rows.min(ext);
        let tt = &self.tangent;
        // without an end condition the chunk angle is the whole correction: turn at once
        let turn_now = matches!(self.twist, Twist::None);

        // one slice of rows per chunk (chunks ≤ rows); a closed curve's extended frame may
        // form a last chunk with no row to write
        let mut bufs: Vec<&mut [f64]> = out[..9 * write_rows].chunks_mut(9 * cs).collect();
        bufs.resize_with(chunks, Default::default);
        let angle = |c: usize, prev: ChunkEnds, prev_angle: f64, p: ChunkEnds| {
            let a = c * cs;
            let last = rotate_about(prev.1, tt(a - 1), prev_angle);
            let true_start = (self.boundary_step)(a - 1, last);
            signed_angle(p.0, true_start, tt(a))
        };
        // one result per chunk, within `super::WORKING_BYTES_PER_ROW` (checked free by the
        // binding's `ensure_memory` probe)
        let resolved = super::carry::run(
            bufs,
            |c, buf| work(c, (c == 0).then_some(self.r0), buf),
            angle,
            turn_now,
        )?;

        let (last, last_angle) = resolved[chunks - 1];
        let end_r = rotate_about(last.1, tt(ext - 1), last_angle);
        let (raw, total) = match self.twist {
            Twist::None => (0.0, 0.0),
            Twist::Closed { turns } => {
                let a = signed_angle(end_r, self.r0, tt(0));
                (a, a + std::f64::consts::TAU * turns)
            }
            Twist::End { target, turns } => {
                let a = signed_angle(end_r, target, tt(n - 1));
                (a, a + std::f64::consts::TAU * turns)
            }
        };
        if !turn_now {
            // one per chunk (chunks ≤ rows), within `super::WORKING_BYTES_PER_ROW` (checked
            // free by the binding's `ensure_memory` probe)
            let mut len_prefix = vec![0.0; chunks + 1];
            for (c, &(p, _)) in resolved.iter().enumerate() {
                len_prefix[c + 1] = len_prefix[c] + p.2;
            }
            let length = len_prefix[chunks];
            let rate = if total != 0.0 && length > 0.0 {
                total / length
            } else {
                0.0
            };
            // Turn every row about its tangent by the chunk's angle plus the twist
            // `rate · s`: (r, s) ← (cos φ r + sin φ s, cos φ s − sin φ r).
            let seg = &self.seg;
            out[..9 * write_rows]
                .par_chunks_mut(9 * cs)
                .enumerate()
                .filter(|(c, _)| rate != 0.0 || resolved[*c].1 != 0.0)
                .for_each(|(c, buf)| {
                    let a = c * cs;
                    let angle = resolved[c].1;
                    let mut arc = len_prefix[c];
                    let (mut sin, mut cos) = angle.sin_cos();
                    for (off, f) in buf.chunks_exact_mut(9).enumerate() {
                        if off % CANCEL_ROWS == 0 && cancel() {
                            return;
                        }
                        if rate != 0.0 {
                            (sin, cos) = (angle + rate * arc).sin_cos();
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
        Some(raw)
    }
}

/// Rows of a chunk between two polls of the cancel hook ([`transport_into`]).
const CANCEL_ROWS: usize = 1 << 16;

/// Transport `r0` (unit, ⟂ `t[0]`) along the curve and write the frames.
///
/// * `t`: unit tangents of the `n` distinct samples; `closed` adds the segment `n−1 → 0`.
/// * `seg`: length of every segment (`n−1`, or `n` when closed), for the twist weights.
/// * `out`: `9·rows` values, `rows = n` (or `n + 1` for a closed curve whose input repeated
///   its first point; that row is set to a copy of frame 0).
///
/// Returns the raw end angle `α` (closing angle, or angle to the end target), before adding
/// `2π·turns`; 0 when there is no end condition.
///
/// Polls `cancel` every [`CANCEL_ROWS`] rows of every chunk and stops the scan once it says stop
/// (`out` is then incomplete and the angle 0; see [`crate::run::cancel`]).
#[allow(clippy::too_many_arguments)]
pub fn transport_into<S: Step>(
    step: &S,
    t: &[DVec3],
    seg: &[f64],
    closed: bool,
    r0: DVec3,
    twist: Twist,
    out: &mut [f64],
    cancel: crate::run::cancel::Cancel<'_>,
) -> f64 {
    let ext = if closed { t.len() } else { t.len() - 1 } + 1;
    let (_, cs) = plan(ext, step.is_rotation());
    transport_chunked(step, t, seg, closed, r0, twist, out, cs, cancel)
}

/// [`transport_into`] with chunks of `cs` extended frames (the scan's result
/// does not depend on `cs` beyond rounding).
#[allow(clippy::too_many_arguments)]
fn transport_chunked<S: Step>(
    step: &S,
    t: &[DVec3],
    seg: &[f64],
    closed: bool,
    r0: DVec3,
    twist: Twist,
    out: &mut [f64],
    cs: usize,
    cancel: crate::run::cancel::Cancel<'_>,
) -> f64 {
    let n = t.len();
    let m = if closed { n } else { n - 1 }; // segments; extended frames 0..=m
    let ext = m + 1;
    let rows = out.len() / 9;
    debug_assert!(rows == n || (closed && rows == n + 1));
    let tt = |i: usize| t[if i == n { 0 } else { i }];
    let work = |c: usize, start: Option<DVec3>, buf: &mut [f64]| {
        let (a, b) = (c * cs, ((c + 1) * cs).min(ext));
        let s0 = start.unwrap_or_else(|| any_perpendicular(tt(a)));
        let mut rows = buf.chunks_exact_mut(9);
        let mut r = s0;
        for i in a..b {
            if (i - a) % CANCEL_ROWS == 0 && cancel() {
                return None;
            }
            if let Some(f) = rows.next() {
                write_frame(f, r, tt(i));
            }
            if i + 1 < b {
                r = step.step(i, r);
            }
        }
        Some((s0, r, seg[a.min(m)..b.min(m)].iter().sum::<f64>()))
    };
    let angle = Scan {
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
    .scan(work, out, cancel);
    // `work` fails only when cancelled, and so does the scan
    debug_assert!(angle.is_some() || cancel());
    angle.unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::super::carry::tests::pool;
    use super::super::double_reflection::DoubleReflection;
    use super::super::{Method, Orientation, Request, compute_general, compute_into};
    use super::*;
    use crate::run::cancel;
    use std::f64::consts::TAU;

    /// The same values, bit for bit.
    fn same_bits(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits())
    }

    fn worst(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn plan_cuts_long_rotation_curves_the_same_on_any_thread_count() {
        for threads in [1, 2, 3] {
            pool(threads).install(|| {
                assert_eq!(plan(0, true), (0, 1), "no frames: no chunk");
                assert_eq!(plan(1, true), (1, 1));
                // the longest curve kept in one chunk, and the shortest one cut
                let long = 2 * PAR_CHUNK;
                assert_eq!(plan(long - 1, true), (1, long - 1));
                let cut = |ext: usize| (ext.div_ceil(SCAN_CHUNK), SCAN_CHUNK);
                assert_eq!(plan(long, true), cut(long));
                // one frame past whole chunks: a last chunk of a single frame
                assert_eq!(plan(long + 1, true), cut(long + 1));
                assert_eq!(plan(3 * SCAN_CHUNK + 1, true), cut(3 * SCAN_CHUNK + 1));
                // a step that depends on r is never cut
                assert_eq!(plan(4 * long, false), (1, 4 * long));
                for ext in [1, 2, long - 1, long, long + 1, 5 * long + 3] {
                    let (chunks, cs) = plan(ext, true);
                    assert!(chunks * cs >= ext && (chunks - 1) * cs < ext, "{ext}");
                }
            });
        }
    }

    /// A trefoil knot with its unit tangents, unevenly sampled.
    fn trefoil(n: usize) -> (Vec<DVec3>, Vec<DVec3>) {
        (0..n)
            .map(|i| {
                let k = TAU / n as f64;
                let u = k * (i as f64 + 0.3 * (5.0 * k * i as f64).sin());
                let (c2, s2, c3, s3) = (
                    (2.0 * u).cos(),
                    (2.0 * u).sin(),
                    (3.0 * u).cos(),
                    (3.0 * u).sin(),
                );
                let r = 2.0 + c3;
                let x = DVec3::new(r * c2, r * s2, s3);
                let d = DVec3::new(
                    -3.0 * s3 * c2 - 2.0 * r * s2,
                    -3.0 * s3 * s2 + 2.0 * r * c2,
                    3.0 * c3,
                );
                (x, d.normalize())
            })
            .unzip()
    }

    /// The frames of the scan computed serially: `r` carried one step after another, then
    /// every row turned by the twist `total · s / L` at its arc length `s`.
    fn serial<S: Step>(
        step: &S,
        t: &[DVec3],
        seg: &[f64],
        closed: bool,
        r0: DVec3,
        twist: Twist,
        rows: usize,
    ) -> (Vec<f64>, f64) {
        let n = t.len();
        let ext = if closed { n + 1 } else { n };
        let mut r = vec![r0];
        for i in 0..ext - 1 {
            r.push(step.step(i, r[i]));
        }
        let end = r[ext - 1];
        let (raw, total) = match twist {
            Twist::None => (0.0, 0.0),
            Twist::Closed { turns } => {
                let a = signed_angle(end, r0, t[0]);
                (a, a + TAU * turns)
            }
            Twist::End { target, turns } => {
                let a = signed_angle(end, target, t[n - 1]);
                (a, a + TAU * turns)
            }
        };
        let length: f64 = seg[..ext - 1].iter().sum();
        let mut out = vec![0.0; 9 * rows];
        let mut s = 0.0;
        for (i, f) in out.chunks_exact_mut(9).enumerate() {
            let ti = t[i % n];
            write_frame(
                f,
                rotate_about(r[i.min(ext - 1)], ti, total * s / length),
                ti,
            );
            s += seg[i.min(seg.len() - 1)];
        }
        if closed && rows == n + 1 {
            let first: [f64; 9] = out[..9].try_into().expect("a frame");
            out[9 * n..].copy_from_slice(&first);
        }
        (out, raw)
    }

    /// [`Scan`] with chunks of a few frames (so that many chunks, a last chunk of one frame
    /// and the empty chunk of a closed curve's extra frame all occur) on 1–3 threads: the
    /// frames and the end angle of the serial transport, and the same bits on every run.
    #[test]
    fn scan_with_small_chunks_equals_the_serial_transport() {
        for n in [2, 3, 4, 5, 6, 9, 11] {
            let (x, t) = trefoil(n);
            for closed in [false, true] {
                if closed && n < 3 {
                    continue;
                }
                let dr = DoubleReflection {
                    x: &x,
                    t: &t,
                    closed,
                    tangent_chords: false,
                };
                let m = if closed { n } else { n - 1 };
                let seg: Vec<f64> = (0..m).map(|i| (x[(i + 1) % n] - x[i]).length()).collect();
                let r0 = any_perpendicular(t[0]);
                let target = any_perpendicular(t[n - 1]).cross(t[n - 1]);
                let twists = if closed {
                    vec![
                        Twist::None,
                        Twist::Closed { turns: 0.0 },
                        Twist::Closed { turns: -2.0 },
                    ]
                } else {
                    vec![Twist::None, Twist::End { target, turns: 1.0 }]
                };
                for twist in twists {
                    for rows in [n, n + usize::from(closed)] {
                        let (want, want_raw) = serial(&dr, &t, &seg, closed, r0, twist, rows);
                        for cs in [1, 2, 3, 5] {
                            let mut three: Option<Vec<f64>> = None;
                            for threads in [1, 2, 3, 3] {
                                let mut out = vec![0.0; 9 * rows];
                                let raw = pool(threads).install(|| {
                                    transport_chunked(
                                        &dr,
                                        &t,
                                        &seg,
                                        closed,
                                        r0,
                                        twist,
                                        &mut out,
                                        cs,
                                        &crate::run::cancel::never,
                                    )
                                });
                                let what = format!(
                                    "n {n}, closed {closed}, {twist:?}, rows {rows}, chunk {cs}, {threads} threads"
                                );
                                assert!(
                                    (raw - want_raw).abs() < 1e-12,
                                    "{what}: {raw} vs {want_raw}"
                                );
                                let w = worst(&out, &want);
                                assert!(w < 1e-12, "{what}: frames differ by {w:e}");
                                if threads == 3 {
                                    if let Some(before) = &three {
                                        assert!(same_bits(before, &out), "{what}: not repeatable");
                                    }
                                    three = Some(out);
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// A chunk whose check fails makes the whole scan fail, on any thread count, without
    /// leaving the other workers waiting.
    #[test]
    fn a_failed_chunk_fails_the_scan() {
        let (n, cs) = (40, 3);
        let (x, t) = trefoil(n);
        let dr = DoubleReflection {
            x: &x,
            t: &t,
            closed: false,
            tangent_chords: false,
        };
        let scan = Scan {
            boundary_step: |i: usize, r: DVec3| dr.step(i, r),
            tangent: |i: usize| t[i],
            seg: |_: usize| 1.0,
            n,
            closed: false,
            r0: any_perpendicular(t[0]),
            twist: Twist::None,
            cs,
            ext: n,
        };
        for bad in [0, 1, 6, n.div_ceil(cs) - 1] {
            for threads in [1, 2, 4] {
                let work = |c: usize, start: Option<DVec3>, _: &mut [f64]| {
                    let s0 = start.unwrap_or_else(|| any_perpendicular(t[c * cs]));
                    (c != bad).then_some((s0, s0, 1.0))
                };
                let mut out = vec![0.0; 9 * n];
                let got = pool(threads).install(|| scan.scan(work, &mut out, &cancel::never));
                assert!(got.is_none(), "chunk {bad} failed, {threads} threads");
            }
        }
    }

    /// Through the public drivers (the general path, several chunks on two threads): the
    /// frames of one thread (one chunk) to 1e-12, and the same bits on every run.
    #[test]
    fn chunked_scan_through_the_drivers_equals_the_serial_result() {
        let n = 3 * SCAN_CHUNK + 5;
        let (x, t) = trefoil(n);
        let open = &x[..n - 7];
        let target = Orientation::Vector(DVec3::new(0.3, 0.2, 1.0));
        let requests = [
            // a closed curve: the closing twist
            Request {
                points: Some(&x),
                closed: true,
                turns: 1.0,
                ..Default::default()
            },
            // the rotation method with an end condition
            Request {
                points: Some(open),
                method: Method::Rotation,
                end: Some(target),
                ..Default::default()
            },
            // double reflection without a condition (the rows turned at once)
            Request {
                points: Some(open),
                ..Default::default()
            },
            // tangents only: chords from the tangents
            Request {
                tangents: Some(&t),
                tangent_chords: true,
                closed: true,
                ..Default::default()
            },
        ];
        for (k, req) in requests.iter().enumerate() {
            let rows = req.points.or(req.tangents).map_or(0, <[DVec3]>::len);
            let run = |threads: usize| {
                let mut out = vec![0.0; 9 * rows];
                let raw = pool(threads)
                    .install(|| {
                        assert!(plan(rows + 1, true).0 > 2, "cut on any thread count");
                        compute_general(req, &mut out, &cancel::never)
                    })
                    .expect("valid input");
                (out, raw)
            };
            let (one, raw1) = run(1);
            let (two, raw2) = run(2);
            let (three, raw3) = run(3);
            assert!(
                same_bits(&one, &two) && same_bits(&one, &three),
                "request {k}: the bits depend on the thread count"
            );
            assert!(raw1.to_bits() == raw2.to_bits() && raw1.to_bits() == raw3.to_bits());
            for _ in 0..3 {
                let (again, raw) = run(2);
                assert!(same_bits(&again, &two) && raw.to_bits() == raw2.to_bits());
            }
            // compute_into (which may take the fused path) agrees
            let mut out = vec![0.0; 9 * rows];
            pool(2)
                .install(|| compute_into(req, &mut out, &cancel::never))
                .expect("valid input");
            assert!(worst(&out, &two) < 1e-12, "request {k}");
        }
    }
}
