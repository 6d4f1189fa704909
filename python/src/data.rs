//! Inputs: a config (`Config.load`, `Config.from_toml`) and frequency-response data (a CSV
//! file through the library's reader, or numpy arrays checked here as the reader checks a
//! file: shapes, finite values, positive strictly increasing frequencies).

use crate::errors::{guarded, input, OrRaise};
use nalgebra::DMatrix;
use num_complex::Complex64;
use numpy::{IntoPyArray, PyArray1, PyArray3, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use rshape::data::FrfData;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A loaded and validated config (model, `r`, data file, noise).
#[pyclass(module = "rshape", frozen)]
pub struct Config {
    pub inner: Arc<rshape::Config>,
    /// The text it was parsed from (for pickling to Dask workers).
    pub text: String,
}

#[pymethods]
impl Config {
    /// Reads and validates a TOML config file.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        guarded(py, || {
            let inner = rshape::Config::load(&path).py()?;
            // The text travels with the config when it is pickled (Dask workers).
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            Ok(Self {
                inner: Arc::new(inner),
                text,
            })
        })
    }

    /// Parses config text; `path` names it in messages and resolves a relative `data` file.
    #[staticmethod]
    #[pyo3(signature = (text, path = PathBuf::from("config.toml")))]
    fn from_toml(py: Python<'_>, text: String, path: PathBuf) -> PyResult<Self> {
        guarded(py, || Self::parse(&text, &path))
    }

    /// The config file.
    #[getter]
    fn path(&self) -> PathBuf {
        self.inner.path.clone()
    }

    /// The data file the config names (resolved), or None.
    #[getter]
    fn data(&self) -> Option<PathBuf> {
        self.inner.data.clone()
    }

    /// The config's `name`, or None.
    #[getter]
    fn name(&self) -> Option<String> {
        self.inner.raw.name.clone()
    }

    /// The configured `r` as `(num, den)` (descending powers of s), or None.
    #[getter]
    fn r(&self) -> Option<(Vec<f64>, Vec<f64>)> {
        self.inner
            .r
            .as_ref()
            .map(|r| (r.num.coeffs().to_vec(), r.den.coeffs().to_vec()))
    }

    /// True for a `[closed_loop]` config (its weight is `V`, not `r`).
    #[getter]
    fn closed_loop(&self) -> bool {
        self.inner.closed_loop.is_some()
    }

    /// `(outputs, inputs)` of the model.
    #[getter]
    fn size(&self) -> (usize, usize) {
        let f = &self.inner.factorization;
        (f.outputs(), f.inputs())
    }

    /// `σ_min(M̃(jω))` at each frequency: the A1 limit on `|r(jω)|`.
    fn a1_limit<'py>(&self, py: Python<'py>, omega: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
        let f = &self.inner.factorization;
        omega
            .iter()
            .map(|w| f.a1_limit(*w))
            .collect::<Vec<_>>()
            .into_pyarray(py)
    }

    /// The config's text.
    #[getter]
    fn text(&self) -> String {
        self.text.clone()
    }

    fn __reduce__(slf: &Bound<'_, Self>) -> PyResult<(PyObject, (String, PathBuf))> {
        let ctor = slf.get_type().getattr("from_toml")?.unbind();
        let me = slf.get();
        Ok((ctor, (me.text.clone(), me.inner.path.clone())))
    }

    fn __repr__(&self) -> String {
        format!("rshape.Config({:?})", self.inner.path.display().to_string())
    }
}

impl Config {
    fn parse(text: &str, path: &Path) -> PyResult<Self> {
        let inner = rshape::Config::parse(text, path).py()?;
        Ok(Self {
            inner: Arc::new(inner),
            text: text.to_string(),
        })
    }
}

/// Frequency-response data `Φ_i` at frequencies `ω_i`, with optional noise radii.
#[pyclass(module = "rshape", frozen)]
pub struct Frf {
    pub inner: Arc<FrfData>,
}

