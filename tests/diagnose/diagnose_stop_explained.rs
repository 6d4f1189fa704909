//! A stop that explains itself (issue 33): when nothing admissible passes, the report says
//! what the remaining misfit is, in words and in the JSON's `residual`.  A one-mode beam
//! whose configured model is the truth, measured with a scatter three times the stated σ:
//! nothing is missing, so nothing may be added, and the stop must say that the residual is
//! white but above the stated noise, with the `std_factor` that would cover it — checked
//! against the scatter computed directly from the data and the truth.  The same beam measured
//! at exactly the stated noise stops "white at the noise", with no `std_factor` suggestion.

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rshape::diagnose::{diagnose_channels, Channels, SearchSettings};
use rshape::model::physical::{Gains, ModeSpec, PhysicalModel};

const TAU: f64 = std::f64::consts::TAU;

fn truth() -> PhysicalModel {
    let w = TAU * 120.0;
    PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: w,
            zeta: 0.01,
            mass: 1.0,
            input_gain: Gains::Scalar(1.0),
            output_gain: Gains::Scalar(0.2 * w * w * 0.01),
        }],
        ..Default::default()
    }
}

/// 400 lines 20–400 Hz, radius 2 % |G| + 1e-3; the data scatter `scale` times the stated σ
/// (`σ = r/√2`, complex Gaussian).
fn data(scale: f64, seed: u64) -> Channels {
    let m = truth();
    let omega: Vec<f64> = (0..400)
        .map(|k| TAU * (20.0 + 380.0 * k as f64 / 399.0))
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut gauss = || {
        // Box–Muller.
        let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    };
    let (mut g, mut radius) = (Vec::new(), Vec::new());
    for w in &omega {
        let h = m.eval(*w)[(0, 0)];
        let r = 0.02 * h.norm() + 1e-3;
        let s = scale * r / std::f64::consts::SQRT_2 / std::f64::consts::SQRT_2;
        g.push(h + Complex64::new(s * gauss(), s * gauss()));
        radius.push(r);
    }
    Channels {
        path: "one mode".into(),
        omega,
        entries: vec![(0, 0)],
        g: vec![g],
        radius: vec![radius],
        radius_source: vec!["test".into()],
    }
}

#[test]
fn a_stop_on_data_scattering_above_the_stated_noise_suggests_a_std_factor() {
    let d_ = data(3.0, 7);
    // The scatter against the truth, from the data directly: √(Σ|e|²/σ² / F).
    let direct = (d_.g[0]
        .iter()
        .zip(&d_.radius[0])
        .zip(&d_.omega)
        .map(|((g, r), w)| 2.0 * ((g - truth().eval(*w)[(0, 0)]).norm() / r).powi(2))
        .sum::<f64>()
        / d_.len() as f64)
        .sqrt();
    assert!((direct / 3.0 - 1.0).abs() < 0.15, "generator: {direct}");
    let s = SearchSettings {
        max_effects: 1,
        ..Default::default()
    };
    let d = diagnose_channels(&truth(), &d_, &s, &Default::default()).unwrap();
    assert_eq!(d.verdict, "no_effect_found", "{}", d.message);
    assert!(d.chosen.is_empty());
    let r = d
        .residual
        .as_ref()
        .expect("a stop has its residual account");
    assert_eq!(r.kind, "scatter_above_noise", "{r:?}");
    assert!(r.white && r.ljung_box_q <= r.q_critical, "{r:?}");
    assert!(r.concentrated_hz.is_none());
    // The factor that would cover the scatter: √(V/E[V]) of the final model, within 10 %
    // of the scatter measured against the truth (the refit absorbs a few parameters' worth).
    let k = r.std_factor_times.expect("a std_factor suggestion");
    assert!((k / direct - 1.0).abs() < 0.1, "{k} vs {direct}");
    assert!((r.level.sqrt() - k).abs() < 1e-12);
    assert!(
        d.message
            .contains("the data scatter more than the stated σ")
            && d.message.contains("std_factor ×"),
        "{}",
        d.message
    );
    // The JSON carries it.
    let j = serde_json::to_value(&d).unwrap();
    assert_eq!(j["residual"]["kind"], "scatter_above_noise");
    assert!((j["residual"]["std_factor_times"].as_f64().unwrap() - k).abs() < 1e-12);
}

