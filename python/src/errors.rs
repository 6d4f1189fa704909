//! Python exceptions and the guard every entry point runs its Rust work in: the GIL is
//! released, a library error becomes the exception of its kind with the CLI's one-line
//! message, and a panic (a bug) becomes `rshape.InternalError`, never an abort.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use rshape::Error;
use std::panic::{catch_unwind, AssertUnwindSafe};

create_exception!(
    _rshape,
    RshapeError,
    PyException,
    "Base class of rshape's exceptions."
);
create_exception!(
    _rshape,
    InputError,
    RshapeError,
    "Bad input: a file that cannot be read, a malformed config or data file, wrong shapes, \
     sizes that do not fit. The message names the file, line or frequency and what to do."
);
create_exception!(
    _rshape,
    AssumptionError,
    RshapeError,
    "An assumption of the theory fails at a datum (the message gives the frequency)."
);
create_exception!(
    _rshape,
    NotAdmissible,
    RshapeError,
    "The bound r given is not admissible: not a unit of RH∞ (stable, minimum phase, biproper)."
);
create_exception!(
    _rshape,
    FitError,
    RshapeError,
    "No certified r(s) was found above the envelope."
);
create_exception!(
    _rshape,
    InternalError,
    RshapeError,
    "A bug in rshape (a Rust panic caught at the boundary); please report it with the inputs."
);

/// The one line the CLI prints after `error: ` for a library error: the message and its
/// sources, as `anyhow`'s `{:#}` writes them.
pub fn message(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    rshape::report::fmt::one_line(&text)
}

/// The exception of a library error.
pub fn to_py(e: Error) -> PyErr {
    let msg = message(&e);
    match e {
        Error::Assumption { .. } => AssumptionError::new_err(msg),
        _ => InputError::new_err(msg),
    }
}

/// An input error with a message.
pub fn input(msg: impl Into<String>) -> PyErr {
    InputError::new_err(msg.into())
}

/// Runs `f` without the GIL and with panics caught.
pub fn guarded<T: Send>(py: Python<'_>, f: impl FnOnce() -> PyResult<T> + Send) -> PyResult<T> {
    py.allow_threads(|| match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(p) => {
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            Err(InternalError::new_err(format!(
                "internal error (a bug in rshape, please report it with the inputs): {}",
                rshape::report::fmt::one_line(&what)
            )))
        }
    })
}

/// `Result<T, Error>` → `PyResult<T>`.
pub trait OrRaise<T> {
    /// Maps the library error to its exception.
    fn py(self) -> PyResult<T>;
}

impl<T> OrRaise<T> for rshape::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}

/// Registers the exceptions in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("RshapeError", py.get_type::<RshapeError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("AssumptionError", py.get_type::<AssumptionError>())?;
    m.add("NotAdmissible", py.get_type::<NotAdmissible>())?;
    m.add("FitError", py.get_type::<FitError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    Ok(())
}
