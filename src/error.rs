//! The one error type of the physics core.

use std::fmt;

/// What went wrong, coarse enough for a C status code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// An argument is malformed: NaN, negative where positive is needed, wrong length.
    InvalidArgument,
    /// An index or id names nothing.
    OutOfRange,
    /// The step would leave a non-finite or exploding state; nothing was changed.
    Unstable,
    /// Memory for the request could not be had; nothing was changed.
    OutOfMemory,
    /// The implicit solver stopped at its iteration cap above its tolerance; nothing was
    /// changed.
    NotConverged,
}

/// An error with a message for humans.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub kind: ErrorKind,
    pub message: String,
}

impl Error {
    pub fn invalid(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::InvalidArgument,
            message: message.into(),
        }
    }
    pub fn out_of_range(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::OutOfRange,
            message: message.into(),
        }
    }
    pub fn out_of_memory(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::OutOfMemory,
            message: message.into(),
        }
    }
    pub fn not_converged(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::NotConverged,
            message: message.into(),
        }
    }
    pub fn unstable(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorKind::Unstable,
            message: message.into(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// Checks that a scalar parameter is finite and not negative.
pub(crate) fn check_non_negative(name: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{name} must be finite and >= 0, got {value}"
        )))
    }
}

/// Checks that a scalar parameter is finite and strictly positive.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{name} must be finite and > 0, got {value}"
        )))
    }
}

/// Checks that every component of a vector is finite.
pub(crate) fn check_finite_vec(name: &str, v: &crate::math::Vec3) -> Result<(), Error> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{name} must be finite, got ({}, {}, {})",
            v.x, v.y, v.z
        )))
    }
}
