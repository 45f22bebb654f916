//! Cooperative cancellation of long computations. A caller passes a [`Cancel`] hook that the
//! parallel loops poll once per block of work (a few thousand rows) and skip the remaining
//! blocks once it returns `true`; the outputs are then incomplete and the caller discards
//! them. The Python binding's hook reads a flag that its calling thread sets on Ctrl-C.
//! A call that stops with an error returns [`InputError::stopped`] (of kind
//! [`ErrorKind::Stopped`](crate::error::ErrorKind::Stopped)), which the caller discards.
//! Every long operation takes its hook as an argument; callers that never stop pass
//! [`never`].

use crate::error::{InputError, Result};

/// Returns `true` when the computation should stop.
pub type Cancel<'a> = &'a (dyn Fn() -> bool + Sync);

/// The hook of callers that never cancel.
pub fn never() -> bool {
    false
}

/// Items (rows, keys, cubics) between polls of a sequential cancellable loop.
pub const BLOCK: usize = 1 << 14;

/// The poll of a sequential loop at item `i`: [`InputError::stopped`] when `i` starts a
/// block of [`BLOCK`] items and `cancel` says stop (`cancel::poll(i, cancel)?` in the loop).
#[inline]
pub fn poll(i: usize, cancel: Cancel<'_>) -> Result<()> {
    if i % BLOCK == 0 && cancel() {
        Err(InputError::stopped())
    } else {
        Ok(())
    }
}

/// Rows per block of [`fill`]: large enough that a poll costs nothing beside the rows,
/// small enough that each block (and the page faults of its fresh output) ends within
/// well under a millisecond.
pub const GRAIN: usize = 1 << 12;

/// `out[i] = row(i)` for every index, on the current thread pool in blocks of [`GRAIN`]
/// rows, polling `cancel` before each block. Once it says stop the remaining blocks are
/// skipped and `false` is returned (`out` is then incomplete; the caller discards it).
pub fn fill<T: Send>(out: &mut [T], cancel: Cancel<'_>, row: impl Fn(usize) -> T + Sync) -> bool {
    fill_in_blocks(out, GRAIN, cancel, row)
}

/// [`fill`] with blocks of `grain` rows (for rows that cost microseconds each).
pub fn fill_in_blocks<T: Send>(
    out: &mut [T],
    grain: usize,
    cancel: Cancel<'_>,
    row: impl Fn(usize) -> T + Sync,
) -> bool {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, Ordering};
    let stopped = AtomicBool::new(false);
    let grain = grain.max(1);
    out.par_chunks_mut(grain)
        .enumerate()
        .for_each(|(b, block)| {
            if stopped.load(Ordering::Relaxed) || cancel() {
                stopped.store(true, Ordering::Relaxed);
                return;
            }
            for (k, o) in block.iter_mut().enumerate() {
                *o = row(b * grain + k);
            }
        });
    !stopped.into_inner()
}

/// The first index of `0..n` failing `ok`, scanning blocks of [`GRAIN`] indices in
/// parallel and polling `cancel` before each block; once it says stop the blocks after it
/// count as passing (the caller, told to stop, discards the answer).
pub fn first_bad_index(
    n: usize,
    cancel: Cancel<'_>,
    ok: impl Fn(usize) -> bool + Sync,
) -> Option<usize> {
    use rayon::prelude::*;
    (0..n.div_ceil(GRAIN))
        .into_par_iter()
        .position_first(|b| !cancel() && !(b * GRAIN..n.min((b + 1) * GRAIN)).all(&ok))
        .and_then(|b| (b * GRAIN..n).find(|&i| !ok(i)))
}

/// Sort `v` by `cmp` on the current thread pool, polling `cancel` between the sorts of
/// pieces of 2¹⁶ items (each a few milliseconds); the sorted pieces are then merged by a
/// stable parallel merge sort, which finds them as runs (2²³ items in about 0.2 s on two
/// threads). Returns `false`, `v` in some order, when `cancel` said stop. With distinct
/// keys the result is that of any other sort.
pub fn sort_by<T: Send>(
    v: &mut [T],
    cmp: impl Fn(&T, &T) -> std::cmp::Ordering + Sync,
    cancel: Cancel<'_>,
) -> bool {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, Ordering};
    let stopped = AtomicBool::new(false);
    v.par_chunks_mut(1 << 16).for_each(|piece| {
        if stopped.load(Ordering::Relaxed) || cancel() {
            stopped.store(true, Ordering::Relaxed);
        } else {
            piece.sort_unstable_by(&cmp);
        }
    });
    if stopped.into_inner() || cancel() {
        return false;
    }
    v.par_sort_by(&cmp);
    true
}

#[cfg(test)]
mod tests {
    #[test]
    fn fill_and_first_bad_index_by_blocks() {
        let n = 3 * super::GRAIN + 17;
        let mut out = vec![0usize; n];
        assert!(super::fill(&mut out, &super::never, |i| 2 * i));
        assert!(out.iter().enumerate().all(|(i, &v)| v == 2 * i));
        let mut out = vec![0usize; n];
        assert!(!super::fill(&mut out, &|| true, |i| i + 1));
        assert!(out.iter().all(|&v| v == 0));
        // the first failing index, with failures in several blocks
        let bad = |i: usize| !(i == super::GRAIN + 5 || i == 2 * super::GRAIN || i == n - 1);
        assert_eq!(
            super::first_bad_index(n, &super::never, bad),
            Some(super::GRAIN + 5)
        );
        assert_eq!(super::first_bad_index(n, &super::never, |_| true), None);
        assert_eq!(super::first_bad_index(n, &|| true, bad), None);
    }
}
