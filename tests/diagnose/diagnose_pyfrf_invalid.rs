//! Issue 33's acceptance wants `misfit_rms` and the invalid fraction falling at every applied
//! step.  On pyfrf 20–1200 Hz from the mass line, `--apply chosen` at the default
//! `--max-effects` adds the three modes at once and meets it (87.8 % → 53.6 %,
//! `diagnose_ema_reference`); at `--max-effects 2` step 1 adds two of them (900, 810 Hz)
//! and raises the invalid fraction 87.8 % → 94.8 % while `misfit_rms` falls 129.8 → 13.86
//! (`tests/data/pyfrf_rev1.toml`, the model it writes).  What the fraction measures there
//! and why it rises, recomputed here independently of `diagnose` (a plain count over the
//! data; a weighted least squares of one constant in closed form):
//! * it is the share of the 1181 lines with `|G_d − G| > r` (one channel), over the same
//!   lines before and after — the recount gives the chain's figures;
//! * the noise bound is not what fails: in the flat band (below 700 Hz) the data's own
//!   line-to-line scatter is within the stated radius (rms of `|ΔG|/√(r₁² + r₂²)` 0.57);
//! * the rise is the flat band's: there the invalid share rises 81 % → 92 %, because the
//!   joint least squares moved the mass line −1.2 → −1.057 to absorb part of the residual of
//!   the third, still missing, mode (851 Hz) and its neighbours: the lines above 780 Hz carry
//!   more than 95 % of `V`.  With the two modes held, the least-squares mass line of the
//!   flat band alone (≈ −1.163) brings the invalid fraction below the configured model's
//!   while raising `misfit_rms` by a few per cent: the L2 likelihood with a mode missing does
//!   not pick it.
//!
//! Not a fault of the measure or of the noise: a step that adds fewer modes than the
//! cluster holds is a least-squares compromise on the shared constant.  The acceptance
//! chain (default `--max-effects`) meets the criterion and asserts it.

use crate::common::repo;
use crate::diagnose_pyfrf::pyfrf;
use rshape::diagnose::Channels;
use rshape::model::physical::PhysicalModel;
use rshape::model::Config;

const FLAT_HZ: f64 = 780.0;

/// `|G_d − G|/r` at every line (one channel).
fn misfits(m: &PhysicalModel, d: &Channels) -> Vec<f64> {
    (0..d.len())
        .map(|k| (d.g[0][k] - m.eval(d.omega[k])[(0, 0)]).norm() / d.radius[0][k])
        .collect()
}

/// `(misfit_rms, invalid fraction, invalid share below FLAT_HZ, share of V below FLAT_HZ)`.
fn account(m: &PhysicalModel, d: &Channels) -> (f64, f64, f64, f64) {
    let e = misfits(m, d);
    let flat: Vec<bool> = d
        .omega
        .iter()
        .map(|w| *w < std::f64::consts::TAU * FLAT_HZ)
        .collect();
    let n = e.len() as f64;
    let v: f64 = e.iter().map(|x| x * x).sum();
    let v_flat: f64 = e
        .iter()
        .zip(&flat)
        .filter(|p| *p.1)
        .map(|p| p.0 * p.0)
        .sum();
    let n_flat = flat.iter().filter(|x| **x).count() as f64;
    let bad = e.iter().filter(|x| **x > 1.0).count() as f64;
    let bad_flat = e.iter().zip(&flat).filter(|p| *p.1 && *p.0 > 1.0).count() as f64;
    ((v / n).sqrt(), bad / n, bad_flat / n_flat, v_flat / v)
}

fn load(path: &str) -> PhysicalModel {
    Config::load(&repo(path)).unwrap().physical.unwrap()
}

fn set_mass_line(m: &mut PhysicalModel, c: f64) {
    let rb = &mut m.rigid_body[0];
    rb.output_gain = rshape::model::physical::Gains::Scalar(c * rb.mass);
    rb.input_gain = rshape::model::physical::Gains::Scalar(1.0);
}

