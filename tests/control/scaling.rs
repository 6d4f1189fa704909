//! `[scaling]`: `G_s = D_o·G·D_i` applied to the model, the data, the noise and a controller.
//! Each check builds the scaled matrices itself (by hand in the test, not through
//! `rshape::model::Scaling`) and compares with what the scaled config gives.

use crate::common::{repo, rshape, stderr, stdout};
use nalgebra::DMatrix;
use num_complex::Complex64;
use rshape::pipeline::envelope::load_data;
use rshape::{Config, RunOptions};
use std::path::Path;

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// Writes an FRF CSV (`omega_rad_s`, `re_i_j,im_i_j`) of `p×m` data.
fn write_frf(path: &Path, omega: &[f64], h: &[DMatrix<Complex64>]) {
    let (p, m) = h[0].shape();
    let mut head = vec!["omega_rad_s".to_string()];
    for i in 1..=p {
        for j in 1..=m {
            head.push(format!("re_{i}_{j}"));
            head.push(format!("im_{i}_{j}"));
        }
    }
    let mut text = head.join(",") + "\n";
    for (w, hh) in omega.iter().zip(h) {
        let mut row = vec![format!("{w:e}")];
        for i in 0..p {
            for j in 0..m {
                row.push(format!("{:e}", hh[(i, j)].re));
                row.push(format!("{:e}", hh[(i, j)].im));
            }
        }
        text += &(row.join(",") + "\n");
    }
    std::fs::write(path, text).unwrap();
}

fn envelope_of(text: &str, path: &Path) -> (Vec<f64>, Vec<f64>, Option<Vec<f64>>) {
    std::fs::write(path, text).unwrap();
    let cfg = Config::load(path).unwrap_or_else(|e| panic!("{e}"));
    let data = load_data(&cfg, cfg.data.as_ref().unwrap()).unwrap();
    let out = rshape::envelope(&cfg, &data, &RunOptions::default()).unwrap();
    (
        out.envelope.r_min,
        out.envelope.a1_limit.expect("open-loop A1 limit"),
        out.noise_radii,
    )
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-300
}

