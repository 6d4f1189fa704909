//! The `rshape stability` pipeline: the bounds `r` to test (configured, `r.json`, fitted),
//! the frequency grid, the Theorem 1 test ([`crate::stability::analyze`]), the report text,
//! `stability.svg` and `stability.json`. Usable from Rust code; the CLI only parses and
//! prints.

use crate::error::{Error, Result};
use crate::model::controller::Controller;
use crate::model::{Config, FactorizationKind};
use crate::plot::stability::{stability_svg, StabilityInput};
use crate::report::fmt::fmt_g;
use crate::stability::{analyze_gridded, GridCurve, RobustStability, Verdict};
use crate::system::{logspace, TransferFunction};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(serde::Deserialize)]
struct RFile {
    num: Vec<f64>,
    den: Vec<f64>,
}

/// Reads the `r` of an `r.json` written by `rshape fit` or `rshape run` (keys `num`, `den`).
pub fn read_r_json(path: &Path) -> Result<TransferFunction> {
    let text = crate::util::read_text_file(path)?;
    let r: RFile = serde_json::from_str(&text).map_err(|e| Error::Input {
        path: path.to_path_buf(),
        msg: format!("{e}; expected the r.json of `rshape fit` (keys num, den)"),
    })?;
    if r.num.iter().chain(&r.den).any(|v| !v.is_finite()) || r.den.iter().all(|v| *v == 0.0) {
        return Err(Error::Input {
            path: path.to_path_buf(),
            msg: "num/den must be finite, den non-zero".into(),
        });
    }
    let r = TransferFunction::new(r.num, r.den);
    if let Some(why) = r.unit_violation() {
        return Err(Error::Input {
            path: path.to_path_buf(),
            msg: format!(
                "r = {} is not a unit of RH∞: {why}; Theorem 1 needs a stable, minimum-phase, biproper r (the r.json of `rshape fit` is one)",
                r.brief(),
            ),
        });
    }
    Ok(r)
}

/// The labelled bounds of a config: its `[r]` as `configured` (not for a `[closed_loop]`
/// config, whose `[v]` bounds the dual-Youla perturbation, not the factor perturbation of
/// Theorem 1), then `given` as `fitted`.
pub fn bounds(config: &Config, given: Option<TransferFunction>) -> Vec<(String, TransferFunction)> {
    let mut rs = Vec::new();
    if let Some(r) = config.r.as_ref().filter(|_| config.closed_loop.is_none()) {
        rs.push(("configured".to_string(), r.clone()));
    }
    if let Some(r) = given {
        rs.push(("fitted".to_string(), r));
    }
    rs
}

/// The grid of the figure and of the grid margin: a decade beyond the data's range (the
/// data file given, `data`, else the config's), else two decades beyond the closed-loop
/// poles' magnitudes; 1000 points.
pub fn grid(config: &Config, data: Option<&Path>, poles: &[num_complex::Complex64]) -> Vec<f64> {
    let data_range = data
        .or(config.data.as_deref())
        .and_then(|p| super::envelope::read_data_file(config, p).ok())
        .filter(|d| !d.omega.is_empty())
        .map(|d| (d.omega[0], d.omega[d.omega.len() - 1]));
    let (lo, hi) = match data_range {
        Some((a, b)) if a > 0.0 && b >= a => (a / 10.0, b * 10.0),
        _ => {
            let mags: Vec<f64> = poles
                .iter()
                .map(|z| z.norm())
                .filter(|w| *w > 0.0)
                .collect();
            let lo = mags.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = mags.iter().copied().fold(0.0, f64::max);
            if lo.is_finite() && hi > 0.0 {
                (lo / 100.0, hi * 100.0)
            } else {
                (1e-3, 1e3)
            }
        }
    };
    logspace(lo, hi, 1000)
}

/// What the Theorem 1 test found for one controller.
#[derive(Debug, Clone)]
pub struct StabilityOutcome {
    /// The report (poles, exact norms, one margin row per bound).
    pub report: RobustStability,
    /// The grid curves of the figure.
    pub curve: GridCurve,
    /// Labels of the bounds, in the order of `report.margins`.
    pub labels: Vec<String>,
    /// Whether every bound is proven robust (internally stable, every verdict `Robust`).
    pub robust: bool,
    /// The factorization's kind (for the text).
    pub kind: FactorizationKind,
    /// Whether the config is a `[closed_loop]` one (its `[v]` is not a bound).
    pub closed_loop: bool,
}

/// Checks that `controller` fits the plant (size, well-posed loop) before any output is
/// written, and returns the closed-loop poles (for the grid).
pub fn check_controller(
    config: &Config,
    controller: &Controller,
) -> Result<Vec<num_complex::Complex64>> {
    // The poles alone: the H∞ norms of `analyze` (the dear part on a large model) are
    // computed once, by `run`, not here too.
    crate::stability::closed_loop_poles(&config.factorization, controller)
}

