//! Nominal coprime factorizations `G = C·M̃⁻¹·Ñ·J` (Boulet & Francis 1998, eq. (1)).
//!
//! * the **standard** left coprime factorization `G = M̃⁻¹Ñ` (`C = I_p`, `J = I_m`,
//!   Sec. IV-A "Standard Factorization");
//! * the **special** factorization for flexible structures (Sec. IV-A, "Special
//!   Factorization for Square LFSS Models"): `C` a constant `p×n` matrix, `M̃` `n×n`,
//!   `Ñ` `n×p`, `J` diagonal `p×p`, `n ≥ p` (A3).

use crate::error::{Error, Result};
use crate::system::ncf::NormalizedLcf;
use crate::system::{TfMatrix, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::sync::Arc;

/// Which factorization the model uses; it selects Theorem 2 or Theorem 3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FactorizationKind {
    /// `G = M̃⁻¹Ñ`, Theorem 2 (eq. (8)).
    Standard,
    /// `G = C·M̃⁻¹·Ñ·J`, Theorem 3.
    Special,
}

/// A nominal coprime factorization `G = C·M̃⁻¹·Ñ·J`.
#[derive(Debug, Clone)]
pub struct Factorization {
    /// Standard or special.
    pub kind: FactorizationKind,
    /// Constant output matrix `C` (`p×n`); the identity for the standard factorization.
    pub c: DMatrix<f64>,
    /// Denominator factor `M̃` (`n×n`).
    pub m: TfMatrix,
    /// Numerator factor `Ñ` (`n×m`).
    pub n: TfMatrix,
    /// Diagonal of the input matrix `J` (`m` entries); all ones for the standard case.
    pub j: Vec<TransferFunction>,
    /// State-space factors (normalized left coprime factorization of a `[plant]`). When
    /// set, `M̃` and `Ñ` are evaluated from this realization, and `m`, `n` above are only
    /// zero placeholders of the right sizes: always evaluate through [`Factorization::at`].
    pub realization: Option<Arc<NormalizedLcf>>,
}

/// The factors evaluated at one frequency.
#[derive(Debug, Clone)]
pub struct FactorsAt {
    /// `C` (`p×n`).
    pub c: DMatrix<Complex64>,
    /// `M̃(jω)` (`n×n`).
    pub m: DMatrix<Complex64>,
    /// `Ñ(jω)` (`n×m`).
    pub n: DMatrix<Complex64>,
    /// Diagonal of `J(jω)`.
    pub j: Vec<Complex64>,
    /// `(σ_max, σ_min)` of `M̃(jω)`: the singularity test and the A1 limit.
    pub m_sigma: (f64, f64),
}

impl Factorization {
    /// The standard factorization `G = M̃⁻¹Ñ`; checks that `M̃` is square and the sizes agree.
    pub fn standard(m: TfMatrix, n: TfMatrix) -> Result<Self> {
        if m.rows() != m.cols() {
            return Err(Error::Invalid(format!(
                "M̃ must be square, got {}×{}",
                m.rows(),
                m.cols()
            )));
        }
        if n.rows() != m.rows() {
            return Err(Error::Invalid(format!(
                "Ñ must have as many rows as M̃ ({}), got {}",
                m.rows(),
                n.rows()
            )));
        }
        let p = m.rows();
        let inputs = n.cols();
        let f = Self {
            kind: FactorizationKind::Standard,
            c: DMatrix::identity(p, p),
            m,
            n,
            j: vec![TransferFunction::gain(1.0); inputs],
            realization: None,
        };
        f.check_proper()?;
        Ok(f)
    }

