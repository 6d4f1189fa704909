//! The pipeline's first three steps: envelope (Boulet & Francis Theorems 2–4, Crowder & de
//! Callafon for closed loop), check of a given `r`, fit of the smallest certified `r(s)`.
//! Every call is the library's ([`rshape::pipeline::envelope::envelope`], [`rshape::check`],
//! [`rshape::pipeline::integration::fit_r`]); results that are tables go to Python as JSON
//! (serde of the library's structs, the content of the CLI's `--json`) and are typed there.

use crate::data::{Config, Frf};
use crate::errors::{guarded, input, FitError, NotAdmissible, OrRaise};
use num_complex::Complex64;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use rshape::consistency::Envelope as LibEnvelope;
use rshape::fit::OrderChoice;
use rshape::pipeline::{closed_loop, envelope as env_mod, integration};
use rshape::TransferFunction;
use std::sync::Arc;

/// Per-datum smallest consistent `|r|` (the lower envelope) and the A1 limit.
#[pyclass(module = "rshape", frozen)]
pub struct Envelope {
    pub inner: Arc<LibEnvelope>,
    /// The config it was computed for (its factorization bounds the fit by A1).
    pub config: Option<Arc<rshape::Config>>,
    pub noise_radii: Option<Vec<f64>>,
    pub warnings: Vec<String>,
}

#[pymethods]
impl Envelope {
    /// Envelope from arrays (e.g. read from an `envelope.csv`): no model, so no A1 bound.
    #[new]
    #[pyo3(signature = (omega, r_min, a1_limit=None))]
    fn new(omega: Vec<f64>, r_min: Vec<f64>, a1_limit: Option<Vec<f64>>) -> PyResult<Self> {
        let n = omega.len();
        if n == 0 || r_min.len() != n || a1_limit.as_ref().is_some_and(|a| a.len() != n) {
            return Err(input(format!(
                "Envelope: omega has {n} values, r_min {}: give one r_min (and a1_limit) per frequency, at least one",
                r_min.len()
            )));
        }
        let increasing = (1..n).all(|k| omega[k] > omega[k - 1]);
        if !increasing || omega[0].is_nan() || omega[0] <= 0.0 {
            return Err(input(
                "Envelope: omega must be positive and strictly increasing",
            ));
        }
        if r_min.iter().any(|r| r.is_nan() || *r < 0.0) {
            return Err(input("Envelope: r_min must be ≥ 0 (inf allowed), not NaN"));
        }
        Ok(Self {
            inner: Arc::new(LibEnvelope {
                omega,
                r_min,
                a1_limit,
                method: rshape::consistency::EnvelopeMethod::File,
            }),
            config: None,
            noise_radii: None,
            warnings: Vec::new(),
        })
    }

    /// Frequencies in rad/s.
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.omega.clone().into_pyarray(py)
    }

    /// Smallest consistent `|r(jω_i)|` per datum (`inf`: no admissible r explains it).
    #[getter]
    fn r_min<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.r_min.clone().into_pyarray(py)
    }

    /// `σ_min(M̃(jω_i))`, the A1 upper limit on `|r|`, or None.
    #[getter]
    fn a1_limit<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.inner.a1_limit.clone().map(|v| v.into_pyarray(py))
    }

    /// How r_min was computed: `theorem2`, `theorem3`, `theorem4_mu`, `file`,
    /// `closed_loop_theorem1`, `closed_loop_theorem2`.
    #[getter]
    fn method(&self) -> String {
        serde_json::to_value(self.inner.method)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    }

    /// Per-datum noise radii used (noisy data), or None.
    #[getter]
    fn noise_radii<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.noise_radii.clone().map(|v| v.into_pyarray(py))
    }

    /// Warnings (data no r explains, uninformative closed-loop data).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// Frequencies where r_min reaches the A1 limit: no admissible r explains them.
    #[getter]
    fn beyond_a1(&self) -> Vec<f64> {
        self.inner.beyond_a1()
    }

    /// The `envelope.csv` text `rshape envelope` writes.
    fn to_csv(&self) -> String {
        rshape::report::envelope_csv(&self.inner)
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "rshape.Envelope({} points, {}, max r_min = {})",
            self.inner.len(),
            self.method(),
            self.inner.r_min.iter().copied().fold(f64::NAN, f64::max)
        )
    }
}

/// The data of a config: `frf` when given (its `[channel]` and `[scaling]` applied), else the config's file.
pub fn config_data(config: &rshape::Config, frf: Option<&Frf>) -> PyResult<rshape::FrfData> {
    match frf {
        Some(d) => env_mod::prepare_data(config, (*d.inner).clone()).py(),
        None => {
            let path = config.data.clone().ok_or_else(|| {
                input(format!(
                    "{}: no data file: add `data = \"FILE.csv\"` to the config or pass frf=",
                    config.path.display()
                ))
            })?;
            env_mod::load_data(config, &path).py()
        }
    }
}

/// Checks a noise radius as the CLI checks `--noise-radius`.
pub fn noise_arg(x: Option<f64>) -> PyResult<()> {
    match x {
        Some(x) if !(x.is_finite() && x >= 0.0) => Err(input(format!(
            "noise_radius={x}: must be a finite number ≥ 0"
        ))),
        _ => Ok(()),
    }
}

