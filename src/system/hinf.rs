//! The H∞ norm `‖G‖∞ = sup_ω σ_max(G(jω))` of a stable state-space system, computed exactly
//! by the Boyd–Balakrishnan / Bruinsma–Steinbuch iteration: `γ` is a singular value of
//! `G(jω)` iff `jω` is an eigenvalue of the Hamiltonian (Bruinsma & Steinbuch 1990, eq. 3)
//!
//! `H(γ) = [A − BR⁻¹DᵀC   −γBR⁻¹Bᵀ;  γCᵀS⁻¹C   −Aᵀ + CᵀDR⁻¹Bᵀ]`, `R = DᵀD − γ²I`,
//! `S = DDᵀ − γ²I`.
//!
//! Starting from a lower bound (the peak over the poles' frequencies and a log grid), each
//! step takes the imaginary-axis eigenvalues at the level `(1 + 2ε)γ`, evaluates `σ_max` at
//! the geometric midpoints of the intervals they bound, and raises `γ`; the iteration
//! converges quadratically and stops when there is no imaginary eigenvalue, which proves
//! `γ ≤ ‖G‖∞ ≤ (1 + 2ε)γ` ([`HinfNorm::upper`] is the proven upper bound).
//!
//! **Levels near `σ_max(D)`.** `H(γ)` needs `R⁻¹`, whose norm grows like `1/(γ² − σ_max(D)²)`:
//! at `γ = (1 + 2ε)σ_max(D)` the entries reach 1e12 and the crossings of an interior peak a
//! percent above `σ_max(D)` leave the axis (issue 22: a wrong "robust" verdict). Below
//! `(1 + 10⁻³)σ_max(D)` the crossings are therefore taken from the extended
//! `(2n + m + p)` pencil that needs no inverse (Benner, Sima & Voigt 2003, eq. (5); the
//! same equations `λx = Ax + Bu`, `λq = −Aᵀq − Cᵀv`, `Bᵀq + Dᵀv = γu`, `Cx + Du = γv`)
//!
//! `M − λN = [A − λI  0  B  0;  0  −Aᵀ − λI  0  −Cᵀ;  0  Bᵀ  −γI  Dᵀ;  C  0  D  −γI]`,
//!
//! solved by a real shift-and-invert: the finite eigenvalues are `λ = σ₀ + 1/μ` with `μ` the
//! eigenvalues of the leading `2n × 2n` block of `(M − σ₀N)⁻¹` (an LU solve; the eigenvalues
//! that go to infinity as `γ → σ_max(D)` map harmlessly to `μ → 0`).

use super::eig::{eigenvalues, spectral_abscissa};
use super::freq_eval::FreqEvaluator;
use super::logspace;
use super::state_space::StateSpace;
use crate::error::{Error, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Relative accuracy `ε` of the returned norm.
pub const HINF_RTOL: f64 = 1e-9;
const MAX_ITER: usize = 50;

/// An H∞ norm with the frequency where it is attained.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HinfNorm {
    /// `‖G‖∞` (a lower bound within relative `2ε` of the true value).
    pub gamma: f64,
    /// Frequency (rad/s) of the peak; `inf` when the supremum is approached as `ω → ∞`.
    pub omega: f64,
    /// Proven upper bound: `‖G‖∞ ≤ upper` (the last level without an imaginary-axis
    /// eigenvalue, `(1 + 2ε)·gamma`). A verdict `‖G‖∞ ≤ 1` must use this, not `gamma`.
    pub upper: f64,
    /// Hamiltonian iterations used.
    pub iterations: usize,
}

/// Below `(1 + PENCIL_BELOW)·σ_max(D)` the crossings come from the extended pencil.
const PENCIL_BELOW: f64 = 1e-3;

fn sigma_max(ev: &FreqEvaluator, omega: f64) -> f64 {
    if omega.is_infinite() {
        return f64::NAN;
    }
    ev.freq(omega)
        .map(|g| super::linalg::spectral_norm(&g))
        .unwrap_or(f64::INFINITY)
}

/// The end of an iteration with no interval above the level: the peak polished by
/// [`refine_peak`] is the norm (`Ok`), unless it rises above `level`, in which case the
/// iteration goes on from it (`Err` carries the new `(γ, ω)`).
fn polish(
    ev: &dyn Fn(f64) -> f64,
    gamma: f64,
    omega: f64,
    level: f64,
    lo: f64,
    iterations: usize,
) -> std::result::Result<HinfNorm, (f64, f64)> {
    let (g2, w2) = refine_peak(ev, omega, lo);
    if g2 > level {
        return Err((g2, w2));
    }
    Ok(HinfNorm {
        gamma: gamma.max(g2),
        omega: if g2 > gamma { w2 } else { omega },
        upper: level,
        iterations,
    })
}

