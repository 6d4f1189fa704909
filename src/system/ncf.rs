//! The normalized left coprime factorization `G = M̃⁻¹Ñ`, `M̃M̃* + ÑÑ* = I`, of a
//! state-space plant (McFarlane & Glover 1990; Zhou, Doyle & Glover, *Robust and Optimal
//! Control*, Thm 13.37).
//!
//! With `R = I + DᵀD`, `R̃ = I + DDᵀ` and `Y ≥ 0` the stabilizing solution of the **filter
//! Riccati equation**
//!
//! `(A − BDᵀR̃⁻¹C)Y + Y(A − BDᵀR̃⁻¹C)ᵀ − YCᵀR̃⁻¹CY + BR⁻¹Bᵀ = 0`,
//!
//! the output injection `L = −(BDᵀ + YCᵀ)R̃⁻¹` makes `A + LC` Hurwitz and
//!
//! `[Ñ  M̃] = [A + LC | B + LD   L ; R̃^(−1/2)C | R̃^(−1/2)D   R̃^(−1/2)]`.
//!
//! The normalization is canonical: it is unique up to a constant unitary left factor, it
//! needs no choice from the user, `[Ñ M̃]` is co-inner so the Theorem 1 margin with a
//! constant `r` is exactly the normalized-coprime-factor stability margin `b(G, K)`
//! divided by `|r|`, and the factors exist for unstable plants (rigid-body modes,
//! integrators) as long as `(A, C)` is detectable and `(A, B)` has no uncontrollable mode
//! on the imaginary axis.
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).

use super::freq_eval::FreqEvaluator;
use super::riccati::{care, CareSolution};
use super::state_space::StateSpace;
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// A plant with its normalized left coprime factors in state space.
#[derive(Debug, Clone)]
pub struct NormalizedLcf {
    /// The plant `G = (A, B, C, D)`, in the state coordinates of the factors (`C = [C₁ 0]`,
    /// an orthogonal similarity of the plant as given).
    pub plant: StateSpace,
    /// The output injection `L`.
    pub l: DMatrix<f64>,
    /// `R̃^(1/2)`, `R̃ = I + DDᵀ`.
    pub r_half: DMatrix<f64>,
    /// `[Ñ M̃]` as one state-space system (`p × (m + p)`).
    pub factors: StateSpace,
    /// The Riccati solution with its residual and closed-loop abscissa.
    pub riccati: CareSolution,
    eval: FreqEvaluator,
}

/// `P^(±1/2)` of a symmetric positive definite matrix by its eigen-decomposition.
fn spd_power(p: &DMatrix<f64>, power: f64) -> DMatrix<f64> {
    let eig = nalgebra::linalg::SymmetricEigen::new((p + p.transpose()) * 0.5);
    let d = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| l.powf(power)));
    &eig.eigenvectors * d * eig.eigenvectors.transpose()
}

/// The same plant after the state similarity `x ↦ x/α` (`α` a power of two, `B ↦ αB`,
/// `C ↦ C/α`) chosen so that `‖C/α‖ = ‖B‖^w·‖C‖^(1−w)`: `w = 1/2` equalizes `‖B‖` and
/// `‖C‖`, `w = 1` swaps them (the gain moves from `C` into `B`). The transfer function is unchanged; the filter Riccati solution scales by `α²`, which keeps
/// it O(1) for a plant scaled by `10^k` (a stable plant with a large gain wants `w = 1/2`;
/// an unstable one with a small gain, whose unscaled solution grows like `10^(−2k)`, wants
/// the gain moved into `B`).
fn rescaled(plant: &StateSpace, w: f64) -> Option<StateSpace> {
    let (nb, nc) = (plant.b.norm(), plant.c.norm());
    if plant.a.nrows() == 0 || !(nb > 0.0 && nc > 0.0 && nb.is_finite() && nc.is_finite()) {
        return None;
    }
    // ‖C‖/α = nb^w nc^(1−w)  ⇒  log2 α = w (log2 nc − log2 nb).
    let e = (w * (nc.log2() - nb.log2())).round();
    if e == 0.0 || !e.is_finite() {
        return None;
    }
    let alpha = 2f64.powi(e as i32);
    Some(StateSpace {
        a: plant.a.clone(),
        b: &plant.b * alpha,
        c: &plant.c / alpha,
        d: plant.d.clone(),
    })
}