/// Runs the Theorem 1 test of `controller` on the config's factorization for every bound in
/// `rs`, on the grid of [`grid`] (`data` overriding the config's data file).
pub fn run(
    config: &Config,
    controller: &Controller,
    rs: &[(String, TransferFunction)],
    data: Option<&Path>,
) -> Result<StabilityOutcome> {
    run_with_stages(config, controller, rs, data, &|_| ())
}

/// [`run`], telling `stage` what it starts (see [`crate::stability::analyze_with_stages`]).
pub fn run_with_stages(
    config: &Config,
    controller: &Controller,
    rs: &[(String, TransferFunction)],
    data: Option<&Path>,
    stage: &dyn Fn(&str),
) -> Result<StabilityOutcome> {
    // The grid needs the poles only without data: the loop and its poles once, in `analyze`.
    let (report, curve) = analyze_gridded(
        &config.factorization,
        controller,
        rs,
        &|poles| grid(config, data, poles),
        stage,
    )?;
    let robust = report.internally_stable && report.margins.iter().all(|m| m.robust);
    Ok(StabilityOutcome {
        report,
        curve,
        labels: rs.iter().map(|(l, _)| l.clone()).collect(),
        robust,
        kind: config.factorization.kind,
        closed_loop: config.closed_loop.is_some(),
    })
}

/// Longest title of `stability.svg` in characters: one line of the caption at its font size
/// (about 860 of the figure's 960 pixels).
pub const FIGURE_TITLE_CHARS: usize = 92;

/// The title of `stability.svg`: it names the model and the controller (a figure travels
/// without its folder), at most [`FIGURE_TITLE_CHARS`] characters.  The controller's name is
/// never dropped: a long model name is shortened first, in the middle (`…`), keeping at least
/// 16 of its characters; only then is the controller's name shortened in the middle too.
pub fn figure_title(config: &Config, controller: &str) -> String {
    // Whole words out of the middle (`f…998` was unreadable); a single long word is cut in
    // its middle as before.
    fn ellipsize_words(s: &str, n: usize) -> String {
        if s.chars().count() <= n {
            return s.to_string();
        }
        let words: Vec<&str> = s.split(' ').collect();
        for keep in (2..words.len()).rev() {
            let front = keep.div_ceil(2);
            let t = format!(
                "{} … {}",
                words[..front].join(" "),
                words[words.len() - (keep - front)..].join(" ")
            );
            if t.chars().count() <= n {
                return t;
            }
        }
        crate::report::fmt::ellipsize_middle(s, n)
    }
    let name = config
        .raw
        .name
        .clone()
        .unwrap_or_else(|| config.path.display().to_string());
    let prefix = "Theorem 1: 1/σ_max(T) vs |r| — ";
    let fixed = prefix.chars().count() + ", ".chars().count();
    let room = FIGURE_TITLE_CHARS.saturating_sub(fixed);
    let controller_chars = controller.chars().count();
    let name_room = room.saturating_sub(controller_chars).max(16);
    let name = ellipsize_words(&name, name_room);
    let controller = ellipsize_words(controller, room.saturating_sub(name.chars().count()));
    format!("{prefix}{name}, {controller}")
}

/// The lines `stability.svg` carries in its corner: `head` (e.g. the synthesis method and its
/// γ), then per bound `α*`, where it binds and the verdict.
pub fn figure_notes(o: &StabilityOutcome, head: &[String]) -> Vec<String> {
    let mut lines = head.to_vec();
    if !o.report.internally_stable {
        lines.push("NOT internally stable: Theorem 1 condition 1 fails".to_string());
    }
    for m in &o.report.margins {
        let verdict = match m.verdict {
            Verdict::Robust => "PROVEN robust (α* ≥ 1)",
            Verdict::NotRobust => "NOT proven robust (α* < 1)",
            Verdict::Withheld => "verdict withheld (cross-checks disagree)",
        };
        lines.push(format!("{} r: α* = {}: {verdict}", m.label, fmt_g(m.alpha)));
    }
    lines
}

/// Writes `stability.svg` (titled `title`, see [`figure_title`]; `head` lines on the figure
/// before the margins, see [`figure_notes`]) and `stability.json` into `out` (atomically)
/// and returns them.
pub fn write_outputs(
    out: &Path,
    o: &StabilityOutcome,
    title: &str,
    head: &[String],
) -> Result<Vec<PathBuf>> {
    let labelled: Vec<(String, Vec<f64>)> = o
        .labels
        .iter()
        .cloned()
        .zip(o.curve.r.iter().cloned())
        .collect();
    let svg = stability_svg(&StabilityInput {
        title,
        omega: &o.curve.omega,
        inv_t: &o.curve.inv_t,
        r: &labelled,
        binding: &o.report.margins.iter().map(|m| m.omega).collect::<Vec<_>>(),
        notes: &figure_notes(o, head),
    })?;
    let svg_path = out.join("stability.svg");
    crate::util::write_atomic(&svg_path, svg.as_bytes())?;
    let json = serde_json::json!({ "report": &o.report, "grid": &o.curve, "robust": o.robust });
    let json_path = out.join("stability.json");
    let text = serde_json::to_string_pretty(&json)
        .map_err(|e| Error::Invalid(format!("stability.json: {e}")))?;
    crate::util::write_atomic(&json_path, text.as_bytes())?;
    Ok(vec![svg_path, json_path])
}

