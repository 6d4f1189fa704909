//! Acceptance of the foundation on the paper's noise-free MIMO example (Sec. IV-A).
use crate::common;

use common::{repo, rshape, stdout};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::consistency::min_norm_perturbation;
use rshape::data::read_frf_csv;
use rshape::model::Config;

#[test]
fn check_names_exactly_omega_10_and_100_as_inconsistent() {
    let cfg = repo("configs/paper_mimo.toml");
    let out = rshape(&["check", cfg.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(1), "{}", stdout(&out));
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    let failing: Vec<f64> = v["failing_omegas"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(failing, vec![10.0, 100.0]);
    assert_eq!(v["rows"].as_array().unwrap().len(), 5);
    assert!(v["a1_violations"].as_array().unwrap().is_empty());
}

#[test]
fn check_with_paper_r1_is_consistent() {
    let cfg = repo("configs/paper_mimo.toml");
    let out = rshape(&[
        "check",
        cfg.to_str().unwrap(),
        "--r-num",
        "1e-8,0.3",
        "--r-den",
        "0.5,1",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    assert!(stdout(&out).contains("consistent: r explains all 5 data"));
}

/// Minimum-norm solution of `ΔW = U` by the SVD pseudo-inverse, independent of the
/// Cholesky path in the library.
fn min_norm_by_pinv(u: &DMatrix<Complex64>, w: &DMatrix<Complex64>) -> DMatrix<Complex64> {
    let pinv = w.clone().pseudo_inverse(1e-14).unwrap();
    u * pinv
}

#[test]
fn delta_norms_agree_with_pseudo_inverse_and_solve_the_interpolation_equation() {
    let cfg = Config::load(&repo("configs/paper_mimo.toml")).unwrap();
    let data = read_frf_csv(&repo("configs/paper_mimo.csv")).unwrap();
    let env = rshape::consistency::noise_free_envelope(&cfg.factorization, &data).unwrap();
    assert_eq!(env.omega, vec![0.01, 0.1, 1.0, 10.0, 100.0]);
    for (i, w) in env.omega.iter().enumerate() {
        let at = cfg.factorization.at(*w);
        let phi = &data.response[i];
        let (p, m) = (phi.nrows(), phi.ncols());
        let u = &at.n - &at.m * phi;
        let mut wm = DMatrix::zeros(m + p, m);
        for k in 0..m {
            wm[(k, k)] = Complex64::new(-1.0, 0.0);
        }
        wm.view_mut((m, 0), (p, m)).copy_from(&(-phi));
        let d_ref = min_norm_by_pinv(&u, &wm);
        let norm_ref = d_ref.clone().svd(false, false).singular_values.max();
        let rel = (env.r_min[i] - norm_ref).abs() / norm_ref;
        assert!(
            rel < 1e-9,
            "omega {w}: {} vs {norm_ref} ({rel:e})",
            env.r_min[i]
        );
        // The library's Δ solves ΔW = U and equals the pseudo-inverse solution.
        let (d, _) = min_norm_perturbation(&at, phi).unwrap();
        let resid = (&d * &wm - &u).norm() / u.norm();
        assert!(resid < 1e-12, "omega {w}: ΔW − U residual {resid:e}");
        assert!((&d - &d_ref).norm() / d_ref.norm() < 1e-10);
        // Row space of the minimum-norm solution lies in the range of W^*: Δ(I − WW⁺) = 0.
        let proj = DMatrix::<Complex64>::identity(m + p, m + p)
            - &wm * wm.clone().pseudo_inverse(1e-14).unwrap();
        assert!((&d * proj).norm() < 1e-12 * d.norm());
    }
    // The paper's Fig. 3: the data at 10 and 100 rad/s lie above |r|, the others below.
    let r = cfg.r.unwrap();
    let above: Vec<bool> = env
        .omega
        .iter()
        .zip(&env.r_min)
        .map(|(w, d)| *d >= r.freq(*w).norm())
        .collect();
    assert_eq!(above, vec![false, false, false, true, true]);
}

#[test]
fn envelope_writes_sorted_csv_with_required_columns() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = repo("configs/paper_mimo.toml");
    let out = rshape(&[
        "envelope",
        cfg.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let text = std::fs::read_to_string(dir.path().join("envelope.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "omega_rad_s,r_min,a1_limit");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 5);
    assert!(rows.windows(2).all(|w| w[0][0] < w[1][0]));
    // A1 limit: σ_min(M̃(jω)) recomputed from the closed-form 2×2 singular values.
    for row in &rows {
        let w = row[0];
        let s = Complex64::new(0.0, w);
        let m = [
            (s + 2.0) / (s + 1.0),
            (s + 3.0) / (s + 2.0),
            Complex64::new(0.0, 0.0),
            (s + 1.0) / (s + 2.0),
        ];
        let fro2: f64 = m.iter().map(|z| z.norm_sqr()).sum();
        let det = (m[0] * m[3] - m[1] * m[2]).norm();
        let smin = ((fro2 - (fro2 * fro2 - 4.0 * det * det).sqrt()) / 2.0).sqrt();
        assert!((row[2] - smin).abs() / smin < 1e-12, "A1 at {w}");
    }
}