/// The complex Ljung–Box statistic of `z` over `m` lags, written out here (not the library's
/// `lsq::whiteness`): `Q = Σ_k 2N²|ρ̂_k|²/(N − k)`, `ρ̂_k = Σ_i z_i z̄_{i+k} / Σ_i |z_i|²`.
fn ljung_box(z: &[Complex64], m: usize) -> f64 {
    let n = z.len();
    let c0: f64 = z.iter().map(|x| x.norm_sqr()).sum();
    (1..=m)
        .map(|k| {
            let ck: Complex64 = (0..n - k).map(|i| z[i] * z[i + k].conj()).sum();
            2.0 * (n * n) as f64 * (ck / c0).norm_sqr() / (n - k) as f64
        })
        .sum()
}

#[test]
fn a_stop_on_a_right_model_at_the_stated_noise_says_white_at_the_noise() {
    // The configured model is the truth and the data scatter exactly as stated: nothing is
    // missing and the σ is right, so the stop must say "white at the noise" and suggest
    // no std_factor.
    let d_ = data(1.0, 11);
    // The premise from the data directly: the normalized residual against the truth,
    // z = (G_d − G)·√2/r, has V/F near 1 and no correlation along frequency.
    let z: Vec<Complex64> = d_.g[0]
        .iter()
        .zip(&d_.radius[0])
        .zip(&d_.omega)
        .map(|((g, r), w)| (g - truth().eval(*w)[(0, 0)]) * std::f64::consts::SQRT_2 / r)
        .collect();
    let direct = z.iter().map(|x| x.norm_sqr()).sum::<f64>() / z.len() as f64;
    assert!((direct - 1.0).abs() < 0.15, "generator: V/F {direct}");
    let s = SearchSettings {
        max_effects: 1,
        ..Default::default()
    };
    let d = diagnose_channels(&truth(), &d_, &s, &Default::default()).unwrap();
    assert_eq!(d.verdict, "no_effect_found", "{}", d.message);
    assert!(d.chosen.is_empty());
    let r = d
        .residual
        .as_ref()
        .expect("a stop has its residual account");
    assert_eq!(r.kind, "white_at_noise", "{r:?}");
    assert!(r.white && r.ljung_box_q <= r.q_critical, "{r:?}");
    // The level of the final model's residual: the truth's V/F less what a refit of a few
    // parameters absorbs, so within 15 % of the direct figure, and under the "above the
    // noise" line (1.5).
    assert!(
        (r.level / direct - 1.0).abs() < 0.15,
        "{} vs {direct}",
        r.level
    );
    assert!(r.level < 1.5);
    // The truth's own residual is white by the same test, computed independently here.
    let q_truth = ljung_box(&z, r.lags);
    assert!(
        q_truth <= r.q_critical,
        "Q of the truth {q_truth} vs {}",
        r.q_critical
    );
    // No std_factor suggestion and no concentration, in the account, the JSON and the text.
    assert!(r.std_factor_times.is_none(), "{r:?}");
    assert!(r.concentrated_hz.is_none() && r.concentrated_level.is_none());
    assert!(
        d.message
            .contains("the residual is white at the stated noise")
            && d.message.contains("nothing more to find")
            && !d.message.contains("std_factor"),
        "{}",
        d.message
    );
    let j = serde_json::to_value(&d).unwrap();
    assert_eq!(j["residual"]["kind"], "white_at_noise");
    assert!(j["residual"].get("std_factor_times").is_none());
}

#[test]
fn a_run_that_adds_an_effect_has_no_residual_account() {
    // The mode missing from the configured model: it is found, and `residual` is absent.
    let d_ = data(1.0, 8);
    let empty = PhysicalModel {
        mode: vec![],
        feedthrough: Some(rshape::model::physical::Feedthrough::Scalar(0.0)),
        ..Default::default()
    };
    let s = SearchSettings {
        max_effects: 1,
        ..Default::default()
    };
    let d = diagnose_channels(&empty, &d_, &s, &Default::default()).unwrap();
    assert_eq!(d.verdict, "effects_found", "{}", d.message);
    assert!(d.residual.is_none());
    assert!(serde_json::to_value(&d).unwrap().get("residual").is_none());
}