/// The envelope of the config's data (or of `frf`): Theorem 2 or 3 for noise-free data,
/// Theorem 4 for noisy SISO data, Crowder & de Callafon for a `[closed_loop]` config.
/// `noise_radius` overrides the config's noise as the CLI's `--noise-radius` does.
#[pyfunction]
#[pyo3(signature = (config, frf=None, noise_radius=None))]
pub fn envelope(
    py: Python<'_>,
    config: &Config,
    frf: Option<&Frf>,
    noise_radius: Option<f64>,
) -> PyResult<Envelope> {
    let cfg = config.inner.clone();
    guarded(py, || {
        noise_arg(noise_radius)?;
        let data = config_data(&cfg, frf)?;
        let out = env_mod::envelope(
            &cfg,
            &data,
            &rshape::pipeline::RunOptions::noise_radius(noise_radius),
        )
        .py()?;
        Ok(Envelope {
            inner: Arc::new(out.envelope),
            config: Some(cfg.clone()),
            noise_radii: out.noise_radii,
            warnings: out.warnings,
        })
    })
}

/// `r` from `(num, den)`, checked to be a unit of RH∞ (stable, minimum phase, biproper).
pub fn unit(num: Vec<f64>, den: Vec<f64>, what: &str) -> PyResult<TransferFunction> {
    if num.is_empty()
        || num.iter().chain(&den).any(|c| !c.is_finite())
        || den.iter().all(|c| *c == 0.0)
    {
        return Err(input(format!(
            "{what}: coefficients must be finite and the denominator nonzero"
        )));
    }
    let r = TransferFunction::new(num, den);
    if let Some(why) = r.unit_violation() {
        return Err(NotAdmissible::new_err(format!(
            "{what}: r = {} is not a unit of RH∞: {why}; give equal degrees and poles and zeros in the open left half-plane",
            r.brief()
        )));
    }
    Ok(r)
}

/// The check of `r = num/den` against the envelope (JSON of the library's report).
#[pyfunction]
pub fn _check(
    py: Python<'_>,
    num: Vec<f64>,
    den: Vec<f64>,
    envelope: &Envelope,
) -> PyResult<String> {
    let env = envelope.inner.clone();
    guarded(py, || {
        let r = unit(num, den, "r")?;
        let rep = rshape::check(&r, &env);
        serde_json::to_string(&rep).map_err(|e| input(e.to_string()))
    })
}

/// A fitted unit `r(s)` (the handle behind `rshape.Fit`).
#[pyclass(module = "rshape", frozen)]
pub struct FitHandle {
    pub r: TransferFunction,
    /// The `r.json` document, as `rshape fit` writes it.
    #[pyo3(get)]
    pub json: String,
}

#[pymethods]
impl FitHandle {
    /// `r(jω)` at each frequency (rad/s), complex.
    fn freqresp<'py>(&self, py: Python<'py>, omega: Vec<f64>) -> Bound<'py, PyArray1<Complex64>> {
        omega
            .iter()
            .map(|w| self.r.freq(*w))
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }
}

/// `r(jω)` of `num/den` (any transfer function, no unit check), complex.
#[pyfunction]
pub fn _freqresp<'py>(
    py: Python<'py>,
    num: Vec<f64>,
    den: Vec<f64>,
    omega: Vec<f64>,
) -> Bound<'py, PyArray1<Complex64>> {
    let r = TransferFunction::new(num, den);
    omega
        .iter()
        .map(|w| r.freq(*w))
        .collect::<Vec<_>>()
        .into_pyarray(py)
}

/// `order` from Python: `"auto"` or an int.
pub fn order_arg(order: &Bound<'_, PyAny>, max_order: usize) -> PyResult<OrderChoice> {
    if let Ok(s) = order.extract::<String>() {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(OrderChoice::Auto { max: max_order });
        }
    } else if let Ok(n) = order.extract::<i64>() {
        if (0..=rshape::fit::MAX_ORDER as i64).contains(&n) {
            return Ok(OrderChoice::Fixed(n as usize));
        }
    }
    Err(input(format!(
        "order={order}: expected \"auto\" or an integer 0..={}",
        rshape::fit::MAX_ORDER
    )))
}

/// The fit of `rshape run` (and `rshape fit`'s defaults): the smallest certified unit above
/// the envelope, below the A1 limit of the envelope's model.
pub fn fit_envelope(env: &Envelope, order: OrderChoice) -> PyResult<FitHandle> {
    let f = env
        .config
        .as_deref()
        .and_then(closed_loop::a1_factorization);
    let fitted = integration::fit_r(&env.inner, f, order, None)
        .map_err(|e| FitError::new_err(crate::errors::message(&e)))?;
    let json = serde_json::to_string(&fitted.json).map_err(|e| input(e.to_string()))?;
    Ok(FitHandle { r: fitted.r, json })
}

/// Fits `r` above the envelope (`order`: "auto" sweeps 0..=max_order).
#[pyfunction]
#[pyo3(signature = (envelope, order, max_order=8))]
pub fn _fit(
    py: Python<'_>,
    envelope: &Envelope,
    order: &Bound<'_, PyAny>,
    max_order: usize,
) -> PyResult<FitHandle> {
    let order = order_arg(order, max_order)?;
    let env = Envelope {
        inner: envelope.inner.clone(),
        config: envelope.config.clone(),
        noise_radii: None,
        warnings: Vec::new(),
    };
    guarded(py, || fit_envelope(&env, order))
}