    /// The special factorization `G = C·M̃⁻¹·Ñ·J`; checks sizes, `n ≥ p` (A3) and that `C`
    /// has full row rank (A4).
    pub fn special(
        c: DMatrix<f64>,
        m: TfMatrix,
        n: TfMatrix,
        j: Vec<TransferFunction>,
    ) -> Result<Self> {
        let modes = m.rows();
        if m.cols() != modes {
            return Err(Error::Invalid(format!(
                "M̃ must be square, got {}×{}",
                m.rows(),
                m.cols()
            )));
        }
        if c.ncols() != modes {
            return Err(Error::Invalid(format!(
                "C must have {modes} columns (one per row of M̃), got {}",
                c.ncols()
            )));
        }
        let p = c.nrows();
        if n.rows() != modes || n.cols() != j.len() {
            return Err(Error::Invalid(format!(
                "Ñ must be {modes}×{} (modes × inputs), got {}×{}",
                j.len(),
                n.rows(),
                n.cols()
            )));
        }
        if modes < p {
            return Err(Error::Invalid(format!(
                "assumption A3 fails: n = {modes} modes < p = {p} outputs; add modes"
            )));
        }
        let sv = c.clone().svd(false, false).singular_values;
        let smax = sv.max();
        let rank = sv.iter().filter(|s| **s > 1e-12 * smax.max(1e-300)).count();
        if rank < p {
            return Err(Error::Invalid(format!(
                "assumption A4 fails: C ({p}×{modes}) has rank {rank} < {p}; its rows must be independent"
            )));
        }
        let f = Self {
            kind: FactorizationKind::Special,
            c,
            m,
            n,
            j,
            realization: None,
        };
        f.check_proper()?;
        Ok(f)
    }

    /// The standard factorization by the normalized left coprime factors of a state-space
    /// plant (`M̃M̃* + ÑÑ* = I`, see [`crate::system::NormalizedLcf`]).
    pub fn normalized(ncf: NormalizedLcf) -> Self {
        let (p, m) = ncf.shape();
        let zeros = |r: usize, c: usize| {
            TfMatrix::from_rows(vec![vec![TransferFunction::gain(0.0); c]; r])
                .expect("non-empty placeholder")
        };
        Self {
            kind: FactorizationKind::Standard,
            c: DMatrix::identity(p, p),
            m: zeros(p, p),
            n: zeros(p, m),
            j: vec![TransferFunction::gain(1.0); m],
            realization: Some(Arc::new(ncf)),
        }
    }

    /// `M̃(jω)` and `Ñ(jω)` from whichever representation the factors have.
    fn factor_values(&self, omega: f64) -> (DMatrix<Complex64>, DMatrix<Complex64>) {
        match &self.realization {
            Some(ncf) => ncf.at(omega).unwrap_or_else(|| {
                let (p, m) = ncf.shape();
                let nan = Complex64::new(f64::NAN, f64::NAN);
                (
                    DMatrix::from_element(p, p, nan),
                    DMatrix::from_element(p, m, nan),
                )
            }),
            None => (self.m.freq(omega), self.n.freq(omega)),
        }
    }

    fn check_proper(&self) -> Result<()> {
        let all = self
            .m
            .entries()
            .iter()
            .chain(self.n.entries())
            .chain(self.j.iter());
        for tf in all {
            if !tf.is_proper() {
                return Err(Error::Invalid(
                    "every entry of M̃, Ñ and J must be proper (deg num ≤ deg den): the factors live in RH∞".into(),
                ));
            }
        }
        Ok(())
    }

    /// Number of outputs `p`.
    pub fn outputs(&self) -> usize {
        self.c.nrows()
    }

    /// Number of inputs `m`.
    pub fn inputs(&self) -> usize {
        self.j.len()
    }

    /// Number of rows of `M̃` (`p` for the standard factorization, the number of modes `n`
    /// for the special one).
    pub fn states(&self) -> usize {
        self.m.rows()
    }

    /// The factors at `s = jω`.
    pub fn at(&self, omega: f64) -> FactorsAt {
        let (m, n) = self.factor_values(omega);
        FactorsAt::new(
            self.c.map(|x| Complex64::new(x, 0.0)),
            m,
            n,
            self.j.iter().map(|t| t.freq(omega)).collect(),
        )
    }

    /// The nominal plant `G(jω) = C·M̃⁻¹·Ñ·J`, by an LU solve with `M̃`.
    /// Returns `None` where `M̃(jω)` is singular.
    pub fn plant(&self, omega: f64) -> Option<DMatrix<Complex64>> {
        self.at(omega).plant()
    }

