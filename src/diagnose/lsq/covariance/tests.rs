use super::*;
use crate::diagnose::lsq::slots::slots;
use crate::diagnose::lsq::varpro::tests::{channels, model};

/// The whole model's weighted residual, datum by datum (an independent route: every term
/// evaluated, no structure used).
fn residual(m: &PhysicalModel, data: &Channels) -> Vec<f64> {
    let mut out = Vec::new();
    for (k, w) in data.omega.iter().enumerate() {
        let g = m.eval(*w);
        for (ch, e) in data.entries.iter().enumerate() {
            let d = (data.g[ch][k] - g[*e]) * (std::f64::consts::SQRT_2 / data.radius[ch][k]);
            out.push(d.re);
            out.push(d.im);
        }
    }
    out
}

/// `(2JᵀJ)⁻¹` inverted by Cholesky, from the whole model's residual differenced over each
/// slot: forward with the covariance's own steps (`central = false`), or central.
fn reference(
    m: &PhysicalModel,
    lin: &[Lin],
    nl: &[Nl],
    data: &Channels,
    central: bool,
) -> DMatrix<f64> {
    let all: Vec<Slot> = lin
        .iter()
        .map(|l| Slot::Lin(*l))
        .chain(nl.iter().map(|s| Slot::Nl(*s)))
        .collect();
    let rows = 2 * data.len() * data.n_ch();
    let w_max = *data.omega.last().unwrap();
    let r0 = residual(m, data);
    let mut jac = DMatrix::<f64>::zeros(rows, all.len());
    for (j, s) in all.iter().enumerate() {
        let (t, h) = stepped(m, *s, w_max);
        let rp = residual(&t, data);
        if central {
            // The same step backwards: `x − h`.
            let mut b = m.clone();
            match s {
                Slot::Lin(l) => set_lin(&mut b, *l, 2.0 * get_lin(m, *l) - get_lin(&t, *l)),
                Slot::Nl(q) => set_nl(&mut b, *q, 2.0 * get_nl(m, *q) - get_nl(&t, *q)),
            }
            let rm = residual(&b, data);
            for i in 0..rows {
                jac[(i, j)] = (rp[i] - rm[i]) / (2.0 * h);
            }
        } else {
            for i in 0..rows {
                jac[(i, j)] = (rp[i] - r0[i]) / h;
            }
        }
    }
    (jac.transpose() * &jac * 2.0)
        .cholesky()
        .expect("full rank")
        .inverse()
}

/// σ and correlations of the structured route (one term per column, QR then SVD) against
/// `(2JᵀJ)⁻¹` of the whole model's residual inverted by Cholesky (no structure, no QR, no
/// SVD) on a rigid body with friction, two modes with three input gains each, a
/// feedthrough matrix, an input delay and a lag (every kind of part a slot can change):
/// with the same forward differences, σ within 1e-6 and correlations within 1e-6; with
/// central differences (no truncation error of order `h`), σ within 1e-3 (what the forward
/// differences' truncation leaves: 1.5e-4 here).
#[test]
fn the_structured_covariance_matches_the_whole_models() {
    let truth = model(1.0);
    let data = channels(&truth);
    // Off the optimum, so the Jacobian is that of a refit that is not exact.
    let m = model(1.02);
    let (lin, nl) = slots(&m, &data);
    let n = lin.len() + nl.len();
    assert!(n >= 15, "{n} slots");
    let (sigma, corr) = slot_covariance(&m, &lin, &nl, &data);
    let corr = corr.expect("full rank: correlations");
    let forward = reference(&m, &lin, &nl, &data, false);
    let central = reference(&m, &lin, &nl, &data, true);
    for j in 0..n {
        let s_fwd = forward[(j, j)].sqrt();
        let s_cen = central[(j, j)].sqrt();
        assert!(
            (sigma[j] - s_fwd).abs() <= 1e-6 * s_fwd,
            "slot {j}: σ {} vs {s_fwd} (forward)",
            sigma[j]
        );
        assert!(
            (sigma[j] - s_cen).abs() <= 1e-3 * s_cen,
            "slot {j}: σ {} vs {s_cen} (central)",
            sigma[j]
        );
        for k in 0..n {
            let c_ref = forward[(j, k)] / (s_fwd * forward[(k, k)].sqrt());
            assert!(
                (corr[(j, k)] - c_ref).abs() <= 1e-6,
                "slots {j}, {k}: correlation {} vs {c_ref}",
                corr[(j, k)]
            );
        }
    }
}