/// A 2×2 standard `[model]` with a full `M̃`: the envelope of the scaled config equals, per
/// datum, eq. (8) computed here on `M̃_s = D_o·M̃·D_o⁻¹`, `Ñ_s = D_o·Ñ·D_i` and
/// `Φ_s = D_o·Φ·D_i`: `‖U_s (I + Φ_s*Φ_s)^{-1/2}‖`, `U_s = Ñ_s − M̃_sΦ_s`, by an eigenvalue of
/// `U_s (I + Φ_s*Φ_s)^{-1} U_s*`; and the A1 limit `σ_min(M̃_s)`.
#[test]
fn standard_factors_envelope_is_eq8_of_the_hand_scaled_matrices() {
    let dir = tempfile::tempdir().unwrap();
    let omega = [0.1, 0.7, 2.0, 9.0, 40.0];
    let m_of = |w: f64| {
        let s = c(0.0, w);
        DMatrix::from_row_slice(
            2,
            2,
            &[
                (s + 2.0) / (s + 1.0),
                0.5 / (s + 1.0),
                c(0.0, 0.0),
                (s + 3.0) / (s + 2.0),
            ],
        )
    };
    let n_of = |w: f64| {
        let s = c(0.0, w);
        DMatrix::from_row_slice(
            2,
            2,
            &[
                1.0 / (s + 1.0),
                2.0 / (s + 1.0),
                c(0.5, 0.0) / (s + 2.0),
                1.0 / (s + 3.0),
            ],
        )
    };
    // Data: the nominal plus a misfit, so that r_min is not zero.
    let data: Vec<DMatrix<Complex64>> = omega
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            let g = m_of(w).lu().solve(&n_of(w)).unwrap();
            let e = DMatrix::from_row_slice(
                2,
                2,
                &[
                    c(0.05, 0.01 * k as f64),
                    c(-0.02, 0.03),
                    c(0.01, 0.0),
                    c(0.0, -0.04),
                ],
            );
            g + e
        })
        .collect();
    let csv = dir.path().join("h.csv");
    write_frf(&csv, &omega, &data);
    let (d_o, d_i) = ([1e-3, 40.0], [2.5, 0.02]);
    let text = format!(
        r#"data = "{}"
[model]
factorization = "standard"
m = [[{{ num = [1, 2], den = [1, 1] }}, {{ num = [0.5], den = [1, 1] }}],
     [0, {{ num = [1, 3], den = [1, 2] }}]]
n = [[{{ num = [1], den = [1, 1] }}, {{ num = [2], den = [1, 1] }}],
     [{{ num = [0.5], den = [1, 2] }}, {{ num = [1], den = [1, 3] }}]]
[scaling]
outputs = [{}, {}]
inputs = [{}, {}]
"#,
        csv.display(),
        d_o[0],
        d_o[1],
        d_i[0],
        d_i[1]
    );
    let (r_min, a1, _) = envelope_of(&text, &dir.path().join("s.toml"));
    let dom = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(
        d_o.iter().map(|x| c(*x, 0.0)).collect(),
    ));
    let dom_inv = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(
        d_o.iter().map(|x| c(1.0 / x, 0.0)).collect(),
    ));
    let dim = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(
        d_i.iter().map(|x| c(*x, 0.0)).collect(),
    ));
    for (k, &w) in omega.iter().enumerate() {
        let ms = &dom * m_of(w) * &dom_inv;
        let ns = &dom * n_of(w) * &dim;
        let phis = &dom * &data[k] * &dim;
        let u = &ns - &ms * &phis;
        let gram = DMatrix::<Complex64>::identity(2, 2) + phis.adjoint() * &phis;
        let x = &u * gram.lu().solve(&u.adjoint()).unwrap();
        let herm = (&x + x.adjoint()) * c(0.5, 0.0);
        let lam = herm.symmetric_eigenvalues().max();
        let r_hand = lam.sqrt();
        assert!(
            close(r_min[k], r_hand, 1e-9),
            "omega {w}: r_min {} vs eq. (8) by hand {r_hand}",
            r_min[k]
        );
        let sv = ms.singular_values();
        let smin = sv.min();
        assert!(
            close(a1[k], smin, 1e-9),
            "omega {w}: A1 {} vs {smin}",
            a1[k]
        );
    }
    // The scaling matters for standard factors: the unscaled envelope differs.
    let plain = text.split("[scaling]").next().unwrap().to_string();
    let (r0, _, _) = envelope_of(&plain, &dir.path().join("plain.toml"));
    assert!(r0.iter().zip(&r_min).any(|(a, b)| !close(*a, *b, 1e-3)));
}

