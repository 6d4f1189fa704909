//! Is what the model leaves the stated noise?  A test of the normalized residual
//! `z_k = (G_d − Ĝ)(ω_k)/σ_k` (`σ = r/√2`, the noise uniform in the disk of radius `r`) on
//! two counts, for the stop explanation (issue 33):
//!
//! * **level**: `V/E[V]` with `V = Σ|z|²` and `E[V] = N − p/2` (`p` real parameters
//!   fitted): near 1 at the stated noise;
//! * **whiteness** along frequency: a complex Ljung–Box statistic over the first `m` lags of
//!   each channel, `Q = Σ_ch Σ_k 2N²|ρ̂_k|²/(N − k)` with `ρ̂_k = Σ_i z_i z̄_{i+k} / Σ_i |z_i|²`.
//!   For independent circular noise `ρ̂_k` is approximately `CN(0, (N−k)/N²)`, so each term
//!   is `χ²₂` and `Q ~ χ²_{2m·n_ch}` (Ljung & Box 1978, in its complex form); `Q` beyond the
//!   `1 − α` quantile means structure in the residual (a missing resonance, a slope, a
//!   wrong phase), whatever its level.  The statistic is scale-free: a σ stated too small
//!   or too large by a constant factor does not change it.
//!
//! The cases the stop explanation tells apart: white at the level (nothing left to find),
//! white above it (the data scatter more than stated: a `std_factor`), structured (missing
//! dynamics, with the band where the residual concentrates), structured below the level (the
//! noise is overstated and still something is missing) — and, before these, one line holding
//! at least [`OUTLIER_SHARE`] of `V` above the level: an outlier (a spectral line such as
//! mains interference, a dropout), which a single spike makes look white (its lagged
//! products vanish) and a `std_factor` would wrongly spread over every line.

use num_complex::Complex64;

/// The false-alarm probability of the whiteness verdict.
pub const ALPHA: f64 = 1e-3;
/// Most lags per channel.
pub const MAX_LAGS: usize = 10;
/// A level `V/E[V]` above this is beyond the stated noise.
pub const LEVEL_HIGH: f64 = 1.5;
/// One line holding this share of `V` or more (above [`LEVEL_HIGH`], on at least
/// [`OUTLIER_MIN_LINES`] lines) is an outlier.  For noise at any level the largest share of
/// `n` lines (each `|z|²` exponential) is about `ln n / n`: 0.23 for 10 lines.
pub const OUTLIER_SHARE: f64 = 0.5;
/// Fewest lines for the outlier account.
pub const OUTLIER_MIN_LINES: usize = 10;

/// The verdict on a residual (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Whiteness {
    /// `V/E[V]`.
    pub level: f64,
    /// Lags per channel.
    pub lags: usize,
    /// The Ljung–Box statistic `Q`.
    pub q: f64,
    /// Its degrees of freedom `2m·n_ch`.
    pub dof: usize,
    /// The `1 − ALPHA` quantile of `χ²_dof` (exact: `dof` is even).
    pub q_crit: f64,
    /// `Q ≤ q_crit`.
    pub white: bool,
    /// The index range (first, last line) of the window of `window` lines where `|z|²`
    /// summed over channels is largest, and its mean per datum there.
    pub worst: Option<(usize, usize, f64)>,
    /// The line holding at least [`OUTLIER_SHARE`] of `V` (summed over channels) when the
    /// level is above [`LEVEL_HIGH`], and its share.
    pub outlier: Option<(usize, f64)>,
}

/// `P(χ²_{2k} > x) = e^{−x/2} Σ_{j<k} (x/2)^j / j!` (exact for even degrees of freedom,
/// the only ones [`whiteness`] uses), summed in logs to stay finite for large `k`.
pub fn chi2_even_survival(k: usize, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let h = x / 2.0;
    let (mut term, mut sum) = (0.0f64, 0.0f64); // ln of (h^j / j!), and the sum
    for j in 0..k {
        if j > 0 {
            term += h.ln() - (j as f64).ln();
        }
        sum += (term - h).exp();
    }
    sum.min(1.0)
}

