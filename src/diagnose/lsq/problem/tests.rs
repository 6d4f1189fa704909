use super::*;
use crate::model::physical::{EffectKind, EffectSpec, Gains, ModeSpec};

/// A delay on input 2 of three: the residual keeps that channel's rows and folds the
/// other two into one row; its cost is the whole residual's, summed here datum by datum
/// through [`Problem::parts`] (the per-datum route, no cache, no folding).
#[test]
fn the_folded_residual_has_the_whole_cost() {
    use crate::diagnose::effects::candidates::Sel;
    let base = PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: 900.0,
            zeta: 0.01,
            mass: 1.0,
            input_gain: Gains::Vector(vec![1.0, -0.4, 0.7]),
            output_gain: Gains::Scalar(3e4),
        }],
        ..Default::default()
    };
    let omega = crate::system::logspace(100.0, 3000.0, 80);
    let data = Channels::of_model(
        &base,
        omega,
        vec![(0, 0), (0, 1), (0, 2)],
        1.1,
        (0.02, 1e-3),
    );
    let p = Problem::new(&base, &data).expect("problem");
    let mask: Vec<usize> = (0..data.len()).step_by(3).collect();
    let mods = Mods {
        cands: vec![Cand::Delay(Sel::Input(1))],
        theta: vec![3e-4],
    };
    let mut r = Vec::new();
    p.residual(&mods, &mask, &mut r);
    assert_eq!(r.len(), 2 * mask.len() + 1);
    let mut whole = 0.0;
    for ch in 0..3 {
        for &k in &mask {
            let (c, pa) = p.parts(&mods, ch, Some(k), data.omega[k]);
            whole += 2.0 * ((data.g[ch][k] - c * pa).norm() / data.radius[ch][k]).powi(2);
        }
    }
    let v: f64 = r.iter().map(|x| x * x).sum();
    assert!(whole > 1.0, "{whole}");
    assert!((v - whole).abs() <= 1e-12 * whole, "{v} vs {whole}");
    assert_eq!(p.v(&mods, &mask), v);
    // The delay's own channel: the rows of the datum-by-datum route.
    for (q, &k) in mask.iter().enumerate() {
        let (c, pa) = p.parts(&mods, 1, Some(k), data.omega[k]);
        let e = (data.g[1][k] - c * pa) * p.inv_sigma[1][k];
        assert!((r[2 * q] - e.re).abs() <= 1e-12 * e.norm().max(1.0));
        assert!((r[2 * q + 1] - e.im).abs() <= 1e-12 * e.norm().max(1.0));
    }
}

/// The analytic Jacobian of a lone added mode against fourth-order central differences
/// of the residual itself (one output, three inputs, a delay on the path so `P ≠ 1`).
#[test]
fn the_lone_mode_jacobian_matches_central_differences() {
    let mut delay = EffectSpec::new(EffectKind::Delay);
    delay.tau_s = Some(2e-4);
    let base = PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: 900.0,
            zeta: 0.01,
            mass: 1.0,
            input_gain: Gains::Vector(vec![1.0, -0.4, 0.7]),
            output_gain: Gains::Scalar(3e4),
        }],
        effect: vec![delay],
        ..Default::default()
    };
    let omega = crate::system::logspace(100.0, 3000.0, 80);
    let entries = vec![(0, 0), (0, 1), (0, 2)];
    let data = Channels::of_model(&base, omega, entries, 1.1, (0.02, 1e-3));
    let p = Problem::new(&base, &data).expect("problem");
    let mask: Vec<usize> = (0..data.len()).step_by(2).collect();
    let th = vec![450f64.ln(), 0.03f64.ln(), 2e3, -7e2, 1.1e3];
    let resid = |t: &[f64]| {
        let mut out = Vec::new();
        let m = Mods {
            cands: vec![Cand::Mode],
            theta: t.to_vec(),
        };
        p.residual(&m, &mask, &mut out);
        out
    };
    let rows = resid(&th).len();
    let mut jac = DMatrix::zeros(rows, th.len());
    assert!(p.lone_mode_jacobian(&th, &mask, &mut jac));
    for k in 0..th.len() {
        let h = 1e-4 * th[k].abs().max(1.0);
        let at = |d: f64| {
            let mut t = th.clone();
            t[k] += d;
            resid(&t)
        };
        let (p2, p1, m1, m2) = (at(2.0 * h), at(h), at(-h), at(-2.0 * h));
        let scale = (0..rows).map(|i| jac[(i, k)].abs()).fold(0.0, f64::max);
        assert!(scale > 0.0, "column {k} is zero");
        for i in 0..rows {
            let fd = (-p2[i] + 8.0 * p1[i] - 8.0 * m1[i] + m2[i]) / (12.0 * h);
            assert!(
                (fd - jac[(i, k)]).abs() <= 1e-6 * scale,
                "θ_{k}, row {i}: analytic {} vs {fd}",
                jac[(i, k)]
            );
        }
    }
}

