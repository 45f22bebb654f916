//! Fallible allocation of buffers whose size comes from the input. Rust's infallible
//! allocation aborts the process when the allocator refuses (under `ulimit -v`, a container
//! limit, or a request larger than the address space); these helpers ask with
//! `try_reserve_exact` and checked multiplication instead, and return
//! [`InputError::out_of_memory`] (of kind [`ErrorKind::OutOfMemory`]) naming the call, which
//! the Python binding raises as `MemoryError`.
//!
//! [`ErrorKind::OutOfMemory`]: crate::error::ErrorKind::OutOfMemory

use super::cancel::{self, Cancel};
use crate::error::{InputError, Result};

/// An empty vector with room for exactly `n` elements.
pub fn with_capacity<T>(what: &'static str, n: usize) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| InputError::out_of_memory(what, n, size_of::<T>()))?;
    Ok(v)
}

/// `n` copies of `value`.
pub fn filled<T: Clone>(what: &'static str, n: usize, value: T) -> Result<Vec<T>> {
    let mut v = with_capacity(what, n)?;
    v.resize(n, value);
    Ok(v)
}

/// A copy of `x`.
pub fn copied<T: Copy>(what: &'static str, x: &[T]) -> Result<Vec<T>> {
    let mut v = with_capacity(what, x.len())?;
    v.extend_from_slice(x);
    Ok(v)
}

/// The items of an iterator of known length.
pub fn collect<T>(what: &'static str, it: impl ExactSizeIterator<Item = T>) -> Result<Vec<T>> {
    let mut v = with_capacity(what, it.len())?;
    v.extend(it);
    Ok(v)
}

/// The `Ok` items of an iterator of known length, or its first error (or the out-of-memory
/// error before any item is made), polling `cancel` before every [`CANCEL_ITEMS`] items: once
/// it says stop the items made so far are returned (an incomplete result the caller
/// discards; see [`super::cancel`]).
pub fn try_collect<T>(
    what: &'static str,
    it: impl ExactSizeIterator<Item = Result<T>>,
    cancel: Cancel<'_>,
) -> Result<Vec<T>> {
    let mut v = with_capacity(what, it.len())?;
    for (i, x) in it.enumerate() {
        if i % CANCEL_ITEMS == 0 && cancel() {
            break;
        }
        v.push(x?);
    }
    Ok(v)
}

/// Items between polls of [`try_collect`].
pub const CANCEL_ITEMS: usize = 1 << 14;

/// The rows `row(0..n)` in a vector reserved fallibly (out of memory named by `what`) and
/// written by [`cancel::fill_in_blocks`]; `Ok(None)` when `cancel` said stop.
pub fn rows<T: Send + Default + Clone>(
    what: &'static str,
    n: usize,
    grain: usize,
    cancel: Cancel<'_>,
    row: impl Fn(usize) -> T + Sync,
) -> Result<Option<Vec<T>>> {
    let mut out = filled(what, n, T::default())?;
    Ok(cancel::fill_in_blocks(&mut out, grain, cancel, row).then_some(out))
}

/// The rows of an iterator of known length, concatenated.
pub fn flat<T: Copy, const K: usize>(
    what: &'static str,
    rows: impl ExactSizeIterator<Item = [T; K]>,
) -> Result<Vec<T>> {
    let n = product(what, rows.len(), K, size_of::<T>())?;
    let mut v = with_capacity(what, n)?;
    for r in rows {
        v.extend_from_slice(&r);
    }
    Ok(v)
}

/// The items of an indexed parallel iterator, in order, into a vector reserved fallibly
/// first (rayon's `collect_into_vec` then uses the reserved room).
pub fn par_collect<T: Send>(
    what: &'static str,
    it: impl rayon::iter::IndexedParallelIterator<Item = T>,
) -> Result<Vec<T>> {
    let mut v = with_capacity(what, it.len())?;
    it.collect_into_vec(&mut v);
    Ok(v)
}

