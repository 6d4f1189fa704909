//! Issue 34 item 9: from [`CASCADE_ROWS_FROM`] modal coordinates on, the Theorem 1 loop of a
//! diagonal `M̃` is realized one row at a time (`M̃ᵢᵢ⁻¹·[Ñᵢ  1]`, then `J`) instead of the
//! staircase reduction of the whole cascade `M̃⁻¹·[Ñ·J  I]` (1000 modes: minutes). Checked
//! on the 60-mode structure of the large-model bench against that whole-matrix cascade
//! (`modal_cascade`, the route below the threshold): the same number of states, the same
//! eigenvalues (the factors' hidden modes included), the same frequency response, and the
//! same closed-loop poles with the bench's controller.

use crate::modes;

use num_complex::Complex64;
use rshape::model::{Config, Controller};
use rshape::stability::{closed_loop_poles, modal_cascade, modal_system, CASCADE_ROWS_FROM};
use rshape::system::eigenvalues;
use rshape::system::{FreqEvaluator, TransferFunction};

/// Every value of `a` matched to a distinct value of `b` within `rtol·max(1, |z|)`.
fn same_multiset(a: &[Complex64], b: &[Complex64], rtol: f64) {
    assert_eq!(a.len(), b.len());
    let mut used = vec![false; b.len()];
    for z in a {
        let best = (0..b.len())
            .filter(|j| !used[*j])
            .min_by(|i, j| (b[*i] - z).norm().total_cmp(&(b[*j] - z).norm()))
            .unwrap();
        assert!(
            (b[best] - z).norm() <= rtol * z.norm().max(1.0),
            "{z} has no partner (nearest {})",
            b[best]
        );
        used[best] = true;
    }
}

#[test]
fn row_by_row_cascade_has_the_poles_and_response_of_the_whole_cascade() {
    let k = 60;
    assert!(k >= CASCADE_ROWS_FROM);
    let dir = tempfile::tempdir().unwrap();
    let cfg = modes::write(dir.path(), k, 20);
    let config = Config::load(&cfg).unwrap();
    let f = &config.factorization;
    let rows = modal_system(f).unwrap();
    let whole = modal_cascade(f).unwrap();
    // 4 states per mode either way: the mode and the hidden poles of its factor.
    assert_eq!(rows.states(), 4 * k);
    assert_eq!(whole.states(), rows.states());
    let (pr, pw) = (
        eigenvalues(&rows.a, "rows").unwrap(),
        eigenvalues(&whole.a, "whole").unwrap(),
    );
    same_multiset(&pr, &pw, 1e-6);
    // The same transfer function M̃⁻¹·[Ñ·J  I] (inputs [u; w], outputs ξ).
    let (er, ew) = (FreqEvaluator::new(&rows), FreqEvaluator::new(&whole));
    for w in [3.0, 10.0, 137.0, 2e3, 9.9e3, 5e4] {
        let (gr, gw) = (er.freq(w).unwrap(), ew.freq(w).unwrap());
        let scale = gw.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let err = (&gr - &gw).iter().map(|z| z.norm()).fold(0.0, f64::max);
        assert!(err <= 1e-9 * scale, "at {w} rad/s: {err:e} of {scale:e}");
    }
    // The closed loop with the bench's controller K = 1e-3: the same poles as the loop
    // closed around the whole cascade (built here from it, negative feedback on y = C·ξ).
    let kp = dir.path().join("k.toml");
    std::fs::write(&kp, "[controller]\ntf = [[1e-3]]\n").unwrap();
    let controller = Controller::load(&kp).unwrap();
    let poles = closed_loop_poles(f, &controller).unwrap();
    let m = f.inputs();
    let bu = whole.b.columns(0, m).into_owned();
    let kc = &f.c * &whole.c * 1e-3;
    assert_eq!(
        whole.d.columns(0, m).iter().map(|x| x.abs()).sum::<f64>(),
        0.0
    );
    let a_cl = &whole.a - &bu * &kc;
    let dense = eigenvalues(&a_cl, "dense loop").unwrap();
    same_multiset(&poles, &dense, 1e-6);
    assert!(poles.iter().all(|z| z.re < 0.0));
}

/// `b(G,K)` of a large loop, its Hamiltonian iteration started from the peaks of the gang of
/// four's value computed from the factor values (`gang_sigma_max`), equals the iteration's
/// own dense start on the same system, at 50 modes (200 loop states, the structured route);
/// and that value equals the dense response of the gang's state space.
#[test]
fn b_gk_from_the_gangs_peaks_matches_the_dense_start() {
    use rshape::stability::{analyze, gang_of_four, gang_sigma_max};
    use rshape::system::{hinf_norm, logspace, spectral_norm};
    let dir = tempfile::tempdir().unwrap();
    let cfg = modes::write(dir.path(), 50, 20);
    let kp = dir.path().join("k.toml");
    std::fs::write(&kp, "[controller]\ntf = [[1e-3]]\n").unwrap();
    let config = Config::load(&cfg).unwrap();
    let controller = Controller::load(&kp).unwrap();
    let f = &config.factorization;
    let k = controller.negative_feedback_gain();
    let g4 = gang_of_four(f, &k).unwrap();
    let kev = FreqEvaluator::new(&k);
    let gev = FreqEvaluator::new(&g4);
    for w in [0.5, 10.0, 47.0, 480.0, 9.9e3, 1e5] {
        let dense = spectral_norm(&gev.freq(w).unwrap());
        let fast = gang_sigma_max(f, &kev, w).unwrap();
        assert!(
            (dense - fast).abs() <= 1e-9 * dense,
            "at {w}: {dense} vs {fast}"
        );
    }
    let dense = 1.0 / hinf_norm(&g4).unwrap().gamma;
    let rs = vec![("configured".to_string(), TransferFunction::gain(1e-3))];
    let (report, _) = analyze(f, &controller, &rs, &logspace(0.5, 2e5, 1000)).unwrap();
    let b = report.b_gk.unwrap();
    assert!((b - dense).abs() <= 1e-7 * dense, "{b} vs {dense}");
}
