//! The library API of `rshape fit`, as docs/guide/run-check-fit.md shows it (the guide's
//! block is this file, checked by tests/docs/docs_snippets.rs): the paper's MIMO example, its
//! envelope, a fixed-order fit, the automatic order and the whole `rshape fit` job.
use rshape::fit::{fit_auto, fit_unit, run_fit, FitSettings, OrderChoice};
use rshape::{envelope, read_frf_csv, Config, RunOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let config = Config::load(Path::new("configs/paper_mimo.toml"))?;
    let data = read_frf_csv(Path::new("configs/paper_mimo.csv"))?;
    let env = envelope(&config, &data, &RunOptions::default())?.envelope;
    let a1 = |w: f64| config.factorization.a1_limit(w);
    // One order.
    let settings = FitSettings {
        order: 2,
        ..Default::default()
    };
    let fit = fit_unit(&env, Some(&a1), &settings, &Default::default())?;
    println!("order 2: worst |r|/r_min = {}", fit.certificate.worst_ratio);
    // The smallest good order among 0..=8, with the order table.
    let (fit, table) = fit_auto(
        &env,
        Some(&a1),
        &FitSettings::default(),
        8,
        &Default::default(),
    )?;
    println!("auto: order {} of {} tried", fit.order, table.len());
    // The whole job of `rshape fit`: fit, certificate and a report; then the exports
    // (r.json, r.m, r.py, r.jl) into a folder.
    let progress = |p: rshape::fit::FitProgress| eprintln!("fitting order {}", p.order);
    let outcome = run_fit(
        &env,
        Some(&a1),
        &settings,
        OrderChoice::Auto { max: 8 },
        Some(&progress),
    )?;
    print!("{}", outcome.text);
    let out = std::env::temp_dir().join("rshape-library-api");
    for file in rshape::pipeline::write_fit_exports(&outcome, &out, config.scaling.as_ref())? {
        println!("wrote {}", file.display());
    }
    Ok(())
}
