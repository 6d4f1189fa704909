//! Issue 38: `--order auto` on 24 random envelopes of the kind users produce (smooth or
//! jagged, 1–6 decades, 20–2000 points, 0–3 Lorentzian bumps; `benches/support/
//! random_envelopes.rs`, fixed seed).  The per-order max `log10 |r|/r_min` of the code before
//! the speed work of issue 38 is stored in `tests/data/fit_sweep_reference.csv`, the per-order
//! ceiling and the sum bound of the rule in `tests/data/fit_sweep_ceiling.csv`; the rule
//! (twelfth step, [`super::fit_sweep_rule`]): (a) no order rises above its ceiling by more than
//! 0.002 decade, (b) the sum of the 216 maxes stays within the stored route's sum plus the
//! spread of that sum under row-order perturbations; every order must stay certified.
//!
//! Heavy (a few minutes in release): `cargo test --release --test fit fit_sweep:: -- --ignored
//! --nocapture`.  It prints LPs and seconds per envelope, the worst rise over the table and
//! over the ceiling, and the sum.  `RSHAPE_SWEEP_WRITE=1` rewrites
//! the reference table instead of checking it (only on the code the table is meant to record);
//! `RSHAPE_SWEEP_CSV=DIR` also writes the 24 envelopes as `DIR/envNN.csv`;
//! `RSHAPE_SWEEP_ONLY=0,4,15` fits only those envelopes (a subset while developing; the sum
//! (b) is then not judged).
//!
//! Measurement switches (issue 38, eleventh step; [`rshape::fit::experiment`], hidden, read
//! here only): `RSHAPE_SWEEP_PERM=reverse` or `=seed:N` hands every LP's rows to Clarabel
//! reversed or in a fixed seeded permutation (the same LPs: the noise floor of the rule);
//! `RSHAPE_SWEEP_FAST=none` or a list of `ws,refine,k30,centre` sets the speedups from
//! the route before them (`none`: `Switches::BASELINE`, the default to the twelfth step;
//! unset: the code's default, `Switches::ROUTE` = `ws,refine,k30` since the thirteenth);
//! `RSHAPE_SWEEP_OUT=FILE` writes this run's table (the reference's format) to `FILE`.

#[path = "../../benches/support/random_envelopes.rs"]
pub(crate) mod random_envelopes;

use super::fit_sweep_rule::{self as rule, MAX_ORDER};
use random_envelopes::{envelope, sweep_specs, to_csv, SWEEP_LEN};
use rshape::fit::{fit_auto, FitSettings};
use std::time::Instant;

const REFERENCE: &str = "tests/data/fit_sweep_reference.csv";

/// The measurement switches from the environment (see the module doc); prints them.
pub(crate) fn apply_switches() {
    use rshape::fit::experiment::{set_switches, switches, RowOrder, Switches};
    let mut sw = switches();
    if let Ok(fast) = std::env::var("RSHAPE_SWEEP_FAST") {
        sw = Switches {
            row_order: sw.row_order,
            ..Switches::BASELINE
        };
        for f in fast.split(',').map(str::trim).filter(|f| !f.is_empty()) {
            match f {
                "none" => {}
                "ws" => sw.keep_working_set = true,
                "refine" => sw.refine_rest_of_level = true,
                "centre" => sw.previous_centre_first = true,
                k if k.starts_with('k') => sw.level_budget = k[1..].parse().expect("kNN"),
                other => panic!("RSHAPE_SWEEP_FAST: unknown {other:?}"),
            }
        }
    }
    if let Ok(p) = std::env::var("RSHAPE_SWEEP_PERM") {
        sw.row_order = match p.as_str() {
            "none" | "" => RowOrder::AsBuilt,
            "reverse" => RowOrder::Reversed,
            s => RowOrder::Seeded(
                s.strip_prefix("seed:")
                    .and_then(|n| n.parse().ok())
                    .expect("RSHAPE_SWEEP_PERM=reverse or seed:N"),
            ),
        };
    }
    set_switches(sw);
    println!("switches: {sw:?}");
}

