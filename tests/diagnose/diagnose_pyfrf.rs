//! Real impact-hammer data (../shared/data/pyfrf-impact, accelerance of a free body, three
//! close modes at 810, 851 and 900 Hz with ζ ≈ 1e-3): discovery step by step.
//!
//! The noise radius comes from the coherence γ² of the H1 estimate over `n` = 5 averages:
//! the random error of `|H1|` is `ε = √(1 − γ²)/(|γ|·√(2n))` (Bendat & Piersol, *Random Data*,
//! Table 9.6), and the radius is 3ε|H| (3σ, as `std_factor = 3` elsewhere).

use num_complex::Complex64;
use rshape::diagnose::cost;
use rshape::diagnose::{diagnose_channels, retune_within, Channels, SearchSettings};
use rshape::diagnose::{Diagnosis, PeakFate};
use rshape::model::physical::{Feedthrough, Gains, PhysicalModel, PoleAtZeroSpec, Quantity};
use std::path::Path;

const TAU: f64 = std::f64::consts::TAU;
/// `../shared/data/pyfrf-impact`, looked up from the repository's folder upwards (a git
/// worktree sits one level deeper than the main checkout).
fn dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .skip(1)
        .map(|a| a.join("shared/data/pyfrf-impact"))
        .find(|p| p.is_dir())
        .expect("../shared/data/pyfrf-impact")
}

fn columns(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.trim().parse().unwrap()).collect())
        .collect()
}

