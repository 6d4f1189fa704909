//! Errors of the library.  Every message is one line that names the file, the line or the
//! frequency at fault and says what to do; the CLI maps every variant to exit code 2.

use std::path::PathBuf;
use thiserror::Error;

/// Errors from reading inputs and from the consistency computations.
#[derive(Debug, Error)]
pub enum Error {
    /// A file could not be read or written.  The message says what to check; the OS
    /// error follows as the source (`anyhow`'s `{:#}` appends it).
    #[error("{path}: {}", io_hint(source))]
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
    /// An input file that cannot serve as given: not the kind of file expected, or its
    /// content does not fit the model or the run (sizes, channels, frequencies, missing
    /// parts).  The message says what is wrong and what to do.
    #[error("{}: {msg}", path.display())]
    Input {
        /// The file (or the data set named by it).
        path: PathBuf,
        /// What is wrong and what to do.
        msg: String,
    },
    /// A command-line argument (or the library setting it stands for) out of its range or
    /// not applicable: `--band 5:1: give FMIN:FMAX in Hz with 0 ≤ FMIN < FMAX`.
    #[error("{arg}: {msg}")]
    Argument {
        /// The argument with its value, as given (`--band 5:1`).
        arg: String,
        /// What is wrong and what to do.
        msg: String,
    },
    /// A settings field out of its range (`FitSettings.margin = -1: must be a finite number
    /// ≥ 0`).
    #[error(transparent)]
    Setting(#[from] crate::settings::InvalidSetting),
    /// Inputs that do not fit together (sizes, missing parts).
    #[error("{0}")]
    Invalid(String),
    /// A numerical method failed on these inputs: a Riccati, Lyapunov, eigenvalue or H∞
    /// iteration that found no (stabilizing) solution or did not converge, a matrix that must
    /// be inverted and is singular.
    #[error("{what}: {msg}")]
    Numerical {
        /// The computation (`"X∞"`, `"H∞ norm"`, `"synthesis"`, …).
        what: String,
        /// Why it failed and, where known, what to do.
        msg: String,
    },
}

impl Error {
    /// A [`Error::Numerical`] failure of `what`.
    pub fn numerical(what: impl Into<String>, msg: impl Into<String>) -> Self {
        Self::Numerical {
            what: what.into(),
            msg: msg.into(),
        }
    }

    /// The same error with `; hint` appended to its message, its kind kept for
    /// [`Error::Invalid`], [`Error::Input`], [`Error::Argument`] and [`Error::Numerical`]
    /// (a [`Error::Setting`] becomes an [`Error::Invalid`] with the same text); `Err(self)`
    /// for the other kinds.
    pub fn with_hint(self, hint: &str) -> std::result::Result<Self, Self> {
        match self {
            Self::Invalid(msg) => Ok(Self::Invalid(format!("{msg}; {hint}"))),
            Self::Input { path, msg } => Ok(Self::Input {
                path,
                msg: format!("{msg}; {hint}"),
            }),
            Self::Argument { arg, msg } => Ok(Self::Argument {
                arg,
                msg: format!("{msg}; {hint}"),
            }),
            Self::Setting(s) => Ok(Self::Invalid(format!("{s}; {hint}"))),
            Self::Numerical { what, msg } => Ok(Self::Numerical {
                what,
                msg: format!("{msg}; {hint}"),
            }),
            other => Err(other),
        }
    }
}

/// What to check for an I/O error, by its kind.
fn io_hint(e: &std::io::Error) -> &'static str {
    use std::io::ErrorKind as K;
    match e.kind() {
        K::NotFound => "not found: check the path",
        K::PermissionDenied => "permission denied: check the file's and the folder's permissions",
        K::IsADirectory => "is a folder: give a file",
        K::NotADirectory => "a part of the path is a file, not a folder: check the path",
        K::InvalidData => "not UTF-8 text: save the file as UTF-8",
        K::AlreadyExists => "already exists",
        K::StorageFull => "the disk is full: free space and run again",
        K::ReadOnlyFilesystem => "read-only file system: choose a writable folder",
        _ => "cannot be read or written",
    }
}

/// Result alias of the library.
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The typed kinds read as the `Invalid(format!(…))` messages they replaced, and keep
    /// their kind (and path) under a hint.
    #[test]
    fn typed_kinds_read_as_the_messages_they_replaced() {
        let e = Error::Input {
            path: "data/a.csv".into(),
            msg: "2 noise radii for 3 data".into(),
        };
        assert_eq!(e.to_string(), "data/a.csv: 2 noise radii for 3 data");
        let h = e.with_hint("check the std file").unwrap();
        assert!(matches!(&h, Error::Input { path, .. } if path == Path::new("data/a.csv")));
        assert_eq!(
            h.to_string(),
            "data/a.csv: 2 noise radii for 3 data; check the std file"
        );
        let e = Error::Argument {
            arg: "--band 5:1".into(),
            msg: "give FMIN:FMAX in Hz with 0 ≤ FMIN < FMAX".into(),
        };
        assert_eq!(
            e.to_string(),
            "--band 5:1: give FMIN:FMAX in Hz with 0 ≤ FMIN < FMAX"
        );
        let s = crate::settings::InvalidSetting {
            settings: "SearchSettings",
            field: "beam",
            value: "0".into(),
            requirement: "must be at least 1",
        };
        let e = Error::from(s.clone());
        assert_eq!(e.to_string(), "SearchSettings.beam = 0: must be at least 1");
        assert!(matches!(&e, Error::Setting(x) if *x == s));
        assert_eq!(
            e.with_hint("h").unwrap().to_string(),
            "SearchSettings.beam = 0: must be at least 1; h"
        );
    }

    #[test]
    fn a_numerical_failure_reads_as_the_message_it_replaced() {
        let e = Error::numerical("X∞", "the sign iteration did not converge in 100 steps");
        assert_eq!(
            e.to_string(),
            "X∞: the sign iteration did not converge in 100 steps"
        );
        let hinted = e.with_hint("check (A, B)").unwrap();
        assert!(matches!(&hinted, Error::Numerical { what, .. } if what == "X∞"));
        assert_eq!(
            hinted.to_string(),
            "X∞: the sign iteration did not converge in 100 steps; check (A, B)"
        );
        let io = Error::Io {
            path: "a.csv".into(),
            source: std::io::Error::from(std::io::ErrorKind::NotFound),
        };
        assert!(matches!(io.with_hint("x"), Err(Error::Io { .. })));
    }
}
