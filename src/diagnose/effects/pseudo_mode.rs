//! What the two pseudo-modes share (`residual_mode` above the band, `residual_mode_below`
//! below it): the term `ρ_ch/(s² + 2ζ₀ω_n s + ω_n²)` with the small fixed damping
//! [`PSEUDO_ZETA`], θ = [ln ω_n, ρ_1 … ρ_C], `ω_n` boxed in a range beyond one band edge, its
//! starts on a log grid of that range, and its written mode.  Each pseudo-mode's file keeps
//! only what differs: the range, when it is tried, and its words.

use crate::diagnose::effects::effect::{
    fmt_w, log_grid, one, per_channel, Site, Writer, PSEUDO_ZETA,
};
use crate::diagnose::effects::mode::mode_term;
use crate::model::physical::ModeSpec;
use num_complex::Complex64;

/// Typical sizes: 1 for `ln ω_n`, the residues' own magnitudes.
pub(crate) fn typ(theta: &[f64]) -> Vec<f64> {
    let mut v = vec![1.0];
    v.extend(theta[1..].iter().map(|x| x.abs().max(1e-300)));
    v
}

/// `ln ω_n` in `[ln lo, ln hi]`, the `n_ch` residues free.
pub(crate) fn bounds(n_ch: usize, (lo, hi): (f64, f64)) -> Vec<(f64, f64)> {
    let mut v = vec![(lo.ln(), hi.ln())];
    v.extend(std::iter::repeat_n(
        (f64::NEG_INFINITY, f64::INFINITY),
        n_ch,
    ));
    v
}

/// The term on channel `ch` at `ω` (natural parameters `[ω_n, ρ_1 … ρ_C]`).
pub(crate) fn term(nat: &[f64], omega: f64, ch: usize) -> Complex64 {
    mode_term(omega, nat[0], PSEUDO_ZETA, nat[1 + ch])
}

/// The SI parameters: `omega_n` and one `rho` per channel.
pub(crate) fn si_params(th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
    let mut v = one("omega_n", th[0].exp(), th[0].exp());
    v.extend(per_channel("rho", th, 1, entries));
    v
}

/// Writes the pseudo-mode as a mode named by the writer's note (the name marks it).
pub(crate) fn write(w: &mut Writer) {
    let (b, c) = w.gains(1);
    w.m.mode.push(ModeSpec {
        name: Some(w.note.to_string()),
        omega_n: w.get("omega_n"),
        zeta: PSEUDO_ZETA,
        mass: 1.0,
        input_gain: b,
        output_gain: c,
    });
}

/// `ω_n` on a log grid of `[lo, hi]`, the residues by least squares: the three cheapest.
pub(crate) fn starts(site: &dyn Site, (lo, hi): (f64, f64)) -> Vec<Vec<f64>> {
    let mut trials: Vec<(f64, Vec<f64>)> = log_grid(lo, hi, 16)
        .into_iter()
        .map(|lw| {
            let mut th = site.mode_theta(lw.exp(), PSEUDO_ZETA);
            // `mode_theta` is an added mode's [ln ω_n, ln ζ, ρ…]: ζ is not a parameter here.
            th.remove(1);
            (site.cost(&th), th)
        })
        .collect();
    trials.sort_by(|a, b| a.0.total_cmp(&b.0));
    trials.into_iter().take(3).map(|t| t.1).collect()
}

/// The flag of an `ω_n` that ended at its bound; `instead` says what then explains the data.
pub(crate) fn not_placed(
    th: &[f64],
    at: &dyn Fn(usize) -> bool,
    instead: &str,
    out: &mut Vec<String>,
) {
    if at(0) {
        out.push(format!(
            "ω_n at its bound {}: the pseudo-mode is not placed ({instead})",
            fmt_w(th[0].exp())
        ));
    }
}