/// The accelerance on `[f_lo, f_hi]` Hz with its noise radius from the coherence.
pub(crate) fn pyfrf(f_lo: f64, f_hi: f64) -> Channels {
    let h = columns(&dir().join("frf_h1.csv"));
    let c = columns(&dir().join("frf_h1_coherence.csv"));
    let (mut omega, mut g, mut radius) = (vec![], vec![], vec![]);
    for (row, coh) in h.iter().zip(&c) {
        assert_eq!(row[0], coh[0]);
        if row[0] < f_lo || row[0] > f_hi {
            continue;
        }
        let gamma2 = coh[1].clamp(1e-6, 1.0 - 1e-9);
        let hv = Complex64::new(row[1], row[2]);
        let eps = ((1.0 - gamma2) / (gamma2 * 2.0 * 5.0)).sqrt();
        omega.push(TAU * row[0]);
        g.push(hv);
        radius.push(3.0 * eps * hv.norm());
    }
    Channels {
        path: dir(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![radius],
        radius_source: vec!["coherence".into()],
    }
}

/// The mass line of the free body (the accelerance's constant), as a displacement-type model.
fn mass_line() -> PhysicalModel {
    PhysicalModel {
        feedthrough: Some(Feedthrough::Scalar(-1.2)),
        ..Default::default()
    }
}

use crate::common::mode_hz as mode;

/// The hand check, independent of the holdout code: with the 900 Hz mode in the
/// model, the 810 Hz mode lowers the held-out cost in every one of the four interleaved
/// splits (fit on 3 of every 4 lines, test on the fourth), and the diagnosis keeps it.
#[test]
fn the_810_hz_mode_lowers_the_held_out_error_in_every_split_and_is_kept() {
    let data = pyfrf(20.0, 1200.0);
    let s = SearchSettings {
        max_effects: 1,
        beam: 3,
        ..Default::default()
    };
    // Step 1 from the mass line: the 900 Hz mode (the largest peak).
    let d1 = diagnose_channels(&mass_line(), &data, &s, &Default::default()).unwrap();
    let with_900 = d1.final_model.clone();
    assert_eq!(with_900.mode.len(), 1, "{}", d1.message);
    let f900 = with_900.mode[0].omega_n / TAU;
    assert!(
        (f900 - 900.0).abs() < 5.0,
        "step 1 added a mode at {f900} Hz"
    );
    // The 810 Hz mode added by hand (residue from the peak height: |G| ≈ ρ/(2ζω²)).
    let mut with_810 = with_900.clone();
    with_810.mode.push(mode(810.0, 1.3e-3, -8.4e6));
    let with_810 = retune_within(&with_810, &with_900, &data, None, true).model;
    let f: Vec<f64> = with_810.mode.iter().map(|m| m.omega_n / TAU).collect();
    assert!(f.iter().any(|x| (x - 810.0).abs() < 3.0), "{f:?}");
    let n = data.len();
    for j in 0..4 {
        let fit: Vec<usize> = (0..n).filter(|k| k % 4 != j).collect();
        let test: Vec<usize> = (0..n).filter(|k| k % 4 == j).collect();
        let held_out = |m: &PhysicalModel| {
            cost(
                &retune_within(m, &with_900, &data, Some(&fit), false).model,
                &data,
                &test,
            )
        };
        let (v_with, v_without) = (held_out(&with_810), held_out(&with_900));
        println!(
            "split {j}: held-out V with 810 Hz {v_with:.4e}, without {v_without:.4e}, ratio {:.1}",
            v_without / v_with
        );
        assert!(
            v_with < 0.5 * v_without,
            "split {j}: {v_with} vs {v_without}"
        );
    }
    // The diagnosis from the model with the 900 Hz mode adds the 810 Hz mode and keeps it.
    let d2 = diagnose_channels(&with_900, &data, &s, &Default::default()).unwrap();
    println!("{}\n{:?}\n{:?}", d2.message, d2.holdout, d2.dropped);
    assert!(d2.dropped.is_empty(), "{:?}", d2.dropped);
    let f: Vec<f64> = d2
        .final_model
        .mode
        .iter()
        .map(|m| m.omega_n / TAU)
        .collect();
    assert!(f.iter().any(|x| (x - 810.0).abs() < 3.0), "{f:?}");
    assert!(f.iter().any(|x| (x - 900.0).abs() < 3.0), "{f:?}");
}

/// The free body as an accelerance: the mass line is a rigid body `c/(m s²)` times `s²`.
fn accelerance_mass_line() -> PhysicalModel {
    PhysicalModel {
        quantity: Quantity::Acceleration,
        rigid_body: vec![PoleAtZeroSpec {
            name: None,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(-1.2),
            friction_pole: None,
        }],
        ..Default::default()
    }
}

/// One `diagnose` per step, its chosen set applied (`--apply chosen`), until nothing passes.
fn walk(data: &Channels, max_steps: usize) -> Vec<Diagnosis> {
    let mut m = accelerance_mass_line();
    let mut out = Vec::new();
    for _ in 0..max_steps {
        let t = std::time::Instant::now();
        let s = SearchSettings {
            max_effects: 1,
            beam: 3,
            ..Default::default()
        };
        let d = diagnose_channels(&m, data, &s, &Default::default()).unwrap();
        let modes: Vec<String> = d
            .final_model
            .mode
            .iter()
            .map(|x| format!("{:.1} Hz (ζ {:.2e})", x.omega_n / TAU, x.zeta))
            .collect();
        println!(
            "step {} ({:.1} s): {}\n  modes {modes:?}, dropped by the holdout {:?}",
            out.len() + 1,
            t.elapsed().as_secs_f64(),
            d.message,
            d.dropped
        );
        let done = d.chosen.is_empty();
        if !done {
            m = d.final_model.clone();
        }
        out.push(d);
        if done {
            break;
        }
    }
    out
}

fn has_mode(m: &PhysicalModel, f_hz: f64, tol_hz: f64) -> bool {
    m.mode
        .iter()
        .any(|x| (x.omega_n / TAU - f_hz).abs() < tol_hz)
}

/// docs/guide/discovery-walkthrough.md, section 6: on 20–1200 Hz, as an accelerance, the
/// three close modes (810, 851, 900 Hz, ζ ≈ 1e-3) in three steps, `misfit_rms` falling at
/// every step; the invalid fraction falls over the walk and at steps 2 and 3 (step 1 raises
/// it: the one mass-line constant is shared by the bands below and above the cluster, see
/// the guide).  Step 4: the chosen set (a fourth mode at 824 Hz) fails the holdout, and the
/// next-best set that passes it is taken instead of "nothing passes": the upper residual
/// (a feedthrough of the displacement model, `D s²` on the accelerance: the modes above
/// 1200 Hz), no fourth mode, both measures falling.
#[test]
fn pyfrf_accelerance_walk_finds_the_three_close_modes() {
    let data = pyfrf(20.0, 1200.0);
    let steps = walk(&data, 4);
    assert_eq!(steps.len(), 4, "four applied steps");
    let last = &steps[2].final_model;
    for f in [810.0, 851.0, 900.0] {
        assert!(has_mode(last, f, 2.0), "no mode at {f} Hz: {:?}", last.mode);
    }
    assert_eq!(last.mode.len(), 3);
    for m in &last.mode {
        assert!((5e-4..3e-3).contains(&m.zeta), "ζ = {}", m.zeta);
    }
    for (k, d) in steps[..3].iter().enumerate() {
        assert_eq!(d.chosen, ["mode"], "step {}", k + 1);
        assert!(
            d.after.misfit_rms < 0.5 * d.before.misfit_rms,
            "step {}: {:?} -> {:?}",
            k + 1,
            d.before,
            d.after
        );
        if k > 0 {
            assert!(
                d.after.invalid_fraction < d.before.invalid_fraction,
                "step {}",
                k + 1
            );
        }
    }
    assert!(steps[2].after.invalid_fraction < 0.65 * steps[0].before.invalid_fraction);
    // Step 4: the 824 Hz mode is dropped by the holdout, and the upper residual (misfit_rms
    // 5.994 -> 5.954, 0.66 %) and friction (0.11 %) pass ΔBIC but are refused as negligible
    // on their joint refit (issue 33): nothing is added, and the stop names them.
    let d4 = &steps[3];
    assert_eq!(d4.dropped, ["mode"], "{}", d4.message);
    assert!(d4.chosen.is_empty(), "{}", d4.message);
    assert!(
        d4.refused.iter().any(|r| r.refusal.effect == "feedthrough"
            && r.refusal.rule == rshape::diagnose::admissible::Rule::Negligible),
        "{:?}",
        d4.refused
    );
    assert!(
        d4.message
            .contains("refused as not physical: feedthrough (negligible)"),
        "{}",
        d4.message
    );
    assert_eq!(d4.final_model.mode.len(), 3);
    // The per-peak account calls a peak explained only where the final model brought it
    // down to half or into the noise (a broad window around an added mode once said
    // "explained" of a residual that grew, 26.7 -> 28.8 at 831 Hz).
    let mut added_not_down = 0;
    for d in &steps {
        for p in &d.peaks {
            let down = p.height_after <= 0.5 * p.height || p.height_after < 3.0;
            assert!(
                down || !p.reason.starts_with("explained") && !p.reason.starts_with("lowered"),
                "{p:?}"
            );
            if matches!(p.fate, PeakFate::Added) && !down {
                assert!(p.reason.contains("not that mode's alone"), "{p:?}");
                added_not_down += 1;
            }
        }
    }
    eprintln!("peaks in the window of an added mode but not brought down: {added_not_down}");
    // The 1/s term on an accelerance is flagged as implausible, never applied.
    for d in &steps {
        for c in d.candidates.iter().filter(|c| c.effect == "integrator") {
            if c.params.get("order") == Some(&1.0) {
                assert!(!c.passes && c.flags.iter().any(|f| f.contains("accelerance")));
            }
        }
    }
}

/// The whole band, 20–5000 Hz (ten steps, about 60 s in release on a loaded 2-core machine):
/// the modes found (900, 3665, 3669, 3689, 4126, 810, 4391, 2640, 851 Hz among them), nothing
/// at a band edge, and every mode the issue lists (810, 851, 900, 2640, 3035, 3670,
/// 4130/4160, 4390 Hz) either in the final model or named in the last step's per-peak
/// account with its fate and a reason (docs/guide/discovery-walkthrough.md, section 6).
///
/// Around 3670 Hz the data hold three modes (`tests/data/ema_reference/pyfrf_3665_local.py`,
/// a local fit independent of rshape): a sharp one at 3668.9 Hz, one at 3689.3 Hz and a
/// broader, weaker one at 3665.1 Hz (ζ 8.7e-4, the shoulder of the 3669 Hz peak; its residue
/// has its neighbour's sign, V 36,944 → 17,590 with it).  Fails today (traced, release, this
/// branch): step 2 adds 3669.6 Hz (ζ 1.8e-4); step 3's joint refit moves it to the
/// single-mode compromise 3663.8 Hz (ζ 7.6e-4; a single mode's least-squares optimum there
/// is 3664.7 Hz, ζ 6.6e-4); step 8 adds 3668.6 Hz and its joint refit moves the compromise
/// mode on to the unexplained 3689 Hz peak; the walk ends (ten steps) with 3668.5 and
/// 3689.2 Hz (ζ 3.98e-4 and 3.09e-4) and the 3665 Hz mode missing.  Why (measured on the
/// tenth step's model, issue 33 disc33y): the mode is **never proposed, and would be refused
/// if it were**.
/// * Never proposed: the residual keeps a shoulder peak, 28.6 noise units at 3666 Hz (27.2
///   at 3667, falling to 20.0 at the 3669 Hz line), but a residual peak's window is at least
///   ±0.3 % (`peaks::MIN_WINDOW_REL`, ±11 Hz here) and a peak whose window holds a mode of
///   the model is skipped as "what is left of its fit" (`peak_modes`, the guard against
///   cancelling pairs); no mode candidate, refusal or peak line falls in 3640–3710 Hz at
///   steps 9 and 10.  No admissibility rule is involved up to here.
/// * Proposed by hand (a mode at 3665.1 Hz, ζ 8.7e-4, written into that model and refit
///   jointly): it refits to 3664.4 Hz (ζ 7.3e-4, residue +0.50) and its neighbour returns
///   to 3668.94 Hz (ζ 2.02e-4, residue +1.23) — the three-mode local fit above (3665.1 Hz,
///   8.7e-4, +0.60; 3668.94 Hz, 2.02e-4, +1.20) — with ΔBIC 46,639; but the admissibility
///   rule "negligible" refuses it: misfit_rms 16.15 → 16.08 (0.45 % < 1 %) over the whole
///   20–5000 Hz band, where the modes still missing elsewhere dominate misfit_rms.
///
/// So the loss is the two rules together, both as issue 33 specifies them; lifting it needs
/// a peak rule that tells a shoulder from a mode's own residue (a window of the mode's
/// half-power band, not 0.3 %) and a size rule judged where the mode acts rather than on
/// the whole band's misfit_rms — not changed here (the acceptance suite is built on them).
/// A longer walk (14 steps, measured once, session 10) does not find it either: steps 11–14
/// add 4163, 851 and 3035 Hz and a delay.
///
/// Both rules changed, tried and not landed (disc33z, commit 7c5193a, reverted by e29aab9):
/// (1) a mode's "negligible" size judged on `misfit_rms` over the lines within
/// `max(5·2ζω_n, 3 lines)` of it, against the parent model; (2) a residual peak whose window
/// holds a mode of the model proposed anyway when it reaches 10 noise units, fitted from the
/// window's highest line outside that mode's half-power band, kept when the fit lands
/// outside it, screened on its local ΔBIC.  Measured (release, this test): the peak the
/// residual locates is at the 3669 Hz line itself (16.4 noise units at step 9, 18.7 at step
/// 10; the 28.6 at 3666 Hz is `e`, not the locating `s`), so a rule "peak line outside the
/// mode's half-power band" alone proposes nothing; started at 3665 Hz the lone mode fits to
/// 3662.5–3662.6 Hz (local ΔBIC 40,700–52,000, whole-band ΔBIC −103,000 to −134,000: on top
/// of a neighbour whose broadened damping absorbed it, the lone fit is no measure); its joint
/// refit is then an admissible child at steps 9 and 10 (joint ΔBIC 42,652 and 44,585, no
/// refusal), but each one-effect step chooses a larger child (3008.7 Hz at step 10, 4163 Hz
/// at step 11) and at step 11 the lone fit from 3666 Hz slides to 3636.5 Hz (ζ 6.0e-3, out
/// of the window): the walk still ends, at 10, 11 and 14 steps, without 3664 Hz (steps 11–14
/// add 4163, 851 and 3035 Hz and a delay, as without the rules).  The local
/// size rule also refused a joint refit at step 9 whose moved neighbour (3668.5 Hz) changed
/// the local `misfit_rms` by 0.81 %, and makes the 1e-16-residue mode of
/// `admissible::tests::a_mode_the_covariance_does_not_determine_is_not_identified`
/// negligible before the covariance rule is reached.  The release discovery suites were
/// not run on it.
///
/// Measured after the kept set's admissibility re-check (disc33w, release, this data):
/// * The ten one-effect steps end as before (the step lines and the final modes above, to
///   the digits printed), and the test's list fails on **851 Hz too**: no mode within 3 Hz
///   of it at step 10 (the 14-step walk adds it at step 12).  The assertion stops at
///   3664 Hz because it is listed first.  A shoulder rule alone cannot make this test pass
///   within ten one-effect steps: two of the ten would have to go to 3664 and 851 Hz instead
///   of the feedthrough (step 6), 4694 Hz (ζ 0.021, step 9) or 3008.7 Hz (step 10).
/// * "When a step's largest child is refused, take the best admissible child" is what the
///   beam already does: a refused child is no node, and the set chosen is the best node
///   (`search::beam`).  The shoulder was admissible only with 7c5193a's local size rule, and
///   then never the best; a two-mode proposal {shoulder, neighbour refit} is that same
///   child (every child refits the neighbour jointly), so neither was built again.
/// * At the default `max_effects` (3, groups of modes, `SearchSettings::default()`, a walk
///   from the same mass line until nothing is chosen): nine steps, the last adds nothing.
///   851.4 Hz comes at step 3, but not the shoulder: step 1 writes the single-mode
///   compromise 3663.8 Hz, step 3's refit replaces it by 3668.6 and 3689.2 Hz (the holdout
///   drops two modes of that step's group), and it never returns; the walk ends with 19
///   modes, among them 5000.0 Hz (the band top) and a residual term at 5250 Hz.  At its
///   step 4 the re-check refused a mode of the reduced set: 2640.2 Hz as mains (44 × 60 Hz,
///   its half-power half-width ζf 0.70 Hz narrower than the 1 Hz lines, 0.195 Hz from the
///   harmonic).  The issue lists a mode there; the search had it only as a mode that
///   reached it in a joint refit (the one-effect walk: the mode added at 3007.6 Hz is read at
///   2640.2 Hz after step 8's refit, whose rules judged the new mode, read at 3668.6 Hz); no
///   rule re-checked it before; step 5 adds it back.  The mains rule
///   counts every harmonic: at the 44th, ±0.7 Hz of one of the 50 or 60 Hz harmonics covers
///   about 5 % of the band.  Since disc33z the rule asks the data: a line-narrow mode at a
///   harmonic is refused only when the lines outside the resolution do not support it, or at
///   a harmonic low enough to stay on its line (`admissible::mains`); 2640.2 Hz shows its
///   skirts and is kept (`pyfrf_whole_band_keeps_2640_hz_once_found`).
#[test]
#[ignore = "the whole band, ten steps: about 60 s in release; fails today: no mode within 3 Hz of 3664 Hz — the data hold three modes there (3665.1, 3668.9, 3689.3 Hz, pyfrf_3665_local.py), the walk ends with 3668.5 and 3689.2 Hz; the 3665 Hz shoulder is never proposed (its peak lies within the 0.3 % window of the 3668.5 Hz mode) and, forced in, is refused as negligible (misfit_rms −0.45 % over the whole band, ΔBIC 46,639); with a local size rule and shoulder proposals (7c5193a, not landed) it is an admissible child at steps 9–10 but never the largest; none at 851 Hz either at ten one-effect steps (step 12 adds it)"]
fn pyfrf_accelerance_whole_band() {
    let data = pyfrf(20.0, 5000.0);
    let steps = walk(&data, 10);
    let last_step = steps.last().unwrap();
    let last = &last_step.final_model;
    for f in [
        900.0, 3664.0, 3668.9, 3689.3, 4126.0, 810.0, 851.0, 2640.0, 4391.0,
    ] {
        assert!(has_mode(last, f, 3.0), "no mode at {f} Hz: {:?}", last.mode);
    }
    let w_max = TAU * 5000.0;
    for d in &steps {
        assert!(
            d.final_model.mode.iter().all(|m| m.omega_n < 0.99 * w_max),
            "a mode at the band edge: {:?}",
            d.final_model.mode
        );
        assert!(d.after.misfit_rms < d.before.misfit_rms || d.chosen.is_empty());
    }
    println!("per-peak account of the last step:");
    for p in &last_step.peaks {
        println!(
            "  {:8.1} Hz  {:9.3} -> {:9.3}  {}: {}",
            p.frequency_hz,
            p.height,
            p.height_after,
            p.fate.as_str(),
            p.reason
        );
    }
    // Every listed mode: found (a mode of the final model within 0.3 %), or a peak of the
    // last account within 1 % with a fate other than "explained by a mode" and a reason.
    for f in [
        810.0, 851.0, 900.0, 2640.0, 3035.0, 3670.0, 4130.0, 4160.0, 4390.0,
    ] {
        if has_mode(last, f, 3e-3 * f) {
            continue;
        }
        let p = last_step
            .peaks
            .iter()
            .filter(|p| (p.frequency_hz - f).abs() < 0.01 * f)
            .min_by(|a, b| {
                (a.frequency_hz - f)
                    .abs()
                    .total_cmp(&(b.frequency_hz - f).abs())
            });
        let p = p.unwrap_or_else(|| panic!("{f} Hz: neither found nor in the peak account"));
        assert!(
            !matches!(p.fate, PeakFate::Added | PeakFate::Modelled) && p.reason.len() > 20,
            "{f} Hz: {p:?}"
        );
        // An unexplained peak carries the probe: one mode fitted there on the final model.
        if matches!(p.fate, PeakFate::Rejected | PeakFate::NotProposed) {
            assert!(p.probe.is_some(), "{f} Hz: {p:?}");
        }
    }
}

/// Issue 33 (disc33z): the whole band walked at the default settings from the mass line
/// (as measured before under `pyfrf_accelerance_whole_band`: nine steps, and at step 4 the
/// re-check refused the mode at 2640.2 Hz as mains, 44 × 60 Hz, step 5 added it back).  The
/// data show its skirts (|H| 160, 319, 229, 123 at 2639–2642 Hz, radii 1.7–2.8; three lines
/// below, at 2637 Hz, still 68 against about 25 away from the peak): no mains refusal within 1 Hz of 2640 Hz at
/// any step, and once the walk has the mode it keeps it.
///
/// Measured (release, disc33z, `cargo test --release --test diagnose -- --ignored
/// --show-output pyfrf_whole_band_keeps`): step 1 (12 s) refits a mode proposed at 2640 Hz
/// but chooses a larger set; step 2 adds it (2640.2 Hz, ζ 2.66e-4) and steps 3–9 keep it;
/// no mains refusal at any step; step 9 chooses nothing (misfit_rms 97.1 → 6.11 over the
/// eight applied steps; steps take 12–58 s, 208 s in all).  The one-effect walk
/// (`pyfrf_accelerance_whole_band`) ends with it too (16588.8 rad/s, ζ 2.66e-4).
#[test]
#[ignore = "the whole band at the default settings, nine steps: about 3.5 min in release"]
fn pyfrf_whole_band_keeps_2640_hz_once_found() {
    let data = pyfrf(20.0, 5000.0);
    let mut m = accelerance_mass_line();
    let mut first = None;
    for step in 1..=9 {
        let t = std::time::Instant::now();
        let d =
            diagnose_channels(&m, &data, &SearchSettings::default(), &Default::default()).unwrap();
        let has = has_mode(&d.final_model, 2640.2, 1.0);
        println!(
            "step {step} ({:.1} s): {}\n  2640 Hz in the model: {has}; refused: {:?}",
            t.elapsed().as_secs_f64(),
            d.message,
            d.refused
                .iter()
                .map(|r| (
                    r.step,
                    r.refusal.rule,
                    r.refusal.frequency_hz,
                    r.in_kept_set
                ))
                .collect::<Vec<_>>()
        );
        let mains: Vec<_> = d
            .refused
            .iter()
            .filter(|r| {
                r.refusal.rule == rshape::diagnose::admissible::Rule::Mains
                    && r.refusal
                        .frequency_hz
                        .is_some_and(|f| (f - 2640.2).abs() < 1.0)
            })
            .collect();
        assert!(mains.is_empty(), "step {step}: {mains:?}");
        if has {
            first.get_or_insert(step);
        } else {
            assert!(
                first.is_none(),
                "2640 Hz found at step {first:?}, lost at {step}"
            );
        }
        if d.chosen.is_empty() {
            break;
        }
        m = d.final_model.clone();
    }
    assert!(first.is_some(), "no mode at 2640.2 Hz");
}

/// The shipped config `configs/pyfrf_rigid.toml` (`[noise] coherence`, `averages = 5`,
/// `coverage = 3` on the 20–1200 Hz copy of the data) gives the radii this file computes by
/// hand from ../shared's full-band files: the same frequencies, the same `3ε|H|`.
#[test]
fn the_shipped_config_noise_is_the_coherence_radius() {
    let cfg_path = Path::new("configs/pyfrf_rigid.toml");
    let cfg = rshape::model::Config::load(cfg_path).unwrap();
    let data = rshape::data::read_frf_csv(cfg.data.as_ref().unwrap()).unwrap();
    let r = rshape::model::resolve_noise(None, Some(&cfg), &data)
        .unwrap()
        .unwrap();
    assert_eq!(r.source, rshape::model::NoiseSource::ConfigCoherence);
    let hand = pyfrf(20.0, 1200.0);
    assert_eq!(data.omega.len(), hand.omega.len());
    for (k, (a, b)) in r.radii.iter().zip(&hand.radius[0]).enumerate() {
        assert!((data.omega[k] - hand.omega[k]).abs() < 1e-9 * hand.omega[k]);
        assert!((a - b).abs() <= 1e-12 * b, "line {k}: {a} vs {b}");
    }
}

/// Issue 20, acceptance: step 1 of the 20–1200 Hz walk raises the invalid fraction against
/// the configured model (87.8 % → 95.7 %).  What the evidence shows:
/// * the rise is the retune's: the configured mass line refit alone goes to 100 % invalid,
///   and the mode lowers both measures against that retuned model;
/// * the step-1 model class (the mass line `c` and one mode at the fitted ω_n, ζ, residue by
///   weighted linear least squares: a closed form here, independent of the library's fit)
///   does hold models with both measures below the configured model's (`c` ≈ −1.19), but
///   their cost `V` is far above the least-squares one (ΔV in the thousands, where a 95 %
///   confidence region spans a few units): no fit of the stated noise model picks them;
///   only a loss that counts invalid data (or a heavy-tailed one) would.
#[test]
fn step_1_raises_the_invalid_fraction_only_against_the_configured_model() {
    let data = pyfrf(20.0, 1200.0);
    let s = SearchSettings {
        max_effects: 1,
        beam: 3,
        ..Default::default()
    };
    let d1 = diagnose_channels(&accelerance_mass_line(), &data, &s, &Default::default()).unwrap();
    let m1 = &d1.final_model.mode[0];
    let (wn, z) = (m1.omega_n, m1.zeta);
    let (rms0, inv0) = (d1.before.misfit_rms, d1.before.invalid_fraction);
    // The retune alone raises the invalid fraction; the mode then lowers both measures.
    assert!(d1.retuned.invalid_fraction > inv0, "{:?}", d1.retuned);
    assert!(d1.after.invalid_fraction < d1.retuned.invalid_fraction);
    assert!(d1.after.misfit_rms < d1.retuned.misfit_rms);
    let g = &data.g[0];
    let r = &data.radius[0];
    let psi = |w: f64| {
        let s = Complex64::new(0.0, w);
        s * s / (s * s + 2.0 * z * wn * s + wn * wn)
    };
    // (V, misfit_rms, invalid_fraction) of the class at mass line c, residue by weighted LS.
    let at = |c: f64| {
        let (mut a, mut b) = (0.0, 0.0);
        for (k, w) in data.omega.iter().enumerate() {
            let wt = 1.0 / (r[k] * r[k]);
            a += (psi(*w).conj() * (g[k] - c)).re * wt;
            b += psi(*w).norm_sqr() * wt;
        }
        let rho = a / b;
        let (mut c2, mut bad) = (0.0, 0usize);
        for (k, w) in data.omega.iter().enumerate() {
            let e = (g[k] - c - rho * psi(*w)).norm() / r[k];
            c2 += e * e;
            bad += usize::from(e > 1.0);
        }
        let n = data.omega.len() as f64;
        (2.0 * c2, (c2 / n).sqrt(), bad as f64 / n)
    };
    let grid: Vec<(f64, (f64, f64, f64))> = (0..=600)
        .map(|j| {
            let c = -1.10 - 0.30 * j as f64 / 600.0;
            (c, at(c))
        })
        .collect();
    let ls = grid
        .iter()
        .min_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
        .unwrap();
    let both: Vec<_> = grid
        .iter()
        .filter(|(_, (_, rms, inv))| *rms < rms0 && *inv < inv0)
        .collect();
    let fewest = grid
        .iter()
        .min_by(|a, b| a.1 .2.total_cmp(&b.1 .2))
        .unwrap();
    println!(
        "configured: rms {rms0:.2}, invalid {:.1} %; retuned: rms {:.2}, invalid {:.1} %; step 1: rms {:.2}, invalid {:.1} %",
        100.0 * inv0,
        d1.retuned.misfit_rms,
        100.0 * d1.retuned.invalid_fraction,
        d1.after.misfit_rms,
        100.0 * d1.after.invalid_fraction
    );
    println!(
        "class scan: least squares at c = {:.4} (rms {:.2}, invalid {:.1} %); fewest invalid at c = {:.4} (rms {:.2}, invalid {:.1} %, ΔV = {:.0}); {} of 601 grid points lower both",
        ls.0,
        ls.1 .1,
        100.0 * ls.1 .2,
        fewest.0,
        fewest.1 .1,
        100.0 * fewest.1 .2,
        fewest.1 .0 - ls.1 .0,
        both.len()
    );
    // The closed-form least squares of the class reproduces the library's step 1.
    assert!((ls.1 .1 - d1.after.misfit_rms).abs() < 0.02 * d1.after.misfit_rms);
    assert!(
        ls.1 .2 > inv0,
        "the least-squares member raises the invalid fraction"
    );
    // Members with both measures lower exist, and every one costs far more than the
    // least-squares member: ΔV > 1000 (a 95 % confidence region of 3 parameters: 7.8).
    assert!(!both.is_empty());
    for (c, (v, _, _)) in &both {
        assert!(v - ls.1 .0 > 1000.0, "c = {c}: ΔV = {}", v - ls.1 .0);
    }
}