/// Reads an FRF CSV file (the format of `rshape run`'s data files).  `sample_time = Ts`
/// reads its frequency column as normalized (per sample) and divides it by `Ts`, as a
/// config's `sample_time` does for the config's own data.
#[pyfunction]
#[pyo3(signature = (path, sample_time=None))]
pub fn read_frf(py: Python<'_>, path: PathBuf, sample_time: Option<f64>) -> PyResult<Frf> {
    guarded(py, || {
        let mut d = rshape::read_frf_csv(&path).py()?;
        if let Some(ts) = sample_time {
            rshape::data::check_sample_time(ts).map_err(input)?;
            d = rshape::data::denormalize_frf(d, ts).py()?;
        }
        Ok(Frf { inner: Arc::new(d) })
    })
}

fn vector(name: &str, a: PyReadonlyArrayDyn<'_, f64>, n: Option<usize>) -> PyResult<Vec<f64>> {
    let a = a.as_array();
    if a.ndim() != 1 {
        return Err(input(format!(
            "Frf: {name} must be a 1-D array, got shape {:?}",
            a.shape()
        )));
    }
    let v: Vec<f64> = a.iter().copied().collect();
    if let Some(n) = n {
        if v.len() != n {
            return Err(input(format!(
                "Frf: {name} has {} values, omega has {n}: give one per frequency",
                v.len()
            )));
        }
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(input(format!(
            "Frf: {name}[{i}] = {} is not a finite number: drop or repair that datum",
            v[i]
        )));
    }
    Ok(v)
}

fn nonneg(name: &str, v: &[f64]) -> PyResult<()> {
    match v.iter().position(|x| *x < 0.0) {
        Some(i) => Err(input(format!(
            "Frf: {name}[{i}] = {} is negative: give values ≥ 0",
            v[i]
        ))),
        None => Ok(()),
    }
}

