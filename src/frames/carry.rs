//! Handing out the chunks of the parallel transport scan ([`super::transport::Scan`]) so
//! that no worker ever waits for a chunk another worker holds.
//!
//! The scan transports every chunk `c` from a provisional start vector; the angle `φ_c`
//! that turns its provisional vectors into the true ones follows from `φ_{c−1}` and the ends
//! of chunks `c − 1` and `c` (a serial carry of a few operations per chunk, see
//! [`super::transport`]). Workers take chunks in order from a shared counter. A worker that
//! has transported chunk `c` records its ends and advances the carry as far as the recorded
//! chunks allow. When that reaches `c`, it turns its rows at once, while they are still in
//! its cache. Otherwise it parks them and takes the next chunk; the worker whose chunk later
//! lets the carry pass `c` queues the parked rows, and whichever worker is free turns them.
//! A worker the system has descheduled therefore holds up only the carry past its own chunk,
//! never the transport of the others; workers with nothing left to take sleep until queued
//! rows arrive or the scan is over.
//!
//! The carry runs in chunk order whoever computes it, each chunk starts from its own
//! provisional vector, and the chunks do not depend on the number of threads, so the
//! frames have the same bits on any thread count and under any timing.

use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

use glam::DVec3;

/// The shared state of the chunks, behind one lock (taken a few times per chunk).
struct State<'a> {
    /// Chunks handed out so far (the next one to take).
    next: usize,
    /// What each chunk's transport reported: `None` until it ran, `Some(None)` if a check
    /// failed in it.
    ends: Vec<Option<Option<ChunkEnds>>>,
    /// `φ_c` for every chunk `c < known`.
    angles: Vec<f64>,
    known: usize,
    /// The rows of each chunk while no worker holds them: before the chunk is taken, and
    /// after it ran until its angle is known.
    rows: Vec<Option<&'a mut [f64]>>,
    /// Rows whose angle is known and that wait for a free worker to turn them.
    queue: Vec<(f64, &'a mut [f64])>,
    /// A chunk failed (or its worker panicked): nothing more to do.
    failed: bool,
}

impl State<'_> {
    fn over(&self) -> bool {
        self.failed || self.known == self.ends.len()
    }
}

fn lock<'m, 'a>(m: &'m Mutex<State<'a>>) -> MutexGuard<'m, State<'a>> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Marks the scan failed if a worker unwinds while it holds a chunk, so that no other worker
/// sleeps for ever waiting for the carry to pass it.
struct Abandon<'m, 'a> {
    state: &'m Mutex<State<'a>>,
    more: &'m Condvar,
    armed: bool,
}

impl Drop for Abandon<'_, '_> {
    fn drop(&mut self) {
        if self.armed {
            lock(self.state).failed = true;
            self.more.notify_all();
        }
    }
}

