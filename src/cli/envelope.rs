//! `rshape envelope CONFIG [--data FILE] --out DIR`: writes `DIR/envelope.csv`.

use super::common::{fmt_g, fmt_omegas, InputArgs};
use crate::report::envelope_csv;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `rshape envelope`.
#[derive(Debug, Args)]
pub struct EnvelopeArgs {
    /// Model and data.
    #[command(flatten)]
    pub input: InputArgs,
    /// Output directory (created if needed).
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs `rshape envelope`.
pub fn run(a: &EnvelopeArgs) -> Result<i32> {
    let (_inputs, env) = a.input.envelope()?;
    let path = a.out.join("envelope.csv");
    crate::util::write_atomic(&path, envelope_csv(&env).as_bytes())?;
    println!("{:>14} {:>14} {:>14}", "omega_rad_s", "r_min", "a1_limit");
    for (i, w) in env.omega.iter().enumerate() {
        let a1 = env.a1_limit.as_ref().map_or("-".into(), |a| fmt_g(a[i]));
        println!("{:>14} {:>14} {:>14}", fmt_g(*w), fmt_g(env.r_min[i]), a1);
    }
    let beyond = env.beyond_a1();
    if !beyond.is_empty() {
        println!(
            "warning: r_min reaches the A1 limit at {} datum(s) (omega = {} rad/s): no admissible r explains them; the nominal model must change",
            beyond.len(),
            fmt_omegas(&env.omega, &beyond)
        );
    }
    println!("wrote {}", path.display());
    Ok(0)
}
