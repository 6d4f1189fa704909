//! The text report of `rshape diagnose`: header, candidates, the path taken, dropped, refused and
//! alternative effects, the peak account and (with `--verbose`) the search phases.

use super::super::common::fmt_g;
use crate::diagnose::{params_text, Channels, DiagnoseVerdict, Diagnosis};
use crate::report::fmt::{fmt_pct, sig};

/// The text report of `diagnose`, section by section.
pub(super) fn print_text(
    config: &crate::model::Config,
    data: &Channels,
    d: &Diagnosis,
    hint_apply: bool,
) {
    print_header(config, data, d);
    if d.verdict == DiagnoseVerdict::Consistent {
        println!("\nverdict: {}: {}", d.verdict, d.message);
        return;
    }
    println!(
        "retune (every configured parameter refit, nothing added): misfit_rms = {}, invalid_fraction = {}",
        fmt_g(d.retuned.misfit_rms),
        fmt_pct(d.retuned.invalid_fraction)
    );
    print_changes(&d.retuned.moved, "the retune moved");
    if let Some(note) = &d.retuned.moved.settled {
        println!("  note: {note}");
    }
    print_candidates(d);
    print_path(d);
    if !d.chosen.is_empty() {
        print_changes(
            &d.retuned_in_chosen,
            "with the chosen set, the joint refit moved",
        );
    }
    print_dropped(d);
    print_refused(d);
    print_alternatives(d);
    print_peaks(d);
    let given_up = match d.search.refits_given_up {
        0 => String::new(),
        k => format!(" ({k} given up, far above their reference)"),
    };
    println!(
        "\nsearch: {} nodes expanded, {} joint refits{given_up}, {} s (beam {})",
        d.search.nodes_expanded,
        d.search.joint_refits,
        sig(d.search.seconds),
        d.search.beam
    );
    println!("verdict: {}: {}", d.verdict, d.message);
    if hint_apply && !d.candidates.is_empty() {
        println!(
            "write the chosen set with: rshape diagnose {} --apply chosen --write NEW.toml (or one candidate that passes: --apply K)",
            config.path.display()
        );
    }
}

/// What was compared (model, data, channels, noise) and the misfit before any change.
fn print_header(config: &crate::model::Config, data: &Channels, d: &Diagnosis) {
    let chans = data
        .entries
        .iter()
        .map(|(o, i)| format!("{},{}", o + 1, i + 1))
        .collect::<Vec<_>>()
        .join(" ");
    println!(
        "model: {}   data: {} (channel{} {chans}; {} frequencies; noise: {})",
        config.path.display(),
        data.path.display(),
        if data.n_ch() > 1 { "s, jointly" } else { "" },
        data.len(),
        data.radius_source.join("; ")
    );
    println!(
        "before: misfit_rms = {}, invalid_fraction = {}",
        fmt_g(d.before.misfit_rms),
        fmt_pct(d.before.invalid_fraction)
    );
}

/// The candidates on the configured model, ranked by ΔBIC, with their parameters.
fn print_candidates(d: &Diagnosis) {
    if d.candidates.is_empty() {
        return;
    }
    println!("\ncandidates on the configured model (ranked by ΔBIC = 2ΔV − n·ln 2F; each with every parameter refit jointly when marked *; pass = ΔBIC > 10 against the retune, plausible, and no more invalid data or a lower misfit_rms):");
    for c in &d.candidates {
        if let Some(why) = &c.no_fit {
            println!("{:>2}. {:<18} no fit: {why}", c.rank, c.effect);
            continue;
        }
        let params = c
            .params
            .iter()
            .map(|(n, v)| match c.uncertainty_2sigma.get(n) {
                Some(u) if u.is_finite() && *u > 0.0 => {
                    format!("{n} = {} ± {}", sig(*v), sig(*u))
                }
                _ => format!("{n} = {}", sig(*v)),
            })
            .collect::<Vec<_>>()
            .join(", ");
        println!(
            "{:>2}. {:<18} ΔBIC {:>10}{}  misfit_rms {} → {}  invalid {} → {}  {}{}",
            c.rank,
            c.effect,
            sig(c.delta_bic),
            if c.joint_refit { "*" } else { " " },
            sig(c.misfit_rms_before),
            sig(c.misfit_rms_after),
            fmt_pct(c.invalid_fraction_before),
            fmt_pct(c.invalid_fraction_after),
            if c.passes { "pass" } else { "-" },
            if c.tie_with_best {
                "  (tie with #1)"
            } else {
                ""
            }
        );
        if !params.is_empty() {
            println!("    {params}");
        }
        for f in &c.flags {
            println!("    flag: {f}");
        }
        println!("    {}", c.explanation);
    }
}

/// The chosen path of the beam search and the effects of the final model.
fn print_path(d: &Diagnosis) {
    if !d.steps.is_empty() {
        println!("\nchosen path (beam search, joint refit of every parameter at each node):");
        for s in &d.steps {
            println!(
                "  step {}: + {} ({}, after the refit) → misfit_rms {}, invalid {} (joint refit of {} parameters; before the refit {}, {})",
                s.step,
                s.effect,
                params_text(&s.params),
                sig(s.misfit_rms),
                fmt_pct(s.invalid_fraction),
                s.n_refit,
                sig(s.misfit_rms_before_refit),
                fmt_pct(s.invalid_fraction_before_refit)
            );
        }
    }
    if !d.final_effects.is_empty() {
        println!("\nchosen effects in the final model (every parameter refit jointly; ± 1σ):");
        for e in &d.final_effects {
            let p = e
                .params
                .iter()
                .map(|(n, v)| match e.sigma.get(n) {
                    Some(u) => format!("{n} = {} ± {}", sig(*v), sig(*u)),
                    None => format!("{n} = {}", sig(*v)),
                })
                .collect::<Vec<_>>()
                .join(", ");
            println!("  {}: {p}", e.effect);
        }
    }
}