/// The same plant after the orthogonal similarity `x ↦ Qᵀx` that puts the row space of `C`
/// on the first coordinates: `C·Q = [C₁ 0]` with exact zeros (`QR = [Cᵀ 0]`, Householder).
///
/// Why: when the output gain is large, the filter Riccati solution is `Y = Y₀ + Y₁/k + …`
/// with `C·Y₀ = 0` (the direction a zero in the right half-plane keeps unseen), and the
/// slow closed-loop pole of `A + LC` lives in the `1/k²` tail of `Y`. In the plant's own
/// coordinates that tail is mixed into every entry of `Y` with `Y₀` and lost below its
/// rounding (`k = 10⁷`: a closed-loop pole at +0.71 instead of −1.60, the factors refused;
/// `k = 10⁹`: −0.25, accepted and wrong). With `C = [C₁ 0]`, `Y₀` has exact zeros in the
/// rows and columns of `C₁`, and the tail keeps entries of its own.
fn output_aligned(plant: &StateSpace) -> StateSpace {
    let (n, p) = (plant.a.nrows(), plant.c.nrows());
    if n == 0 || p == 0 {
        return plant.clone();
    }
    let cols = n.max(p);
    let mut m = DMatrix::<f64>::zeros(n, cols);
    m.view_mut((0, 0), (n, p)).copy_from(&plant.c.transpose());
    let qr = m.qr();
    let q = qr.q(); // n×n
    let r = qr.r(); // n×cols, upper triangular: exact zeros below the diagonal
    let c = r.view((0, 0), (n, p)).transpose();
    StateSpace {
        a: q.transpose() * &plant.a * &q,
        b: q.transpose() * &plant.b,
        c,
        d: plant.d.clone(),
    }
}

impl NormalizedLcf {
    /// Computes the factors; fails with a one-line error when the filter Riccati equation
    /// has no stabilizing solution (an unstable mode that the output does not see, or a
    /// mode on the imaginary axis that the input does not reach).
    ///
    /// The plant is first brought to coordinates with `C = [C₁ 0]` (see `output_aligned`:
    /// an orthogonal similarity, so `plant` holds the same transfer function in those
    /// coordinates); when the Riccati equation fails, it is retried in two rescaled state
    /// coordinates (see `rescaled`) before the failure is reported, so that the verdict
    /// does not depend on the plant's gain scale.
    pub fn new(plant: StateSpace) -> Result<Self> {
        plant.validate("plant")?;
        let plant = output_aligned(&plant);
        match Self::in_coordinates(plant.clone()) {
            Ok(f) => Ok(f),
            Err(e) => {
                for w in [0.5, 1.0] {
                    if let Some(f) = rescaled(&plant, w).and_then(|s| Self::in_coordinates(s).ok())
                    {
                        return Ok(f);
                    }
                }
                Err(e)
            }
        }
    }

    fn in_coordinates(plant: StateSpace) -> Result<Self> {
        let (p, m) = plant.d.shape();
        let (a, b, c, d) = (&plant.a, &plant.b, &plant.c, &plant.d);
        let rt = DMatrix::<f64>::identity(p, p) + d * d.transpose();
        let r = DMatrix::<f64>::identity(m, m) + d.transpose() * d;
        let rt_inv = spd_power(&rt, -1.0);
        let r_inv = spd_power(&r, -1.0);
        let abar = a - b * d.transpose() * &rt_inv * c;
        // Filter equation in the CARE form AᵀX + XA − XGX + Q = 0 with A := Āᵀ.
        let g = c.transpose() * &rt_inv * c;
        let q = b * &r_inv * b.transpose();
        let riccati = care(&abar.transpose(), &g, &q, "filter Riccati equation of the plant")
            .map_err(|e| {
                // A gain far from 1 makes the Hamiltonian ill-conditioned: say so instead of
                // blaming detectability (the false reason for a plant scaled by 1e150).
                let spread = plant.b.norm() * plant.c.norm() / plant.a.norm();
                if spread.is_finite() && spread > 1e20 {
                    return crate::Error::Invalid(format!(
                        "filter Riccati equation of the plant: the plant's gain scale ‖B‖‖C‖/‖A‖ ≈ {spread:.1e} is too extreme for its normalized coprime factors in double precision; express the plant in other units so that its gain is nearer 1"
                    ));
                }
                e.with_hint("normalized coprime factors need (A, C) detectable and no uncontrollable mode of (A, B) on the imaginary axis")
                    .unwrap_or_else(|other| other)
            })?;
        let y = &riccati.x;
        let l = -(b * d.transpose() + y * c.transpose()) * &rt_inv;
        let rt_mhalf = spd_power(&rt, -0.5);
        let n = a.nrows();
        let mut fb = DMatrix::zeros(n, m + p);
        fb.view_mut((0, 0), (n, m)).copy_from(&(b + &l * d));
        fb.view_mut((0, m), (n, p)).copy_from(&l);
        let mut fd = DMatrix::zeros(p, m + p);
        fd.view_mut((0, 0), (p, m)).copy_from(&(&rt_mhalf * d));
        fd.view_mut((0, m), (p, p)).copy_from(&rt_mhalf);
        let factors = StateSpace {
            a: a + &l * c,
            b: fb,
            c: &rt_mhalf * c,
            d: fd,
        };
        let eval = FreqEvaluator::new(&factors);
        Ok(Self {
            r_half: spd_power(&rt, 0.5),
            plant,
            l,
            factors,
            riccati,
            eval,
        })
    }