/// The `p` quantile of `χ²_{2k}` (bisection on [`chi2_even_survival`], 200 halvings at most,
/// to a relative 1e-12).
pub fn chi2_even_quantile(k: usize, p: f64) -> f64 {
    let tail = 1.0 - p;
    let (mut lo, mut hi) = (0.0f64, 2.0 * k as f64 + 10.0);
    while chi2_even_survival(k, hi) > tail {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi2_even_survival(k, mid) > tail {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// The test of the normalized residual `z[ch][k]` (see the module docs); `n_params` real
/// parameters were fitted; `window` lines for the worst band (at least 1).
pub fn whiteness(z: &[Vec<Complex64>], n_params: usize, window: usize) -> Whiteness {
    let n_ch = z.len();
    let n = z.first().map_or(0, |c| c.len());
    let total = (n * n_ch) as f64;
    let v: f64 = z.iter().flatten().map(|x| x.norm_sqr()).sum();
    let ev = (total - n_params as f64 / 2.0).max(1.0);
    let lags = MAX_LAGS.min(n / 5);
    let mut q = 0.0;
    for c in z {
        let s0: f64 = c.iter().map(|x| x.norm_sqr()).sum();
        if s0 <= 0.0 {
            continue;
        }
        for k in 1..=lags {
            let r: Complex64 = (0..n - k)
                .map(|i| c[i] * c[i + k].conj())
                .sum::<Complex64>()
                / s0;
            let nf = n as f64;
            q += 2.0 * nf * nf * r.norm_sqr() / (nf - k as f64);
        }
    }
    let dof = 2 * lags * n_ch;
    let q_crit = if dof > 0 {
        chi2_even_quantile(dof / 2, 1.0 - ALPHA)
    } else {
        f64::INFINITY
    };
    let window = window.clamp(1, n.max(1));
    let per_line: Vec<f64> = (0..n)
        .map(|k| z.iter().map(|c| c[k].norm_sqr()).sum())
        .collect();
    let outlier = per_line
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(k, x)| (k, x / v))
        .filter(|(_, share)| {
            n >= OUTLIER_MIN_LINES && v / ev > LEVEL_HIGH && *share >= OUTLIER_SHARE
        });
    let worst = (n >= window && n_ch > 0).then(|| {
        let mut s: f64 = per_line[..window].iter().sum();
        let (mut best, mut at) = (s, 0);
        for k in window..n {
            s += per_line[k] - per_line[k - window];
            if s > best {
                (best, at) = (s, k + 1 - window);
            }
        }
        (at, at + window - 1, best / (window * n_ch) as f64)
    });
    Whiteness {
        level: v / ev,
        lags,
        q,
        dof,
        q_crit,
        white: q <= q_crit,
        worst,
        outlier,
    }
}

/// The normalized residual `z[ch][k] = (G_d − Ĝ)(ω_k)/σ_k`, `σ = r/√2`, of model `m` on
/// `data`.
pub fn normalized_residual(
    m: &crate::model::physical::PhysicalModel,
    data: &super::channels::Channels,
) -> Vec<Vec<Complex64>> {
    let g: Vec<_> = data.omega.iter().map(|w| m.eval(*w)).collect();
    data.entries
        .iter()
        .enumerate()
        .map(|(ch, e)| {
            (0..data.omega.len())
                .map(|k| (data.g[ch][k] - g[k][*e]) * std::f64::consts::SQRT_2 / data.radius[ch][k])
                .collect()
        })
        .collect()
}

impl Whiteness {
    /// What the residual says, in words, for the stop explanation; `hz(k)` is line `k`'s
    /// frequency in Hz.
    pub fn explain(&self, hz: impl Fn(usize) -> f64) -> String {
        use crate::diagnose::effects::candidates::sig;
        let where_ = |w: &Option<(usize, usize, f64)>| match w {
            Some((a, b, m)) if *m > 2.0 => format!(
                "; it concentrates at {}–{} Hz (V per datum {} there, 1 at the stated noise)",
                sig(hz(*a)),
                sig(hz(*b)),
                sig(*m)
            ),
            _ => String::new(),
        };
        let lb = format!(
            "Ljung–Box Q = {} over {} lags, {} at α = {ALPHA}",
            sig(self.q),
            self.lags,
            if self.white {
                format!("≤ {}", sig(self.q_crit))
            } else {
                format!("> {}", sig(self.q_crit))
            }
        );
        if let Some((k, share)) = self.outlier {
            // Half the spacing to a neighbour each side: the range holds that line alone.
            let d = if k > 0 {
                hz(k) - hz(k - 1)
            } else {
                hz(k + 1) - hz(k)
            };
            let p = (-(d / 4.0).log10()).ceil().max(0.0) as usize;
            return format!(
                "the residual is {}× the stated noise (V/E[V], {lb}), and {} of it is the one line at {} Hz: an outlier there (a spectral line such as mains interference, or a dropout), not scatter — leave that line out (`--exclude {:.p$}:{:.p$}`) or raise its noise radius alone, not std_factor",
                sig(self.level),
                crate::report::fmt::fmt_pct(share),
                sig(hz(k)),
                hz(k) - d / 2.0,
                hz(k) + d / 2.0,
            );
        }
        match (self.white, self.level > LEVEL_HIGH) {
            (true, false) => format!(
                "the residual is white at the stated noise (V/E[V] = {}, {lb}): nothing more to find",
                sig(self.level)
            ),
            (true, true) => format!(
                "the residual is white but {}× the stated noise (V/E[V], {lb}): no structure is left, the data scatter more than the stated σ; std_factor × {} would cover it",
                sig(self.level),
                sig(self.level.sqrt())
            ),
            (false, high) => format!(
                "the residual is not white ({lb}; V/E[V] = {}): structure is left that no admissible effect explains{}{}",
                sig(self.level),
                where_(&self.worst),
                if high {
                    ""
                } else {
                    " (below the stated noise level: the noise may be overstated as well)"
                }
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn quantiles_match_tables() {
        // χ²₂ is exponential: its quantile is −2 ln(1 − p).
        assert!((chi2_even_quantile(1, 0.999) + 2.0 * 1e-3f64.ln()).abs() < 1e-9);
        // Tables (Abramowitz & Stegun 26.8): χ²₂₀(0.999) = 45.315, χ²₆₀(0.999) = 99.607,
        // χ²₁₀(0.95) = 18.307.
        assert!((chi2_even_quantile(10, 0.999) - 45.315).abs() < 1e-3);
        assert!((chi2_even_quantile(30, 0.999) - 99.607).abs() < 1e-3);
        assert!((chi2_even_quantile(5, 0.95) - 18.307).abs() < 1e-3);
        // Large k stays finite (the survival sum in logs).
        let q = chi2_even_quantile(900, 0.999);
        assert!(q > 1800.0 && q < 2100.0, "{q}");
    }

    /// Uniform in the unit disk, scaled to `E|z|² = 1` (the stated noise model).
    fn disk(rng: &mut rand::rngs::StdRng, n: usize) -> Vec<Complex64> {
        (0..n)
            .map(|_| loop {
                let (a, b) = (rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
                if a * a + b * b <= 1.0 {
                    break Complex64::new(a, b) * std::f64::consts::SQRT_2;
                }
            })
            .collect()
    }

    #[test]
    fn white_noise_passes_at_its_false_alarm_rate() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(33);
        let (mut rejected, trials) = (0, 400);
        let mut levels = Vec::new();
        for _ in 0..trials {
            let z = vec![disk(&mut rng, 400), disk(&mut rng, 400)];
            let w = whiteness(&z, 0, 20);
            rejected += usize::from(!w.white);
            levels.push(w.level);
        }
        // α = 1e-3: 0.4 expected; 4 would be a 1-in-1000 event for a right test.
        assert!(rejected <= 3, "{rejected} of {trials}");
        let mean = levels.iter().sum::<f64>() / trials as f64;
        assert!((mean - 1.0).abs() < 0.01, "{mean}");
        // Scale-free: the same noise at 3× its stated σ keeps Q, and the level is 9.
        let z = vec![disk(&mut rng, 400)];
        let a = whiteness(&z, 0, 20);
        let z3: Vec<Vec<Complex64>> = z
            .iter()
            .map(|c| c.iter().map(|x| 3.0 * x).collect())
            .collect();
        let b = whiteness(&z3, 0, 20);
        assert!((a.q - b.q).abs() < 1e-9 * a.q && (b.level / a.level - 9.0).abs() < 1e-9);
        let text = b.explain(|k| k as f64);
        if b.white {
            let want = format!(
                "std_factor × {}",
                crate::diagnose::effects::candidates::sig(b.level.sqrt())
            );
            assert!(text.contains(&want), "{text}");
        }
    }

    #[test]
    fn a_missing_resonance_is_structure_and_is_located() {
        // White noise plus what a missing mode leaves: a Lorentzian bump at line 300 of 400,
        // 4 lines wide, peak 3σ (its level over all lines is only about 1.3).
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut z = disk(&mut rng, 400);
        for (k, x) in z.iter_mut().enumerate() {
            let d = (k as f64 - 300.0) / 4.0;
            *x += Complex64::new(3.0, 0.0) / Complex64::new(1.0, d);
        }
        let w = whiteness(&[z], 0, 10);
        assert!(!w.white, "{w:?}");
        assert!(w.level < LEVEL_HIGH, "{w:?}");
        let (a, b, _) = w.worst.unwrap();
        assert!(a <= 300 && b >= 300, "{w:?}");
        let text = w.explain(|k| 10.0 + k as f64);
        assert!(text.contains("not white") && text.contains("Hz"), "{text}");
    }

    /// One line far off (a mains line in an FRF) on white noise at the stated level: the
    /// residual looks white (a single spike has no lagged products), its level is high, and
    /// the account names the line instead of a `std_factor`; the same noise without the
    /// spike, or with the excess spread over every line, names no outlier.
    #[test]
    fn a_single_line_far_off_is_an_outlier_not_scatter() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(48);
        let base = disk(&mut rng, 300);
        let mut z = base.clone();
        z[140] += Complex64::new(60.0, 0.0);
        let w = whiteness(std::slice::from_ref(&z), 0, 10);
        assert!(w.white && w.level > LEVEL_HIGH, "{w:?}");
        let (k, share) = w.outlier.expect("outlier");
        assert_eq!(k, 140);
        // The share computed here: the line's |z|² over the sum.
        let v: f64 = z.iter().map(|x| x.norm_sqr()).sum();
        assert!(
            (share - z[140].norm_sqr() / v).abs() < 1e-12 && share > 0.9,
            "{share}"
        );
        let text = w.explain(|k| 2500.0 + k as f64);
        assert!(text.contains("one line at 2640 Hz"), "{text}");
        assert!(!text.contains("std_factor ×"), "{text}");
        // The range offered holds that line alone (half a spacing each side).
        assert!(text.contains("`--exclude 2639.5:2640.5`"), "{text}");
        let text = w.explain(|k| 2500.0 + 0.01 * k as f64);
        assert!(text.contains("`--exclude 2501.395:2501.405`"), "{text}");
        assert_eq!(whiteness(std::slice::from_ref(&base), 0, 10).outlier, None);
        let spread: Vec<Complex64> = base.iter().map(|x| 8.0 * x).collect();
        let w = whiteness(&[spread], 0, 10);
        assert!(w.level > LEVEL_HIGH && w.outlier.is_none(), "{w:?}");
    }
}
