//! The loop-stability check beyond `m + p ≤ 7` (issue 9): a 4×4 unstable plant with a 4×4
//! dynamic controller, checked from coprime factors (state-space route of
//! `stability_ss`), against an independent computation: the eigenvalues of the closed-loop
//! state matrix `[[A_p − B_p D_k C_p, −B_p C_k], [B_k C_p, A_k]]` built from minimal
//! state-space realizations of the plant and the controller.  On small loops the
//! state-space route and the exact polynomial route agree.

use nalgebra::{DMatrix, Matrix4};
use num_complex::Complex64;
use rshape::model::closed_loop::{check_loop_with, LoopInstability, LoopRoute};
use rshape::system::{TfMatrix, TransferFunction};

/// Unstable poles `a_i`, stable poles `−b_i` of `p_i = 1/((s − a_i)(s + b_i))`.
const A: [f64; 4] = [0.5, 1.0, 1.5, 2.0];
const B: [f64; 4] = [3.0, 4.0, 5.0, 6.0];
/// Pole of the factors, `(s + c)²`.
const C: f64 = 3.0;
/// Pole of the controller's dynamics.
const POLE_K: f64 = 5.0;

fn u() -> Matrix4<f64> {
    Matrix4::new(
        1.0, 0.3, -0.2, 0.1, //
        0.2, 1.1, 0.4, -0.3, //
        -0.1, 0.2, 0.9, 0.5, //
        0.3, -0.4, 0.1, 1.2,
    )
}
fn w() -> Matrix4<f64> {
    Matrix4::new(
        0.8, -0.2, 0.1, 0.3, //
        0.1, 1.2, -0.3, 0.2, //
        0.4, 0.1, 1.0, -0.2, //
        -0.2, 0.3, 0.2, 0.9,
    )
}

/// `K = K₀ + K₁/(s + POLE_K)`: `K₀ = W⁻¹ diag(k) U⁻¹` (decouples the loop) plus coupling.
fn controller(k: [f64; 4]) -> (Matrix4<f64>, Matrix4<f64>) {
    let k0 =
        w().try_inverse().unwrap() * Matrix4::from_diagonal(&k.into()) * u().try_inverse().unwrap()
            + Matrix4::from_fn(|i, j| 0.05 * ((i + 2 * j) % 5) as f64 - 0.1);
    let k1 = Matrix4::from_fn(|i, j| {
        if i == j {
            2.0
        } else {
            0.3 * (i as f64 - j as f64)
        }
    });
    (k0, k1)
}

fn tf(n: &[f64], d: &[f64]) -> TransferFunction {
    TransferFunction::new(n.to_vec(), d.to_vec())
}

/// Coprime factors: `N = U diag(n_i)`, `D = W⁻¹ diag(d_i)` with `n_i = 1/(s+c)²`,
/// `d_i = (s − a_i)(s + b_i)/(s+c)²`, so `N D⁻¹ = U diag(p_i) W`; the controller is stable:
/// `(K, I)`.
fn factors(k: [f64; 4]) -> (TfMatrix, TfMatrix, TfMatrix, TfMatrix) {
    let q = [1.0, 2.0 * C, C * C];
    let (u, wi) = (u(), w().try_inverse().unwrap());
    let n = TfMatrix::from_rows(
        (0..4)
            .map(|i| (0..4).map(|j| tf(&[u[(i, j)]], &q)).collect())
            .collect(),
    )
    .unwrap();
    let d = TfMatrix::from_rows(
        (0..4)
            .map(|i| {
                (0..4)
                    .map(|j| {
                        let s = wi[(i, j)];
                        tf(&[s, s * (B[j] - A[j]), -s * A[j] * B[j]], &q)
                    })
                    .collect()
            })
            .collect(),
    )
    .unwrap();
    let (k0, k1) = controller(k);
    let nk = TfMatrix::from_rows(
        (0..4)
            .map(|i| {
                (0..4)
                    .map(|j| {
                        tf(
                            &[k0[(i, j)], k0[(i, j)] * POLE_K + k1[(i, j)]],
                            &[1.0, POLE_K],
                        )
                    })
                    .collect()
            })
            .collect(),
    )
    .unwrap();
    let dk = TfMatrix::diagonal(vec![TransferFunction::gain(1.0); 4]);
    (n, d, nk, dk)
}

/// The closed-loop poles from state space (independent of the factors).
fn closed_loop_poles(k: [f64; 4]) -> Vec<Complex64> {
    // Plant: diag(p_i) in controllable form, P = U G W.
    let mut ag = DMatrix::zeros(8, 8);
    let mut bg = DMatrix::zeros(8, 4);
    let mut cg = DMatrix::zeros(4, 8);
    for i in 0..4 {
        ag[(2 * i, 2 * i)] = -(B[i] - A[i]);
        ag[(2 * i, 2 * i + 1)] = A[i] * B[i];
        ag[(2 * i + 1, 2 * i)] = 1.0;
        bg[(2 * i, i)] = 1.0;
        cg[(i, 2 * i + 1)] = 1.0;
    }
    let uu = DMatrix::from_fn(4, 4, |i, j| u()[(i, j)]);
    let ww = DMatrix::from_fn(4, 4, |i, j| w()[(i, j)]);
    let (bp, cp) = (&bg * &ww, &uu * &cg);
    // Controller: A_k = −POLE_K·I, B_k = K₁, C_k = I, D_k = K₀.
    let (k0, k1) = controller(k);
    let dk = DMatrix::from_fn(4, 4, |i, j| k0[(i, j)]);
    let bk = DMatrix::from_fn(4, 4, |i, j| k1[(i, j)]);
    let mut acl = DMatrix::zeros(12, 12);
    acl.view_mut((0, 0), (8, 8))
        .copy_from(&(&ag - &bp * &dk * &cp));
    acl.view_mut((0, 8), (8, 4)).copy_from(&(-&bp));
    acl.view_mut((8, 0), (4, 8)).copy_from(&(&bk * &cp));
    acl.view_mut((8, 8), (4, 4))
        .copy_from(&(DMatrix::identity(4, 4) * -POLE_K));
    acl.complex_eigenvalues()
        .iter()
        .map(|z| Complex64::new(z.re, z.im))
        .collect()
}