/// `(envelope, order) → max log10` from the stored table.
pub(crate) fn reference() -> rule::Table {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE);
    rule::parse_table(&std::fs::read_to_string(&path).expect("reference table"))
}

/// The generator is deterministic and within the ranges.
#[test]
fn generator_is_fixed_and_in_range() {
    let a = sweep_specs();
    let b = sweep_specs();
    assert_eq!(a.len(), SWEEP_LEN);
    let (mut smooth, mut jagged, mut bumps) = (0, 0, [0usize; 4]);
    for (s, t) in a.iter().zip(&b) {
        assert_eq!(envelope(s).r_min, envelope(t).r_min);
        assert!((1.0..=6.0).contains(&s.decades), "{}", s.label());
        assert!((20..=2000).contains(&s.points), "{}", s.label());
        assert!(s.bumps.len() <= 3);
        for bump in &s.bumps {
            assert!((1.0..=20.0).contains(&bump.height));
            assert!((0.005..=0.05).contains(&(bump.width / s.decades)));
            assert!(bump.centre > s.lo && bump.centre < s.lo + s.decades);
        }
        let env = envelope(s);
        assert_eq!(env.omega.len(), s.points);
        assert!(env.r_min.iter().all(|r| r.is_finite() && *r > 0.0));
        let span = env.omega[s.points - 1] / env.omega[0];
        assert!((span.log10() - s.decades).abs() < 1e-9);
        if s.jagged {
            jagged += 1;
        } else {
            smooth += 1;
        }
        bumps[s.bumps.len()] += 1;
    }
    // The sweep must exercise both kinds and every bump count, or it tests less than it says.
    assert!(
        smooth >= 4 && jagged >= 4,
        "smooth {smooth}, jagged {jagged}"
    );
    assert!(bumps.iter().all(|&c| c > 0), "bump counts {bumps:?}");
    let table = reference();
    assert!(table.iter().flatten().all(|v| v.is_finite()));
}

