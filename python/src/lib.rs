//! `rshape._rshape`: the Python extension of rshape (PyO3). The pure-Python package
//! `rshape` (python/rshape/) wraps it into typed results and python-control objects; the
//! numerics are the library's, one implementation for the CLI and Python alike.
//!
//! Every entry point runs its Rust work without the GIL and with panics caught
//! ([`errors::guarded`]); library errors raise `rshape.InputError` (and kin) with the
//! one-line message the CLI prints after `error: `.

mod batch;
mod control;
mod core;
mod data;
mod discover;
mod errors;

use pyo3::prelude::*;

#[pymodule]
fn _rshape(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<data::Config>()?;
    m.add_class::<data::Frf>()?;
    m.add_class::<core::Envelope>()?;
    m.add_class::<core::FitHandle>()?;
    m.add_class::<discover::DiagnosisHandle>()?;
    m.add_function(wrap_pyfunction!(data::read_frf, m)?)?;
    m.add_function(wrap_pyfunction!(core::envelope, m)?)?;
    m.add_function(wrap_pyfunction!(core::_check, m)?)?;
    m.add_function(wrap_pyfunction!(core::_fit, m)?)?;
    m.add_function(wrap_pyfunction!(core::_freqresp, m)?)?;
    m.add_function(wrap_pyfunction!(control::_stability, m)?)?;
    m.add_function(wrap_pyfunction!(control::_synthesize, m)?)?;
    m.add_function(wrap_pyfunction!(discover::_compare, m)?)?;
    m.add_function(wrap_pyfunction!(discover::_diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(batch::_discover, m)?)?;
    m.add_function(wrap_pyfunction!(batch::_safe_name, m)?)?;
    m.add_function(wrap_pyfunction!(batch::_run_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(batch::_summary_csv, m)?)?;
    m.add_function(wrap_pyfunction!(batch::_batch, m)?)?;
    Ok(())
}
