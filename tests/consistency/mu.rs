//! Property tests of the structured singular value for `Γ = {diag(Δ̃, w̃)}` (eqs. (16)–(17)).

use nalgebra::DMatrix;
use num_complex::Complex64;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rshape::mu::{mu_full_scalar, FullPlusScalar, MuSettings, MuStatus};

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

/// A random `(n+2)×(n+1)` complex matrix; entry magnitudes spread over `10^±spread`.
fn random_m(seed: u64, n: usize, spread: f64) -> DMatrix<Complex64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    DMatrix::from_fn(n + 2, n + 1, |_, _| {
        let mag = 10f64.powf(rng.gen_range(-spread..=spread));
        let ph = rng.gen_range(0.0..std::f64::consts::TAU);
        Complex64::from_polar(mag, ph)
    })
}

fn sigma_max(a: &DMatrix<Complex64>) -> f64 {
    a.clone().svd(false, false).singular_values.max()
}

fn sigma_min(a: &DMatrix<Complex64>) -> f64 {
    a.clone().svd(false, false).singular_values.min()
}

/// Spectral radius through a capped complex Schur form.
fn spectral_radius(a: &DMatrix<Complex64>) -> f64 {
    let schur = a
        .clone()
        .try_schur(1e-14, 10_000)
        .expect("Schur form converges");
    let (_, t) = schur.unpack();
    (0..t.nrows()).map(|i| t[(i, i)].norm()).fold(0.0, f64::max)
}

