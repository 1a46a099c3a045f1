//! The host's error: everything a user can get wrong, what and where (file, line,
//! value). The CLI prints it and exits 2.

use crate::hw::error::HwError;

/// A user-facing error: what is wrong and where (file, line, value).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Error(pub String);

impl Error {
    pub fn new(msg: impl Into<String>) -> Self {
        Error(msg.into())
    }
}

impl From<HwError> for Error {
    fn from(e: HwError) -> Self {
        Error(e.to_string())
    }
}

pub type Result<T> = std::result::Result<T, Error>;
