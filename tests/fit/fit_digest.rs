//! Issue 38, profile step (docs/internals-fit-profile.md): a bit-exact digest of `fit_auto` on
//! the bench cases and the 24-envelope sweep, so that a change meant to make the fit
//! cheaper without moving any LP can be checked to leave it the same to the bit.
//!
//! `cargo test --release --test fit fit_digest:: -- --ignored --nocapture` with
//! `RSHAPE_DIGEST_OUT=FILE` writes, per case, the whole [`rshape::fit::FitResult`] (chosen `r`,
//! zeros, poles, gain, certificate, solver events, LP count) and every order's row as JSON
//! (`serde_json` prints every `f64` in its shortest round-trip form, so equal text is equal
//! bits).  `RSHAPE_DIGEST_CASES` picks cases (`2000,21,iss,sweep`; default `2000,21,iss`);
//! `sweep` also writes `FILE.table` in the format of `RSHAPE_SWEEP_OUT`.  Diff two files.

use super::fit_sweep::random_envelopes::{envelope, smooth_bumps, sweep_specs};
use rshape::fit::{fit_auto, FitSettings};
use std::time::Instant;

const MAX_ORDER: usize = 8;

fn digest(
    name: &str,
    env: &rshape::consistency::Envelope,
    a1: Option<rshape::fit::A1Fn<'_>>,
    out: &mut String,
    table: Option<(usize, &mut String)>,
) {
    let t = Instant::now();
    let (res, rows) = fit_auto(
        env,
        a1,
        &FitSettings::default(),
        MAX_ORDER,
        &Default::default(),
    )
    .expect("fit");
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{name:28} {:5} LPs {dt:7.2} s  order {} max {:.5}",
        res.lp_solves, res.order, res.certificate.max_log10_ratio
    );
    out.push_str(&format!("== {name}\n"));
    out.push_str(&serde_json::to_string_pretty(&res).expect("json"));
    out.push('\n');
    out.push_str(&serde_json::to_string_pretty(&rows).expect("json"));
    out.push('\n');
    if let Some((k, t)) = table {
        for r in &rows {
            t.push_str(&format!(
                "{k},{},{:.6},{:.6},{}\n",
                r.order, r.max_log10, r.mean_log10, r.lp_solves
            ));
        }
    }
}

#[test]
#[ignore = "heavy digest for bit-identity checks (run with --release --nocapture)"]
fn bench_and_sweep_digest() {
    super::fit_sweep::apply_switches();
    let cases = std::env::var("RSHAPE_DIGEST_CASES").unwrap_or_else(|_| "2000,21,iss".into());
    let cases: Vec<&str> = cases.split(',').map(str::trim).collect();
    let mut out = String::new();
    let t0 = Instant::now();
    for n in [2000usize, 21] {
        if cases.contains(&n.to_string().as_str()) {
            digest(
                &format!("smooth {n} bumps"),
                &smooth_bumps(n),
                None,
                &mut out,
                None,
            );
        }
    }
    if cases.contains(&"iss") {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/iss1r_reduced.toml");
        let config = rshape::Config::load(&path).expect("config");
        let data = rshape::read_frf_csv(config.data.as_ref().expect("data")).expect("data");
        let env = rshape::envelope(&config, &data, &Default::default())
            .expect("envelope")
            .envelope;
        let f = &config.factorization;
        // How often the fit asks for `σ_min(M̃(jω))`, at how many distinct ω, and the time
        // it takes (the profile's question: what a memo of the A1 limit could save).
        let calls = std::cell::Cell::new(0usize);
        let spent = std::cell::Cell::new(0.0f64);
        let seen = std::cell::RefCell::new(std::collections::HashSet::new());
        let a1 = |w: f64| {
            let t = Instant::now();
            let v = f.a1_limit(w);
            spent.set(spent.get() + t.elapsed().as_secs_f64());
            calls.set(calls.get() + 1);
            seen.borrow_mut().insert(w.to_bits());
            v
        };
        digest("ISS stability --fit", &env, Some(&a1), &mut out, None);
        println!(
            "ISS: A1 limit evaluated {} times at {} distinct frequencies, {:.2} s",
            calls.get(),
            seen.borrow().len(),
            spent.get()
        );
    }
    let mut table = String::from(
        "# issue 38: max log10 |r|/r_min per order of fit_auto (orders 0-8) on the 24 envelopes\n\
         # of benches/support/random_envelopes.rs, recorded on the code before the speed work\n\
         envelope,order,max_log10,mean_log10,lp_solves\n",
    );
    if cases.contains(&"sweep") {
        for (k, spec) in sweep_specs().iter().enumerate() {
            let name = format!("env {k:2} {}", spec.label());
            digest(
                &name,
                &envelope(spec),
                None,
                &mut out,
                Some((k, &mut table)),
            );
        }
    }
    println!("total {:.1} s", t0.elapsed().as_secs_f64());
    if let Ok(file) = std::env::var("RSHAPE_DIGEST_OUT") {
        std::fs::write(&file, &out).unwrap();
        if cases.contains(&"sweep") {
            std::fs::write(format!("{file}.table"), &table).unwrap();
        }
    }
}
