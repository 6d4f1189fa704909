//! `‖T‖∞` and `1/b(G,K)` of a large diagonal-`M̃` loop by a certified branch and bound over
//! the frequency axis, from the factor values (issue 34 item 9): no Hamiltonian of twice the
//! loop's states.
//!
//! On an interval `I` the factor entries are enclosed in disks ([`enclosure`](super::enclosure)),
//! and the norm of the system over `I` is bounded from the value at the centre `ω₀`:
//!
//! * `T = [−V; I]·X`, `X = (D + U·V)⁻¹`, `D = M̃` diagonal, `U = Ñ`, `V = J·K·C`. With
//!   `T − T₀ = [−(V − V₀); 0]·X + T₀·(M₀ − M)·X` (`M = D + UV`) and `‖X‖ ≤ ‖T‖`:
//!   `sup_I ‖T‖ ≤ γ₀/(1 − ΔV − γ₀·ΔM)` whenever `‖T₀‖ ≤ γ₀` (continuity excludes a singular
//!   `M` inside `I`). `‖T₀‖ < γ₀` is decided exactly at `ω₀` in `O(n·m²)`: it holds iff
//!   `P = γ₀²MᴴM − I − VᴴV ≻ 0`, and `P = Λ + W·Z·Wᴴ` with `Λ = γ₀²|D|² − I` diagonal,
//!   `W = [Vᴴ  DᴴU]`, `Z = [γ₀²UᴴU − I  γ₀²I; γ₀²I  0]`. By Haynsworth's inertia additivity on
//!   `[Λ  W; Wᴴ  −Z⁻¹]` (eliminating the well-conditioned part `Λ_R` of `Λ` and keeping the
//!   few entries near zero, `Λ_S`, in the small block), `n₋(P) = n₋(Λ_R) + n₋(Q) − m` with
//!   `Q = [Λ_S  W_S; W_Sᴴ  −Z⁻¹ − W_RᴴΛ_R⁻¹W_R]` of size `|S| + 2m`; each eigenvalue of `Q` is
//!   counted only when it clears a norm-wise rounding bound, or else when the entry-wise
//!   bound of the same rounding, weighted by `Q`'s eigenvectors, decides the inertia
//!   ([`weighted_inertia`](super::weighted_inertia): next to a resonance damped 1e-4 the
//!   deciding eigenvalue is 1e-15, the norm-wise bound 1e-11); else the interval is split.
//! * The gang of four `Γ = [−K; I]·S·[I  G]`, `S = (I + GK)⁻¹`, `G = C·D⁻¹·U·J` (`p × m`): its
//!   value at `ω₀` is a small dense matrix, and with the same splitting
//!   `sup_I ‖Γ‖ ≤ σ₀(1 + ΔG)/(1 − ΔK − σ₀·ΔM)`, `ΔM` the bound of `‖(G − G₀)K + G₀(K − K₀)‖`.
//!
//! The sweep ([`certify`]) keeps the best value found (a lower bound of the norm, polished
//! locally) and splits every interval whose bound exceeds the level `(1 + 2ε)·best`, as the
//! Hamiltonian iteration of `system::hinf` tests the same level; it ends when every interval
//! is below it: `gamma ≤ ‖·‖∞ ≤ upper = (1 + 2ε)·gamma`, the contract of [`HinfNorm`]. The
//! ray `[Ω, ∞]` is the interval `[0, 1/Ω]` of `1/ω`. A capped number of tests; past it (or
//! for factors it cannot enclose) `None`, and the caller keeps the Hamiltonian route.

use super::centre_inertia::{positive_definite, PdContext};
use super::enclosure::{ControllerEnclosure, Disk, Interval, Rational};
use super::factor_loop::t_sigma_max;
use super::gang_sweep::GangSweep;
use crate::model::Factorization;
use crate::system::freq_eval::FreqEvaluator;
use crate::system::{HinfNorm, StateSpace, HINF_RTOL};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Unit roundoff.
pub(super) const U: f64 = f64::EPSILON / 2.0;

/// Interval tests before the sweep gives up (the caller then takes the Hamiltonian route):
/// the 1000-mode bench model needs about 19 000 per norm (about 1 ms each there).
pub const MAX_INTERVAL_TESTS: usize = 100_000;

/// The controller's resolvent is a dense solve per interval: a larger controller (a
/// synthesized one, hundreds of states) keeps the Hamiltonian route.
pub const MAX_CONTROLLER_STATES: usize = 16;

/// Entries of `Λ` with `|Λᵢ| < SMALL_LAMBDA·(γ²|Dᵢ|² + 1)` are kept in the small block.
pub(super) const SMALL_LAMBDA: f64 = 1e-2;
/// At most this many such entries (else the interval is split).
pub(super) const MAX_SMALL: usize = 12;

/// The outcome of one interval test at a level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Test {
    /// Proven: the norm is below the level on the whole interval.
    Below,
    /// Proven: the value at the centre exceeds the level.
    Above,
    /// Neither: split.
    Unknown,
}