    /// The worst reconstruction residual `‖M̃(jω)·G(jω) − Ñ(jω)‖` at frequencies between the
    /// plant's poles (the geometric means of consecutive pole moduli, half the smallest and
    /// twice the largest; 1 rad/s when no pole is nonzero), with `G(jω)` evaluated from the
    /// plant itself — a route independent of the factors' realization.  Returns
    /// `(ω, residual, σ_max(G(jω)))` at the worst frequency.
    ///
    /// Not at the poles themselves: there `|G|` is large through the plant's dynamics, not
    /// its scale (an integrator computed at 7e-17 rad/s gave `|G|` ≈ 4e15 and a residual of
    /// 1.9 for a plant of gain 1), and the test would refuse sound plants.
    ///
    /// `[Ñ M̃]` is co-inner (norm 1), so the residual is an absolute error of the factors; it
    /// grows like `ε·|G|`: a plant gain of 1e15 leaves `M̃ ≈ 1/G` with no correct digit
    /// (`1e150/(s(s+1))` failed later with "frequency response not finite", issue 34).
    pub fn reconstruction_residual(&self) -> Result<(f64, f64, f64)> {
        let poles = super::eig::eigenvalues(&self.plant.a, "plant poles")?;
        let mut ws: Vec<f64> = poles
            .iter()
            .filter(|z| z.im >= 0.0)
            .map(|z| z.norm())
            .filter(|w| w.is_finite())
            .collect();
        let top = ws.iter().copied().fold(0.0_f64, f64::max);
        // Poles at the origin come out of the eigensolver as ±1e-17 or so: not a frequency.
        ws.retain(|w| *w > 1e-9 * top && *w > 0.0);
        ws.sort_by(f64::total_cmp);
        ws.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        // The frequencies between the poles, in place: from the top down, each modulus becomes
        // the geometric mean with the one below it, the lowest half itself, and twice the
        // highest is appended.
        if let (Some(&lo), Some(&hi)) = (ws.first(), ws.last()) {
            for i in (1..ws.len()).rev() {
                ws[i] = (ws[i - 1] * ws[i]).sqrt();
            }
            ws[0] = lo / 2.0;
            ws.push(hi * 2.0);
        }
        if ws.len() > 64 {
            // A large model: every 1 in k, the extremes kept (the check costs O(n²) each).
            let step = ws.len().div_ceil(64);
            let last = *ws.last().expect("non-empty");
            ws = ws.into_iter().step_by(step).chain([last]).collect();
        }
        if ws.is_empty() {
            ws.push(1.0);
        }
        let plant = FreqEvaluator::new(&self.plant);
        let mut worst = (ws[0], 0.0, 0.0);
        for w in ws {
            let Some(g) = plant.freq(w) else {
                // A pole on the axis (an integrator's is at 0, not tested): the plant has no
                // value there; the factors are tested elsewhere.
                continue;
            };
            // Factors that cannot be evaluated where the plant can are as wrong as can be.
            let res = self.at(w).map_or(f64::INFINITY, |(mt, nt)| {
                super::linalg::spectral_norm(&(&mt * &g - &nt))
            });
            let gain = super::linalg::spectral_norm(&g);
            if res.is_nan() || res > worst.1 {
                worst = (w, if res.is_nan() { f64::INFINITY } else { res }, gain);
            }
        }
        Ok(worst)
    }

    /// Outputs `p` and inputs `m` of the plant.
    pub fn shape(&self) -> (usize, usize) {
        self.plant.d.shape()
    }

    /// `(M̃(jω), Ñ(jω))`; `None` only on a numerical breakdown (the factors are stable).
    pub fn at(&self, omega: f64) -> Option<(DMatrix<Complex64>, DMatrix<Complex64>)> {
        let (p, m) = self.shape();
        let f = self.eval.freq(omega)?;
        Some((
            f.view((0, m), (p, p)).into_owned(),
            f.view((0, 0), (p, m)).into_owned(),
        ))
    }

    /// A realization of `[G  M̃⁻¹]` sharing the plant's states: `M̃⁻¹ = (A, −L·R̃^(1/2),
    /// C, R̃^(1/2))`, the system seen by the perturbation in Theorem 1.
    pub fn plant_and_m_inverse(&self) -> StateSpace {
        let (p, m) = self.shape();
        let n = self.plant.states();
        let mut b = DMatrix::zeros(n, m + p);
        b.view_mut((0, 0), (n, m)).copy_from(&self.plant.b);
        b.view_mut((0, m), (n, p))
            .copy_from(&(-(&self.l * &self.r_half)));
        let mut d = DMatrix::zeros(p, m + p);
        d.view_mut((0, 0), (p, m)).copy_from(&self.plant.d);
        d.view_mut((0, m), (p, p)).copy_from(&self.r_half);
        StateSpace {
            a: self.plant.a.clone(),
            b,
            c: self.plant.c.clone(),
            d,
        }
    }
}
