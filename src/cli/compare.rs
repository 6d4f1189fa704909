//! `rshape compare CONFIG [--data FILE] [--noise-radius X] [--channel OUT,IN] [--svg FILE] [--json]`.

use super::common::{fmt_g, InputArgs};
use crate::diagnose::{bode_overlay, dense_grid, BodeData, ModelCurve};
use crate::diagnose::{compare, prepare, Band, CompareReport, CompareVerdict, PlantModel};
use crate::diagnose::{data_vs_data, AgreementVerdict};
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `rshape compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Model and data.
    #[command(flatten)]
    pub input: InputArgs,
    /// SISO channel of MIMO data, `OUT,IN` (1-based); overrides the config's [channel].
    #[arg(long, value_delimiter = ',')]
    pub channel: Option<Vec<usize>>,
    /// Write the Bode overlay (data with their noise band, model as a line, unwrapped phase)
    /// to this SVG file.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Also test the data against a second experiment (data-vs-data consistency: do the
    /// two noise disks intersect at the common frequencies?); its noise comes from the
    /// config's rules (a `<stem>_std.csv` beside it, a noise_radius column, --noise-radius).
    #[arg(long)]
    pub against: Option<PathBuf>,
    /// Compare (and plot) only the lines with FMIN ≤ f ≤ FMAX (Hz), e.g. `--band 20:120`,
    /// as `diagnose --band`.
    #[arg(long, value_parser = super::diagnose::parse_band, value_name = "FMIN:FMAX", allow_hyphen_values = true)]
    pub band: Option<(f64, f64)>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Parses `--channel`.
pub fn channel_arg(c: &Option<Vec<usize>>) -> Result<Option<(usize, usize)>> {
    match c.as_deref() {
        None => Ok(None),
        Some([o, i]) if *o >= 1 && *i >= 1 => Ok(Some((*o, *i))),
        Some(_) => Err(anyhow!("--channel OUT,IN: two 1-based indices")),
    }
}

/// Loads, prepares and compares; used by `compare` and `history`.
pub fn run_compare(
    input: &InputArgs,
    channel: Option<(usize, usize)>,
    band: Option<(f64, f64)>,
) -> Result<(CompareReport, crate::diagnose::Siso, PlantModel)> {
    let inputs = input.load()?;
    // Closed-loop data: compare the plant recovered from Φ and C̄, with the radii
    // propagated to it (they replace --noise-radius and [noise], which are radii on Φ).
    let inputs = crate::pipeline::closed_loop::discovery_inputs(
        inputs.config,
        inputs.data,
        input.noise_radius,
    )?;
    let noise = inputs.noise_radius;
    let mut siso = prepare(&inputs.config, &inputs.data, channel, noise)?;
    if let Some((lo, hi)) = band {
        // As `diagnose --band`: the lines with FMIN ≤ f ≤ FMAX (Hz), at least two.
        let tau = std::f64::consts::TAU;
        let keep: Vec<usize> = (0..siso.omega.len())
            .filter(|k| {
                let f = siso.omega[*k] / tau;
                f >= lo * (1.0 - 1e-12) && f <= hi * (1.0 + 1e-12)
            })
            .collect();
        if keep.len() < 2 {
            return Err(anyhow!(
                "--band {lo}:{hi}: {} of the data's lines lie in it (the data span {} … {} Hz); at least 2 are needed",
                keep.len(),
                fmt_g(siso.omega.first().copied().unwrap_or(0.0) / tau),
                fmt_g(siso.omega.last().copied().unwrap_or(0.0) / tau)
            ));
        }
        siso.omega = keep.iter().map(|k| siso.omega[*k]).collect();
        siso.g = keep.iter().map(|k| siso.g[*k]).collect();
        siso.radius = siso.radius.map(|r| keep.iter().map(|k| r[*k]).collect());
    }
    let model = PlantModel::from_config(&inputs.config);
    let rep = compare(&inputs.config, &model, &siso)?;
    Ok((rep, siso, model))
}

/// Most bands printed on the terminal; `--json` lists them all.
pub const MAX_BANDS_SHOWN: usize = 3;

/// Formats bands for the text report: all of them up to [`MAX_BANDS_SHOWN`], else the
/// bands with the largest peak misfit (in frequency order) and a count of the others, so
/// that a badly failing model gives a readable line instead of dozens of bands.
pub fn fmt_bands(b: &[Band]) -> String {
    if b.is_empty() {
        return "none".into();
    }
    let one = |b: &Band| {
        format!(
            "{}–{} rad/s ({}–{} Hz, {} data, peak misfit {} at {} Hz)",
            fmt_g(b.omega_lo),
            fmt_g(b.omega_hi),
            fmt_g(b.omega_lo / std::f64::consts::TAU),
            fmt_g(b.omega_hi / std::f64::consts::TAU),
            b.count,
            fmt_g(b.peak_misfit),
            fmt_g(b.omega_peak / std::f64::consts::TAU)
        )
    };
    if b.len() <= MAX_BANDS_SHOWN {
        return b.iter().map(one).collect::<Vec<_>>().join("; ");
    }
    let mut worst: Vec<usize> = (0..b.len()).collect();
    worst.sort_by(|&x, &y| b[y].peak_misfit.total_cmp(&b[x].peak_misfit));
    worst.truncate(MAX_BANDS_SHOWN);
    worst.sort_unstable();
    let shown = worst
        .iter()
        .map(|&k| one(&b[k]))
        .collect::<Vec<_>>()
        .join("; ");
    let rest: usize = (0..b.len())
        .filter(|k| !worst.contains(k))
        .map(|k| b[k].count)
        .sum();
    format!(
        "{} bands, {} data, {}–{} rad/s; the {MAX_BANDS_SHOWN} worst: {shown}; {} more bands ({rest} data) in `--json` (bands)",
        b.len(),
        b.iter().map(|x| x.count).sum::<usize>(),
        fmt_g(b[0].omega_lo),
        fmt_g(b[b.len() - 1].omega_hi),
        b.len() - MAX_BANDS_SHOWN,
    )
}

/// Runs `rshape compare`.
pub fn run(a: &CompareArgs) -> Result<i32> {
    if let Some(svg) = &a.svg {
        let mut inputs = a.input.files();
        if let Some(p) = &a.against {
            inputs.extend(super::common::data_and_siblings(p));
        }
        super::common::check_out_file("--svg", svg, &inputs)?;
    }
    let (mut rep, siso, model) = run_compare(&a.input, channel_arg(&a.channel)?, a.band)?;
    // Everything is read and checked before the figure is written (no figure left behind
    // by a refusal such as a missing --against file).
    let agreement = match &a.against {
        Some(p) => {
            let inputs = a.input.load()?;
            let other = crate::pipeline::envelope::read_data_file(&inputs.config, p)?;
            // In the units of the compared data: the config's [scaling], if any.
            let other = crate::pipeline::envelope::scale_data(&inputs.config, other)?;
            let sb = prepare(
                &inputs.config,
                &other,
                Some(siso.channel),
                a.input.noise_radius,
            )?;
            Some(data_vs_data(&siso, &sb)?)
        }
        None => None,
    };
    if let Some(path) = &a.svg {
        let invalid: Vec<bool> = rep.rows.iter().map(|r| r.invalid).collect();
        // The model is drawn on a dense grid (it can be evaluated anywhere); a frequency
        // where it cannot be evaluated breaks the line.
        let grid = dense_grid(&siso.omega);
        let gm = grid
            .iter()
            .map(|w| {
                model
                    .eval(*w)
                    .map(|g| g[siso.model_entry])
                    .unwrap_or(num_complex::Complex64::new(f64::NAN, f64::NAN))
            })
            .collect();
        bode_overlay(
            path,
            &format!(
                "{} vs {} (channel {},{})",
                rep.config, rep.data, siso.channel.0, siso.channel.1
            ),
            &BodeData {
                omega: &siso.omega,
                g: &siso.g,
                radius: siso.radius.as_deref(),
                invalid: &invalid,
            },
            &[ModelCurve {
                name: "model".into(),
                omega: grid,
                g: gm,
            }],
        )?;
        rep.figure = Some(path.display().to_string());
    }
    if a.json {
        let mut v = serde_json::to_value(&rep)?;
        if let Some(ag) = &agreement {
            v["against"] = serde_json::to_value(ag)?;
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(0);
    }
    println!("model:  {}", rep.config);
    println!(
        "data:   {} (channel {},{}; {} data)",
        rep.data,
        rep.channel[0],
        rep.channel[1],
        rep.rows.len()
    );
    println!("noise:  {}", rep.noise_source);
    println!(
        "misfit_rms = {}   misfit_max = {}   invalid_fraction = {}   r_env_max = {}",
        fmt_g(rep.misfit_rms),
        fmt_g(rep.misfit_max),
        rep.invalid_fraction
            .map_or("-".into(), |f| format!("{:.1} %", 100.0 * f)),
        rep.r_env_max.map_or("-".into(), fmt_g)
    );
    println!("r_env:  {}", rep.r_env_method);
    if let Some(n) = rep.n_unexplainable.filter(|n| *n > 0) {
        println!(
            "r_env:  {n} data have r_min = inf (no admissible |r| explains them; not in r_env_max)"
        );
    }
    println!("fails (noise only):      {}", fmt_bands(&rep.bands));
    match &rep.bands_with_r {
        Some(b) => println!(
            "fails (with the config's r): {} (invalid_fraction {:.1} %; {})",
            fmt_bands(b),
            100.0 * rep.invalid_fraction_with_r.unwrap_or(0.0),
            if rep.with_r_exact {
                "exact: |r| ≤ r_min of Theorem 4"
            } else {
                "conservative noise-free test"
            }
        ),
        None => println!("fails (with the config's r): - (no [r] in the config, or no envelope)"),
    }
    println!(
        "verdict: {}{}",
        rep.verdict,
        match rep.verdict {
            CompareVerdict::Consistent => " (invalid_fraction ≤ 5 % and misfit_rms ≤ 1: the data are explained within the noise)",
            CompareVerdict::Inconsistent => " (run `rshape diagnose` to find the missing effect)",
            CompareVerdict::UnknownNoise => " (no noise radius: give --noise-radius, a noise_radius column or [noise])",
        }
    );
    if let Some(f) = &rep.figure {
        println!("figure: {f}");
    }
    if let Some(ag) = &agreement {
        println!(
            "data vs data: {} against {} at {} common frequencies: distance_rms = {} (|G_a − G_b|/(r_a + r_b)), disagree at {} ({}){}",
            rep.data,
            ag.against,
            ag.n_common,
            fmt_g(ag.distance_rms),
            crate::report::fmt::fmt_pct(ag.disagree_fraction),
            fmt_bands(&ag.bands),
            if ag.verdict == AgreementVerdict::Agree {
                ": the two experiments agree within their noise"
            } else {
                ": the two experiments disagree by more than their noise, so no model can reach the noise on both"
            }
        );
    }
    Ok(0)
}
