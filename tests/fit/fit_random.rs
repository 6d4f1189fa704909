//! ≥ 100 random envelopes, smooth and jagged, 1 to 6 decades, 20 to 2000 points: the fitted
//! r must be stable, minimum phase and biproper (from its returned poles and zeros AND from
//! roots recomputed here from its coefficients), cover every datum, and not dip between data
//! on a dense re-evaluation done here, independently of the certificate code.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::consistency::{Envelope, EnvelopeMethod};
use rshape::fit::{fit_unit, FitSettings, Objective};
use rshape::system::{logspace, TransferFunction};

fn random_envelope(rng: &mut ChaCha8Rng, k: usize) -> Envelope {
    let decades = rng.gen_range(1.0..=6.0);
    let n = if k.is_multiple_of(10) {
        2000
    } else {
        rng.gen_range(20..=600)
    };
    let lo = 10f64.powf(rng.gen_range(-3.0..2.0));
    let omega = logspace(lo, lo * 10f64.powf(decades), n);
    let jagged = !k.is_multiple_of(2);
    // Smooth trend: a random rational-like shape in log-log (slopes up to ±1.5).
    let c1 = rng.gen_range(-1.0..1.0);
    let c2 = rng.gen_range(-0.3..0.3);
    let bump = rng.gen_range(0.0..1.0);
    let bw = 10f64.powf(rng.gen_range(lo.log10()..lo.log10() + decades));
    let scale = 10f64.powf(rng.gen_range(-4.0..2.0));
    let r_min = omega
        .iter()
        .map(|w| {
            let u = (w / lo).log10() / decades - 0.5;
            let mut v =
                scale * 10f64.powf(c1 * u * decades * 0.3 + c2 * (u * decades).powi(2) * 0.3);
            v *= 1.0 + bump * 3.0 / (1.0 + ((w / bw).ln() * 4.0).powi(2));
            if jagged {
                v *= rng.gen_range(0.3..1.0);
                if rng.gen_bool(0.03) {
                    v = 0.0; // datum within the noise: no bound
                }
            }
            v
        })
        .collect();
    Envelope {
        omega,
        r_min,
        a1_limit: None,
        method: EnvelopeMethod::File,
    }
}

fn check_unit(
    r: &TransferFunction,
    zeros: &[num_complex::Complex64],
    poles: &[num_complex::Complex64],
    tag: &str,
) {
    assert_eq!(r.num.degree(), r.den.degree(), "{tag}: not biproper");
    assert_eq!(zeros.len(), poles.len(), "{tag}");
    assert!(r.at_infinity() > 0.0, "{tag}: r(∞) = {}", r.at_infinity());
    for z in zeros.iter().chain(poles) {
        assert!(z.re < 0.0, "{tag}: returned root {z} not in the open LHP");
    }
    for (p, what) in [(&r.num, "zero"), (&r.den, "pole")] {
        let roots = p.roots();
        assert!(roots.converged, "{tag}");
        for z in roots.roots {
            assert!(
                z.re < 0.0,
                "{tag}: recomputed {what} {z} not in the open LHP"
            );
        }
    }
}

#[test]
fn random_envelopes_give_certified_units() {
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let mut worst_time = 0.0f64;
    for k in 0..110 {
        let env = random_envelope(&mut rng, k);
        let order = 1 + k % 6;
        let set = FitSettings {
            order,
            objective: if k.is_multiple_of(3) {
                Objective::Area
            } else {
                Objective::Minimax
            },
            ..Default::default()
        };
        let tag = format!(
            "envelope {k} ({} points, {:.1} decades, order {order})",
            env.omega.len(),
            (env.omega[env.omega.len() - 1] / env.omega[0]).log10()
        );
        let t0 = std::time::Instant::now();
        let fit = fit_unit(&env, None, &set, &Default::default())
            .unwrap_or_else(|e| panic!("{tag}: {e}"));
        worst_time = worst_time.max(t0.elapsed().as_secs_f64());
        assert!(
            fit.certificate.passed,
            "{tag}: {:?}",
            fit.certificate.failures
        );
        check_unit(&fit.r, &fit.zeros, &fit.poles, &tag);
        // Independent dense re-evaluation from the coefficients.
        let n = env.omega.len();
        for i in 0..n {
            if env.r_min[i] > 0.0 {
                let ratio = fit.r.freq(env.omega[i]).norm() / env.r_min[i];
                assert!(ratio >= 1.0 - 1e-9, "{tag}: datum {i} ratio {ratio}");
            }
        }
        for i in 0..n - 1 {
            let bound = env.r_min[i].min(env.r_min[i + 1]);
            for j in 1..8 {
                let w = env.omega[i] * (env.omega[i + 1] / env.omega[i]).powf(j as f64 / 8.0);
                let m = fit.r.freq(w).norm();
                assert!(
                    m >= bound * (1.0 - 1e-6),
                    "{tag}: dips to {m} < {bound} at {w}"
                );
            }
        }
        // Strict positivity far outside the band and at infinity.
        for w in logspace(env.omega[0] * 1e-4, env.omega[n - 1] * 1e4, 400) {
            assert!(
                fit.r.freq(w).norm() >= fit.floor * (1.0 - 1e-6),
                "{tag}: |r| below floor at {w}"
            );
        }
        if k == 10 && std::env::var("FIT_DEBUG").is_ok() {
            for e in &fit.solver_events {
                println!("  {e:?}");
            }
        }
        if k.is_multiple_of(10) {
            println!(
                "{tag}: mean {:.4} max {:.4}, {:?}, {} LPs, {} events",
                fit.certificate.mean_log10_ratio,
                fit.certificate.max_log10_ratio,
                t0.elapsed(),
                fit.lp_solves,
                fit.solver_events.len()
            );
        }
    }
    println!("slowest fit {worst_time:.3} s (test profile)");
}
