//! How a long call runs: [`cancel`] holds the stop hook that its loops poll between blocks
//! of work and the block loops themselves, [`alloc`] the fallible allocation of buffers
//! sized by the input. A stop and a refused allocation end the call with the errors of
//! kinds [`ErrorKind::Stopped`] and [`ErrorKind::OutOfMemory`] ([`crate::error`]), which
//! the Python binding raises as `KeyboardInterrupt` and `MemoryError`. `alloc` uses
//! `cancel`, never the other way round.
//!
//! [`ErrorKind::Stopped`]: crate::error::ErrorKind::Stopped
//! [`ErrorKind::OutOfMemory`]: crate::error::ErrorKind::OutOfMemory

pub mod alloc;
pub mod cancel;

#[cfg(test)]
mod tests;
