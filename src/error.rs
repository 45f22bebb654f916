//! Errors for bad input. Every error names the argument it is about, so the binding layer
//! can raise a Python `ValueError` whose message starts with that argument's name; two
//! kinds are no fault of the input: a buffer that could not be allocated
//! ([`ErrorKind::OutOfMemory`], raised as `MemoryError`) and a call stopped by its hook
//! ([`ErrorKind::Stopped`], raised as `KeyboardInterrupt`).

use std::borrow::Cow;
use std::fmt;

/// An input that cannot be processed, with the name of the offending argument.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// Name of the argument as the user sees it (`"points"`, `"tangents"`, `"initial"`, …),
    /// of the call for [`ErrorKind::OutOfMemory`], `"cancel"` for [`ErrorKind::Stopped`]. A
    /// literal, or the name under which the user passed an argument that a request carries
    /// (the points of a curve moving in time as `points_t`, a tube's scale as `radius`).
    pub arg: Cow<'static, str>,
    /// What is wrong, in words, including the row index where one applies.
    pub msg: String,
    /// Bad input, input too large for the memory, or a call stopped by its hook.
    pub kind: ErrorKind,
}

/// The kind of an [`InputError`] (the binding raises `ValueError`, `MemoryError` or
/// `KeyboardInterrupt`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ErrorKind {
    /// A value, shape or combination of arguments that cannot be processed.
    #[default]
    Invalid,
    /// A buffer sized by the input could not be allocated.
    OutOfMemory,
    /// The call's stop hook said stop ([`crate::run::cancel`]); the caller, which asked it
    /// to stop, discards the error.
    Stopped,
    /// Consecutive samples that coincide: invalid as given, which the Python layer answers
    /// by merging them (`frames::validate::distinct_rows`) where it can.
    Repeated,
}

impl InputError {
    pub fn new(arg: impl Into<Cow<'static, str>>, msg: impl Into<String>) -> Self {
        InputError {
            arg: arg.into(),
            msg: msg.into(),
            kind: ErrorKind::Invalid,
        }
    }

    /// `what` (a call, e.g. `"walk_mesh"`) needs `count` more elements of `size` bytes than
    /// the allocator gives (or than the address space holds, when the product overflows).
    pub fn out_of_memory(what: &'static str, count: usize, size: usize) -> Self {
        let msg = match count.checked_mul(size) {
            Some(b) => format!(
                "out of memory: cannot allocate {:.3} GB ({count} elements of {size} bytes)",
                b as f64 / 1e9
            ),
            None => {
                format!("out of memory: {count} elements of {size} bytes exceed the address space")
            }
        };
        InputError {
            arg: Cow::Borrowed(what),
            msg,
            kind: ErrorKind::OutOfMemory,
        }
    }

    /// The error of a call stopped by its hook ([`crate::run::cancel`]).
    pub fn stopped() -> Self {
        InputError {
            arg: Cow::Borrowed("cancel"),
            msg: "stopped on request".to_string(),
            kind: ErrorKind::Stopped,
        }
    }

    /// An out-of-memory error of `what` with its own explanation (a size derived from the
    /// input's numbers rather than one buffer's element count).
    pub fn oom_message(what: &'static str, msg: String) -> Self {
        InputError {
            arg: Cow::Borrowed(what),
            msg: format!("out of memory: {msg}"),
            kind: ErrorKind::OutOfMemory,
        }
    }

    /// The same error of another kind.
    pub fn with_kind(self, kind: ErrorKind) -> Self {
        InputError { kind, ..self }
    }

    /// The same error with a prefix locating it (used for curve bundles).
    pub fn context(self, prefix: &str) -> Self {
        InputError {
            msg: format!("{prefix}: {}", self.msg),
            ..self
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.arg, self.msg)
    }
}

impl std::error::Error for InputError {}

pub type Result<T> = std::result::Result<T, InputError>;