    /// Frequencies (rad/s) where `σ_min(M̃(jω))` may dip sharply: `|z|` and `|Im z|` of each
    /// lightly damped (`|Re z| < |z|/2`) zero `z` of `M̃` — the eigenvalues of the plant's
    /// `A` for normalized factors (the zeros of `M̃ = [A + LC | L; R̃^(−1/2)C | R̃^(−1/2)]`),
    /// else the numerator roots of `M̃`'s entries (exact for a diagonal `M̃`, candidates
    /// otherwise). At most 2000, the least damped first. For the fit's certificate.
    pub fn a1_dips(&self) -> Vec<f64> {
        let zeros: Vec<Complex64> = match &self.realization {
            Some(ncf) => crate::system::eigenvalues(&ncf.plant.a, "A1 dips").unwrap_or_default(),
            None => self
                .m
                .entries()
                .iter()
                .filter(|t| !t.num.is_zero())
                .flat_map(|t| t.zeros())
                .collect(),
        };
        let mut light: Vec<(f64, Complex64)> = zeros
            .into_iter()
            .filter(|z| z.im >= 0.0 && z.norm() > 0.0 && z.re.abs() < 0.5 * z.norm())
            .map(|z| (z.re.abs() / z.norm(), z))
            .collect();
        light.sort_by(|a, b| a.0.total_cmp(&b.0));
        light.truncate(2000);
        let mut out = Vec::with_capacity(2 * light.len());
        for (_, z) in light {
            out.push(z.norm());
            if z.im > 0.0 {
                out.push(z.im);
            }
        }
        out
    }

    /// `σ_min(M̃(jω))`, the A1 limit on `|r(jω)|`.
    pub fn a1_limit(&self, omega: f64) -> f64 {
        if self.realization.is_none()
            && self.m.rows() >= crate::system::linalg::DIAGONAL_FROM
            && self.m.is_diagonal()
        {
            // σ_min of a diagonal matrix: the smallest modulus on the diagonal (a physical
            // model has one row per mode; no n×n matrix or SVD per frequency).
            return crate::system::linalg::extreme_moduli(
                (0..self.m.rows()).map(|i| self.m.entry(i, i).freq(omega)),
            )
            .1;
        }
        sigma_min(&self.factor_values(omega).0)
    }
}

impl FactorsAt {
    /// Bundles the factor values at one frequency and computes the extreme singular
    /// values of `M̃`.
    pub fn new(
        c: DMatrix<Complex64>,
        m: DMatrix<Complex64>,
        n: DMatrix<Complex64>,
        j: Vec<Complex64>,
    ) -> Self {
        let m_sigma = crate::system::linalg::extreme_singular_values(&m);
        Self {
            c,
            m,
            n,
            j,
            m_sigma,
        }
    }

    /// `σ_min(M̃(jω))`, the A1 limit on `|r(jω)|`.
    pub fn a1_limit(&self) -> f64 {
        self.m_sigma.1
    }

    /// True when `M̃(jω)` is singular to working precision.
    pub fn m_singular(&self) -> bool {
        crate::system::linalg::is_singular(self.m_sigma)
    }

    /// `M̃⁻¹·B` by an LU solve, or by a division per row when `M̃` is diagonal (a physical
    /// model: one row per mode, where an LU of 200 modes would cost O(n³) per frequency).
    /// `None` where the LU finds `M̃` singular.
    pub fn m_solve(&self, b: &DMatrix<Complex64>) -> Option<DMatrix<Complex64>> {
        if crate::system::linalg::diagonal_fast_path(&self.m) {
            let mut x = b.clone();
            for (i, mut row) in x.row_iter_mut().enumerate() {
                let d = self.m[(i, i)];
                if d == Complex64::default() {
                    return None;
                }
                row /= d;
            }
            return Some(x);
        }
        self.m.clone().lu().solve(b)
    }

    /// `C·M̃⁻¹·Ñ·J` at this frequency, `None` where `M̃` is singular.
    pub fn plant(&self) -> Option<DMatrix<Complex64>> {
        let x = self.m_solve(&self.n)?;
        let mut g = &self.c * x;
        for (k, jk) in self.j.iter().enumerate() {
            let mut col = g.column_mut(k);
            col *= *jk;
        }
        g.iter().all(|v| v.is_finite()).then_some(g)
    }
}

/// Smallest singular value of a complex matrix.
pub fn sigma_min(a: &DMatrix<Complex64>) -> f64 {
    crate::system::linalg::extreme_singular_values(a).1
}
