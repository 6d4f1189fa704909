//! Transfer-function matrices: a `rows × cols` array of scalar transfer functions.

use super::transfer_function::TransferFunction;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// A matrix of scalar transfer functions, stored row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct TfMatrix {
    rows: usize,
    cols: usize,
    entries: Vec<TransferFunction>,
    /// Row-major indices of the entries with a nonzero numerator.
    nonzero: Vec<usize>,
}

fn nonzero_of(entries: &[TransferFunction]) -> Vec<usize> {
    (0..entries.len())
        .filter(|&i| !entries[i].num.is_zero())
        .collect()
}

impl TfMatrix {
    /// Builds from rows of entries; every row must have the same length (checked by callers
    /// that parse user input; here a mismatch is a programming error reported as `None`).
    pub fn from_rows(rows: Vec<Vec<TransferFunction>>) -> Option<Self> {
        let r = rows.len();
        let c = rows.first().map_or(0, |x| x.len());
        if r == 0 || c == 0 || rows.iter().any(|row| row.len() != c) {
            return None;
        }
        let entries: Vec<TransferFunction> = rows.into_iter().flatten().collect();
        Some(Self {
            rows: r,
            cols: c,
            nonzero: nonzero_of(&entries),
            entries,
        })
    }

    /// A diagonal matrix with the given entries.
    pub fn diagonal(diag: Vec<TransferFunction>) -> Self {
        let n = diag.len();
        let mut entries = vec![TransferFunction::gain(0.0); n * n];
        for (i, d) in diag.into_iter().enumerate() {
            entries[i * n + i] = d;
        }
        Self {
            rows: n,
            cols: n,
            nonzero: nonzero_of(&entries),
            entries,
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Entry `(i, j)` (0-based).
    pub fn entry(&self, i: usize, j: usize) -> &TransferFunction {
        &self.entries[i * self.cols + j]
    }

    /// All entries, row-major.
    pub fn entries(&self) -> &[TransferFunction] {
        &self.entries
    }

    /// Value at `s = jω`.
    pub fn freq(&self, omega: f64) -> DMatrix<Complex64> {
        // Zero entries (most of a physical model's diagonal M̃) cost no evaluation.
        let mut m = DMatrix::zeros(self.rows, self.cols);
        for &k in &self.nonzero {
            m[(k / self.cols, k % self.cols)] = self.entries[k].freq(omega);
        }
        m
    }

    /// True when the matrix is square and every entry off the diagonal is zero.
    pub fn is_diagonal(&self) -> bool {
        self.rows == self.cols && self.nonzero.iter().all(|k| k / self.cols == k % self.cols)
    }

    /// Value at `s = ∞` (each entry must be proper).
    pub fn at_infinity(&self) -> DMatrix<Complex64> {
        DMatrix::from_fn(self.rows, self.cols, |i, j| {
            Complex64::new(self.entry(i, j).at_infinity(), 0.0)
        })
    }
}