fn rhp(v: &[Complex64]) -> Vec<Complex64> {
    let mut r: Vec<Complex64> = v.iter().copied().filter(|z| z.re >= 0.0).collect();
    r.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
    r
}

#[test]
fn four_by_four_stabilizing_controller_is_accepted() {
    // k_i = 3 a_i b_i: each decoupled channel s² + (b−a)s + (k − ab) is stable.
    let k = [0, 1, 2, 3].map(|i| 3.0 * A[i] * B[i]);
    let indep = closed_loop_poles(k);
    assert!(rhp(&indep).is_empty(), "independent poles {indep:?}");
    let (n, d, nk, dk) = factors(k);
    assert_eq!(check_loop_with(&n, &d, &nk, &dk, LoopRoute::Auto), Ok(()));
}

#[test]
fn four_by_four_unstable_loop_lists_the_same_poles() {
    // Channels 2 and 4 under-stabilized (k < ab): real closed-loop poles in Re s > 0.
    let k = [
        3.0 * A[0] * B[0],
        0.3 * A[1] * B[1],
        3.0 * A[2] * B[2],
        0.5 * A[3] * B[3],
    ];
    let want = rhp(&closed_loop_poles(k));
    assert_eq!(want.len(), 2, "{want:?}");
    let (n, d, nk, dk) = factors(k);
    match check_loop_with(&n, &d, &nk, &dk, LoopRoute::Auto) {
        Err(LoopInstability::RightHalfPlaneZeros(z)) => {
            let got = rhp(&z);
            assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).norm() < 1e-7 * w.norm().max(1.0), "{g} vs {w}");
            }
        }
        other => panic!("expected RHP poles, got {other:?}"),
    }
    // A plant pole exactly cancelled on the axis by a bad controller (k = ab: pole at 0).
    let k = [
        3.0 * A[0] * B[0],
        A[1] * B[1],
        3.0 * A[2] * B[2],
        3.0 * A[3] * B[3],
    ];
    let want = rhp(&closed_loop_poles(k));
    let (n, d, nk, dk) = factors(k);
    let r = check_loop_with(&n, &d, &nk, &dk, LoopRoute::Auto);
    assert_eq!(want.is_empty(), r.is_ok(), "{want:?} vs {r:?}");
}

#[test]
fn state_space_and_polynomial_routes_agree_on_small_loops() {
    // 2×2 sub-problems of the plant above (channels 1 and 2 only, m + p = 4).
    let q = [1.0, 2.0 * C, C * C];
    let (mut stable, mut unstable) = (0, 0);
    for (g1, g2) in [(3.0, 3.0), (3.0, 0.4), (0.2, 0.6), (1.5, 1.0)] {
        let n = TfMatrix::from_rows(vec![
            vec![tf(&[1.0], &q), tf(&[0.3], &q)],
            vec![tf(&[0.2], &q), tf(&[1.1], &q)],
        ])
        .unwrap();
        let d = TfMatrix::diagonal(
            (0..2)
                .map(|i| tf(&[1.0, B[i] - A[i], -A[i] * B[i]], &q))
                .collect(),
        );
        let nk = TfMatrix::from_rows(vec![
            vec![
                tf(
                    &[g1 * A[0] * B[0], g1 * A[0] * B[0] * POLE_K + 1.0],
                    &[1.0, POLE_K],
                ),
                tf(&[0.1], &[1.0, POLE_K]),
            ],
            vec![
                tf(&[-0.2], &[1.0]),
                tf(
                    &[g2 * A[1] * B[1], g2 * A[1] * B[1] * POLE_K],
                    &[1.0, POLE_K],
                ),
            ],
        ])
        .unwrap();
        let dk = TfMatrix::diagonal(vec![TransferFunction::gain(1.0); 2]);
        let exact = check_loop_with(&n, &d, &nk, &dk, LoopRoute::Polynomial);
        let ss = check_loop_with(&n, &d, &nk, &dk, LoopRoute::StateSpace);
        match (&exact, &ss) {
            (Ok(()), Ok(())) => stable += 1,
            (
                Err(LoopInstability::RightHalfPlaneZeros(a)),
                Err(LoopInstability::RightHalfPlaneZeros(b)),
            ) => {
                let (a, b) = (rhp(a), rhp(b));
                assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
                for (x, y) in a.iter().zip(&b) {
                    assert!((x - y).norm() < 1e-7 * x.norm().max(1.0), "{x} vs {y}");
                }
                unstable += 1;
            }
            _ => panic!("routes disagree for ({g1}, {g2}): {exact:?} vs {ss:?}"),
        }
    }
    assert!(
        stable >= 1 && unstable >= 1,
        "{stable} stable, {unstable} unstable"
    );
}
