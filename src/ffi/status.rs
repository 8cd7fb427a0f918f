//! Status codes, the thread-local last error message, and the panic boundary.

use std::cell::RefCell;
use std::ffi::{c_char, CString};

use crate::{Error, ErrorKind};

/// Result of every fallible call. `FC_OK` is zero.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FcStatus {
    /// Success.
    FC_OK = 0,
    /// A required pointer argument was NULL.
    FC_ERROR_NULL_ARGUMENT = 1,
    /// An argument was malformed (NaN or infinite, dt <= 0, wrong buffer length, bad enum value, grid smaller than 2 x 2, ...).
    FC_ERROR_INVALID_ARGUMENT = 2,
    /// A vertex index or collider id names nothing.
    FC_ERROR_OUT_OF_RANGE = 3,
    /// The step would have produced a non-finite or exploding state; the cloth is unchanged. Retry with a smaller dt.
    FC_ERROR_UNSTABLE = 4,
    /// The library hit an internal error (a Rust panic was caught); the handle is unchanged where the failure allowed it.
    FC_ERROR_PANIC = 5,
    /// A file could not be created, written or completed (cache writers); the message has the operating system's reason.
    FC_ERROR_IO = 6,
    /// Memory for the request could not be allocated; nothing was changed (the process is never aborted for it).
    FC_ERROR_OUT_OF_MEMORY = 7,
    /// An implicit step's solver stopped at `solver_max_iterations` above `solver_tolerance`; the cloth is unchanged. Raise the cap, loosen the tolerance, shorten dt, or accept such steps with `fc_cloth_set_solver_accept_unconverged`.
    FC_ERROR_NOT_CONVERGED = 8,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// An error at the ABI: a status plus a message.
#[derive(Debug)]
pub struct FfiError {
    pub status: FcStatus,
    pub message: String,
}

impl FfiError {
    pub fn null(what: &str) -> Self {
        Self {
            status: FcStatus::FC_ERROR_NULL_ARGUMENT,
            message: format!("{what} is NULL"),
        }
    }
    pub fn invalid(message: impl Into<String>) -> Self {
        Self {
            status: FcStatus::FC_ERROR_INVALID_ARGUMENT,
            message: message.into(),
        }
    }
    pub fn io(what: &str, e: &std::io::Error) -> Self {
        let status = match e.kind() {
            std::io::ErrorKind::InvalidInput => FcStatus::FC_ERROR_INVALID_ARGUMENT,
            std::io::ErrorKind::OutOfMemory => FcStatus::FC_ERROR_OUT_OF_MEMORY,
            _ => FcStatus::FC_ERROR_IO,
        };
        Self {
            status,
            message: format!("{what}: {e}"),
        }
    }
}

impl From<Error> for FfiError {
    fn from(e: Error) -> Self {
        let status = match e.kind {
            ErrorKind::InvalidArgument => FcStatus::FC_ERROR_INVALID_ARGUMENT,
            ErrorKind::OutOfRange => FcStatus::FC_ERROR_OUT_OF_RANGE,
            ErrorKind::Unstable => FcStatus::FC_ERROR_UNSTABLE,
            ErrorKind::OutOfMemory => FcStatus::FC_ERROR_OUT_OF_MEMORY,
            ErrorKind::NotConverged => FcStatus::FC_ERROR_NOT_CONVERGED,
        };
        Self {
            status,
            message: e.message,
        }
    }
}

pub(crate) fn set_last_error(message: &str) {
    LAST_ERROR.with(|e| {
        // A successful call after a successful call changes nothing: no allocation in the
        // calls a host makes every frame.
        if message.is_empty() && e.borrow().as_bytes().is_empty() {
            return;
        }
        *e.borrow_mut() = CString::new(message.replace('\0', " ")).unwrap_or_default();
    });
}

/// Runs `f` inside the panic boundary and turns its result into a status.
pub(crate) fn guard(f: impl FnOnce() -> Result<(), FfiError>) -> FcStatus {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            set_last_error("");
            FcStatus::FC_OK
        }
        Ok(Err(e)) => {
            set_last_error(&e.message);
            e.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!(
                "internal error (panic caught at the C boundary): {what}"
            ));
            FcStatus::FC_ERROR_PANIC
        }
    }
}

/// Runs an infallible query inside the panic boundary; `fallback` on panic.
pub(crate) fn guard_value<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// Message of the last failed call on this thread; "" after a successful call.
///
/// Never NULL. The pointer stays valid until the next `fc_` call on this thread.
#[no_mangle]
pub extern "C" fn fc_last_error_message() -> *const c_char {
    guard_value(c"internal error".as_ptr(), || {
        LAST_ERROR.with(|e| e.borrow().as_ptr())
    })
}

/// Short, static description of a status code (an `FcStatus` value; never NULL).
#[no_mangle]
pub extern "C" fn fc_status_string(status: i32) -> *const c_char {
    let s = match status {
        0 => c"ok",
        1 => c"null argument",
        2 => c"invalid argument",
        3 => c"out of range",
        4 => c"unstable",
        5 => c"internal error",
        6 => c"i/o error",
        7 => c"out of memory",
        8 => c"solver did not converge",
        _ => c"unknown status",
    };
    s.as_ptr()
}