#[test]
#[ignore = "heavy: 24 envelopes × orders 0–8 (run with --release)"]
fn sweep_no_order_rises() {
    apply_switches();
    let write = std::env::var("RSHAPE_SWEEP_WRITE").is_ok();
    let csv_dir = std::env::var("RSHAPE_SWEEP_CSV").ok();
    let table = if write { None } else { Some(reference()) };
    let ceiling = if write {
        None
    } else {
        Some(rule::stored_ceiling())
    };
    let mut run = rule::empty();
    let mut out = String::from(
        "# issue 38: max log10 |r|/r_min per order of fit_auto (orders 0-8) on the 24 envelopes\n\
         # of benches/support/random_envelopes.rs, recorded on the code before the speed work\n\
         envelope,order,max_log10,mean_log10,lp_solves\n",
    );
    let (mut lps, mut secs) = (0usize, 0.0);
    let mut failures = Vec::new();
    // `RSHAPE_SWEEP_ONLY=0,4,15` fits only those envelopes (a subset while developing).
    let only: Option<Vec<usize>> = std::env::var("RSHAPE_SWEEP_ONLY")
        .ok()
        .map(|v| v.split(',').filter_map(|k| k.trim().parse().ok()).collect());
    // `RSHAPE_SWEEP_LB=1`: the proven lower bound of every order beside its max (ninth step).
    let mut lb = std::env::var("RSHAPE_SWEEP_LB")
        .is_ok()
        .then(LbTally::default);
    for (k, spec) in sweep_specs().iter().enumerate() {
        if only.as_ref().is_some_and(|o| !o.contains(&k)) {
            continue;
        }
        let env = envelope(spec);
        if let Some(dir) = &csv_dir {
            std::fs::create_dir_all(dir).unwrap();
            std::fs::write(format!("{dir}/env{k:02}.csv"), to_csv(&env)).unwrap();
        }
        let t = Instant::now();
        let (res, rows) = fit_auto(
            &env,
            None,
            &FitSettings::default(),
            MAX_ORDER,
            &Default::default(),
        )
        .expect("fit");
        let dt = t.elapsed().as_secs_f64();
        let n_lp: usize = rows.iter().map(|r| r.lp_solves).sum();
        lps += n_lp;
        secs += dt;
        let maxes: Vec<String> = rows.iter().map(|r| format!("{:.4}", r.max_log10)).collect();
        let per: Vec<String> = rows.iter().map(|r| r.lp_solves.to_string()).collect();
        println!(
            "env {k:2} {:32} {n_lp:5} LPs {dt:7.2} s  max [{}]  LPs [{}]",
            spec.label(),
            maxes.join(" "),
            per.join(" ")
        );
        if let Some(lb) = lb.as_mut() {
            lb.add(k, &env, None, &rows, &res.solver_events);
        }
        for r in &rows {
            if r.status != "ok" {
                failures.push(format!("env {k} order {}: {}", r.order, r.status));
            }
            out.push_str(&format!(
                "{k},{},{:.6},{:.6},{}\n",
                r.order, r.max_log10, r.mean_log10, r.lp_solves
            ));
            run[k][r.order] = r.max_log10;
        }
    }
    println!("total: {lps} LPs, {secs:.1} s");
    if let (Some(t), Some(c)) = (&table, &ceiling) {
        let v = rule::judge(&run, t, c);
        println!(
            "worst rise over the table {:+.5} decade, over the ceiling {:+.5} (rule: +{}); sum of the maxes {} (rule: ≤ {:.4} + {:.4})",
            v.worst_over_table,
            v.worst_over_ceiling,
            rule::RISE,
            v.sum.map_or("- (a subset)".into(), |s| format!("{s:.4}")),
            c.sum_today,
            c.sum_spread
        );
        failures.extend(v.failures);
    }
    if let Some(lb) = &lb {
        lb.report();
    }
    if let Ok(file) = std::env::var("RSHAPE_SWEEP_OUT") {
        std::fs::write(file, &out).unwrap();
    }
    if write && only.is_none() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, out).unwrap();
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The fit's `STALL_LOG10` (src/fit/order.rs): an order that gains less on the order below
/// is a stall.
const STALL_LOG10: f64 = 0.0017;

/// The proven lower bounds of the orders of the sweep (`RSHAPE_SWEEP_LB=1`): per order the gap
/// `max_n − LB_n`, the orders whose bound proves they cannot beat the order below by
/// `STALL_LOG10`, and the LPs those orders cost the fit.
#[derive(Default)]
struct LbTally {
    /// Per order: gaps (decades) of the orders with a bound.
    gaps: Vec<Vec<f64>>,
    /// Orders proved to stall, and the fit's LPs at them.
    stalled: usize,
    stalled_lps: usize,
    /// Orders with no bound, LPs and seconds of the bounds.
    unproved: usize,
    lps: usize,
    secs: f64,
    /// Any order whose certified max is below its bound (must never happen).
    violations: Vec<String>,
    /// Doubtful levels of the polynomial candidate (`LevelNotFeasible` events with a level),
    /// those below the order's proven level, and the orders whose every doubt is below it
    /// (with the fit's LPs at them).
    doubts: usize,
    doubts_below: usize,
    all_below: usize,
    all_below_lps: usize,
}

