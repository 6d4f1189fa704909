//! The certificate: the final `r(s)` re-evaluated, in rad/s and unscaled units, from its
//! poles and zeros (not from the LP variables), at every datum and on a dense grid
//! (`≥ 50` points per decade over the band widened by two decades each side).  The no-dip
//! bound between data is *proved* on every interval ([`super::between`]: interval
//! branch-and-bound, no sampling); the floor is checked on the dense grid and at `ω = ∞`.
//! A1 is *proved* on the band `[ω_lo, ∞]` (`ω_lo` the lowest datum two decades down, where
//! the fit enforces it) when a realization of `M̃⁻¹` is given ([`super::a1_proof`]: an `L∞`
//! norm by the Hamiltonian iteration), and checked by a second, cheap route that must
//! agree: the dense grid refined by golden-section search where its margin is small and at
//! each lightly damped zero of `M̃`. Without a realization, that second route alone decides.
//!
//! If coverage fails (LP tolerance, or a dip between data), the gain is rescaled by the
//! worst under-coverage, as MATLAB's `ucover` does, and everything is checked again; a
//! failure that remains (for example A1 broken by the rescaling) is reported, never hidden.

use super::a1_proof::{prove, A1Proof};
use super::spectral::Zpk;
use serde::Serialize;

/// What the certificate checked and found.  Frequencies in rad/s.
#[derive(Debug, Clone, Serialize)]
pub struct Certificate {
    /// True when every check passed.
    pub passed: bool,
    /// One line per failed check.
    pub failures: Vec<String>,
    /// `min |r(jω_i)|/r_min,i` over the data with `r_min > 0` (must be ≥ 1 + margin).
    pub worst_ratio: f64,
    /// Where the worst ratio is.
    pub worst_ratio_omega: f64,
    /// Mean of `log10(|r|/r_min)` over the data (conservatism).
    pub mean_log10_ratio: f64,
    /// Max of `log10(|r|/r_min)` over the data.
    pub max_log10_ratio: f64,
    /// `min |r|/min(r_min,i, r_min,i+1)` between consecutive data (no dip), refined.
    pub worst_between_ratio: f64,
    /// Where it is.
    pub worst_between_omega: f64,
    /// Proved lower bound of `|r|/min(r_min,i, r_min,i+1)` over every interval between
    /// consecutive data (must be ≥ (1 + margin)·(1 − 1e-9)); see `fit::between`.
    pub between_lower_bound: f64,
    /// How the between-data bound was established.
    pub between_method: String,
    /// Intervals where the proof hit its cap (each one is a failure).
    pub between_unresolved: usize,
    /// `min σ_min(M̃(jω))/|r(jω)|` on the dense grid (refined), when the A1 limit is known
    /// (must be > 1).
    pub worst_a1_margin: Option<f64>,
    /// Where it is.
    pub worst_a1_omega: Option<f64>,
    /// How A1 was checked: `proved` (the `L∞` proof on `[a1_band_lo, ∞]`, cross-checked by
    /// the grid), `function` (dense grid and dips only), `data` (only at the data), `none`.
    pub a1_checked_on: String,
    /// Proven lower bound of `σ_min(M̃(jω))/|r(jω)|` on `[a1_band_lo, ∞]` (must be > 1),
    /// when `a1_checked_on` is `proved`.
    pub a1_lower_bound: Option<f64>,
    /// Lower edge (rad/s) of the band on which A1 is checked.
    pub a1_band_lo: Option<f64>,
    /// `min |r(jω)|` over the dense grid and `ω = ∞` (strict positivity).
    pub min_abs_r: f64,
    /// `|r(∞)|` (biproper: nonzero).
    pub r_at_infinity: f64,
    /// `min |Re p|` over the poles (rad/s); `inf` for order 0.
    pub min_axis_distance_pole: f64,
    /// `min |Re z|` over the zeros (rad/s); `inf` for order 0.
    pub min_axis_distance_zero: f64,
    /// `min |Re|/|root|` over poles and zeros (damping; 1 for real roots).
    pub min_damping: f64,
    /// Number of frequencies evaluated (grid, data and refinement).
    pub grid_points: usize,
    /// Gain factor applied by the repair (1: none).
    pub repair_factor: f64,
}

/// The method and guarantee of the between-data check, as stated in the certificate.
pub const BETWEEN_METHOD: &str = "exact: interval branch-and-bound on |r(jw)|^2 as a product of factors in w^2 (closed-form min/max of each factor per sub-interval), rounding allowance included; guarantee: |r| >= (1+margin)*min(r_min_i, r_min_i+1)*(1 - 1e-9) on every interval between consecutive data";

