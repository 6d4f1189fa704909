//! The text `synthesize` prints: the optimum, the controller, then the proof.

use super::{stab, SynthesisOutcome};
use crate::report::fmt::fmt_g;
use std::fmt::Write as _;

/// The summary the CLI prints: the optimum, the controller, then the proof.
pub fn text(o: &SynthesisOutcome) -> String {
    let mut s = String::new();
    if o.hinf.is_some() {
        // The controller is the H∞ one (next line): Glover–McFarlane gives the reference
        // b_opt only.
        let _ = writeln!(
            s,
            "Glover–McFarlane (reference, not the controller): b_opt = {} (gamma_min = {})",
            fmt_g(o.gm.b_opt),
            fmt_g(o.gm.gamma_min),
        );
    } else {
        let _ = writeln!(
            s,
            "Glover–McFarlane: b_opt = {} (gamma_min = {}), central controller at gamma = {} ({} states)",
            fmt_g(o.gm.b_opt),
            fmt_g(o.gm.gamma_min),
            fmt_g(o.gm.gamma),
            o.gm.k.states()
        );
    }
    if let Some((label, h)) = &o.hinf {
        let _ = writeln!(
            s,
            "H∞ synthesis with the {label} r as weight: gamma_opt = {} (alpha_opt = {}; {} gamma tests, {}), central controller at gamma = {} ({} states), its ||r*T||_inf = {} (alpha {})",
            fmt_g(h.gamma_opt),
            fmt_g(h.alpha_opt),
            h.steps.len(),
            match h.status {
                crate::synthesis::hinf_weighted::IterationStatus::Converged => "converged",
                crate::synthesis::hinf_weighted::IterationStatus::IterationCap => "iteration cap reached",
                crate::synthesis::hinf_weighted::IterationStatus::RiccatiLimited => "Riccati-limited: gamma_opt is the controller's verified level",
                crate::synthesis::hinf_weighted::IterationStatus::AtInfinity => "the optimum is the bound at omega = inf",
            },
            fmt_g(h.gamma),
            h.k.states(),
            fmt_g(h.gamma_achieved),
            fmt_g(h.alpha_achieved)
        );
    }
    if let Some(r) = &o.reduction {
        let _ = writeln!(
            s,
            "reduced by balanced truncation: {} -> {} states (||K - Kr||_inf <= {}); the proof below is of the reduced controller",
            r.from,
            r.to,
            fmt_g(r.error_bound)
        );
    }
    for b in &o.bounds {
        if let Some(a) = b.alpha_opt {
            let _ = writeln!(
                s,
                "{} r{}: best attainable alpha = {}",
                b.label,
                if b.constant { " (constant)" } else { "" },
                if b.constant {
                    format!("b_opt/|r| = {}", fmt_g(a))
                } else {
                    format!("1/gamma_opt = {}", fmt_g(a))
                }
            );
        }
    }
    for n in &o.notes {
        let _ = writeln!(s, "{n}");
    }
    let _ = writeln!(
        s,
        "closed loop: bandwidth (sigma_max(S) = -3 dB) {}, peak sensitivity Ms = {}",
        o.merit.bandwidth.map_or(
            "none (sigma_max(S) never crosses -3 dB on the grid)".to_string(),
            |b| format!("{} rad/s", fmt_g(b))
        ),
        fmt_g(o.merit.peak_sensitivity)
    );
    let _ = writeln!(s, "proof (Theorem 1 on the synthesized controller):");
    s.push_str(&stab::text(&o.stability));
    let _ = writeln!(
        s,
        "{}",
        if o.bounds.is_empty() {
            "no r given: nothing to prove beyond internal stability".to_string()
        } else if o.robust {
            "PROVEN robust for every r given".to_string()
        } else {
            "NOT proven robust for every r given".to_string()
        }
    );
    s
}