/// A system whose frequency response the sweep bounds interval by interval.
pub(crate) trait Sweep {
    /// The test of `iv` at `level`.
    fn test(&self, iv: &Interval, level: f64) -> Test;
    /// `σ_max` at `ω` (a lower bound of the norm: never above the true value but by rounding).
    fn value(&self, omega: f64) -> Option<f64>;
}

/// The factor entries prepared for enclosures, and the controller.
pub(super) struct Prepared<'a> {
    pub(super) f: &'a Factorization,
    pub(super) d: Vec<Rational>,
    /// `Ñ`, row-major `n × m`.
    pub(super) u: Vec<Rational>,
    pub(super) j: Vec<Rational>,
    /// `C` (`p × n`) and an upper bound of its spectral norm.
    pub(super) c: DMatrix<Complex64>,
    pub(super) c_abs: DMatrix<f64>,
    pub(super) c_norm: f64,
    pub(super) k: ControllerEnclosure,
    kev: FreqEvaluator,
    /// `Ñᵢₗ/M̃ᵢᵢ` as one rational each (row-major), for the gang's second-order test.
    pub(super) y: Option<Vec<Rational>>,
}

/// The enclosures on one interval.
pub(super) struct At {
    pub(super) d: Vec<Disk>,
    pub(super) u: Vec<Disk>,
    pub(super) j: Vec<Disk>,
    pub(super) k0: DMatrix<Complex64>,
    pub(super) rk: f64,
    pub(super) ek: f64,
}

impl<'a> Prepared<'a> {
    fn new(f: &'a Factorization, k: &StateSpace) -> Option<Self> {
        if f.realization.is_some() || !f.m.is_diagonal() || k.states() > MAX_CONTROLLER_STATES {
            return None;
        }
        let (n, m) = (f.states(), f.inputs());
        let d = (0..n)
            .map(|i| Rational::new(f.m.entry(i, i)))
            .collect::<Option<Vec<_>>>()?;
        let u = (0..n)
            .flat_map(|i| (0..m).map(move |l| (i, l)))
            .map(|(i, l)| Rational::new(f.n.entry(i, l)))
            .collect::<Option<Vec<_>>>()?;
        let j = f.j.iter().map(Rational::new).collect::<Option<Vec<_>>>()?;
        let y = (0..n)
            .flat_map(|i| (0..m).map(move |l| (i, l)))
            .map(|(i, l)| {
                let (ui, di) = (f.n.entry(i, l), f.m.entry(i, i));
                Rational::new(&crate::system::TransferFunction {
                    num: ui.num.mul(&di.den),
                    den: ui.den.mul(&di.num),
                })
            })
            .collect::<Option<Vec<_>>>();
        let cct = &f.c * f.c.transpose();
        let c_norm =
            cct.symmetric_eigenvalues().max().max(0.0).sqrt() * (1.0 + 1e-10) + 1e-14 * f.c.norm();
        Some(Self {
            f,
            d,
            u,
            j,
            c: f.c.map(|x| Complex64::new(x, 0.0)),
            c_abs: f.c.abs(),
            c_norm,
            k: ControllerEnclosure::new(k),
            kev: FreqEvaluator::new(k),
            y,
        })
    }

    pub(super) fn at(&self, iv: &Interval) -> Option<At> {
        let (k0, rk, ek) = self.k.enclose(iv)?;
        Some(At {
            d: self.d.iter().map(|h| h.enclose(iv)).collect(),
            u: self.u.iter().map(|h| h.enclose(iv)).collect(),
            j: self.j.iter().map(|h| h.enclose(iv)).collect(),
            k0,
            rk,
            ek,
        })
    }
}

/// Whether the sweep applies to `k` on `f` (a diagonal `M̃` typed as transfer functions,
/// proper entries, a controller of at most [`MAX_CONTROLLER_STATES`] states).
pub fn sweep_applies(f: &Factorization, k: &StateSpace) -> bool {
    Prepared::new(f, k).is_some()
}

/// `‖T‖∞` of the Theorem 1 system of `k` on `f` by the certified sweep; `breaks` split the
/// axis to start with (a grid, the poles' frequencies), `starts` seed the lower bound.
/// `None` where the factors cannot be enclosed (a dense `M̃`, state-space factors, improper
/// entries) or the sweep reaches [`MAX_INTERVAL_TESTS`].
pub fn certified_t_norm(
    f: &Factorization,
    k: &StateSpace,
    breaks: &[f64],
    starts: &[f64],
) -> Option<HinfNorm> {
    let p = Prepared::new(f, k)?;
    certify(&TSweep(p), breaks, starts, MAX_INTERVAL_TESTS)
}

/// `‖[−K; I](I + GK)⁻¹[I  G]‖∞ = 1/b(G,K)` by the certified sweep (see [`certified_t_norm`]).
pub fn certified_gang_norm(
    f: &Factorization,
    k: &StateSpace,
    breaks: &[f64],
    starts: &[f64],
) -> Option<HinfNorm> {
    let p = Prepared::new(f, k)?;
    certify(&GangSweep(p), breaks, starts, MAX_INTERVAL_TESTS)
}

struct TSweep<'a>(Prepared<'a>);

