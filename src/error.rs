//! Errors for bad input. Every error names the argument it is about, so the binding layer
//! can raise a Python `ValueError` whose message starts with that argument's name.

use std::fmt;

/// An input that cannot be processed, with the name of the offending argument.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// Name of the argument as the user sees it (`"points"`, `"tangents"`, `"initial"`, …).
    pub arg: &'static str,
    /// What is wrong, in words, including the row index where one applies.
    pub msg: String,
}

impl InputError {
    pub fn new(arg: &'static str, msg: impl Into<String>) -> Self {
        InputError {
            arg,
            msg: msg.into(),
        }
    }

    /// The same error with a prefix locating it (used for curve bundles).
    pub fn context(self, prefix: &str) -> Self {
        InputError {
            arg: self.arg,
            msg: format!("{prefix}: {}", self.msg),
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