/// A `[plant]` (normalized factors, 2×2 with coupling): the scaled config equals a config
/// whose transfer functions and data the test scaled itself (every `G_kl` and `Φ_kl` times
/// `d_o,k·d_i,l`), per datum, r_min and A1 limit.
#[test]
fn plant_scaling_equals_the_hand_scaled_plant_and_data() {
    let dir = tempfile::tempdir().unwrap();
    let omega = [0.05, 0.3, 1.0, 3.0, 20.0];
    // G = [[1e4/(s+1), 30/(s+2)], [5/(s^2+0.4s+4), 200/(s+5)]]
    let entries: [(f64, Vec<f64>); 4] = [
        (1e4, vec![1.0, 1.0]),
        (30.0, vec![1.0, 2.0]),
        (5.0, vec![1.0, 0.4, 4.0]),
        (200.0, vec![1.0, 5.0]),
    ];
    let eval = |k: f64, den: &[f64], w: f64| {
        let s = c(0.0, w);
        let d = den.iter().fold(c(0.0, 0.0), |acc, x| acc * s + x);
        c(k, 0.0) / d
    };
    let data: Vec<DMatrix<Complex64>> = omega
        .iter()
        .map(|&w| {
            DMatrix::from_fn(2, 2, |i, j| {
                let (k, den) = &entries[2 * i + j];
                eval(*k, den, w) * c(1.0 + 0.03 * (i + 1) as f64, 0.02 * j as f64)
            })
        })
        .collect();
    let (d_o, d_i) = ([1e-3, 0.05], [0.5, 2.0]);
    let tf = |scale: &dyn Fn(usize, usize) -> f64| {
        let e = |i: usize, j: usize| {
            let (k, den) = &entries[2 * i + j];
            format!("{{ num = [{:e}], den = {:?} }}", k * scale(i, j), den)
        };
        format!(
            "tf = [[{}, {}], [{}, {}]]",
            e(0, 0),
            e(0, 1),
            e(1, 0),
            e(1, 1)
        )
    };
    let raw_csv = dir.path().join("h.csv");
    write_frf(&raw_csv, &omega, &data);
    let scaled_data: Vec<_> = data
        .iter()
        .map(|h| DMatrix::from_fn(2, 2, |i, j| h[(i, j)] * d_o[i] * d_i[j]))
        .collect();
    let hand_csv = dir.path().join("h_scaled.csv");
    write_frf(&hand_csv, &omega, &scaled_data);
    let with_key = format!(
        "data = \"{}\"\n[plant]\n{}\n[scaling]\noutputs = [{}, {}]\ninputs = [{}, {}]\n",
        raw_csv.display(),
        tf(&|_, _| 1.0),
        d_o[0],
        d_o[1],
        d_i[0],
        d_i[1]
    );
    let by_hand = format!(
        "data = \"{}\"\n[plant]\n{}\n",
        hand_csv.display(),
        tf(&|i, j| d_o[i] * d_i[j])
    );
    let (r1, a1, _) = envelope_of(&with_key, &dir.path().join("key.toml"));
    let (r2, a2, _) = envelope_of(&by_hand, &dir.path().join("hand.toml"));
    for k in 0..omega.len() {
        assert!(
            close(r1[k], r2[k], 1e-7),
            "{}: {} vs {}",
            omega[k],
            r1[k],
            r2[k]
        );
        assert!(
            close(a1[k], a2[k], 1e-7),
            "{}: {} vs {}",
            omega[k],
            a1[k],
            a2[k]
        );
    }
    // Theory: the normalized factors of D_o·G·D_i are not those of G (the unscaled
    // envelope differs), and the A1 limit rises where the scaled gain falls.
    let plain = format!(
        "data = \"{}\"\n[plant]\n{}\n",
        raw_csv.display(),
        tf(&|_, _| 1.0)
    );
    let (r0, a0, _) = envelope_of(&plain, &dir.path().join("plain.toml"));
    assert!(r0.iter().zip(&r1).any(|(a, b)| !close(*a, *b, 1e-3)));
    assert!(
        a1[0] > 10.0 * a0[0],
        "A1 at low frequency: {} vs {}",
        a1[0],
        a0[0]
    );
}

/// The special factorization (Theorem 3) and its noisy test (Theorem 4) do not depend on
/// the units: `C` and `J` absorb a SISO scaling by `c_o`, `c_i`, the modal factors and their
/// perturbations are the same, so the envelope of the five-mode robot is unchanged, while
/// the noise radius (given in the data's units) becomes `c_o·c_i·0.06`.
#[test]
fn special_factorization_envelopes_are_unit_invariant() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(repo("configs/robot.toml"))
        .unwrap()
        .replace(
            "data = \"robot.csv\"",
            &format!("data = \"{}\"", repo("configs/robot.csv").display()),
        );
    let (co, ci) = (250.0, 0.004);
    // Noise-free (Theorem 3): the [noise] table removed.
    let free = base.split("[noise]").next().unwrap().to_string();
    let scaled_free = format!("{free}\n[scaling]\noutputs = [{co}]\ninputs = [{ci}]\n");
    let (r0, a0, n0) = envelope_of(&free, &dir.path().join("free.toml"));
    let (r1, a1, n1) = envelope_of(&scaled_free, &dir.path().join("free_s.toml"));
    assert!(n0.is_none() && n1.is_none());
    for k in 0..r0.len() {
        assert!(
            close(r0[k], r1[k], 1e-9),
            "datum {k}: {} vs {}",
            r0[k],
            r1[k]
        );
        assert!(close(a0[k], a1[k], 1e-12), "datum {k}");
    }
    // Noisy (Theorem 4, the μ bisection on the first 25 data to keep it short).
    let (r0, _, n0) = envelope_of(&base, &dir.path().join("noisy.toml"));
    let scaled = format!("{base}\n[scaling]\noutputs = [{co}]\ninputs = [{ci}]\n");
    let (r1, _, n1) = envelope_of(&scaled, &dir.path().join("noisy_s.toml"));
    let (n0, n1) = (n0.unwrap(), n1.unwrap());
    for k in 0..r0.len() {
        assert!(close(n0[k], 0.06, 1e-12) && close(n1[k], 0.06 * co * ci, 1e-12));
        assert!(
            close(r0[k], r1[k], 1e-6),
            "datum {k}: {} vs {}",
            r0[k],
            r1[k]
        );
    }
}