/// Room for `extra` more elements in a growing vector (amortised doubling, as
/// `Vec::reserve`), failing instead of aborting when it cannot be had.
pub fn reserve<T>(what: &'static str, v: &mut Vec<T>, extra: usize) -> Result<()> {
    v.try_reserve(extra)
        .map_err(|_| InputError::out_of_memory(what, v.len().saturating_add(extra), size_of::<T>()))
}

/// Push onto a growing vector (amortised doubling, as `Vec::push`), failing instead of
/// aborting when the next block cannot be had.
pub fn push<T>(what: &'static str, v: &mut Vec<T>, x: T) -> Result<()> {
    if v.len() == v.capacity() {
        // a full vector asks for about twice its length
        v.try_reserve(1).map_err(|_| {
            InputError::out_of_memory(what, v.len().saturating_mul(2), size_of::<T>())
        })?;
    }
    v.push(x);
    Ok(())
}

/// `a · b` elements, or the out-of-memory error when the product overflows `usize`.
pub fn product(what: &'static str, a: usize, b: usize, size: usize) -> Result<usize> {
    a.checked_mul(b)
        .filter(|n| {
            n.checked_mul(size)
                .is_some_and(|b| b <= isize::MAX as usize)
        })
        .ok_or_else(|| InputError::out_of_memory(what, a.saturating_mul(b), size))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::ErrorKind;

    #[test]
    fn refusals_are_errors_not_aborts() {
        let e = with_capacity::<[f64; 3]>("frames", usize::MAX / 8).unwrap_err();
        assert_eq!(e.kind, ErrorKind::OutOfMemory);
        assert!(e.to_string().starts_with("frames: out of memory"), "{e}");
        assert!(filled("x", usize::MAX / 2, 0u64).is_err());
        assert!(product("x", usize::MAX / 2, 3, 1).is_err());
        assert!(product("x", 1 << 40, 1 << 20, 8).is_err());
        assert_eq!(product("x", 3, 4, 8), Ok(12));
        let mut v = Vec::new();
        push("x", &mut v, 1u8).unwrap();
        assert_eq!(copied("x", &v).unwrap(), vec![1]);
        assert_eq!(collect("x", [1, 2].into_iter()).unwrap(), vec![1, 2]);
        assert_eq!(
            flat("x", [[1, 2], [3, 4]].into_iter()).unwrap(),
            vec![1, 2, 3, 4]
        );
        assert!(flat("x", std::iter::repeat_n([0u64; 4], usize::MAX / 8)).is_err());
        let ok: [Result<u8>; 2] = [Ok(1), Ok(2)];
        let never = &cancel::never;
        assert_eq!(try_collect("x", ok.into_iter(), never).unwrap(), vec![1, 2]);
        let bad = [Ok(1), Err(InputError::new("a", "b")), Ok(3)];
        assert_eq!(
            try_collect("x", bad.into_iter(), never).unwrap_err().arg,
            "a"
        );
        let many = (0..3 * CANCEL_ITEMS).map(Ok);
        let stop_now = try_collect("x", many.clone(), &|| true).unwrap();
        assert!(stop_now.is_empty());
        let all = try_collect("x", many, never).unwrap();
        assert_eq!(all.len(), 3 * CANCEL_ITEMS);
        use rayon::prelude::*;
        let v = par_collect("x", (0..10_000u32).into_par_iter().map(|i| 2 * i)).unwrap();
        assert!(v.iter().enumerate().all(|(i, &x)| x == 2 * i as u32));
        let n = 3 * cancel::GRAIN + 17;
        let got = rows("x", n, 7, never, |i| i as u32).expect("room");
        assert!(
            got.expect("not stopped")
                .iter()
                .enumerate()
                .all(|(i, &v)| v == i as u32)
        );
        assert_eq!(rows("x", n, 7, &|| true, |i| i as u32), Ok(None));
    }
}