/// Inputs of the certificate, unscaled.
pub struct CertInput<'a> {
    /// Data frequencies (rad/s), increasing.
    pub omega: &'a [f64],
    /// `r_min` per datum (0: no bound; never `inf` here).
    pub r_min: &'a [f64],
    /// A1 limit function, if known.
    pub a1: Option<&'a dyn Fn(f64) -> f64>,
    /// A1 limit per datum, if known.
    pub a1_data: Option<&'a [f64]>,
    /// Where `σ_min(M̃)` may dip between grid points (lightly damped zeros of `M̃`, rad/s):
    /// A1 is evaluated there and refined around each.
    pub a1_dips: &'a [f64],
    /// Realizations of `M̃⁻¹` for the A1 proof (with `a1`), or [`A1Proof::Sampled`].
    pub a1_proof: &'a A1Proof,
    /// Required relative margin over `r_min`.
    pub margin: f64,
    /// Floor on `|r|` everywhere.
    pub floor: f64,
    /// Grid density.
    pub per_decade: usize,
    /// Decades beyond the data band.
    pub extend_decades: f64,
    /// Check the no-dip bound between data.
    pub no_dip: bool,
    /// Smallest accepted `|Re|/|root|`.
    pub axis_tol: f64,
}

impl<'a> CertInput<'a> {
    /// The inputs with which a fit of `env` under `set` (A1 limit `a1`) certifies its result:
    /// the settings' margin, grid and A1 proof, and the floor `floor_rel` × the smallest
    /// positive `r_min` (infinite when every `r_min` is 0, which no fit accepts).  Another
    /// route to a fit's certificate: [`certify`] of its `r` with these inputs.
    pub fn of_fit(
        env: &'a crate::consistency::Envelope,
        a1: Option<&'a dyn Fn(f64) -> f64>,
        set: &'a super::FitSettings,
    ) -> Self {
        let min_pos = min_positive(&env.r_min);
        Self {
            omega: &env.omega,
            r_min: &env.r_min,
            a1,
            a1_data: env.a1_limit.as_deref(),
            a1_dips: &set.a1_dips,
            a1_proof: &set.a1_proof,
            margin: set.margin,
            floor: set.floor_rel * min_pos,
            per_decade: set.cert_per_decade,
            extend_decades: set.extend_decades,
            no_dip: set.no_dip,
            axis_tol: set.axis_tol,
        }
    }
}

/// The smallest positive `r_min` (`∞` when there is none): the scale of the fit's floor
/// `floor_rel × min r_min`.
pub(crate) fn min_positive(r_min: &[f64]) -> f64 {
    r_min
        .iter()
        .copied()
        .filter(|r| *r > 0.0)
        .fold(f64::INFINITY, f64::min)
}

fn golden_min(f: &dyn Fn(f64) -> f64, a: f64, b: f64, iters: usize) -> (f64, f64) {
    // On ln ω.
    let (x, fx) = crate::system::golden::golden_section_min(|x| f(x.exp()), a, b, iters);
    (x.exp(), fx)
}

/// Minimum of `f` over the sorted grid `w`, refined by golden section around every grid
/// cell whose value is below `refine_below` (at most `max_refine` cells, lowest first).
fn refined_min(
    f: &dyn Fn(f64) -> f64,
    w: &[f64],
    refine_below: f64,
    max_refine: usize,
    count: &mut usize,
) -> (f64, f64) {
    let vals: Vec<f64> = w.iter().map(|x| f(*x)).collect();
    *count += w.len();
    let mut best = (f64::NAN, f64::INFINITY);
    let mut cells: Vec<usize> = Vec::new();
    for (i, v) in vals.iter().enumerate() {
        if *v < best.1 || best.0.is_nan() {
            best = (w[i], *v);
        }
        let left = i == 0 || vals[i - 1] >= *v;
        let right = i + 1 == vals.len() || vals[i + 1] >= *v;
        if *v < refine_below && left && right {
            cells.push(i);
        }
    }
    cells.sort_by(|a, b| vals[*a].total_cmp(&vals[*b]));
    for &i in cells.iter().take(max_refine) {
        let a = w[i.saturating_sub(1)].ln();
        let b = w[(i + 1).min(w.len() - 1)].ln();
        if b > a {
            let (x, v) = golden_min(f, a, b, 40);
            *count += 42;
            if v < best.1 {
                best = (x, v);
            }
        }
    }
    best
}