/// Golden-section search for a local maximum of `σ_max` in `[ω/(1+η), ω(1+η)]`, `η = 1e-3`
/// (cut at the band's lower edge `lo`).
/// Near a sharp peak two crossing eigenvalues of `H(γ)` nearly coalesce and round-off can
/// push them off the axis; this local search recovers the last digits.
fn refine_peak(ev: &dyn Fn(f64) -> f64, omega: f64, lo: f64) -> (f64, f64) {
    if !(omega.is_finite() && omega > 0.0) {
        return (ev(omega), omega);
    }
    let (a, b) = ((omega / 1.001).max(lo).ln(), (omega * 1.001).ln());
    let (x, neg) = super::golden::golden_section_min(|x| -ev(x.exp()), a, b, 80);
    (-neg, x.exp())
}

fn hamiltonian(ss: &StateSpace, gamma: f64) -> Option<DMatrix<f64>> {
    let (p, m) = ss.d.shape();
    let (a, b, c, d) = (&ss.a, &ss.b, &ss.c, &ss.d);
    let g2 = gamma * gamma;
    let r = d.transpose() * d - DMatrix::<f64>::identity(m, m) * g2;
    let s = d * d.transpose() - DMatrix::<f64>::identity(p, p) * g2;
    let r_lu = r.lu();
    let rinv_dtc = r_lu.solve(&(d.transpose() * c))?;
    let rinv_bt = r_lu.solve(&b.transpose())?;
    let sinv_c = s.lu().solve(c)?;
    let n = a.nrows();
    let mut h = DMatrix::zeros(2 * n, 2 * n);
    h.view_mut((0, 0), (n, n)).copy_from(&(a - b * &rinv_dtc));
    h.view_mut((0, n), (n, n))
        .copy_from(&(-(b * &rinv_bt) * gamma));
    h.view_mut((n, 0), (n, n))
        .copy_from(&((c.transpose() * sinv_c) * gamma));
    h.view_mut((n, n), (n, n))
        .copy_from(&(-a.transpose() + c.transpose() * d * &rinv_bt));
    Some(h)
}

/// Frequencies `ω ≥ 0` where `jω` is (to a generous tolerance: a spurious candidate only
/// costs a probe) an eigenvalue of `H(level)`.
fn hamiltonian_crossings(ss: &StateSpace, level: f64) -> Result<Vec<f64>> {
    let h = hamiltonian(ss, level)
        .ok_or_else(|| Error::numerical("H∞ norm", "singular D-term matrix in the Hamiltonian"))?;
    let eigs = eigenvalues(&h, "H∞ norm: Hamiltonian")?;
    let hn = h.amax().max(1.0);
    Ok(eigs
        .iter()
        .filter(|z| z.re.abs() <= 1e-6 * z.norm().max(1e-3 * hn) && z.im >= 0.0)
        .map(|z| z.im)
        .collect())
}

