//! `diagnose --apply K|chosen --write NEW.toml`: the revised config, written as a
//! `[physical]` model a person can read and edit: the applied effect (or the chosen set) with
//! every parameter refit jointly, data paths rewritten relative to the new file, and a
//! header comment that says what was added, why, and how the error changed.  The written
//! file is checked to load before it is written (atomically).

use super::misfit_channels;
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::engine::{apply_candidate, apply_chosen};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::retune::retune_within;
use crate::diagnose::report::Diagnosis;
use crate::error::{Error, Result};
use crate::model::config::RawConfig;
use crate::model::physical::PhysicalModel;
use crate::model::Config;
use crate::report::fmt::fmt_pct;
use std::path::{Path, PathBuf};

/// What `--apply` writes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Apply {
    /// The K-th ranked first-level candidate (1-based).
    Rank(usize),
    /// The chosen effect set.
    Chosen,
}

/// What a revision is made from.
#[derive(Debug, Clone, Copy)]
pub struct Revise<'a> {
    /// The config diagnosed.
    pub config: &'a Config,
    /// Its text as parsed (the revision keeps its other tables).
    pub raw: &'a RawConfig,
    /// The data diagnosed.
    pub data: &'a Channels,
    /// The diagnosis.
    pub diagnosis: &'a Diagnosis,
    /// The configured physical model.
    pub base: &'a PhysicalModel,
    /// What to apply.
    pub what: Apply,
    /// Write a candidate the diagnosis rejected.
    pub force: bool,
}

/// What was written.
#[derive(Debug, Clone)]
pub struct Revision {
    /// The effect (or effect set) added.
    pub label: String,
    /// The `--apply` value as given (`2`, `2 --force`, `chosen`).
    pub flag: String,
}

/// Writes the revised config to `out` (see the module documentation).
pub fn write_revision(r: &Revise<'_>, out: &Path) -> Result<Revision> {
    let Revise {
        config,
        raw,
        data,
        diagnosis: d,
        base,
        what,
        force,
    } = *r;
    // What is written: the label, its parameters, the explanation and the error before.
    let (revised, label, params, explanation, flag, moved) = match what {
        Apply::Rank(k) => {
            // The candidate (already refit jointly when the search got to it), refit once more.
            let applied = apply_candidate(base, d, k, force)?;
            let c = &d.candidates[k - 1];
            (
                retune_within(&applied, base, data, None, false).model,
                c.effect.clone(),
                params_text(&c.params),
                c.explanation.clone(),
                format!("{k}{}", if force { " --force" } else { "" }),
                None,
            )
        }
        Apply::Chosen => {
            let m = apply_chosen(d)?;
            let label = if d.chosen.is_empty() {
                "retune".to_string()
            } else {
                d.chosen.join(" + ")
            };
            // Only the added effects go in the parenthesis (what `history` labels the
            // revision by); the configured parameters the joint refit moved get their own
            // line, matched to their originals by frequency and shape.
            let params = d
                .final_effects
                .iter()
                .map(|e| format!("{}: {}", e.effect, params_text(&e.params)))
                .collect::<Vec<_>>()
                .join("; ");
            let moved = (!d.retuned_in_chosen.changes.is_empty()).then(|| {
                format!(
                    "# Moved by the joint refit (configured parameters): {}\n",
                    d.retuned_in_chosen.summary().replace('\n', " ")
                )
            });
            (
                m,
                label,
                params,
                d.message.clone(),
                "chosen".to_string(),
                moved,
            )
        }
    };
    let (rms_refit, inv_refit) = misfit_channels(&revised, data);
    // The config as written (closed-loop configs keep their [closed_loop], [noise], [v]).
    let mut raw = raw.clone();
    raw.physical = Some(revised);
    raw.model = None;
    // A converted [plant] or [closed_loop] nominal is now the [physical] table.
    raw.plant = None;
    if let Some(cl) = &mut raw.closed_loop {
        (cl.plant, cl.n_hat, cl.d_hat) = (None, None, None);
    }
    raw.name = Some(format!(
        "{} + {}",
        raw.name
            .clone()
            .unwrap_or_else(|| config.path.display().to_string()),
        label
    ));
    let out_dir = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(out_dir).map_err(|source| Error::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let base_dir = config.path.parent().unwrap_or(Path::new("."));
    if let Some(dp) = &raw.data {
        raw.data = Some(rel_to(&base_dir.join(dp), out_dir));
    }
    if let Some(sf) = &raw.noise.std_file {
        raw.noise.std_file = Some(rel_to(&base_dir.join(sf), out_dir));
    }
    if let Some(cf) = &raw.noise.coherence {
        raw.noise.coherence = Some(rel_to(&base_dir.join(cf), out_dir));
    }
    let text = toml::to_string_pretty(&raw).map_err(|e| {
        Error::Invalid(format!(
            "internal: the revised config does not serialize: {e}"
        ))
    })?;
    let header = format!(
        "# Revised by `rshape diagnose {} --apply {flag}`: {label} ({params}), every parameter refit jointly.\n# {}\n# Error on {}: misfit_rms {} -> {}, invalid_fraction {} -> {}.\n",
        config.path.display(),
        explanation.replace('\n', " "),
        data.path.display(),
        sig(d.before.misfit_rms),
        sig(rms_refit),
        fmt_pct(d.before.invalid_fraction),
        fmt_pct(inv_refit),
    );
    let full = format!("{header}{}{text}", moved.unwrap_or_default());
    // The written file must load back.
    crate::model::Config::parse(&full, out)
        .map_err(|e| Error::Invalid(format!("internal: the revised config does not parse: {e}")))?;
    crate::util::write_atomic(out, full.as_bytes())?;
    Ok(Revision { label, flag })
}

/// `name = value` pairs with 4 significant digits.
pub fn params_text(p: &std::collections::BTreeMap<String, f64>) -> String {
    p.iter()
        .map(|(n, v)| format!("{n} = {}", sig(*v)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `target` relative to the folder `from_dir` (both canonicalized), or `target` itself when
/// either does not exist.
fn rel_to(target: &Path, from_dir: &Path) -> PathBuf {
    let (Ok(t), Ok(f)) = (target.canonicalize(), from_dir.canonicalize()) else {
        return target.to_path_buf();
    };
    let tc: Vec<_> = t.components().collect();
    let fc: Vec<_> = f.components().collect();
    let common = tc.iter().zip(&fc).take_while(|(a, b)| a == b).count();
    let mut p = PathBuf::new();
    for _ in common..fc.len() {
        p.push("..");
    }
    for c in &tc[common..] {
        p.push(c);
    }
    p
}