impl Sweep for TSweep<'_> {
    fn value(&self, omega: f64) -> Option<f64> {
        t_sigma_max(self.0.f, &self.0.kev, omega)
    }

    fn test(&self, iv: &Interval, level: f64) -> Test {
        let p = &self.0;
        let Some(at) = p.at(iv) else {
            return Test::Unknown;
        };
        let (n, m) = (p.f.states(), p.f.inputs());
        let d_d = at.d.iter().map(|x| x.r).fold(0.0, f64::max);
        let d_u = at.u.iter().map(|x| x.r * x.r).sum::<f64>().sqrt();
        let d_j = at.j.iter().map(|x| x.r).fold(0.0, f64::max);
        let j0n = at.j.iter().map(|x| x.c.norm()).fold(0.0, f64::max);
        let k0n = at.k0.norm();
        // V₀ = J₀·K₀·C (m × n).
        let mut v0 = &at.k0 * &p.c;
        for (l, jl) in at.j.iter().enumerate() {
            let mut row = v0.row_mut(l);
            row *= jl.c;
        }
        let d_v = (d_j * (k0n + at.rk) + j0n * at.rk) * p.c_norm;
        let v0n = v0.norm();
        let u0n = at.u.iter().map(|x| x.c.norm_sqr()).sum::<f64>().sqrt();
        let d_m = d_d + d_u * (v0n + d_v) + u0n * d_v;
        let second = || match *iv {
            Interval::Finite(a, b) => super::second_order::t_below(p, a, b, level),
            Interval::Ray(_) => false,
        };
        if !(d_v < 0.5 && level * d_m < 0.5) {
            // Too wide for the first order (next to a light resonance): the second order
            // may still prove the interval below.
            return if second() { Test::Below } else { Test::Unknown };
        }
        let gamma0 = level * (1.0 - d_v) / (1.0 + level * d_m) * (1.0 - 8.0 * U);
        let rho_v = (at.ek / k0n.max(f64::MIN_POSITIVE)).min(1.0)
            + at.j
                .iter()
                .map(|x| x.e / x.c.norm().max(f64::MIN_POSITIVE))
                .fold(0.0, f64::max)
            + 8.0 * (p.c.nrows() as f64 + 4.0) * U;
        let ctx = PdContext {
            n,
            m,
            at: &at,
            v0: &v0,
            rho_v,
        };
        if positive_definite(&ctx, gamma0) == Some(true) {
            return Test::Below;
        }
        if second() {
            return Test::Below;
        }
        match positive_definite(&ctx, level) {
            Some(false) => Test::Above,
            _ => Test::Unknown,
        }
    }
}

/// The branch and bound of the module docs.
pub(crate) fn certify(
    sw: &dyn Sweep,
    breaks: &[f64],
    starts: &[f64],
    cap: usize,
) -> Option<HinfNorm> {
    let (mut best, mut omega) = (0.0f64, f64::NAN);
    let consider = |w: f64, best: &mut f64, omega: &mut f64| {
        if let Some(v) = sw.value(w) {
            if v > *best {
                (*best, *omega) = (v, w);
            }
        }
    };
    for w in starts.iter().filter(|w| w.is_finite() && **w >= 0.0) {
        consider(*w, &mut best, &mut omega);
    }
    let polish = |w: f64, best: &mut f64, omega: &mut f64| {
        if !(w.is_finite() && w > 0.0) {
            return;
        }
        let ev = |x: f64| sw.value(x.exp()).unwrap_or(0.0);
        let (x, neg) = crate::system::golden::golden_section_min(
            |x| -ev(x),
            (w / 1.001).ln(),
            (w * 1.001).ln(),
            80,
        );
        if -neg > *best {
            (*best, *omega) = (-neg, x.exp());
        }
    };
    if omega.is_finite() {
        polish(omega, &mut best, &mut omega);
    }
    let mut cuts: Vec<f64> = breaks
        .iter()
        .copied()
        .filter(|w| w.is_finite() && *w > 0.0)
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let top = 100.0 * cuts.last().copied().unwrap_or(1.0).max(1.0);
    let mut stack = vec![Interval::Ray(top)];
    let mut lo = 0.0;
    for w in cuts.iter().copied().chain(std::iter::once(top)) {
        if w > lo {
            stack.push(Interval::Finite(lo, w));
            lo = w;
        }
    }
    let mut level = (1.0 + 2.0 * HINF_RTOL) * best;
    let mut tests = 0usize;
    while let Some(iv) = stack.pop() {
        tests += 1;
        if tests > cap || level.is_nan() || level <= 0.0 {
            return None;
        }
        match sw.test(&iv, level) {
            Test::Below => continue,
            Test::Above => {
                let w0 = iv.omega0();
                let before = best;
                consider(w0, &mut best, &mut omega);
                if best > before {
                    polish(w0, &mut best, &mut omega);
                    level = (1.0 + 2.0 * HINF_RTOL) * best;
                }
            }
            Test::Unknown => {}
        }
        stack.extend(iv.split()?);
    }
    Some(HinfNorm {
        gamma: best,
        omega,
        upper: level,
        iterations: tests,
    })
}