/// A controller's robust stability with `[scaling]` equals the one computed on the scaled
/// plant and the scaled controller `K_s = D_i⁻¹·K·D_o⁻¹` written out by hand (2×2 plant,
/// 2×2 static controller, the configured r).
#[test]
fn stability_with_scaling_equals_the_hand_scaled_loop() {
    let dir = tempfile::tempdir().unwrap();
    let (d_o, d_i) = ([0.01, 0.5], [4.0, 0.25]);
    // G = [[100/(s+1), 0], [2/(s+2), 4/(s+0.5)]]; K = [[0.02, 0], [0.1, 0.5]].
    let k = [[0.02, 0.0], [0.1, 0.5]];
    let (keyed_text, hand_text) = crate::common::scaling_plant_pair(d_o, d_i);
    let keyed = dir.path().join("keyed.toml");
    std::fs::write(&keyed, keyed_text).unwrap();
    let hand = dir.path().join("hand.toml");
    std::fs::write(&hand, hand_text).unwrap();
    let kfile = |name: &str, s: &dyn Fn(usize, usize) -> f64| {
        let p = dir.path().join(name);
        std::fs::write(
            &p,
            format!(
                "[controller]\ntf = [[{:e}, {:e}], [{:e}, {:e}]]\n",
                k[0][0] * s(0, 0),
                k[0][1] * s(0, 1),
                k[1][0] * s(1, 0),
                k[1][1] * s(1, 1)
            ),
        )
        .unwrap();
        p
    };
    let k_plain = kfile("k.toml", &|_, _| 1.0);
    // (K_s)_jk = K_jk / (d_i,j · d_o,k): K is inputs × outputs.
    let k_hand = kfile("k_s.toml", &|j, kk| 1.0 / (d_i[j] * d_o[kk]));
    let run = |cfg: &Path, kf: &Path| {
        let o = rshape(&[
            "stability",
            cfg.to_str().unwrap(),
            "--controller",
            kf.to_str().unwrap(),
            "--json",
        ]);
        assert!(
            matches!(o.status.code(), Some(0) | Some(1)),
            "{}",
            stderr(&o)
        );
        serde_json::from_str::<serde_json::Value>(&stdout(&o)).unwrap()
    };
    let a = run(&keyed, &k_plain);
    let b = run(&hand, &k_hand);
    let num = |v: &serde_json::Value, key: &str| {
        v[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} missing in {v}"))
    };
    assert_eq!(a["internally_stable"], b["internally_stable"]);
    assert_eq!(a["internally_stable"], serde_json::Value::Bool(true));
    assert!(
        close(num(&a, "b_gk"), num(&b, "b_gk"), 1e-6),
        "b(G,K): {} vs {}",
        a["b_gk"],
        b["b_gk"]
    );
    let ra = &a["margins"][0];
    let rb = &b["margins"][0];
    assert_eq!(ra["robust"], rb["robust"], "{ra} vs {rb}");
    assert!(
        close(num(ra, "alpha"), num(rb, "alpha"), 1e-6),
        "{ra} vs {rb}"
    );
}