/// Computes the certificate of `r` without any repair.
pub fn certify(r: &Zpk, inp: &CertInput) -> Certificate {
    let n = inp.omega.len();
    let mut count = 0usize;
    let mut failures = Vec::new();
    let need = 1.0 + inp.margin;
    // Data.
    let (mut worst, mut worst_w, mut sum, mut cnt, mut max) =
        (f64::INFINITY, f64::NAN, 0.0, 0usize, f64::NEG_INFINITY);
    for i in 0..n {
        if inp.r_min[i] > 0.0 {
            let ratio = r.mag(inp.omega[i]) / inp.r_min[i];
            if ratio < worst {
                worst = ratio;
                worst_w = inp.omega[i];
            }
            sum += ratio.log10();
            cnt += 1;
            max = max.max(ratio.log10());
        }
    }
    count += n;
    if worst < need {
        failures.push(format!(
            "datum at ω = {worst_w:.6e} rad/s not covered: |r|/r_min = {worst:.9} < {need}"
        ));
    }
    // Dense grid.
    let (lo, hi) = (inp.omega[0], inp.omega[n - 1]);
    let ext = 10f64.powf(inp.extend_decades);
    let grid = super::basis::dense_grid(lo / ext, hi * ext, inp.per_decade);
    // Between data: |r| ≥ need·min(r_min,i, r_min,i+1), proved on every interval.
    let (mut between, mut between_w, mut between_lb, mut unresolved) =
        (f64::INFINITY, f64::NAN, f64::INFINITY, 0usize);
    if inp.no_dip && n > 1 {
        let c = super::between::check_between(r, inp.omega, inp.r_min, need);
        count += c.nodes;
        between = c.attained * need;
        between_w = c.omega;
        between_lb = c.lower * need;
        unresolved = c.capped;
        if !(c.lower >= 1.0 - super::between::TOL) {
            if c.attained < 1.0 - super::between::TOL {
                failures.push(format!(
                    "|r| dips between data: at ω = {between_w:.6e} rad/s, |r|/min(neighbouring r_min) = {between:.9}"
                ));
            } else {
                failures.push(format!(
                    "no dip found between data, but the proof did not close on {unresolved} interval(s) (proved |r|/min(neighbouring r_min) ≥ {between_lb:.9})"
                ));
            }
        }
    }
    // A1.
    let (mut a1m, mut a1w, a1_on) = (None, None, String::from("none"));
    let (mut a1_lower, mut a1_lo) = (None, None);
    let a1_on = if let Some(a1) = inp.a1 {
        let f = |w: f64| a1(w) / r.mag(w);
        let mut all = grid.clone();
        all.extend_from_slice(inp.omega);
        all.sort_by(f64::total_cmp);
        let (mut w, mut v) = refined_min(&f, &all, 1.05, 200, &mut count);
        // A notch of σ_min(M̃) narrower than the grid (ζ = 1e-7: a relative width of 1e-7)
        // is found from where it must be: at each lightly damped zero of M̃, refined by
        // golden section on ±1e-3 in ln ω (unimodal there; 60 steps reach 1e-16).
        for &d in inp.a1_dips.iter().filter(|d| d.is_finite() && **d > 0.0) {
            let fd = f(d);
            let (x, fx) = golden_min(&f, d.ln() - 1e-3, d.ln() + 1e-3, 60);
            count += 62;
            for (x, fx) in [(d, fd), (x, fx)] {
                if fx < v || fx.is_nan() {
                    (w, v) = (x, fx);
                }
            }
        }
        let far = a1(hi * 1e6) / r.gain.abs();
        let (w, v) = if far < v {
            (f64::INFINITY, far)
        } else {
            (w, v)
        };
        a1m = Some(v);
        a1w = Some(w);
        let band_lo = lo / ext;
        a1_lo = Some(band_lo);
        match inp.a1_proof {
            A1Proof::Sampled => "function".to_string(),
            A1Proof::Impossible(why) => {
                failures.push(format!("A1 fails: {why}"));
                "proved".to_string()
            }
            // A failure already found at a real frequency needs no proof.
            A1Proof::Blocks(_) if !(v > 1.0) => "function".to_string(),
            A1Proof::Blocks(blocks) => {
                match prove(blocks, r, band_lo) {
                    Ok(p) => {
                        a1_lower = Some(p.lower);
                        // The second route must agree: nothing sampled below the proved
                        // bound, and the proof's worst frequency evaluated directly (the
                        // factors' own SVD, not the realization of M̃⁻¹) gives its value.
                        let direct = if p.omega.is_finite() {
                            a1(p.omega) / r.mag(p.omega)
                        } else {
                            far
                        };
                        let agree = v >= p.lower * (1.0 - 1e-6)
                            && (direct - p.attained).abs() <= 1e-3 * p.attained.max(1e-300);
                        if !agree {
                            failures.push(format!(
                                "A1 not proved: the L∞ proof (σ_min/|r| ≥ {:.9} on [{band_lo:.3e}, ∞], {:.9} at ω = {:.6e} rad/s) and the direct evaluation ({v:.9} sampled, {direct:.9} at that frequency) disagree",
                                p.lower, p.attained, p.omega
                            ));
                        } else if p.attained < v {
                            a1m = Some(p.attained);
                            a1w = Some(p.omega);
                        }
                        if agree && !(p.attained > 1.0) {
                            failures.push(format!(
                                "A1 fails: |r| ≥ σ_min(M̃) at ω = {:.6e} rad/s (σ_min/|r| = {:.9}, found by the L∞ proof on [{band_lo:.3e}, ∞])",
                                p.omega, p.attained
                            ));
                        } else if agree && !(p.lower > 1.0) {
                            failures.push(format!(
                                "A1 not proved: σ_min/|r| = {:.9} at ω = {:.6e} rad/s, proved only ≥ {:.9}",
                                p.attained, p.omega, p.lower
                            ));
                        }
                    }
                    Err(e) => failures.push(format!("A1 not proved: {e}")),
                }
                "proved".to_string()
            }
        }
    } else if let Some(d) = inp.a1_data {
        let mut m = (f64::NAN, f64::INFINITY);
        for (w, a) in inp.omega.iter().zip(d) {
            let v = a / r.mag(*w);
            if v < m.1 {
                m = (*w, v);
            }
        }
        a1m = Some(m.1);
        a1w = Some(m.0);
        "data".to_string()
    } else {
        a1_on
    };
    if let (Some(m), Some(w)) = (a1m, a1w) {
        // (A proved failure is reported above with its band.)
        if !(m > 1.0) && a1_lower.is_none() {
            failures.push(format!(
                "A1 fails: |r| ≥ σ_min(M̃) at ω = {w:.6e} rad/s (σ_min/|r| = {m:.9})"
            ));
        }
    }
    // Positivity and units.
    let min_abs = grid.iter().map(|w| r.mag(*w)).fold(r.gain.abs(), f64::min);
    count += grid.len();
    if !(min_abs >= inp.floor * (1.0 - 1e-6)) {
        failures.push(format!(
            "|r| falls to {min_abs:.3e}, below the floor {:.3e}",
            inp.floor
        ));
    }
    if !(r.gain > 0.0 && r.gain.is_finite()) || r.zeros.len() != r.poles.len() {
        failures.push("r is not biproper with a positive finite gain".into());
    }
    let dist = |v: &[num_complex::Complex64]| v.iter().map(|z| -z.re).fold(f64::INFINITY, f64::min);
    let (dp, dz) = (dist(&r.poles), dist(&r.zeros));
    let damping = r
        .poles
        .iter()
        .chain(&r.zeros)
        .map(|z| -z.re / z.norm())
        .fold(1.0, f64::min);
    if !(dp > 0.0) || !(dz > 0.0) || !(damping > inp.axis_tol) {
        failures.push(format!(
            "a pole or zero is on or near the jω-axis (min |Re p| = {dp:.3e}, min |Re z| = {dz:.3e}, damping {damping:.3e})"
        ));
    }
    Certificate {
        passed: failures.is_empty(),
        failures,
        worst_ratio: worst,
        worst_ratio_omega: worst_w,
        mean_log10_ratio: if cnt > 0 { sum / cnt as f64 } else { 0.0 },
        max_log10_ratio: max,
        worst_between_ratio: between,
        worst_between_omega: between_w,
        between_lower_bound: between_lb,
        between_method: BETWEEN_METHOD.into(),
        between_unresolved: unresolved,
        worst_a1_margin: a1m,
        worst_a1_omega: a1w,
        a1_checked_on: a1_on,
        a1_lower_bound: a1_lower,
        a1_band_lo: a1_lo,
        min_abs_r: min_abs,
        r_at_infinity: r.gain.abs(),
        min_axis_distance_pole: dp,
        min_axis_distance_zero: dz,
        min_damping: damping,
        grid_points: count,
        repair_factor: 1.0,
    }
}

/// Certifies `r`; if coverage fails, rescales the gain by the worst under-coverage
/// (`ucover` style) and certifies again.  Returns the (possibly rescaled) `r` and its
/// certificate, which says whether it passed.
pub fn certify_and_repair(r: &Zpk, inp: &CertInput) -> (Zpk, Certificate) {
    let c = certify(r, inp);
    if c.passed {
        return (r.clone(), c);
    }
    let need = 1.0 + inp.margin;
    let under = c.worst_ratio.min(if inp.no_dip {
        c.worst_between_ratio
    } else {
        f64::INFINITY
    });
    if !(under < need) || !under.is_finite() || under <= 0.0 {
        return (r.clone(), c);
    }
    let factor = need / under * (1.0 + 1e-9);
    let mut fixed = r.clone();
    fixed.gain *= factor;
    let mut c2 = certify(&fixed, inp);
    c2.repair_factor = factor;
    (fixed, c2)
}
