//! Issue 34 item 9: the closed-loop poles of a large diagonal-`M̃` loop from its structure
//! (`stability::loop_poles`: the eigenvalues of the loop of the cancelled rows, 2 states per
//! mode, and the roots of each mode's factor denominator `q`, the hidden modes of the
//! 4-states-per-mode cascade) against the dense eigenvalues of the whole loop
//! (`theorem1_system`), on the large-model bench's structure at 50, 75 and 100 modes
//! (200–400 loop states, where both routes run): the same multiset of poles to 1e-6
//! relative (a multiple root, the factors' `(s + 10)²`, to the `√(ε‖A‖)` that rounding
//! splits it by in the dense route, and its cluster's mean to 1e-6), the same largest real
//! part and the same verdict (internally stable or not), for static controllers that
//! stabilize and destabilize it and a dynamic one.

use crate::modes;

use num_complex::Complex64;
use rshape::model::{Config, Controller};
use rshape::stability::{loop_poles, theorem1_system, POLES_BY_STRUCTURE_FROM};
use rshape::system::{eigenvalues, spectral_abscissa};

/// Every value of `a` matched to a distinct value of `b` within `tol(z)`.
fn same_multiset(a: &[Complex64], b: &[Complex64], tol: &dyn Fn(Complex64) -> f64) {
    assert_eq!(a.len(), b.len());
    let mut used = vec![false; b.len()];
    for z in a {
        let best = (0..b.len())
            .filter(|j| !used[*j])
            .min_by(|i, j| (b[*i] - z).norm().total_cmp(&(b[*j] - z).norm()))
            .unwrap();
        assert!(
            (b[best] - z).norm() <= tol(*z),
            "{z} has no partner (nearest {})",
            b[best]
        );
        used[best] = true;
    }
}

/// The poles of `v` within `1e-3·|z|` of `z` (a multiple root and its rounding split).
fn cluster(v: &[Complex64], z: Complex64) -> Vec<Complex64> {
    v.iter()
        .filter(|w| (**w - z).norm() <= 1e-3 * z.norm().max(1.0))
        .copied()
        .collect()
}

#[test]
fn structured_poles_equal_the_dense_eigenvalues_of_the_whole_loop() {
    let dir = tempfile::tempdir().unwrap();
    let controllers = [
        ("stabilizing", "tf = [[1e-3]]"),
        ("dynamic", "tf = [[{ num = [2e-3, 1e-2], den = [1, 30] }]]"),
        ("destabilizing", "tf = [[-2e3]]"),
    ];
    let mut verdicts = Vec::new();
    for modes_count in [50, 75, 100] {
        let sub = dir.path().join(format!("m{modes_count}"));
        let cfg = modes::write(&sub, modes_count, 20);
        let config = Config::load(&cfg).unwrap();
        let f = &config.factorization;
        for (what, tf) in controllers {
            let kp = sub.join(format!("{what}.toml"));
            std::fs::write(&kp, format!("[controller]\n{tf}\n")).unwrap();
            let k = Controller::load(&kp).unwrap().negative_feedback_gain();
            let t = theorem1_system(f, &k).unwrap();
            assert!(t.states() >= POLES_BY_STRUCTURE_FROM);
            let dense = eigenvalues(&t.a, "dense").unwrap();
            let lp = loop_poles(f, &k, &t).unwrap();
            let poles = lp.poles;
            // The structure was used: an eigenproblem of the 2 states per mode (and K's).
            let (rows, own) = lp.row_loop.expect("the structured route");
            assert_eq!(
                rows.states(),
                2 * modes_count + k.states(),
                "{modes_count} {what}"
            );
            assert_eq!(own.len(), rows.states());
            assert_eq!(poles.len(), t.states());
            // A simple pole to 1e-6 relative. A multiple one (the factors' `(s + 10)²`) is
            // split by rounding into `±√(ε‖A‖)` (a Jordan block perturbed by `ε‖A‖`): each
            // to that, and the cluster's mean (well conditioned) to 1e-6.
            let split = 10.0 * (f64::EPSILON * t.a.amax()).sqrt();
            let tol = |z: Complex64| {
                let simple = 1e-6 * z.norm().max(1.0);
                if cluster(&poles, z).len() > 1 {
                    simple.max(split)
                } else {
                    simple
                }
            };
            same_multiset(&poles, &dense, &tol);
            same_multiset(&dense, &poles, &tol);
            for z in &poles {
                let (cs, cd) = (cluster(&poles, *z), cluster(&dense, *z));
                if cs.len() > 1 {
                    assert_eq!(cs.len(), cd.len(), "{modes_count} {what}: {cs:?} {cd:?}");
                    let mean = |c: &[Complex64]| c.iter().sum::<Complex64>() / c.len() as f64;
                    assert!(
                        (mean(&cs) - mean(&cd)).norm() <= 1e-6 * z.norm().max(1.0),
                        "{modes_count} {what}: {cs:?} {cd:?}"
                    );
                }
            }
            let (a, b) = (spectral_abscissa(&poles), spectral_abscissa(&dense));
            let scale = dense.iter().map(|z| z.norm()).fold(1.0, f64::max);
            assert!(
                (a - b).abs() <= 1e-9 * scale,
                "{modes_count} {what}: {a} vs {b}"
            );
            assert_eq!(a < 0.0, b < 0.0, "{modes_count} {what}: {a} vs {b}");
            verdicts.push((what, a < 0.0));
        }
    }
    // Both verdicts were exercised.
    assert!(verdicts.iter().any(|(_, s)| *s));
    assert!(verdicts.iter().any(|(_, s)| !*s), "{verdicts:?}");
}