/// Advance the carry over the chunks whose ends are recorded (see [`run`]); queue the
/// parked rows of the chunks it passes, all but `own`, whose worker turns them itself.
fn advance<A>(st: &mut State<'_>, own: usize, angle: &A, turn: bool)
where
    A: Fn(usize, ChunkEnds, f64, ChunkEnds) -> f64,
{
    while st.known < st.ends.len() {
        let k = st.known;
        let Some(Some(this)) = st.ends[k] else { break };
        let phi = match k.checked_sub(1).and_then(|j| st.ends[j].flatten()) {
            Some(prev) => angle(k, prev, st.angles[k - 1], this),
            None => 0.0,
        };
        st.angles[k] = phi;
        st.known += 1;
        if turn
            && k != own
            && let Some(buf) = st.rows[k].take()
        {
            st.queue.push((phi, buf));
        }
    }
}

/// What a worker does next.
enum Task<'a> {
    Transport(usize, &'a mut [f64]),
    Turn(f64, &'a mut [f64]),
}

/// Transport the chunks whose rows are `rows` (one slice per chunk, possibly empty) and
/// carry their angles: `work(c, buf)` transports chunk `c` into `buf` and reports its
/// [`ChunkEnds`] (`None`: a check failed); `angle(c, prev, φ_prev, this)` is `φ_c` for
/// `c ≥ 1` from the ends of chunks `c − 1` and `c` (`φ_0 = 0`). With `turn` the rows of
/// every chunk are turned about their tangents by its angle. Returns every chunk's ends and
/// angle, or `None` if any chunk failed.
///
/// `work` and `angle` must not use rayon themselves (a worker sleeping at the end of the
/// scan could otherwise hold a task the others need).
pub(super) fn run<W, A>(
    rows: Vec<&mut [f64]>,
    work: W,
    angle: A,
    turn: bool,
) -> Option<Vec<(ChunkEnds, f64)>>
where
    W: Fn(usize, &mut [f64]) -> Option<ChunkEnds> + Sync,
    A: Fn(usize, ChunkEnds, f64, ChunkEnds) -> f64 + Sync,
{
    let chunks = rows.len();
    let state = Mutex::new(State {
        next: 0,
        ends: vec![None; chunks],
        angles: vec![0.0; chunks],
        known: 0,
        rows: rows.into_iter().map(Some).collect(),
        queue: Vec::new(),
        failed: false,
    });
    let more = Condvar::new();

    let worker = || {
        loop {
            let task = {
                let mut st = lock(&state);
                loop {
                    if st.failed {
                        break None;
                    }
                    if let Some((phi, buf)) = st.queue.pop() {
                        break Some(Task::Turn(phi, buf));
                    }
                    if st.next < chunks {
                        let c = st.next;
                        st.next += 1;
                        let buf = st.rows[c].take().unwrap_or_default();
                        break Some(Task::Transport(c, buf));
                    }
                    if st.over() {
                        break None;
                    }
                    // a chunk the carry needs is still running: wait for its worker
                    st = more.wait(st).unwrap_or_else(PoisonError::into_inner);
                }
            };
            match task {
                None => return,
                Some(Task::Turn(phi, buf)) => turn_rows(buf, phi),
                Some(Task::Transport(c, buf)) => {
                    let mut abandon = Abandon {
                        state: &state,
                        more: &more,
                        armed: true,
                    };
                    let ends = work(c, &mut *buf);
                    let mut st = lock(&state);
                    abandon.armed = false;
                    st.ends[c] = Some(ends);
                    st.failed |= ends.is_none();
                    advance(&mut st, c, &angle, turn);
                    let own = if c < st.known {
                        Some((st.angles[c], buf))
                    } else {
                        st.rows[c] = Some(buf);
                        None
                    };
                    if !st.queue.is_empty() || st.over() {
                        more.notify_all();
                    }
                    drop(st);
                    if turn && let Some((phi, buf)) = own {
                        turn_rows(buf, phi);
                    }
                }
            }
        }
    };
    let threads = rayon::current_num_threads().min(chunks);
    if threads > 1 {
        rayon::scope(|s| {
            for _ in 1..threads {
                s.spawn(|_| worker());
            }
            worker();
        });
    } else {
        worker();
    }
    let st = state.into_inner().unwrap_or_else(PoisonError::into_inner);
    if st.failed || st.known < chunks {
        return None;
    }
    st.ends
        .into_iter()
        .zip(st.angles)
        .map(|(e, phi)| Some((e.flatten()?, phi)))
        .collect()
}

/// What the transport of a chunk reports: the start vector it used (the true one for chunk
/// 0, a provisional one otherwise), its last vector, and the chunk's arc length.
pub type ChunkEnds = (DVec3, DVec3, f64);

/// Turn the rows of written frames about their `t` columns by `angle` (nothing for 0).
fn turn_rows(buf: &mut [f64], angle: f64) {
    if angle != 0.0 {
        let (sin, cos) = angle.sin_cos();
        for f in buf.chunks_exact_mut(9) {
            turn_frame(f, cos, sin);
        }
    }
}

/// Turn the `(r, s)` columns of a written frame about its `t` column.
#[inline(always)]
pub(super) fn turn_frame(f: &mut [f64], cos: f64, sin: f64) {
    for row in 0..3 {
        let (r, s) = (f[3 * row], f[3 * row + 1]);
        f[3 * row] = cos * r + sin * s;
        f[3 * row + 1] = cos * s - sin * r;
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use glam::DVec3;
    use std::sync::atomic::{AtomicBool, Ordering};

    /// A rayon pool of `threads` workers.
    pub(in crate::frames) fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
    }

    /// Frames per chunk and chunks of the synthetic scans below.
    const ROWS: usize = 3;
    const CHUNKS: usize = 7;

    /// A synthetic chunk: frames with `r = x̂`, `s = ŷ`, `t = ẑ` scaled by the row index,
    /// ends that carry the chunk index; its angle is the previous one plus `0.1·(c + 1)`.
    fn work(c: usize, buf: &mut [f64]) -> Option<ChunkEnds> {
        for (i, f) in buf.chunks_exact_mut(9).enumerate() {
            let k = (c * ROWS + i + 1) as f64;
            f.copy_from_slice(&[k, 0.0, 0.0, 0.0, k, 0.0, 0.0, 0.0, k]);
        }
        Some((DVec3::X, DVec3::splat(c as f64), 1.0))
    }

    fn angle(c: usize, prev: ChunkEnds, prev_angle: f64, this: ChunkEnds) -> f64 {
        assert_eq!(prev.1.x as usize + 1, c, "the carry uses the chunk before");
        assert_eq!(this.1.x as usize, c);
        prev_angle + 0.1 * (c + 1) as f64
    }

    /// The frames and angles of the scan computed in order on one thread, by hand.
    fn expected() -> (Vec<f64>, Vec<f64>) {
        let mut out = vec![0.0; 9 * ROWS * CHUNKS];
        let mut angles = vec![0.0; CHUNKS];
        for (c, buf) in out.chunks_mut(9 * ROWS).enumerate() {
            work(c, buf);
            if c > 0 {
                angles[c] = angles[c - 1] + 0.1 * (c + 1) as f64;
            }
            turn_rows(buf, angles[c]);
        }
        (out, angles)
    }

    fn scan<W>(threads: usize, work: W) -> (Vec<f64>, Option<Vec<(ChunkEnds, f64)>>)
    where
        W: Fn(usize, &mut [f64]) -> Option<ChunkEnds> + Sync + Send,
    {
        let mut out = vec![0.0; 9 * ROWS * CHUNKS];
        let got =
            pool(threads).install(|| run(out.chunks_mut(9 * ROWS).collect(), work, angle, true));
        (out, got)
    }

    fn same_bits(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits())
    }

    /// On 1–4 threads: every chunk turned once by its carried angle, the same bits as the
    /// scan done in order by hand.
    #[test]
    fn the_carry_turns_every_chunk_by_its_angle() {
        let (want, angles) = expected();
        for threads in [1, 2, 3, 4] {
            for _ in 0..20 {
                let (out, got) = scan(threads, work);
                let got = got.expect("no chunk fails");
                assert!(same_bits(&out, &want), "{threads} threads");
                let phi: Vec<f64> = got.iter().map(|g| g.1).collect();
                assert!(same_bits(&phi, &angles), "{threads} threads");
            }
        }
    }

    /// A worker held up on chunk 0 does not hold up the others: the other worker transports
    /// every later chunk meanwhile (chunk 0's work returns only once the last chunk has been
    /// transported), and the frames are those of the scan in order.
    #[test]
    fn a_held_up_chunk_holds_up_no_other_worker() {
        let (want, _) = expected();
        let last_done = AtomicBool::new(false);
        let held = |c: usize, buf: &mut [f64]| {
            if c == 0 {
                // a guard against a hang in a broken scan, not a timing bound
                let give_up = std::time::Instant::now() + std::time::Duration::from_secs(120);
                while !last_done.load(Ordering::Acquire) {
                    assert!(
                        std::time::Instant::now() < give_up,
                        "chunk 0 waited for ever: the other worker did not go on"
                    );
                    std::thread::yield_now();
                }
            }
            let ends = work(c, buf);
            if c == CHUNKS - 1 {
                last_done.store(true, Ordering::Release);
            }
            ends
        };
        let (out, got) = scan(2, held);
        assert!(got.is_some() && same_bits(&out, &want));
    }

    /// A failed chunk fails the scan, and a worker that panics in its chunk neither hangs the
    /// others nor is lost: the panic reaches the caller.
    #[test]
    fn failures_and_panics_end_the_scan() {
        for threads in [1, 2, 3] {
            for bad in [0, 3, CHUNKS - 1] {
                let fail = |c: usize, buf: &mut [f64]| if c == bad { None } else { work(c, buf) };
                assert!(
                    scan(threads, fail).1.is_none(),
                    "{threads} threads, chunk {bad}"
                );
                let panic = |c: usize, buf: &mut [f64]| {
                    assert!(c != bad, "a panic in chunk {c}");
                    work(c, buf)
                };
                let caught = std::panic::catch_unwind(|| scan(threads, panic));
                assert!(caught.is_err(), "{threads} threads, chunk {bad}");
            }
        }
    }
}