impl LbTally {
    fn add(
        &mut self,
        k: usize,
        env: &rshape::consistency::Envelope,
        a1: Option<rshape::fit::A1Fn<'_>>,
        rows: &[rshape::fit::OrderRow],
        events: &[rshape::fit::SolverEvent],
    ) {
        let maxes: Vec<f64> = rows.iter().map(|r| r.max_log10).collect();
        let t = Instant::now();
        let b = rshape::fit::proven_lower_bounds(env, a1, &FitSettings::default(), &maxes, 1e-4)
            .expect("bounds");
        self.secs += t.elapsed().as_secs_f64();
        self.gaps
            .resize(self.gaps.len().max(rows.len()), Vec::new());
        let mut line = Vec::new();
        for (n, (r, b)) in rows.iter().zip(&b).enumerate() {
            self.lps += b.lp_solves;
            let Some(lbn) = b.max_log10 else {
                self.unproved += 1;
                line.push(format!("{n}: - ({} LPs)", b.lp_solves));
                continue;
            };
            if lbn > r.max_log10 + 1e-9 {
                self.violations.push(format!(
                    "env {k} order {n}: bound {lbn:.6} above the certified max {:.6}",
                    r.max_log10
                ));
            }
            self.gaps[n].push(r.max_log10 - lbn);
            let level = b.level.expect("a level with the bound");
            let doubts: Vec<f64> = events
                .iter()
                .filter(|e| e.order == n && e.kind == rshape::fit::EventKind::LevelNotFeasible)
                .filter_map(|e| e.stage.split("t=").nth(1)?.trim().parse::<f64>().ok())
                .collect();
            // The events print the level to 4 digits: below means below by more than that.
            let below = doubts.iter().filter(|d| **d < level * (1.0 - 1e-3)).count();
            self.doubts += doubts.len();
            self.doubts_below += below;
            if !doubts.is_empty() && below == doubts.len() {
                self.all_below += 1;
                self.all_below_lps += r.lp_solves;
            }
            let stall = n > 0 && lbn >= rows[n - 1].max_log10 - STALL_LOG10;
            if stall {
                self.stalled += 1;
                self.stalled_lps += r.lp_solves;
            }
            line.push(format!(
                "{n}: {:.4}/{lbn:.4}{}",
                r.max_log10,
                if stall { "*" } else { "" }
            ));
        }
        println!("   bounds (max/LB, * proved stall): {}", line.join(" "));
    }

    fn report(&self) {
        for (n, g) in self.gaps.iter().enumerate() {
            if g.is_empty() {
                continue;
            }
            let mut s = g.clone();
            s.sort_by(f64::total_cmp);
            println!(
                "order {n}: gap max − LB over {} envelopes: median {:.4}, largest {:.4}",
                s.len(),
                s[s.len() / 2],
                s[s.len() - 1]
            );
        }
        println!(
            "bounds: {} LPs, {:.1} s; {} orders proved to stall (the fit spent {} LPs on them); {} orders without a bound",
            self.lps, self.secs, self.stalled, self.stalled_lps, self.unproved
        );
        println!(
            "doubtful levels: {}, below the proven level {}; orders whose every doubt is below it: {} (the fit spent {} LPs on them)",
            self.doubts, self.doubts_below, self.all_below, self.all_below_lps
        );
        assert!(self.violations.is_empty(), "{}", self.violations.join("\n"));
    }
}

/// The figures of the bench cases (LPs and seconds of `fit_auto`, orders 0–8): the
/// smooth 4-decade envelope with two bumps at 2000 and 21 points, and the fit of ISS
/// `stability --fit`.  Prints only; the targets live in `benches/fit.rs`.
#[test]
#[ignore = "timing figures (run with --release --nocapture)"]
fn bench_case_figures() {
    apply_switches();
    let run =
        |name: &str, env: &rshape::consistency::Envelope, a1: Option<rshape::fit::A1Fn<'_>>| {
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
            let per: Vec<String> = rows.iter().map(|r| r.lp_solves.to_string()).collect();
            println!(
                "{name:24} {:5} LPs {dt:7.2} s  order {} max {:.5}  LPs [{}]",
                res.lp_solves,
                res.order,
                res.certificate.max_log10_ratio,
                per.join(" ")
            );
            if std::env::var("RSHAPE_SWEEP_LB").is_ok() {
                let mut lb = LbTally::default();
                lb.add(0, env, a1, &rows, &res.solver_events);
                lb.report();
            }
        };
    for n in [2000, 21] {
        let env = random_envelopes::smooth_bumps(n);
        if let Ok(dir) = std::env::var("RSHAPE_SWEEP_CSV") {
            std::fs::write(format!("{dir}/smooth{n}.csv"), to_csv(&env)).unwrap();
        }
        run(&format!("smooth {n} bumps"), &env, None);
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/iss1r_reduced.toml");
    let config = rshape::Config::load(&path).expect("config");
    let data = rshape::read_frf_csv(config.data.as_ref().expect("data")).expect("data");
    let env = rshape::envelope(&config, &data, &Default::default())
        .expect("envelope")
        .envelope;
    let f = &config.factorization;
    let a1 = |w: f64| f.a1_limit(w);
    run("ISS stability --fit", &env, Some(&a1));
}