/// The analytic Jacobian of each lone one-parameter path effect (delay, lag, NMP zero,
/// ZOH; on every channel and on input 2 of three, where the other two channels fold into
/// one row) against fourth-order central differences of the residual itself.
#[test]
fn the_lone_path_jacobian_matches_central_differences() {
    use crate::diagnose::effects::candidates::Sel;
    let base = PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: 900.0,
            zeta: 0.01,
            mass: 1.0,
            input_gain: Gains::Vector(vec![1.0, -0.4, 0.7]),
            output_gain: Gains::Scalar(3e4),
        }],
        ..Default::default()
    };
    let omega = crate::system::logspace(100.0, 3000.0, 80);
    let entries = vec![(0, 0), (0, 1), (0, 2)];
    let data = Channels::of_model(&base, omega, entries, 1.1, (0.02, 1e-3));
    let p = Problem::new(&base, &data).expect("problem");
    let mask: Vec<usize> = (0..data.len()).step_by(2).collect();
    // θ: τ (s) for a delay (both signs: `|τ|` is used), else the logarithm of the corner,
    // zero or hold time.
    for sel in [Sel::All, Sel::Input(1)] {
        for (c, th) in [
            (Cand::Delay(sel), 3e-4),
            (Cand::Delay(sel), -2e-4),
            (Cand::Lag(sel), 1500f64.ln()),
            (Cand::NmpZero(sel), 4000f64.ln()),
            (Cand::Zoh(sel), 5e-4f64.ln()),
        ] {
            let resid = |t: f64| {
                let mut out = Vec::new();
                let m = Mods {
                    cands: vec![c],
                    theta: vec![t],
                };
                p.residual(&m, &mask, &mut out);
                out
            };
            let r = resid(th);
            let rows = r.len();
            assert_eq!(rows % 2, usize::from(sel != Sel::All), "{c:?}: folded row");
            let mut jac = DMatrix::zeros(rows, 1);
            assert!(
                p.lone_path_jacobian(&c, &[th], &mask, &r, &mut jac),
                "{c:?}"
            );
            let h = 1e-4 * th.abs().max(1e-3);
            let (p2, p1, m1, m2) = (
                resid(th + 2.0 * h),
                resid(th + h),
                resid(th - h),
                resid(th - 2.0 * h),
            );
            let scale = (0..rows).map(|i| jac[(i, 0)].abs()).fold(0.0, f64::max);
            assert!(scale > 0.0, "{c:?}: zero column");
            for i in 0..rows {
                let fd = (-p2[i] + 8.0 * p1[i] - 8.0 * m1[i] + m2[i]) / (12.0 * h);
                assert!(
                    (fd - jac[(i, 0)]).abs() <= 1e-6 * scale,
                    "{c:?}, row {i}: analytic {} vs {fd}",
                    jac[(i, 0)]
                );
            }
        }
    }
}

