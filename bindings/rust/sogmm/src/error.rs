//! `Error`: a failed call's status code plus the library's message.
use std::ffi::CStr;
use std::fmt;

use sogmm_sys as sys;

/// The SOGMM_E_* status of a failed call. Codes are frozen in sogmm.h and new
/// ones are only appended, so an unknown code maps to `Unknown` rather than
/// to a wrong variant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Status {
    NullArg,
    InvalidArg,
    InvalidData,
    Numeric,
    Io,
    Format,
    Limit,
    NoMem,
    BufferTooSmall,
    NotFound,
    Internal,
    /// A progress callback asked to stop (SOGMM_E_CANCELLED).
    Cancelled,
    /// Another call is using the map (SOGMM_E_BUSY, "map busy: ..."). Safe
    /// code of this crate never gets it: `Map`'s changing methods take
    /// `&mut self`, so no other call (another thread's, or the progress
    /// closure's) can use the map meanwhile.
    Busy,
    Unknown(i32),
}

impl Status {
    pub fn from_code(code: i32) -> Status {
        match code {
            sys::SOGMM_E_NULL_ARG => Status::NullArg,
            sys::SOGMM_E_INVALID_ARG => Status::InvalidArg,
            sys::SOGMM_E_INVALID_DATA => Status::InvalidData,
            sys::SOGMM_E_NUMERIC => Status::Numeric,
            sys::SOGMM_E_IO => Status::Io,
            sys::SOGMM_E_FORMAT => Status::Format,
            sys::SOGMM_E_LIMIT => Status::Limit,
            sys::SOGMM_E_NOMEM => Status::NoMem,
            sys::SOGMM_E_BUFFER_TOO_SMALL => Status::BufferTooSmall,
            sys::SOGMM_E_NOT_FOUND => Status::NotFound,
            sys::SOGMM_E_INTERNAL => Status::Internal,
            sys::SOGMM_E_CANCELLED => Status::Cancelled,
            sys::SOGMM_E_BUSY => Status::Busy,
            other => Status::Unknown(other),
        }
    }

    /// The C status code (SOGMM_E_*).
    pub fn code(self) -> i32 {
        match self {
            Status::NullArg => sys::SOGMM_E_NULL_ARG,
            Status::InvalidArg => sys::SOGMM_E_INVALID_ARG,
            Status::InvalidData => sys::SOGMM_E_INVALID_DATA,
            Status::Numeric => sys::SOGMM_E_NUMERIC,
            Status::Io => sys::SOGMM_E_IO,
            Status::Format => sys::SOGMM_E_FORMAT,
            Status::Limit => sys::SOGMM_E_LIMIT,
            Status::NoMem => sys::SOGMM_E_NOMEM,
            Status::BufferTooSmall => sys::SOGMM_E_BUFFER_TOO_SMALL,
            Status::NotFound => sys::SOGMM_E_NOT_FOUND,
            Status::Internal => sys::SOGMM_E_INTERNAL,
            Status::Cancelled => sys::SOGMM_E_CANCELLED,
            Status::Busy => sys::SOGMM_E_BUSY,
            Status::Unknown(c) => c,
        }
    }
}

/// A failed call: its status and the message naming what was wrong
/// (`sogmm_last_error()` read right after the call, on the same thread, or a
/// message of this crate for checks made before calling C).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    status: Status,
    message: String,
}

impl Error {
    pub fn new(status: Status, message: impl Into<String>) -> Error {
        Error {
            status,
            message: message.into(),
        }
    }

    /// The error of the call that just returned `code` on this thread.
    pub(crate) fn last(code: i32) -> Error {
        // SAFETY: sogmm_last_error never returns NULL; the text is valid until
        // the next sogmm_* call on this thread, and is copied here at once.
        let msg = unsafe { CStr::from_ptr(sys::sogmm_last_error()) }
            .to_string_lossy()
            .into_owned();
        Error {
            status: Status::from_code(code),
            message: msg,
        }
    }

    pub fn status(&self) -> Status {
        self.status
    }

    pub fn code(&self) -> i32 {
        self.status.code()
    }

    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // SAFETY: static, never-NULL text for any code.
        let what = unsafe { CStr::from_ptr(sys::sogmm_status_string(self.code())) };
        write!(f, "{} ({}): {}", what.to_string_lossy(), self.code(), self.message)
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;

/// Maps a returned status to `Ok(())` or the thread's last error: the role of
/// git2-rs's `try_call!`. Must run right after the C call, before any other
/// sogmm_* call on this thread.
pub(crate) fn check(code: i32) -> Result<()> {
    if code == sys::SOGMM_OK {
        Ok(())
    } else {
        Err(Error::last(code))
    }
}