/// Every noise source is read in the data file's units and its radius scaled by `d_o·d_i`
/// (SISO): a std file (`3·std·d_o·d_i`, computed here), a coherence (`3·ε·|Φ_s|`,
/// `ε = √(1 − γ²)/(|γ|√(2n))`, computed here from the scaled data), the output bound of
/// Sec. III and `--noise-radius` (each the unscaled config's radii times `d_o·d_i`).
#[test]
fn every_noise_source_scales_like_the_entries() {
    let dir = tempfile::tempdir().unwrap();
    let csv = repo("configs/plant_first.csv");
    let raw = rshape::read_frf_csv(&csv).unwrap();
    let n = raw.len();
    let (co, ci) = (0.02, 3.0);
    let k = co * ci;
    let std: Vec<f64> = (0..n).map(|i| 0.002 * (1.0 + i as f64 / 10.0)).collect();
    let coh: Vec<f64> = (0..n).map(|i| 0.95 - 0.5 * i as f64 / n as f64).collect();
    let column = |name: &str, v: &[f64]| {
        let mut t = format!("omega_rad_s,{name}\n");
        for (w, x) in raw.omega.iter().zip(v) {
            t += &format!("{w:e},{x:e}\n");
        }
        t
    };
    let std_file = dir.path().join("std.csv");
    std::fs::write(&std_file, column("std_1_1", &std)).unwrap();
    let coh_file = dir.path().join("coh.csv");
    std::fs::write(&coh_file, column("coh_1_1", &coh)).unwrap();
    let head = format!(
        "data = \"{}\"\n[plant]\ntf = [[{{ num = [1], den = [1, 1, 0] }}]]\n",
        csv.display()
    );
    let scaled = format!("[scaling]\noutputs = [{co}]\ninputs = [{ci}]\n");
    let radii = |noise: &str, scaling: &str, name: &str, cli: Option<f64>| {
        let p = dir.path().join(name);
        std::fs::write(&p, format!("{head}{noise}{scaling}")).unwrap();
        let cfg = Config::load(&p).unwrap_or_else(|e| panic!("{e}"));
        let data = load_data(&cfg, cfg.data.as_ref().unwrap()).unwrap();
        let opts = RunOptions::noise_radius(cli);
        let out = rshape::envelope(&cfg, &data, &opts).unwrap();
        (out.noise_radii.expect("noisy"), data)
    };
    let std_noise = format!("[noise]\nstd_file = \"{}\"\n", std_file.display());
    let (r, _) = radii(&std_noise, &scaled, "std.toml", None);
    for i in 0..n {
        assert!(close(r[i], 3.0 * std[i] * k, 1e-12), "std, datum {i}");
    }
    let coh_noise = format!(
        "[noise]\ncoherence = \"{}\"\naverages = 5\n",
        coh_file.display()
    );
    let (r, data_s) = radii(&coh_noise, &scaled, "coh.toml", None);
    for i in 0..n {
        let g2 = coh[i];
        let eps = (1.0 - g2).sqrt() / (g2.sqrt() * (2.0f64 * 5.0).sqrt());
        let want = 3.0 * eps * data_s.response[i][(0, 0)].norm();
        assert!(
            close(r[i], want, 1e-9),
            "coherence, datum {i}: {} vs {want}",
            r[i]
        );
        assert!(close(
            data_s.response[i][(0, 0)].norm(),
            raw.response[i][(0, 0)].norm() * k,
            1e-12
        ));
    }
    let bound = "[noise]\noutput_bound = 1e-6\ninput_amplitude = 2.0\n";
    let (r1, _) = radii(bound, &scaled, "bound_s.toml", None);
    let (r0, _) = radii(bound, "", "bound.toml", None);
    for i in 0..n {
        assert!(close(r1[i], r0[i] * k, 1e-9), "output bound, datum {i}");
    }
    let (r1, _) = radii("", &scaled, "cli_s.toml", Some(0.03));
    assert!(
        r1.iter().all(|x| close(*x, 0.03 * k, 1e-12)),
        "--noise-radius"
    );
}

/// SISO, only the product `d_o·d_i` scales `G` and `Φ`: `(2, 0.5)` is the identity for the
/// normalized factors of a `[plant]` (the same envelope as no scaling, datum for datum), and
/// `(3, 5)` equals `(15, 1)`.
#[test]
fn siso_plant_scaling_depends_on_the_product_only() {
    let dir = tempfile::tempdir().unwrap();
    let head = format!(
        "data = \"{}\"\n[plant]\ntf = [[{{ num = [1], den = [1, 1, 0] }}]]\n",
        repo("configs/plant_first.csv").display()
    );
    let with = |o: f64, i: f64, name: &str| {
        envelope_of(
            &format!("{head}[scaling]\noutputs = [{o}]\ninputs = [{i}]\n"),
            &dir.path().join(name),
        )
        .0
    };
    let plain = envelope_of(&head, &dir.path().join("plain.toml")).0;
    let unit = with(2.0, 0.5, "unit.toml");
    let a = with(3.0, 5.0, "a.toml");
    let b = with(15.0, 1.0, "b.toml");
    for k in 0..plain.len() {
        assert!(close(plain[k], unit[k], 1e-9), "datum {k}");
        assert!(close(a[k], b[k], 1e-9), "datum {k}");
    }
    assert!(plain.iter().zip(&a).any(|(x, y)| !close(*x, *y, 1e-3)));
}
