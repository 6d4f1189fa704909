//! Errors of the library.  Every message is one line that names the file, the line or the
//! frequency at fault and says what to do; the CLI maps every variant to exit code 2.

use std::path::PathBuf;
use thiserror::Error;

/// Errors from reading inputs and from the consistency computations.
#[derive(Debug, Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A data file is malformed at a given line (1-based, counting comments and header).
    #[error("{path}:{line}: {msg}")]
    Data {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what to do.
        msg: String,
    },
    /// A config file is malformed.
    #[error("{path}: {msg}")]
    Config {
        /// The file.
        path: PathBuf,
        /// What is wrong and what to do (with the line when known).
        msg: String,
    },
    /// An assumption of the theory fails at a datum.
    #[error("at omega = {omega} rad/s: {msg}")]
    Assumption {
        /// The frequency of the datum in rad/s.
        omega: f64,
        /// Which assumption and what to do.
        msg: String,
    },
    /// Inputs that do not fit together (sizes, missing parts).
    #[error("{0}")]
    Invalid(String),
}

/// Result alias of the library.
pub type Result<T> = std::result::Result<T, Error>;