/// More slots than residual rows (the data cannot determine them all): every coordinate
/// with a share in the directions the data do not see gets `σ = ∞`, and no correlation
/// matrix is returned.  Two modes (ω_n, ζ and a residue each: 6 slots) on one channel at
/// two lines (4 real values).
#[test]
fn a_wide_jacobian_leaves_the_unseen_directions_undetermined() {
    let truth = model(1.0);
    let mut data = channels(&truth);
    let keep = [10, 80];
    data.omega = keep.iter().map(|k| data.omega[*k]).collect();
    for ch in 0..data.n_ch() {
        data.g[ch] = keep.iter().map(|k| data.g[ch][*k]).collect();
        data.radius[ch] = keep.iter().map(|k| data.radius[ch][*k]).collect();
    }
    let mut m = truth.clone();
    m.rigid_body.clear();
    m.feedthrough = None;
    m.effect.clear();
    data.entries.truncate(1);
    data.g.truncate(1);
    data.radius.truncate(1);
    data.radius_source.truncate(1);
    let (lin, nl) = slots(&m, &data);
    // One input seen: no input-gain slots.
    assert!(nl.iter().all(|s| !matches!(s, Nl::In(..))), "{nl:?}");
    let n = lin.len() + nl.len();
    let rows = 2 * data.len() * data.n_ch();
    assert!(n > rows, "{n} slots, {rows} rows");
    let (sigma, corr) = slot_covariance(&m, &lin, &nl, &data);
    assert!(corr.is_none());
    // An independent count: J has rank at most `rows`, so at least `n − rows` unit
    // directions of the slot space (after any change of basis) are unseen, and no more
    // than `rows` coordinates can be determined.
    let finite = sigma.iter().filter(|s| s.is_finite()).count();
    assert!(finite <= rows, "{finite} finite σ with {rows} rows");
    assert!(sigma.iter().any(|s| s.is_infinite()));
}

/// The factored SVD ([`svd_right`]) of a wide, a square and a tall matrix against nalgebra's
/// direct SVD: the same singular values (sorted) and the same projector `VᵀV` onto the
/// right singular vectors (signs and order aside), to 1e-10.
#[test]
fn the_factored_svd_matches_the_direct_one() {
    for (rows, n) in [(7, 19), (9, 9), (40, 6)] {
        // Full rank (a pseudo-random fill): every singular vector is defined.
        let mut state = 12345u64 + (rows * n) as u64;
        let a = DMatrix::<f64>::from_fn(rows, n, |_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        });
        let (s, vt) = svd_right(a.clone()).expect("svd");
        let direct = a.clone().svd(false, true);
        let sorted = |v: &DVector<f64>| {
            let mut x: Vec<f64> = v.iter().copied().collect();
            x.sort_by(f64::total_cmp);
            x
        };
        let (s1, s2) = (sorted(&s), sorted(&direct.singular_values));
        assert_eq!(s1.len(), s2.len());
        for (x, y) in s1.iter().zip(&s2) {
            assert!(
                (x - y).abs() <= 1e-10 * s2[s2.len() - 1],
                "{rows}×{n}: {x} vs {y}"
            );
        }
        let vt2 = direct.v_t.unwrap();
        let (p1, p2) = (vt.transpose() * &vt, vt2.transpose() * &vt2);
        assert!((p1 - p2).amax() <= 1e-10, "{rows}×{n}: projectors differ");
    }
}