/// The same frequencies from the extended pencil `M − λN` of the module docs, by the real
/// shift-and-invert `λ = σ₀ + 1/μ`; `G` is scaled by `1/level` so that the pencil tests the
/// level 1 with entries of the size of the data. The shift is moved when it falls on an
/// eigenvalue (a nearly singular `M − σ₀N`): the best conditioned of a few shifts is used.
fn pencil_crossings(ss: &StateSpace, level: f64, shift: f64) -> Result<Vec<f64>> {
    let n = ss.states();
    let (p, m) = ss.d.shape();
    let size = 2 * n + m + p;
    // A state scaling x → x/t that equalizes ‖B‖ and ‖C‖/level (a weight at the inputs,
    // r·T with r ~ 1e-4, leaves them six decades apart and the LU below inaccurate).
    let (bn, cn) = (ss.b.amax(), ss.c.amax() / level);
    let t = if bn > 0.0 && cn > 0.0 {
        (cn / bn).sqrt()
    } else {
        1.0
    };
    let b = &ss.b * t;
    let (c, d) = (&ss.c / (level * t), &ss.d / level);
    // The best conditioned of a few shifts (a shift next to an eigenvalue makes the
    // resolvent huge); the first one with ‖M − σ₀N‖·‖X₁‖ ≤ 1e10 is taken at once.
    let mut best: Option<(f64, f64, DMatrix<f64>)> = None;
    for factor in [1.0, 1.618, 0.437, 3.71, 0.173, 9.3] {
        let s0 = shift * factor;
        let mut mm = DMatrix::<f64>::zeros(size, size);
        mm.view_mut((0, 0), (n, n))
            .copy_from(&(&ss.a - DMatrix::<f64>::identity(n, n) * s0));
        mm.view_mut((0, 2 * n), (n, m)).copy_from(&b);
        mm.view_mut((n, n), (n, n))
            .copy_from(&(-ss.a.transpose() - DMatrix::<f64>::identity(n, n) * s0));
        mm.view_mut((n, 2 * n + m), (n, p))
            .copy_from(&(-c.transpose()));
        mm.view_mut((2 * n, n), (m, n)).copy_from(&b.transpose());
        mm.view_mut((2 * n, 2 * n), (m, m))
            .copy_from(&(-DMatrix::<f64>::identity(m, m)));
        mm.view_mut((2 * n, 2 * n + m), (m, p))
            .copy_from(&d.transpose());
        mm.view_mut((2 * n + m, 0), (p, n)).copy_from(&c);
        mm.view_mut((2 * n + m, 2 * n), (p, m)).copy_from(&d);
        mm.view_mut((2 * n + m, 2 * n + m), (p, p))
            .copy_from(&(-DMatrix::<f64>::identity(p, p)));
        let scale = mm.amax().max(f64::MIN_POSITIVE);
        let mut rhs = DMatrix::<f64>::zeros(size, 2 * n);
        for i in 0..2 * n {
            rhs[(i, i)] = 1.0;
        }
        let Some(x) = mm.lu().solve(&rhs) else {
            continue;
        };
        let x1 = x.view((0, 0), (2 * n, 2 * n)).into_owned();
        let cond = x1.amax() * scale;
        if !cond.is_finite() {
            continue;
        }
        if best.as_ref().is_none_or(|b| cond < b.0) {
            best = Some((cond, s0, x1));
        }
        if cond <= 1e10 {
            break;
        }
    }
    let Some((_, s0, x1)) = best else {
        return Err(Error::numerical(
            "H∞ norm",
            "extended pencil: singular for every shift tried",
        ));
    };
    let xn = x1.amax();
    let mus = eigenvalues(&x1, "H∞ norm: extended pencil")?;
    let mut ws = Vec::new();
    for mu in mus {
        let mag = mu.norm();
        if mag <= 1e-14 * xn {
            continue; // an eigenvalue at infinity
        }
        let lambda = Complex64::new(s0, 0.0) + mu.inv();
        // Absolute error of μ ~ ε‖X₁‖, so of λ ~ ε‖X₁‖/|μ|² (generous multiples).
        let tol = 1e-6 * lambda.norm() + 1e-9 * xn / (mag * mag);
        if lambda.re.abs() <= tol && lambda.im >= 0.0 {
            ws.push(lambda.im);
        }
    }
    Ok(ws)
}

/// Points of the lower bound that starts the iteration: the band's edge `lo`, one frequency
/// per pole (its damped frequency `|Im λ|` when lightly damped, `|λ|` otherwise; conjugates
/// once) and a coarse log grid of [`START_GRID`] points two decades beyond the poles.
///
/// Bruinsma & Steinbuch (1990, Sec. 3) start from `ω = 0`, `∞` and a single pole frequency:
/// the level-set test that follows finds every interval above the level whatever the start,
/// so the candidates only save iterations (each a `2n × 2n` eigenproblem). Near a lightly
/// damped pole `σ_max` peaks within a few `|Re λ|` of `|Im λ|`; the iteration's midpoints and
/// the local polish recover the rest. (Before issue 34 there were eight candidates per pole
/// and 200 grid points: on a 200-mode model, thousands of responses with one input per mode
/// were 60 % of the time and bought nothing the iteration does not prove anyway.)
fn starting_candidates(poles: &[Complex64], lo: f64, wmin: f64, wmax: f64) -> Vec<f64> {
    if poles.len() < FEW_CANDIDATES_FROM {
        return dense_candidates(poles, lo, wmin, wmax);
    }
    let mut candidates = vec![lo];
    for z in poles.iter().filter(|z| z.im >= 0.0) {
        candidates.push(if z.im > z.re.abs() { z.im } else { z.norm() });
    }
    candidates.extend(logspace(wmin * 1e-2, wmax * 1e2, START_GRID));
    candidates.retain(|w| *w >= lo);
    candidates
}

/// Points of the coarse log grid among the starting candidates.
const START_GRID: usize = 40;

/// From this many states on, [`starting_candidates`] keeps one per pole. Below it the start
/// is the earlier, denser one (eight per pole, 200 grid points), which costs nothing there:
/// the norm is the same to `2ε` either way, but the fit of `r` chooses among candidates by
/// margins that move with the norm's last digits (a [plant] example's fitted margin moved
/// by 1 % with the sparse start), so small models keep their figures.
const FEW_CANDIDATES_FROM: usize = 100;

