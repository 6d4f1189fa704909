//! `rshape envelope CONFIG [--data FILE] --out DIR`: writes `DIR/envelope.csv`.

use super::common::{fmt_g, fmt_omegas, InputArgs};
use crate::report::write_envelope_csv;
use crate::util::AtomicFile;
use anyhow::Result;
use clap::Args;
use std::io::Write;
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
    let inputs: Vec<&std::path::Path> = [Some(a.input.config.as_path()), a.input.data.as_deref()]
        .into_iter()
        .flatten()
        .collect();
    // `--out` is checked before the work: a refusal must not cost the user the envelope.
    let _manifest = super::common::prepare_out(&a.out, &inputs)?;
    let (config, env) = a.input.envelope_only()?;
    let path = a.out.join("envelope.csv");
    let mut file = AtomicFile::create(&path)?;
    write_envelope_csv(&env, file.writer()).map_err(|source| crate::error::Error::Io {
        path: path.clone(),
        source,
    })?;
    file.commit()?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    writeln!(
        out,
        "{:>14} {:>14} {:>14}",
        "omega_rad_s", "r_min", "a1_limit"
    )?;
    for (i, w) in env.omega.iter().enumerate() {
        let a1 = env.a1_limit.as_ref().map_or("-".into(), |a| fmt_g(a[i]));
        writeln!(
            out,
            "{:>14} {:>14} {:>14}",
            fmt_g(*w),
            fmt_g(env.r_min[i]),
            a1
        )?;
    }
    out.flush()?;
    drop(out);
    let beyond = env.beyond_a1();
    if !beyond.is_empty() {
        println!(
            "warning: r_min reaches the A1 limit at {} datum(s) (omega = {}): no admissible r explains them; the nominal model must change",
            beyond.len(),
            fmt_omegas(&env.omega, &beyond)
        );
    }
    if let Some(s) = &config.scaling {
        println!(
            "scaling: {}: r_min and the A1 limit are those of the scaled plant G_s = D_o·G·D_i",
            s.describe()
        );
    }
    println!("wrote {}", path.display());
    Ok(0)
}
