//! `rshape check CONFIG [--r-num a,b,.. --r-den c,d,..]`: exit 0 when consistent, 1 when
//! inconsistent or when `r` is not admissible (A1 fails at some datum), 2 on an error.

use super::common::{fmt_g, fmt_omegas, InputArgs};
use crate::consistency::{check, Verdict};
use crate::system::TransferFunction;
use anyhow::{anyhow, Result};
use clap::Args;

/// Arguments of `rshape check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Model and data.
    #[command(flatten)]
    pub input: InputArgs,
    /// Numerator of r, descending powers of s (overrides the config's [r]).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub r_num: Option<Vec<f64>>,
    /// Denominator of r, descending powers of s.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub r_den: Option<Vec<f64>>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Resolves r from the flags or the config and checks that it is a unit of RH∞.
pub fn resolve_r(
    num: &Option<Vec<f64>>,
    den: &Option<Vec<f64>>,
    config: &crate::model::Config,
) -> Result<TransferFunction> {
    let r = match (num, den) {
        (Some(n), Some(d)) => {
            if n.iter().chain(d).any(|c| !c.is_finite()) || d.iter().all(|c| *c == 0.0) {
                return Err(anyhow!(
                    "--r-num/--r-den: coefficients must be finite and the denominator nonzero"
                ));
            }
            TransferFunction::new(n.clone(), d.clone())
        }
        (None, None) => config.r.clone().ok_or_else(|| {
            anyhow!(
                "{}: no r to check: add an [r] table with num and den, or pass --r-num and --r-den",
                config.path.display()
            )
        })?,
        _ => return Err(anyhow!("give both --r-num and --r-den")),
    };
    if let Some(why) = r.unit_violation() {
        let source = match num {
            Some(_) => "--r-num/--r-den".to_string(),
            None => format!("{}: [r]", config.path.display()),
        };
        return Err(anyhow!(
            "{source}: r = {} is not a unit of RH∞: {why}; give equal degrees and poles and zeros in the open left half-plane",
            r.brief()
        ));
    }
    Ok(r)
}

/// Runs `rshape check`.
pub fn run(a: &CheckArgs) -> Result<i32> {
    let (inputs, env) = a.input.envelope()?;
    let r = resolve_r(&a.r_num, &a.r_den, &inputs.config)?;
    let rep = check(&r, &env);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rep)?);
    } else {
        println!(
            "{:>12} {:>12} {:>12} {:>10} {:>12} {:>4}",
            "omega_rad_s", "|r(jw)|", "r_min", "ratio", "a1_limit", "A1"
        );
        for row in &rep.rows {
            println!(
                "{:>12} {:>12} {:>12} {:>10} {:>12} {:>4}{}",
                fmt_g(row.omega),
                fmt_g(row.r_abs),
                fmt_g(row.r_min),
                fmt_g(row.ratio),
                row.a1_limit.map_or("-".into(), fmt_g),
                if row.a1_ok { "ok" } else { "FAIL" },
                match (row.covers, row.a1_ok) {
                    (true, true) => "",
                    (false, _) => "  <- inconsistent",
                    (true, false) => "  <- not admissible (A1)",
                }
            );
        }
        let list = |v: &[f64]| fmt_omegas(&env.omega, v);
        // Closed-loop configs check the weight V of [v] (Crowder & de Callafon, eq. (2)).
        let w = if inputs.config.closed_loop.is_some() {
            "V"
        } else {
            "r"
        };
        if rep.verdict == Verdict::NotAdmissible && !rep.failing_omegas.is_empty() {
            println!(
                "|{w}| <= r_min at {} of {} data: omega = {}",
                rep.failing_omegas.len(),
                rep.rows.len(),
                list(&rep.failing_omegas)
            );
        }
        if let Some(s) = &inputs.config.scaling {
            println!(
                "scaling: {}: {w} and r_min refer to the scaled plant G_s = D_o·G·D_i",
                s.describe()
            );
        }
        match rep.verdict {
            Verdict::Consistent => {
                println!("consistent: {w} explains all {} data", rep.rows.len())
            }
            Verdict::Inconsistent => println!(
                "inconsistent at {} of {} data: omega = {}",
                rep.failing_omegas.len(),
                rep.rows.len(),
                list(&rep.failing_omegas)
            ),
            Verdict::NotAdmissible => println!(
                "not admissible: A1 fails (|{w}| >= sigma_min(M~)) at {} of {} data: omega = {}; the perturbed family then holds unstable plants and Theorems 2-4 give no verdict: make |{w}| smaller there",
                rep.a1_violations.len(),
                rep.rows.len(),
                list(&rep.a1_violations)
            ),
        }
    }
    Ok(if rep.consistent { 0 } else { 1 })
}