#[test]
fn step_1_at_two_modes_raises_the_invalid_fraction_through_the_mass_line_only() {
    let d = pyfrf(20.0, 1200.0);
    let m0 = load("configs/pyfrf_rigid.toml");
    let m1 = load("tests/data/pyfrf_rev1.toml");
    assert_eq!(m1.mode.len(), 2);
    let (rms0, inv0, flat0, _) = account(&m0, &d);
    let (rms1, inv1, flat1, vflat1) = account(&m1, &d);
    println!(
        "configured: rms {rms0:.2}, invalid {:.1} % (flat band {:.1} %); rev1: rms {rms1:.2}, invalid {:.1} % (flat band {:.1} %), V below {FLAT_HZ} Hz {:.2} %",
        100.0 * inv0,
        100.0 * flat0,
        100.0 * inv1,
        100.0 * flat1,
        100.0 * vflat1
    );
    // The recount gives the chain's figures (129.8 → 13.86, 87.8 % → 94.8 %).
    assert!((rms0 - 129.8).abs() < 0.1 && (rms1 - 13.86).abs() < 0.01);
    assert!((inv0 - 0.878).abs() < 1e-3 && (inv1 - 0.948).abs() < 1e-3);
    // The noise bound holds in the flat band: the data's own scatter from line to line
    // (below 700 Hz, where the slope of G between two lines is far below the noise).
    let flat: Vec<usize> = (0..d.len())
        .filter(|k| d.omega[*k] < std::f64::consts::TAU * FLAT_HZ)
        .collect();
    let quiet: Vec<usize> = (0..d.len())
        .filter(|k| d.omega[*k] < std::f64::consts::TAU * 700.0)
        .collect();
    let diffs: Vec<f64> = quiet
        .windows(2)
        .map(|p| {
            let (a, b) = (p[0], p[1]);
            (d.g[0][b] - d.g[0][a]).norm() / d.radius[0][a].hypot(d.radius[0][b])
        })
        .collect();
    let scatter = (diffs.iter().map(|x| x * x).sum::<f64>() / diffs.len() as f64).sqrt();
    println!("flat band line-to-line scatter / stated noise: rms {scatter:.2}");
    assert!(scatter < 0.8, "{scatter}");
    // The rise is the flat band's, whose lines carry under 5 % of V after the step.
    assert!(flat1 > flat0 + 0.05, "{flat0} → {flat1}");
    assert!(vflat1 < 0.05, "{vflat1}");
    // The mass line moved; its weighted least squares over the flat band alone (the two
    // modes held, closed form: c = Σ w Re(G_d − G_modes)/Σ w, w = 1/r²) lowers the invalid
    // fraction below the configured model's, for a few per cent more misfit_rms.
    let c1 = m1.rigid_body[0].output_gain.to_vec(1)[0] / m1.rigid_body[0].mass;
    let mut modes_only = m1.clone();
    set_mass_line(&mut modes_only, 0.0);
    let (mut num, mut den) = (0.0, 0.0);
    for k in &flat {
        let w = d.radius[0][*k].powi(-2);
        num += w * (d.g[0][*k] - modes_only.eval(d.omega[*k])[(0, 0)]).re;
        den += w;
    }
    let c_flat = num / den;
    let mut m_flat = m1.clone();
    set_mass_line(&mut m_flat, c_flat);
    let (rms_f, inv_f, flat_f, _) = account(&m_flat, &d);
    println!(
        "mass line: configured -1.2, rev1 {c1:.4}, flat-band least squares {c_flat:.4}: rms {rms_f:.2}, invalid {:.1} % (flat band {:.1} %)",
        100.0 * inv_f,
        100.0 * flat_f
    );
    assert!((c1 + 1.2).abs() > 0.1, "{c1}");
    assert!((c_flat + 1.2).abs() < (c1 + 1.2).abs());
    assert!(inv_f < inv0, "{inv_f} vs {inv0}");
    assert!(rms_f > rms1 && rms_f < 1.05 * rms1, "{rms_f} vs {rms1}");
}
