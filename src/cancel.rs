//! Cooperative cancellation of long computations. A caller passes a [`Cancel`] hook that the
//! parallel loops poll once per block of work (a few thousand rows) and skip the remaining
//! blocks once it returns `true`; the outputs are then incomplete and the caller discards
//! them. The Python binding's hook reads a flag that its calling thread sets on Ctrl-C.

/// Returns `true` when the computation should stop.
pub type Cancel<'a> = &'a (dyn Fn() -> bool + Sync);

/// The hook of callers that never cancel.
pub fn never() -> bool {
    false
}
