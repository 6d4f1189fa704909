//! The verdict of `rshape diagnose` in words: the one-paragraph summary of the measures
//! before and after, the note on residual peaks the search's proposals did not reach, and,
//! for a stop, why nothing was added (the refusals, and what the remaining residual is) with
//! its JSON account (`residual`).

use crate::diagnose::effects::candidates::sig;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::report::DiagnoseVerdict;
use crate::report::fmt::fmt_pct;

/// A note for the verdict when the per-peak account ([`crate::diagnose::search::peaks`]) found peaks where one
/// mode fitted at the peak would pass the screen although no candidate of the run was
/// fitted there: the modes the search's proposals did not reach (empty when none).  A peak
/// where the search did refit a mode of its own ([`crate::diagnose::search::peak_modes`],
/// alone or in a group of modes, frequencies `proposed_hz`) is named apart: proposed, not
/// chosen.
pub(crate) fn unreached_modes(
    peaks: &[crate::diagnose::report::Peak],
    proposed_hz: &[f64],
) -> String {
    let mut f: Vec<f64> = Vec::new();
    let mut refit: Vec<f64> = Vec::new();
    for p in peaks {
        if p.fate != crate::diagnose::report::PeakFate::NotProposed {
            continue;
        }
        if let Some(pr) = &p.probe {
            let inside = (p.window_hz[0]..=p.window_hz[1]).contains(&pr.frequency_hz);
            let seen = |v: &[f64]| v.iter().any(|x| (x - pr.frequency_hz).abs() < 1e-3 * x);
            if pr.would_pass && inside && !seen(&f) && !seen(&refit) {
                let was_refit = proposed_hz
                    .iter()
                    .any(|x| (p.window_hz[0]..=p.window_hz[1]).contains(x));
                if was_refit {
                    refit.push(pr.frequency_hz);
                } else {
                    f.push(pr.frequency_hz);
                }
            }
        }
    }
    let list = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.iter().map(|x| sig(*x)).collect::<Vec<_>>().join(", ")
    };
    let mut out = String::new();
    if !f.is_empty() {
        out += &format!(
            "; one mode fitted at a peak of the residual would pass the screen at {} Hz, where the search proposed none (see the peaks)",
            list(&mut f)
        );
    }
    if !refit.is_empty() {
        out += &format!(
            "; at {} Hz the search refit a mode proposed at the residual's peak but did not choose it (see the refusals; another step may add it)",
            list(&mut refit)
        );
    }
    out
}

/// Why nothing was added, for a stop: the effects the likelihood wanted but admissibility
/// refused (with their rules), and what the remaining misfit is
/// ([`crate::diagnose::lsq::whiteness`]): white at the stated noise (nothing more to find),
/// white above it (the data's own scatter exceeds the stated σ: `std_factor × √(V/E V)`
/// would cover it), or structured (missing dynamics, and where).
pub(crate) fn stop_explanation(
    refused: &[(usize, crate::diagnose::admissible::Refusal)],
    white: &crate::diagnose::lsq::whiteness::Whiteness,
    hz: impl Fn(usize) -> f64,
) -> String {
    let mut out = String::new();
    if !refused.is_empty() {
        let names: Vec<String> = refused
            .iter()
            .map(|(_, r)| match r.frequency_hz {
                Some(f) => format!("{} {} Hz ({})", r.effect, sig(f), r.rule.word()),
                None => format!("{} ({})", r.effect, r.rule.word()),
            })
            .collect();
        out += &format!(
            "; passed ΔBIC but refused as not physical: {}",
            names.join(", ")
        );
    }
    if white.level.is_finite() {
        out += "; ";
        out += &white.explain(&hz);
        // The refusal at the outlier line, if one was refused there: the two are one story.
        if let Some((k, _)) = white.outlier {
            let f = hz(k);
            let half = 0.5 * (hz(k + 1) - f).max(f - hz(k.saturating_sub(1)));
            let at = refused
                .iter()
                .filter_map(|(_, r)| r.frequency_hz.map(|x| (x, r)))
                .find(|(x, _)| (x - f).abs() <= half);
            if let Some((x, r)) = at {
                out += &format!(
                    " (the {} at {} Hz refused above sits on that line: {})",
                    r.effect,
                    sig(x),
                    r.rule.word()
                );
            }
        }
    }
    out
}

/// The stop's residual for the JSON (`residual`): the same cases as
/// [`crate::diagnose::lsq::whiteness::Whiteness::explain`] says in words.
pub(crate) fn residual_account(
    w: &crate::diagnose::lsq::whiteness::Whiteness,
    hz: impl Fn(usize) -> f64,
) -> crate::diagnose::report::ResidualAccount {
    let high = w.level > crate::diagnose::lsq::whiteness::LEVEL_HIGH;
    let kind = match (w.outlier, w.white, high) {
        (Some(_), _, _) => "outlier_line",
        (None, true, false) => "white_at_noise",
        (None, true, true) => "scatter_above_noise",
        (None, false, _) => "structured",
    };
    // The explanation names a concentration only where it stands out (V per datum > 2), and
    // not beside an outlier line, which it names instead.
    let at = w
        .worst
        .filter(|(_, _, m)| w.outlier.is_none() && !w.white && *m > 2.0);
    crate::diagnose::report::ResidualAccount {
        level: w.level,
        ljung_box_q: w.q,
        q_critical: w.q_crit,
        lags: w.lags,
        white: w.white,
        kind,
        concentrated_hz: at.map(|(a, b, _)| [hz(a), hz(b)]),
        concentrated_level: at.map(|(_, _, m)| m),
        std_factor_times: (w.outlier.is_none() && w.white && high).then(|| w.level.sqrt()),
        outlier_hz: w.outlier.map(|(k, _)| hz(k)),
        outlier_share: w.outlier.map(|(_, s)| s),
    }
}

/// The one-paragraph summary of a verdict, from the measures of the configured, the retuned
/// and the final model.
pub(crate) fn verdict_message(
    verdict: DiagnoseVerdict,
    [before, retuned, after]: [&Measures; 3],
    moved: &crate::diagnose::changes::Changes,
    chosen_labels: &[String],
) -> String {
    let status = if after.consistent() {
        " (now consistent with the data within the noise)"
    } else {
        " (still not consistent: more is missing)"
    };
    match verdict {
        DiagnoseVerdict::Retuned => format!(
            "the configured model explains the data once its own parameters are refit (retune{}): misfit_rms {} → {}, invalid_fraction {} → {}; nothing added",
            if moved.changes.is_empty() {
                String::new()
            } else {
                format!(": {}", moved.summary())
            },
            sig(before.misfit_rms),
            sig(retuned.misfit_rms),
            fmt_pct(before.invalid_fraction),
            fmt_pct(retuned.invalid_fraction)
        ),
        DiagnoseVerdict::EffectsFound => format!(
            "retune + {}: misfit_rms {} → {} (retune alone {}), invalid_fraction {} → {}{status}",
            chosen_labels.join(" + "),
            sig(before.misfit_rms),
            sig(after.misfit_rms),
            sig(retuned.misfit_rms),
            fmt_pct(before.invalid_fraction),
            fmt_pct(after.invalid_fraction)
        ),
        DiagnoseVerdict::Consistent | DiagnoseVerdict::NoEffectFound => format!(
            "the model does not explain the data even retuned (misfit_rms {} → {}), and no candidate effect passes (ΔBIC > 10, plausible, fewer invalid data, holdout): the missing dynamics are not in the catalogue, or the noise radius is too small",
            sig(before.misfit_rms),
            sig(retuned.misfit_rms)
        ),
    }
}