/// Envelope 15 of the sweep (`smooth 3.8 dec 307 pts 3 bumps`): the order-1 optimum puts its
/// zero and pole in the band's bottom decade and lowers the max from order 0's 2.0466 to about
/// 1.774 decade at a mean 0.0015 decade higher.  `--objective minimax` promises the max, with the
/// mean as tie-break only: order 1 must reach within 0.001 decade of the proven lower bound of
/// its order (a Farkas certificate of the relaxation, another route than the fit's search).
/// Until issue 38's tenth step the ranking refused any candidate with a higher mean and
/// carried order 0 over (2.0466, 0.27 decade above the bound).
#[test]
fn env15_order1_reaches_its_proven_bound() {
    let env = envelope(&sweep_specs()[15]);
    let set = FitSettings::default();
    let (_, rows) = fit_auto(&env, None, &set, 1, &Default::default()).expect("fit");
    assert!(rows.iter().all(|r| r.status == "ok"), "{rows:?}");
    let maxes: Vec<f64> = rows.iter().map(|r| r.max_log10).collect();
    let b = rshape::fit::proven_lower_bounds(&env, None, &set, &maxes, 1e-4).expect("bounds");
    let lb = b[1].max_log10.expect("an order-1 bound");
    assert!(
        lb <= maxes[1] + 1e-9,
        "bound {lb} above the fit {}",
        maxes[1]
    );
    assert!(
        maxes[1] <= lb + 1e-3,
        "order 1 at {:.4}, proven bound {lb:.4} (order 0: {:.4})",
        maxes[1],
        maxes[0]
    );
    // Order 0 is the closed form log10(max r_min / min r_min): the bound's neighbour is right.
    let hi = env.r_min.iter().copied().fold(0.0, f64::max);
    let lo = env.r_min.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((maxes[0] - (hi / lo).log10()).abs() < 1e-3, "{}", maxes[0]);
}

/// Envelope 15 at order 1 with the events printed (the ninth step's miss: the fit carried
/// order 0 over at 2.0466 decade while an order-1 form reaches 1.7752; 1.7740 since the
/// tenth step).  A probe:
/// `cargo test --release --test fit fit_sweep::env15_order1_events -- --ignored --nocapture`.
#[test]
#[ignore = "a probe: prints the order-1 search of sweep envelope 15"]
fn env15_order1_events() {
    let spec = &sweep_specs()[15];
    let env = envelope(spec);
    println!(
        "{}: {} points, ω {:.4e}…{:.4e}",
        spec.label(),
        env.omega.len(),
        env.omega[0],
        env.omega[env.omega.len() - 1]
    );
    let (res, rows) =
        fit_auto(&env, None, &FitSettings::default(), 1, &Default::default()).expect("fit");
    for r in &rows {
        println!(
            "order {}: max {:.4} LPs {}",
            r.order, r.max_log10, r.lp_solves
        );
    }
    println!("{}", rshape::fit::events_text(&res));
    // The order-1 row is the best certified of its ranked candidates, never above order 0.
    assert!(rows.iter().all(|r| r.status == "ok"), "{rows:?}");
    assert!(rows[1].max_log10 <= rows[0].max_log10 + 1e-9, "{rows:?}");
}
