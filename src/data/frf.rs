//! A set of frequency-response measurements `Φ_i = G_p(jω_i)` (Sec. II).

use nalgebra::DMatrix;
use num_complex::Complex64;
use std::path::PathBuf;

/// Frequency-response data, sorted by increasing frequency.
#[derive(Debug, Clone)]
pub struct FrfData {
    /// Where the data came from (for messages).
    pub path: PathBuf,
    /// Frequencies in rad/s, strictly increasing and positive.
    pub omega: Vec<f64>,
    /// The measured `p×m` matrices `Φ_i`.
    pub response: Vec<DMatrix<Complex64>>,
    /// Per-frequency noise-disk radius (eq. (5)), when the file has a `noise_radius` column.
    pub noise_radius: Option<Vec<f64>>,
    /// 1-based line of each datum in the file.
    pub lines: Vec<usize>,
}

impl FrfData {
    /// Number of data.
    pub fn len(&self) -> usize {
        self.omega.len()
    }

    /// True when there are no data.
    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }

    /// Number of outputs `p`.
    pub fn outputs(&self) -> usize {
        self.response.first().map_or(0, |m| m.nrows())
    }

    /// Number of inputs `m`.
    pub fn inputs(&self) -> usize {
        self.response.first().map_or(0, |m| m.ncols())
    }

    /// The SISO channel `(out, inp)` (0-based) as a 1×1 data set.
    pub fn channel(&self, out: usize, inp: usize) -> FrfData {
        FrfData {
            path: self.path.clone(),
            omega: self.omega.clone(),
            response: self
                .response
                .iter()
                .map(|m| DMatrix::from_element(1, 1, m[(out, inp)]))
                .collect(),
            noise_radius: self.noise_radius.clone(),
            lines: self.lines.clone(),
        }
    }
}