/// The report as the CLI prints it (answers first: stability, norms, one row per bound,
/// failed cross-checks).
pub fn text(o: &StabilityOutcome) -> String {
    let rep = &o.report;
    let mut s = String::new();
    let n = rep.closed_loop_poles.len();
    if !rep.internally_stable {
        let unstable: Vec<String> = rep
            .closed_loop_poles
            .iter()
            .filter(|z| z.re >= 0.0)
            .map(|z| {
                let sign = if z.im < 0.0 { '-' } else { '+' };
                format!("{}{sign}{}j", fmt_g(z.re), fmt_g(z.im.abs()))
            })
            .collect();
        let _ = writeln!(
            s,
            "NOT internally stable: {} of {n} closed-loop poles in the closed right half-plane: {}",
            unstable.len(),
            unstable.join(", ")
        );
        let _ = writeln!(
            s,
            "Theorem 1 condition 1 fails: K does not stabilize the nominal plant."
        );
        return s;
    }
    if n == 0 {
        let _ = writeln!(
            s,
            "internally stable: no closed-loop poles (a static loop: plant, controller and factors without states)"
        );
    } else {
        let _ = writeln!(
            s,
            "internally stable: {n} closed-loop poles (the loop's and the factors' own), largest real part {}",
            fmt_g(rep.abscissa)
        );
    }
    if let Some(t) = &rep.t_norm {
        let form = match o.kind {
            FactorizationKind::Standard => "T = [K; I](I+GK)^-1 M~^-1",
            FactorizationKind::Special => "T = [JKC; I](M~ + N~JKC)^-1, special factorization",
        };
        let _ = writeln!(
            s,
            "||T||_inf = {} at omega = {} rad/s ({form})",
            fmt_g(t.gamma),
            fmt_g(t.omega)
        );
    }
    if let Some(b) = rep.b_gk {
        let _ = writeln!(
            s,
            "b(G,K) = {} (normalized coprime-factor stability margin)",
            fmt_g(b)
        );
        if rep.normalized {
            if let Some(t) = &rep.t_norm {
                let _ = writeln!(
                    s,
                    "cross-check (normalized factors): 1/||T||_inf = {}, b(G,K) = {}, relative difference {:.1e}",
                    fmt_g(1.0 / t.gamma),
                    fmt_g(b),
                    ((1.0 / t.gamma) - b).abs() / b
                );
            }
        }
    }
    if rep.margins.is_empty() && o.closed_loop {
        let _ = writeln!(s, "no r given: the [v] of a [closed_loop] config is not a factor bound; give --r-json for the Theorem 1 margin");
    } else if rep.margins.is_empty() {
        let _ = writeln!(
            s,
            "no r given: add [r] to the config, --r-json or --fit for the Theorem 1 margin"
        );
    } else {
        let _ = writeln!(
            s,
            "{:<12} {:>12} {:>14} {:>12} {:>8}",
            "r", "alpha*", "binds at w", "alpha grid", "robust"
        );
        for m in &rep.margins {
            let _ = writeln!(
                s,
                "{:<12} {:>12} {:>14} {:>12} {:>8}",
                m.label,
                fmt_g(m.alpha),
                fmt_g(m.omega),
                fmt_g(m.alpha_grid),
                match m.verdict {
                    Verdict::Robust => "yes",
                    Verdict::NotRobust => "NO",
                    Verdict::Withheld => "withheld",
                }
            );
        }
        for m in &rep.margins {
            if let Some(why) = &m.check {
                let _ = writeln!(
                    s,
                    "{}: cross-check failed, {why}{}",
                    m.label,
                    if m.verdict == Verdict::Withheld {
                        ": verdict withheld (not proven robust)"
                    } else {
                        ""
                    }
                );
            }
        }
        // Only a proven gain is a gain: before a "NOT proven robust" the line would read as
        // one (a 1e6 % "gain" of an H∞ controller designed for the fitted r).
        if let [c, f, ..] = rep.margins.as_slice() {
            if f.verdict == Verdict::Robust {
                let _ = writeln!(
                    s,
                    "what the tighter r buys: margin {} -> {} ({:+.1}%)",
                    fmt_g(c.alpha),
                    fmt_g(f.alpha),
                    (f.alpha / c.alpha - 1.0) * 100.0
                );
            }
        }
    }
    s
}

/// The controller of a config's loop: `K` itself, or `K_s = D_i⁻¹·K·D_o⁻¹` when the config
/// has `[scaling]` (its factors are those of `G_s = D_o·G·D_i`; the loop `G_s·K_s` is
/// `D_o·G·K·D_o⁻¹`, so internal stability and the closed-loop poles are those of `G`, `K`).
/// `K` must have the plant's size (checked by [`crate::stability::controller_fits`]).
pub fn scaled_controller(
    config: &Config,
    mut controller: crate::model::Controller,
) -> crate::model::Controller {
    if let Some(s) = &config.scaling {
        controller.k = s.controller(&controller.k);
    }
    controller
}
