//! Regenerates the figures of the documentation, `docs/figures/*.svg`, from the shipped
//! configs, exactly as `rshape run CONFIG --out DIR` draws them:
//!
//! ```sh
//! cargo run --release --example docs_figures              # rewrites docs/figures/
//! cargo run --release --example docs_figures -- OUT_DIR   # writes them elsewhere
//! ```
//!
//! `tests/docs/docs_figures.rs` runs [`regenerate`] into a scratch folder and checks that the
//! committed figures are current.
use rshape::fit::OrderChoice;
use rshape::pipeline::{self, outputs::figures};
use rshape::Config;
use std::path::{Path, PathBuf};

/// The documented figures: per shipped config, the prefix of its figures in `docs/figures/`
/// and which of the figures of `rshape run` the documentation shows.
pub const FIGURES: &[(&str, &str, &[&str])] = &[
    (
        "configs/paper_mimo.toml",
        "paper_mimo",
        &["r_vs_delta", "bode"],
    ),
    ("configs/robot.toml", "robot", &["r_vs_delta", "bode", "mu"]),
    (
        "configs/closed_loop_retuned_noisy.toml",
        "closed_loop",
        &["r_vs_delta", "mu"],
    ),
];

/// Draws the documented figures of the shipped configs into `out` as `PREFIX_FIGURE.svg`;
/// returns the files written.  The configs are read as `configs/…` (the figures name them
/// so), so the working directory must be the repository.
pub fn regenerate(out: &Path) -> Result<Vec<PathBuf>, Box<dyn std::error::Error>> {
    std::fs::create_dir_all(out)?;
    let mut written = Vec::new();
    for (config, prefix, shown) in FIGURES {
        let config = Config::load(Path::new(config))?;
        let data_path = config
            .data
            .clone()
            .ok_or_else(|| format!("{}: no data file", config.path.display()))?;
        let data = pipeline::envelope::load_data(&config, &data_path)?;
        // As `rshape run CONFIG` with its defaults: the noise of the config, order auto.
        let order: OrderChoice = "auto".parse()?;
        let outcome = pipeline::run(&config, &data, order, &pipeline::RunOptions::default())?;
        for (name, svg) in figures(&config, &data, &outcome)? {
            let stem = name.trim_end_matches(".svg");
            if shown.contains(&stem) {
                let path = out.join(format!("{prefix}_{stem}.svg"));
                std::fs::write(&path, svg)?;
                written.push(path);
            }
        }
    }
    Ok(written)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // OUT_DIR is relative to where the command runs; the configs to the repository.
    let here = std::env::current_dir()?;
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| root.join("docs/figures"), |d| here.join(d));
    std::env::set_current_dir(root)?;
    for f in regenerate(&out)? {
        println!("wrote {}", f.display());
    }
    Ok(())
}