#[pymethods]
impl Frf {
    /// Data from numpy: `omega` (n,) in rad/s, strictly increasing and positive;
    /// `response` complex (n, p, m) (or (n,) for SISO). Noise, optional, one of:
    /// `noise_radius` (n,) (Theorem 4's disk radius per datum), `std` (n,) with
    /// `std_factor` (radius = std_factor·std, default 3σ), `coherence` (n,) of an H1
    /// estimate with `averages` and `coverage` (radius = coverage·ε·|H|, Bendat & Piersol).
    #[new]
    #[pyo3(signature = (omega, response, noise_radius=None, std=None, std_factor=3.0, coherence=None, averages=None, coverage=3.0, name="<numpy>".to_string()))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        omega: PyReadonlyArrayDyn<'_, f64>,
        response: PyReadonlyArrayDyn<'_, Complex64>,
        noise_radius: Option<PyReadonlyArrayDyn<'_, f64>>,
        std: Option<PyReadonlyArrayDyn<'_, f64>>,
        std_factor: f64,
        coherence: Option<PyReadonlyArrayDyn<'_, f64>>,
        averages: Option<u32>,
        coverage: f64,
        name: String,
    ) -> PyResult<Self> {
        let omega = vector("omega", omega, None)?;
        let n = omega.len();
        if n == 0 {
            return Err(input("Frf: omega is empty: give at least one frequency"));
        }
        if let Some(i) = omega.iter().position(|w| *w <= 0.0) {
            return Err(input(format!(
                "Frf: omega[{i}] = {} rad/s is not positive: frequencies must be > 0",
                omega[i]
            )));
        }
        if let Some(k) = (1..n).find(|&k| omega[k] <= omega[k - 1]) {
            return Err(input(format!(
                "Frf: omega[{k}] = {} is not above omega[{}] = {}: frequencies must increase strictly; sort the data and merge repeated frequencies",
                omega[k],
                k - 1,
                omega[k - 1]
            )));
        }
        let r = response.as_array();
        let (p, m) = match r.shape() {
            [k] if *k == n => (1, 1),
            [k, p, m] if *k == n && *p >= 1 && *m >= 1 => (*p, *m),
            s => {
                return Err(input(format!(
                    "Frf: response has shape {s:?}; give a complex array of shape (n, p, m) (or (n,) for SISO data) with n = {n}, one p×m matrix per frequency"
                )))
            }
        };
        let flat: Vec<Complex64> = r.iter().copied().collect();
        if let Some(i) = flat
            .iter()
            .position(|z| !(z.re.is_finite() && z.im.is_finite()))
        {
            return Err(input(format!(
                "Frf: response at omega[{}] = {} rad/s is not finite ({}): drop or repair that datum",
                i / (p * m),
                omega[i / (p * m)],
                flat[i]
            )));
        }
        let response: Vec<DMatrix<Complex64>> = flat
            .chunks(p * m)
            .map(|c| DMatrix::from_row_slice(p, m, c))
            .collect();
        let given = [noise_radius.is_some(), std.is_some(), coherence.is_some()];
        if given.iter().filter(|g| **g).count() > 1 {
            return Err(input(
                "Frf: give at most one of noise_radius, std, coherence",
            ));
        }
        let siso = |what: &str| {
            if (p, m) != (1, 1) {
                Err(input(format!("Frf: {what} is for SISO data (Theorem 4), these are {p}×{m}; select a channel first")))
            } else {
                Ok(())
            }
        };
        let radius = if let Some(a) = noise_radius {
            let v = vector("noise_radius", a, Some(n))?;
            nonneg("noise_radius", &v)?;
            Some(v)
        } else if let Some(a) = std {
            siso("std")?;
            let v = vector("std", a, Some(n))?;
            nonneg("std", &v)?;
            if !(std_factor.is_finite() && std_factor > 0.0) {
                return Err(input(format!(
                    "Frf: std_factor = {std_factor}: give a finite number > 0"
                )));
            }
            Some(v.iter().map(|s| std_factor * s).collect())
        } else if let Some(a) = coherence {
            siso("coherence")?;
            let v = vector("coherence", a, Some(n))?;
            if let Some(i) = v.iter().position(|c| *c <= 0.0 || *c > 1.0) {
                return Err(input(format!(
                    "Frf: coherence[{i}] = {} is not a coherence in (0, 1]",
                    v[i]
                )));
            }
            let avg = averages.filter(|a| *a >= 1).ok_or_else(|| {
                input("Frf: coherence needs averages (the number of averages of the H1 estimate, ≥ 1)")
            })?;
            if !(coverage.is_finite() && coverage > 0.0) {
                return Err(input(format!(
                    "Frf: coverage = {coverage}: give a finite number > 0"
                )));
            }
            Some(
                v.iter()
                    .zip(&response)
                    .map(|(c, h)| {
                        coverage * rshape::data::h1_random_error(*c, avg) * h[(0, 0)].norm()
                    })
                    .collect(),
            )
        } else {
            None
        };
        Ok(Self {
            inner: Arc::new(FrfData {
                path: PathBuf::from(name),
                lines: (1..=n).collect(),
                omega,
                response,
                noise_radius: radius,
            }),
        })
    }

    /// Frequencies in rad/s.
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.omega.clone().into_pyarray(py)
    }

    /// The measured matrices, complex (n, p, m).
    #[getter]
    fn response<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<Complex64>>> {
        let d = &self.inner;
        let (n, p, m) = (d.len(), d.outputs(), d.inputs());
        let mut v = Vec::with_capacity(n * p * m);
        for x in &d.response {
            for i in 0..p {
                for j in 0..m {
                    v.push(x[(i, j)]);
                }
            }
        }
        let a = numpy::ndarray::Array3::from_shape_vec((n, p, m), v)
            .map_err(|e| input(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    /// Per-datum noise radii, or None.
    #[getter]
    fn noise_radius<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.inner.noise_radius.clone().map(|v| v.into_pyarray(py))
    }

    /// Where the data came from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.inner.path.clone()
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        let d = &self.inner;
        format!(
            "rshape.Frf({} points, {}×{}, {})",
            d.len(),
            d.outputs(),
            d.inputs(),
            d.path.display()
        )
    }
}
