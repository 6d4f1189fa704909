//! Assumption A1 `|r(jω)| < σ_min(M̃(jω))` *proved* on the band `[ω_lo, ∞]`, not sampled.
//!
//! With `M̃⁻¹` realized block by block (`B_k`, [`crate::model::Factorization::a1_inverse_blocks`]),
//! `σ_min(M̃(jω))/|r(jω)| = min_k 1/σ_max(B_k(jω)·r(jω))`, so the worst A1 margin on the band
//! is `1/max_k sup_ω σ_max(B_k·r)`: the `L∞` norm of the series system `B_k·(r ⊗ I)` on the
//! band, by the Hamiltonian iteration ([`crate::system::peak_gain_above`]), whose level
//! without an imaginary-axis eigenvalue is a proven upper bound. A notch of `σ_min(M̃)` (a
//! mode with ζ = 1e-7: a zero of `M̃` 1e-7 from the axis) is a pole of `B_k` 1e-7 from the
//! axis and cannot fall between grid points: the Hamiltonian's eigenvalues find it.

use super::realization::realize;
use super::spectral::Zpk;
use crate::system::{peak_gain_above, StateSpace};
use nalgebra::DMatrix;

/// What the certificate proves A1 from.
#[derive(Debug, Clone, Default)]
pub enum A1Proof {
    /// No realization of `M̃⁻¹` is known (a bare `ω ↦ σ_min` function): A1 is sampled on the
    /// dense grid and at the given dips (`a1_checked_on: "function"`).
    #[default]
    Sampled,
    /// Realizations of the diagonal blocks of `M̃⁻¹` (`a1_checked_on: "proved"`).
    Blocks(Vec<StateSpace>),
    /// `M̃⁻¹` has no proper realization; the reason (A1 fails, at `ω = ∞`).
    Impossible(String),
}

impl From<Result<Vec<StateSpace>, String>> for A1Proof {
    fn from(r: Result<Vec<StateSpace>, String>) -> Self {
        match r {
            Ok(b) => A1Proof::Blocks(b),
            Err(e) => A1Proof::Impossible(e),
        }
    }
}

/// The proved A1 margin on the band.
#[derive(Debug, Clone, Copy)]
pub(crate) struct A1Proved {
    /// `σ_min/|r|` attained at `omega` (the peak of `σ_max(B_k·r)` found).
    pub attained: f64,
    /// Where (rad/s; `inf` at `ω = ∞`).
    pub omega: f64,
    /// Proven: `σ_min(M̃(jω))/|r(jω)| ≥ lower` on the whole band.
    pub lower: f64,
}

/// `r ⊗ I_p`: `p` copies of the scalar realization, block diagonal.
fn copies(r: &StateSpace, p: usize) -> StateSpace {
    let n = r.states();
    let mut s = StateSpace {
        a: DMatrix::zeros(n * p, n * p),
        b: DMatrix::zeros(n * p, p),
        c: DMatrix::zeros(p, n * p),
        d: DMatrix::identity(p, p) * r.d[(0, 0)],
    };
    for k in 0..p {
        s.a.view_mut((k * n, k * n), (n, n)).copy_from(&r.a);
        s.b.view_mut((k * n, k), (n, 1)).copy_from(&r.b);
        s.c.view_mut((k, k * n), (1, n)).copy_from(&r.c);
    }
    s
}

/// The series connection `g ∘ f` (`f` first): states `[x_f; x_g]`.
fn series(f: &StateSpace, g: &StateSpace) -> StateSpace {
    let (nf, ng) = (f.states(), g.states());
    let (m, p) = (f.d.ncols(), g.d.nrows());
    let mut a = DMatrix::zeros(nf + ng, nf + ng);
    a.view_mut((0, 0), (nf, nf)).copy_from(&f.a);
    a.view_mut((nf, 0), (ng, nf)).copy_from(&(&g.b * &f.c));
    a.view_mut((nf, nf), (ng, ng)).copy_from(&g.a);
    let mut b = DMatrix::zeros(nf + ng, m);
    b.view_mut((0, 0), (nf, m)).copy_from(&f.b);
    b.view_mut((nf, 0), (ng, m)).copy_from(&(&g.b * &f.d));
    let mut c = DMatrix::zeros(p, nf + ng);
    c.view_mut((0, 0), (p, nf)).copy_from(&(&g.d * &f.c));
    c.view_mut((0, nf), (p, ng)).copy_from(&g.c);
    StateSpace {
        a,
        b,
        c,
        d: &g.d * &f.d,
    }
}

/// Proves A1 on `[omega_lo, ∞]` for `r` against the blocks of `M̃⁻¹`; `Err` when an `L∞`
/// computation fails (the caller withholds the verdict).
pub(crate) fn prove(blocks: &[StateSpace], r: &Zpk, omega_lo: f64) -> Result<A1Proved, String> {
    let rs = realize(r);
    let mut out = A1Proved {
        attained: f64::INFINITY,
        omega: f64::INFINITY,
        lower: f64::INFINITY,
    };
    for (k, b) in blocks.iter().enumerate() {
        let g = series(&copies(&rs, b.d.ncols()), b);
        let norm = peak_gain_above(&g, omega_lo)
            .map_err(|e| format!("the L∞ norm of block {} of M̃⁻¹·r: {e}", k + 1))?;
        let attained = 1.0 / norm.gamma;
        if attained < out.attained {
            out.attained = attained;
            out.omega = norm.omega;
        }
        out.lower = out.lower.min(1.0 / norm.upper);
    }
    Ok(out)
}

impl super::FitSettings {
    /// These settings with what the certificate needs to prove A1 against `f`: the lightly
    /// damped zeros of `M̃` (the sampled route's dips) and the realizations of `M̃⁻¹`.
    pub fn with_a1_model(self, f: &crate::model::Factorization) -> Self {
        Self {
            a1_dips: f.a1_dips(),
            a1_proof: f.a1_inverse_blocks().into(),
            ..self
        }
    }
}