/// The earlier start: `lo`, each pole's damped and natural frequency, `|Im λ| ± k|Re λ|`
/// for `k` in ±½, ±1, ±2, and 200 log points.
fn dense_candidates(poles: &[Complex64], lo: f64, wmin: f64, wmax: f64) -> Vec<f64> {
    let mut candidates = vec![lo];
    candidates.extend(poles.iter().map(|z| z.im.abs()));
    candidates.extend(poles.iter().map(|z| z.norm()));
    for z in poles {
        for k in [-2.0, -1.0, -0.5, 0.5, 1.0, 2.0] {
            let w = z.im.abs() + k * z.re.abs();
            if w > 0.0 {
                candidates.push(w);
            }
        }
    }
    candidates.extend(logspace(wmin * 1e-2, wmax * 1e2, 200));
    candidates.retain(|w| *w >= lo);
    candidates
}

/// `‖G‖∞` of a stable system; errors when `A` is not Hurwitz (the norm is infinite) or an
/// eigenvalue computation fails.
pub fn hinf_norm(ss: &StateSpace) -> Result<HinfNorm> {
    peak_gain(ss, 0.0, true, None, None, None)
}

/// [`hinf_norm`] started from the caller's frequencies instead of one per pole and a grid:
/// the lower bound is `σ_max(G(jω))` at those frequencies (evaluated here on `ss`), and the
/// Hamiltonian iteration proves the bound as always, whatever the start. For a large
/// system whose peak the caller has located by a cheaper route (a structured grid), where
/// the built-in candidates (one dense response per pole) would cost more than the iteration.
///
/// `sigma`, when given, evaluates `σ_max(G(jω))` in place of the dense response (the probes
/// and the local polish of the peak): it must never exceed the true value (a Rayleigh
/// quotient, a converged Lanczos value) so that `gamma` stays a lower bound; `None` from
/// it falls back to the dense response. The upper bound is the Hamiltonian's, as always.
pub fn hinf_norm_near(
    ss: &StateSpace,
    omegas: &[f64],
    sigma: Option<&dyn Fn(f64) -> Option<f64>>,
) -> Result<HinfNorm> {
    peak_gain(ss, 0.0, true, Some(omegas), sigma, None)
}

/// [`hinf_norm_near`] for a system whose poles the caller has already computed (the
/// eigenvalues of `ss.a`, e.g. the closed-loop poles of the same loop): on a loop of
/// thousands of states that dense eigenproblem is minutes, and the iteration needs the
/// poles only for the stability test and the scale of the pencil's shift.
pub fn hinf_norm_near_with_poles(
    ss: &StateSpace,
    omegas: &[f64],
    sigma: Option<&dyn Fn(f64) -> Option<f64>>,
    poles: &[Complex64],
) -> Result<HinfNorm> {
    if poles.len() != ss.states() {
        return Err(Error::Invalid(format!(
            "H∞ norm: {} poles given for {} states",
            poles.len(),
            ss.states()
        )));
    }
    peak_gain(ss, 0.0, true, Some(omegas), sigma, Some(poles))
}

/// `sup σ_max(G(jω))` over `ω ∈ [omega_lo, ∞]` for any `A` (stable or not): the `L∞` norm of
/// `G` on that band, by the same Hamiltonian iteration ([`HinfNorm::upper`] is proven). The
/// relation "γ is a singular value of `G(jω)` iff `jω` is an eigenvalue of `H(γ)`" needs
/// only that `jω` is not an eigenvalue of `A`, so unstable poles are allowed; an eigenvalue
/// of `A` on the axis below the band only adds a crossing outside it, which is ignored. A
/// pole on the axis inside the band gives `gamma = upper = inf` at its frequency.
pub fn peak_gain_above(ss: &StateSpace, omega_lo: f64) -> Result<HinfNorm> {
    if !(omega_lo >= 0.0 && omega_lo.is_finite()) {
        return Err(Error::Invalid(format!(
            "peak gain: band edge {omega_lo} must be finite and ≥ 0"
        )));
    }
    peak_gain(ss, omega_lo, false, None, None, None)
}