/// The residual computed effect by effect over each channel's data (one dispatch per
/// channel) is the per-datum route's, bit for bit: every row against
/// `(G_d − core·path)/σ` from [`Problem::parts`] datum by datum, the folded row against the
/// root of the untouched channels' squares summed here in index order, on the whole band
/// (where the folded sums come from the cache) and on part of it; the response likewise;
/// and `V` is `Σ r²` of the rows.  Four effects stacked: a shifted configured mode, an
/// added mode (every channel), a lag on input 2 and a delay on input 2.
#[test]
fn the_channel_batched_residual_is_the_per_datum_one() {
    use crate::diagnose::effects::candidates::Sel;
    let base = PhysicalModel {
        mode: vec![ModeSpec {
            name: None,
            omega_n: 900.0,
            zeta: 0.01,
            mass: 1.0,
            input_gain: Gains::Vector(vec![1.0, -0.4, 0.7]),
            output_gain: Gains::Scalar(3e4),
        }],
        ..Default::default()
    };
    let omega = crate::system::logspace(100.0, 3000.0, 80);
    let data = Channels::of_model(
        &base,
        omega,
        vec![(0, 0), (0, 1), (0, 2)],
        1.1,
        (0.02, 1e-3),
    );
    let p = Problem::new(&base, &data).expect("problem");
    let on_input = Mods {
        cands: vec![Cand::Lag(Sel::Input(1)), Cand::Delay(Sel::Input(1))],
        theta: vec![1500f64.ln(), 2e-4],
    };
    let everywhere = Mods {
        cands: vec![
            Cand::ModeShift(0),
            Cand::Mode,
            Cand::Lag(Sel::Input(1)),
            Cand::Delay(Sel::Input(1)),
        ],
        theta: vec![
            910f64.ln(),
            1700f64.ln(),
            0.02f64.ln(),
            2e3,
            -1e3,
            5e2,
            1500f64.ln(),
            2e-4,
        ],
    };
    let whole: Vec<usize> = (0..data.len()).collect();
    let part: Vec<usize> = (0..data.len()).step_by(3).collect();
    for mods in [&on_input, &everywhere] {
        let acted: Vec<usize> = (0..3)
            .filter(|ch| mods.cands.iter().any(|c| c.acts_on(data.entries[*ch])))
            .collect();
        for mask in [&whole, &part] {
            let mut expected = Vec::new();
            for &ch in &acted {
                for &k in mask.iter() {
                    let (c, pa) = p.parts(mods, ch, Some(k), data.omega[k]);
                    let e = (data.g[ch][k] - c * pa) * p.inv_sigma[ch][k];
                    expected.extend([e.re, e.im]);
                }
            }
            if acted.len() < 3 {
                let mut folded = 0.0;
                for ch in (0..3).filter(|ch| !acted.contains(ch)) {
                    let mut s = 0.0;
                    for &k in mask.iter() {
                        let e =
                            (data.g[ch][k] - p.core0[ch][k] * p.path0[ch][k]) * p.inv_sigma[ch][k];
                        s += e.norm_sqr();
                    }
                    folded += s;
                }
                expected.push(f64::sqrt(folded));
            }
            let mut r = Vec::new();
            p.residual(mods, mask, &mut r);
            assert_eq!(
                r,
                expected,
                "{} effects, {} data",
                mods.cands.len(),
                mask.len()
            );
            let v: f64 = r.iter().map(|x| x * x).sum();
            assert_eq!(p.v(mods, mask), v);
        }
        let g = p.response(mods);
        for (ch, g_ch) in g.iter().enumerate() {
            for (k, g_k) in g_ch.iter().enumerate() {
                let (c, pa) = p.parts(mods, ch, Some(k), data.omega[k]);
                assert_eq!(*g_k, c * pa, "response, channel {ch}, datum {k}");
            }
        }
    }
}