/// The holdout verdicts and the effects dropped by the backward elimination or the holdout.
fn print_dropped(d: &Diagnosis) {
    for h in &d.holdout {
        println!(
            "holdout {}: interleaved {}{}",
            h.effect,
            if h.interleaved_ok { "ok" } else { "FAILS" },
            match h.extrapolation_ok {
                Some(true) => ", extrapolation ok",
                Some(false) => ", extrapolation fails",
                None => "",
            }
        );
    }
    if !d.eliminated.is_empty() {
        println!(
            "dropped by the backward elimination (the data do not need them): {}",
            d.eliminated.join(", ")
        );
    }
    if !d.dropped.is_empty() {
        println!("dropped by the holdout: {}", d.dropped.join(", "));
    }
}

/// The effects the likelihood wanted but physical admissibility refused, with the rule and
/// the reason.
fn print_refused(d: &Diagnosis) {
    if d.refused.is_empty() {
        return;
    }
    println!("refused on their joint refit (ΔBIC passed, not physical):");
    for r in &d.refused {
        let at = r
            .refusal
            .frequency_hz
            .map(|f| format!(" {} Hz", sig(f)))
            .unwrap_or_default();
        println!(
            "  step {}: {}{at}: {}: {}",
            r.step,
            r.refusal.effect,
            r.refusal.rule.word(),
            r.refusal.reason
        );
    }
}

/// The runner-up sets and the ties between effects.
fn print_alternatives(d: &Diagnosis) {
    if !d.runner_up.is_empty() {
        println!("\nrunner-up sets (BIC gap to the chosen set):");
        for r in &d.runner_up {
            println!(
                "  {:<40} {}{}  misfit_rms {}, invalid {}{}",
                if r.effects.is_empty() {
                    "(retune only)".to_string()
                } else {
                    r.effects.join(" + ")
                },
                // A runner-up in a tie may have the lower BIC (the prior order chose).
                if r.bic_gap >= 0.0 { "+" } else { "" },
                sig(r.bic_gap),
                sig(r.misfit_rms),
                fmt_pct(r.invalid_fraction),
                if r.consistent { " (consistent)" } else { "" }
            );
        }
    }
    for t in &d.ties {
        println!(
            "\ntie: {} and {} (BIC gap {}): {}",
            t.effects[0],
            t.effects[1],
            sig(t.bic_gap),
            t.disambiguation
        );
    }
}

/// The per-peak account: every peak of the residual and what became of it.
fn print_peaks(d: &Diagnosis) {
    if d.peaks.is_empty() {
        return;
    }
    println!("\npeaks of the residual (|data − model|/r ≥ 3 and at least twice the dip to higher ground; height on the retuned model → the final one):");
    for p in &d.peaks {
        println!(
            "  {:>9} Hz {:>9} → {:<9} {}: {}",
            sig(p.frequency_hz),
            sig(p.height),
            sig(p.height_after),
            p.fate.as_str().replace('_', " "),
            p.reason
        );
    }
    if d.peaks_not_listed > 0 {
        println!("  ({} lower peaks not listed)", d.peaks_not_listed);
    }
}

/// Where the time went (`--verbose`): the wall time of each phase of the search.
pub(super) fn print_phases(s: &crate::diagnose::SearchStats) {
    println!("\ntime per phase (wall clock):");
    println!("  {:<22} {:>9} {:>6} {:>7}", "phase", "s", "runs", "share");
    let total = s.seconds.max(1e-12);
    let mut sum = 0.0;
    for p in &s.phases {
        sum += p.seconds;
        println!(
            "  {:<22} {:>9.3} {:>6} {:>6.1}%",
            p.phase,
            p.seconds,
            p.count,
            100.0 * p.seconds / total
        );
    }
    println!(
        "  {:<22} {:>9.3} {:>6} {:>6.1}%",
        "other (report, σ)",
        (s.seconds - sum).max(0.0),
        "",
        100.0 * (s.seconds - sum).max(0.0) / total
    );
    println!("  {:<22} {:>9.3}", "total", s.seconds);
}

/// The configured parameters a refit moved, as a table (a common gain as one row).
fn print_changes(c: &crate::diagnose::Changes, what: &str) {
    if c.changes.is_empty() {
        return;
    }
    println!("  {what} (by more than 3σ):");
    println!(
        "    {:<28} {:>12} {:>12} {:>10}",
        "parameter", "before", "after", "σ"
    );
    for ch in &c.changes {
        println!(
            "    {:<28} {:>12} {:>12} {:>10}",
            if ch.parameter == "gain" {
                "gain (common factor)".to_string()
            } else {
                ch.parameter.clone()
            },
            sig(ch.before),
            sig(ch.after),
            sig(ch.sigma)
        );
    }
    if let Some(g) = &c.common_gain {
        println!(
            "    gain ×{}: one factor on {}",
            sig(g.factor),
            g.parameters.join(", ")
        );
    }
}