fn peak_gain(
    ss: &StateSpace,
    lo: f64,
    require_stable: bool,
    start: Option<&[f64]>,
    sigma: Option<&dyn Fn(f64) -> Option<f64>>,
    known_poles: Option<&[Complex64]>,
) -> Result<HinfNorm> {
    ss.validate("H∞ norm")?;
    // An exact similarity that keeps the Hamiltonian's eigenvalues accurate when the
    // realization has widely spread entries (companion forms of high-order weights).
    let ss = &ss.balanced();
    let n = ss.states();
    let d_norm = if ss.d.is_empty() {
        0.0
    } else {
        ss.d.clone().svd(false, false).singular_values.max()
    };
    if n == 0 {
        return Ok(HinfNorm {
            gamma: d_norm,
            omega: f64::INFINITY,
            upper: d_norm,
            iterations: 0,
        });
    }
    // The balancing below is a similarity: the caller's poles are those of `ss.a`.
    let poles = match known_poles {
        Some(p) => p.to_vec(),
        None => eigenvalues(&ss.a, "H∞ norm: poles")?,
    };
    let abscissa = spectral_abscissa(&poles);
    if abscissa.is_nan() || (require_stable && abscissa >= 0.0) {
        return Err(Error::Invalid(format!(
            "H∞ norm: the system is not stable (pole with real part {abscissa:.3e}); the norm is infinite"
        )));
    }
    let dense = FreqEvaluator::new(ss);
    let ev = |w: f64| match sigma.and_then(|f| f(w)) {
        Some(s) => s,
        None => sigma_max(&dense, w),
    };
    // Lower bound: ω = 0, ∞, the poles' natural and damped frequencies, and a log grid.
    let (mut gamma, mut omega) = (d_norm, f64::INFINITY);
    let wmax = poles
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
        .max(1e-300);
    let wmin = poles
        .iter()
        .map(|z| z.norm())
        .filter(|w| *w > 0.0)
        .fold(f64::INFINITY, f64::min)
        .min(wmax);
    let candidates = match start {
        Some(ws) => ws
            .iter()
            .copied()
            .filter(|w| *w >= lo && w.is_finite())
            .collect(),
        None => starting_candidates(&poles, lo, wmin, wmax),
    };
    for w in candidates {
        let s = ev(w);
        if s > gamma {
            gamma = s;
            omega = w;
        }
    }
    if !require_stable && gamma == f64::INFINITY {
        // A pole on the axis inside the band: the gain is unbounded there.
        return Ok(HinfNorm {
            gamma,
            omega,
            upper: gamma,
            iterations: 0,
        });
    }
    if !gamma.is_finite() {
        return Err(Error::Invalid(
            "H∞ norm: the frequency response is not finite on the imaginary axis".into(),
        ));
    }
    if gamma == 0.0 {
        return Ok(HinfNorm {
            gamma,
            omega: 0.0,
            upper: 0.0,
            iterations: 0,
        });
    }
    for it in 1..=MAX_ITER {
        let level = (1.0 + 2.0 * HINF_RTOL) * gamma;
        let mut ws = if level > (1.0 + PENCIL_BELOW) * d_norm {
            hamiltonian_crossings(ss, level)?
        } else {
            // Shift at the scale of the system's frequencies (the peak's when finite).
            let shift = if omega.is_finite() && omega > 0.0 {
                omega
            } else {
                (wmin * wmax).sqrt()
            };
            pencil_crossings(ss, level, shift)?
        };
        ws.retain(|w| *w >= lo);
        ws.sort_by(f64::total_cmp);
        ws.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs().max(1e-300));
        if ws.is_empty() {
            match polish(&ev, gamma, omega, level, lo, it) {
                Ok(done) => return Ok(done),
                Err((g2, w2)) => {
                    (gamma, omega) = (g2, w2);
                    continue;
                }
            }
        }
        let mut improved = false;
        // σ_max exceeds the level on intervals bounded by consecutive crossings (and on
        // [lo, ω₁] when σ_max(G(j·lo)) is above it): probe the band's edge and every
        // geometric midpoint.
        let mut probe = vec![lo];
        probe.extend(ws.windows(2).map(|p| {
            if p[0] > 0.0 {
                (p[0] * p[1]).sqrt()
            } else {
                0.5 * p[1]
            }
        }));
        for w in probe {
            let s = ev(w);
            if s > gamma {
                gamma = s;
                omega = w;
                improved = true;
            }
        }
        if !improved {
            // The candidates bound no interval above γ: round-off touches of the peak (or
            // lightly damped eigenvalues near the axis). Polish the peak locally.
            match polish(&ev, gamma, omega, level, lo, it) {
                Ok(done) => return Ok(done),
                Err((g2, w2)) => {
                    (gamma, omega) = (g2, w2);
                    continue;
                }
            }
        }
    }
    Err(Error::numerical(
        "H∞ norm",
        format!("no convergence in {MAX_ITER} Hamiltonian iterations"),
    ))
}