/// Checks everything the acceptance criterion asks of one matrix.
fn check_bounds(m: &DMatrix<Complex64>, n: usize) -> Result<(), TestCaseError> {
    let s = FullPlusScalar::gamma(n);
    let r = mu_full_scalar(m, s, &MuSettings::default()).unwrap();
    prop_assert_eq!(r.status, MuStatus::Converged, "{:?}", r);
    // Both bounds are computed in floating point: allow rounding only (a few ulps).
    prop_assert!(
        r.lower <= r.upper * (1.0 + 1e-13),
        "lower {} > upper {}",
        r.lower,
        r.upper
    );
    prop_assert!(r.rel_gap <= 1e-9, "gap {}", r.rel_gap);
    prop_assert!((r.upper - r.lower) / r.upper <= 1e-9);
    // The certificate: structured, ‖Δ‖ = 1/lower, I − MΔ singular.
    let delta = r.certificate(m).expect("μ > 0 has a certificate");
    prop_assert_eq!(delta.shape(), (n + 1, n + 2));
    for i in 0..n {
        prop_assert_eq!(delta[(i, n + 1)], c(0.0, 0.0));
    }
    for j in 0..n + 1 {
        prop_assert_eq!(delta[(n, j)], c(0.0, 0.0));
    }
    let norm = sigma_max(&delta);
    prop_assert!(
        (norm * r.lower - 1.0).abs() <= 1e-12,
        "‖Δ‖·lower = {}",
        norm * r.lower
    );
    let sing = DMatrix::<Complex64>::identity(n + 2, n + 2) - m * &delta;
    let smin = sigma_min(&sing);
    prop_assert!(
        smin <= 1e-12 * (1.0 + sigma_max(m) * norm),
        "σ_min(I − MΔ) = {smin}"
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Random Γ-structured matrices with entries of order one.
    #[test]
    fn bounds_meet_with_certificate(seed in any::<u64>(), n in 1usize..=6) {
        let m = random_m(seed, n, 0.0);
        check_bounds(&m, n)?;
    }

    /// Entries spread over six decades (like the robot model's LFT).
    #[test]
    fn bounds_meet_badly_scaled(seed in any::<u64>(), n in 1usize..=6) {
        let m = random_m(seed, n, 3.0);
        check_bounds(&m, n)?;
    }

    /// Nearly block-triangular matrices (`M₁₂` or `M₂₁` scaled by 1e-12): the optimal `d`
    /// runs off towards 0 or ∞.
    #[test]
    fn bounds_meet_nearly_triangular(seed in any::<u64>(), n in 1usize..=5, which in 0usize..2) {
        let mut m = random_m(seed, n, 0.0);
        if which == 0 {
            for i in 0..=n {
                m[(i, n)] *= 1e-12;
            }
        } else {
            for j in 0..n {
                m[(n + 1, j)] *= 1e-12;
            }
        }
        check_bounds(&m, n)?;
    }

    /// Zero-diagonal two-scalar matrices have a repeated `σ̄` at the optimal `d` (a kink).
    #[test]
    fn bounds_meet_at_a_kink(b_re in -3.0f64..3.0, b_im in -3.0f64..3.0, c_re in -3.0f64..3.0, c_im in 0.01f64..3.0) {
        let m = DMatrix::from_row_slice(2, 2, &[c(0.0, 0.0), c(b_re, b_im), c(c_re, c_im), c(0.0, 0.0)]);
        let r = mu_full_scalar(&m, FullPlusScalar { rows: 1, cols: 1 }, &MuSettings::default()).unwrap();
        let exact = (c(b_re, b_im) * c(c_re, c_im)).norm().sqrt();
        prop_assume!(exact > 1e-6);
        prop_assert_eq!(r.status, MuStatus::Converged);
        prop_assert!((r.upper - exact).abs() <= 1e-9 * exact && (r.lower - exact).abs() <= 1e-9 * exact);
    }

    /// The upper bound is a true bound: no structured Δ with ‖Δ‖ < 1/upper destabilizes,
    /// i.e. ρ(MΔ) ≤ 1 for random structured Δ scaled to ‖Δ‖ = 1/upper.
    #[test]
    fn upper_bound_is_not_beaten(seed in any::<u64>(), n in 1usize..=5) {
        let m = random_m(seed, n, 0.0);
        let r = mu_full_scalar(&m, FullPlusScalar::gamma(n), &MuSettings::default()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9);
        for _ in 0..20 {
            let mut delta = DMatrix::zeros(n + 1, n + 2);
            for i in 0..n {
                for j in 0..n + 1 {
                    delta[(i, j)] = c(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
                }
            }
            delta[(n, n + 1)] = Complex64::from_polar(1.0, rng.gen_range(0.0..6.3));
            let full = delta.view((0, 0), (n, n + 1)).into_owned();
            let scale_full = 1.0 / (r.upper * sigma_max(&full));
            for i in 0..n {
                for j in 0..n + 1 {
                    delta[(i, j)] *= scale_full;
                }
            }
            delta[(n, n + 1)] /= r.upper;
            let rho = spectral_radius(&(&m * &delta));
            prop_assert!(rho <= 1.0 + 1e-9, "ρ(MΔ) = {rho} with ‖Δ‖ = 1/upper");
        }
    }
}

/// Two scalar blocks (`Δ̃` 1×1) with zero diagonal: `det(I − MΔ) = 1 − bc·δ₁δ₂`, so
/// `μ = √|bc|` exactly.
#[test]
fn two_scalars_closed_form() {
    let (b, cc) = (c(3.0, -1.0), c(0.02, 0.5));
    let m = DMatrix::from_row_slice(2, 2, &[c(0.0, 0.0), b, cc, c(0.0, 0.0)]);
    let s = FullPlusScalar { rows: 1, cols: 1 };
    let r = mu_full_scalar(&m, s, &MuSettings::default()).unwrap();
    let exact = (b * cc).norm().sqrt();
    assert_eq!(r.status, MuStatus::Converged);
    assert!(
        (r.upper - exact).abs() <= 1e-9 * exact,
        "{} vs {exact}",
        r.upper
    );
    assert!(
        (r.lower - exact).abs() <= 1e-9 * exact,
        "{} vs {exact}",
        r.lower
    );
}

/// `M₁₂ = 0`: block triangular, `μ = max(σ̄(M₁₁), |M₂₂|)`, for either maximizer.
#[test]
fn block_triangular_is_exact() {
    for m22 in [c(0.1, 0.0), c(0.0, 40.0)] {
        let mut m = random_m(7, 3, 0.0);
        for i in 0..4 {
            m[(i, 3)] = c(0.0, 0.0);
        }
        m[(4, 3)] = m22;
        let m11 = m.view((0, 0), (4, 3)).into_owned();
        let exact = sigma_max(&m11).max(m22.norm());
        let r = mu_full_scalar(&m, FullPlusScalar::gamma(3), &MuSettings::default()).unwrap();
        assert_eq!(r.status, MuStatus::Converged);
        assert!((r.upper - exact).abs() <= 1e-12 * exact);
        assert!((r.lower - exact).abs() <= 1e-12 * exact);
        let delta = r.certificate(&m).unwrap();
        let sing = DMatrix::<Complex64>::identity(5, 5) - &m * &delta;
        assert!(sigma_min(&sing) <= 1e-12);
    }
}

/// `μ` of the zero matrix is 0 (eq. (17): nothing makes `I − MΔ` singular).
#[test]
fn zero_matrix_has_zero_mu() {
    let m = DMatrix::<Complex64>::zeros(4, 3);
    let r = mu_full_scalar(&m, FullPlusScalar::gamma(2), &MuSettings::default()).unwrap();
    assert_eq!((r.upper, r.lower), (0.0, 0.0));
    assert!(r.certificate(&m).is_none());
}

/// Shapes that do not match the structure are errors, non-finite entries a status.
#[test]
fn bad_inputs() {
    let m = DMatrix::<Complex64>::zeros(4, 4);
    assert!(mu_full_scalar(&m, FullPlusScalar::gamma(2), &MuSettings::default()).is_err());
    let mut m = random_m(1, 2, 0.0);
    m[(0, 0)] = c(f64::NAN, 0.0);
    let r = mu_full_scalar(&m, FullPlusScalar::gamma(2), &MuSettings::default()).unwrap();
    assert_eq!(r.status, MuStatus::NonFinite);
}

/// A matrix the property test above found (stop 51; seed 15163855199026464158, n = 5) on
/// which the search ends with a gap of 11 % (lower 3.928, upper 4.412 after 81
/// evaluations): the μ bounds do not always meet.  Until they do, the promise here is that
/// the result says so — `GapAboveTolerance` with the gap it reports — and that both bounds
/// stay bounds: the certificate at `1/lower` makes `I − MΔ` singular, and `upper` lies
/// between `lower` and `σ̄(M)` (`μ ≤ σ̄`, the scaling `d = 1`).
#[test]
fn a_gap_that_stays_open_is_reported_with_valid_bounds() {
    let n = 5;
    let m = random_m(15163855199026464158, n, 0.0);
    let r = mu_full_scalar(&m, FullPlusScalar::gamma(n), &MuSettings::default()).unwrap();
    if r.status == MuStatus::Converged {
        // Mended: then it must meet the property test's promise in full.
        check_bounds(&m, n).unwrap();
        return;
    }
    assert_eq!(r.status, MuStatus::GapAboveTolerance, "{r:?}");
    assert!(r.lower > 0.0 && r.lower <= r.upper * (1.0 + 1e-13), "{r:?}");
    assert!(r.upper <= sigma_max(&m) * (1.0 + 1e-12), "{r:?}");
    assert!(((r.upper - r.lower) / r.upper - r.rel_gap).abs() <= 1e-12 && r.rel_gap > 1e-9);
    let delta = r.certificate(&m).expect("a certificate");
    let norm = sigma_max(&delta);
    assert!(
        (norm * r.lower - 1.0).abs() <= 1e-12,
        "‖Δ‖·lower = {}",
        norm * r.lower
    );
    let sing = DMatrix::<Complex64>::identity(n + 2, n + 2) - &m * &delta;
    assert!(sigma_min(&sing) <= 1e-12 * (1.0 + sigma_max(&m) * norm));
}
