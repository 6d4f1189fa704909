//! Are the given factors a coprime factorization at all?  Boulet & Francis (1998, eq. (1))
//! and Theorem 1 need `M̃, Ñ ∈ RH∞` (every entry proper with its poles in `Re s < 0`) and
//! left coprime: `[M̃ Ñ](s)` of full row rank at every `s` of the closed right half-plane,
//! `∞` included (Vidyasagar, *Control System Synthesis*, Sec. 4.1, Lemma 4.1.19's rank
//! test).  An unstable entry or a common right-half-plane zero would let a certificate be
//! issued for a plant the theory does not describe, so both are refused at load time.
//!
//! **Method.**  `[M̃ Ñ](s)` can lose rank only where `M̃(s)` does, i.e. at a zero of
//! `det M̃`.  With every entry stable, multiplying row `i` of `M̃` by the product of its
//! entries' denominators (a Hurwitz polynomial) adds no zero in `Re s ≥ 0`, so the
//! closed-right-half-plane zeros of `det M̃` are exactly those of the polynomial
//! `det(diag(q)·M̃)` ([`scaled_determinant`], exact cofactor expansion; for a diagonal `M̃`
//! simply the numerators of the diagonal).  Its roots come from the capped Aberth
//! iteration; at each root `z` with `Re z ≥ −10⁻⁸·max(1, |z|)` (on the axis to working
//! precision counts as in the half-plane) the rank of `[M̃ Ñ](z)` is tested, and at `∞` the
//! rank of `[M̃(∞) Ñ(∞)]`.
//!
//! **Tolerance.**  Each entry has an evaluation scale `S_ij(z) = Σ|a_k||z|^k / |den(z)|`
//! (the size its value would have without cancellation; at a zero of `M̃` its own value is
//! no scale).  The rows of `[M̃ Ñ](z)` are divided by their largest scale, then the columns
//! by theirs (a diagonal scaling on either side keeps the rank, and makes the test blind to
//! units: an `Ñ` of gain 1e-8 is as coprime as one of gain 1).  The rank is deficient when
//! the smallest singular value of the equilibrated matrix is `≤ 10⁻⁶`.  A common zero to about six digits is therefore refused (the data could
//! not tell it from an exact one, and a multiple root is computed only to about `√ε`),
//! while factors whose zeros differ by `10⁻³` relative are accepted.
//! The right-coprimeness of a pair `(N, D)` (`K = N D⁻¹`, as in `[closed_loop]`) is the
//! left-coprimeness of `(Dᵀ, Nᵀ)`.

use crate::model::closed_loop::stability::scaled_determinant;
use crate::system::{TfMatrix, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Relative rank tolerance of the coprimeness test (see the module documentation).
pub const COPRIME_TOL: f64 = 1e-6;

/// Largest `M̃` whose determinant is expanded by cofactors (`p!` products); a larger
/// non-diagonal `M̃` is refused with a message rather than checked approximately.
pub const MAX_COFACTOR_SIZE: usize = 8;

/// Roots of `Re z ≥ −SLACK·max(1, |z|)` count as in the closed right half-plane.
const SLACK: f64 = 1e-8;

/// `s` for a message: six decimals, trailing zeros dropped (`1`, `-0.5+2j`).
fn fmt_s(z: Complex64) -> String {
    let g = |x: f64| {
        let x = if x.abs() < 1e-12 { 0.0 } else { x };
        let t = format!("{x:.6}");
        let t = t.trim_end_matches('0').trim_end_matches('.');
        if t == "-0" {
            "0".to_string()
        } else {
            t.to_string()
        }
    };
    let (re, im) = (g(z.re), g(z.im));
    match im.as_str() {
        "0" => re,
        _ if im.starts_with('-') => format!("{re}{im}j"),
        _ => format!("{re}+{im}j"),
    }
}

/// The first pole of `tf` in `Re s ≥ 0`, if any (`Err` when the roots did not converge).
fn unstable_pole(tf: &TransferFunction) -> Result<Option<Complex64>, ()> {
    if tf.num.is_zero() {
        return Ok(None);
    }
    let r = tf.den.roots_capped(500);
    if !r.converged {
        return Err(());
    }
    Ok(r.roots
        .into_iter()
        .find(|p| p.re >= -1e-10 * p.norm().max(1.0)))
}

/// Checks every entry of `g` for properness and stability; `name(i, j)` names entry
/// `(i, j)` (0-based) in messages, `what` says which factor it is.
pub fn check_stable(
    g: &TfMatrix,
    name: &dyn Fn(usize, usize) -> String,
    what: &str,
) -> Result<(), String> {
    for i in 0..g.rows() {
        for j in 0..g.cols() {
            let tf = g.entry(i, j);
            if tf.num.is_zero() {
                continue;
            }
            match unstable_pole(tf) {
                Err(()) => {
                    return Err(format!(
                        "{}: the poles could not be computed (root iteration cap); check the denominator",
                        name(i, j)
                    ))
                }
                Ok(Some(p)) => {
                    return Err(format!(
                        "{}: pole at s = {} (Re s ≥ 0): {what} must be stable (in RH∞); give a stable coprime factorization",
                        name(i, j),
                        fmt_s(p)
                    ))
                }
                Ok(None) => {}
            }
        }
    }
    Ok(())
}

/// The evaluation scale of `tf` at `z`: `Σ|a_k||z|^k / |den(z)|`.
fn scale_at(tf: &TransferFunction, z: Complex64) -> f64 {
    let r = z.norm();
    let n = tf.num.coeffs();
    let d = n.len().saturating_sub(1);
    let sum: f64 = n
        .iter()
        .enumerate()
        .map(|(k, c)| c.abs() * r.powi((d - k) as i32))
        .sum();
    sum / tf.den.eval(z).norm()
}

/// A zero of `[M̃ Ñ]`'s rank: where, and which row carries the null direction (0-based).
#[derive(Debug, Clone, PartialEq)]
pub struct CommonZero {
    /// The point (`None` for `s = ∞`).
    pub at: Option<Complex64>,
    /// The row of `[M̃ Ñ]` with the largest weight in the left null vector.
    pub row: usize,
    /// `σ_min / S` at the point.
    pub ratio: f64,
}

/// Candidate points: the zeros of `det M̃` in (or on the edge of) the closed right half-plane.
fn candidate_zeros(m: &TfMatrix) -> Result<Vec<Complex64>, String> {
    let p = m.rows();
    let diagonal = (0..p).all(|i| (0..p).all(|j| i == j || m.entry(i, j).num.is_zero()));
    let polys: Vec<crate::system::Polynomial> = if diagonal {
        (0..p).map(|i| m.entry(i, i).num.clone()).collect()
    } else if p <= MAX_COFACTOR_SIZE {
        let rows: Vec<Vec<TransferFunction>> = (0..p)
            .map(|i| (0..p).map(|j| m.entry(i, j).clone()).collect())
            .collect();
        vec![scaled_determinant(&rows)]
    } else {
        return Err(format!(
            "M̃ is {p}×{p} and not diagonal: coprimeness is checked for a full M̃ up to {MAX_COFACTOR_SIZE}×{MAX_COFACTOR_SIZE}; give M̃ diagonal (m_diag) or fewer rows"
        ));
    };
    let mut out = Vec::new();
    for poly in polys {
        if poly.is_zero() {
            return Err("det M̃ is identically zero: M̃ is singular, G = M̃⁻¹Ñ does not exist".into());
        }
        let r = poly.roots_capped(500);
        if !r.converged {
            return Err(
                "the zeros of det M̃ could not be computed (root iteration cap); check M̃".into(),
            );
        }
        out.extend(
            r.roots
                .into_iter()
                .filter(|z| z.re >= -SLACK * z.norm().max(1.0) && z.im >= 0.0),
        );
    }
    Ok(out)
}

/// Row rank test of `value` with entry scales `scale` (`S_ij ≥ 0`).  Rows and columns are
/// first equilibrated by their largest scales (`r_i`, then `c_j`): a diagonal scaling on
/// either side keeps the rank and makes the test independent of units (an `Ñ` of gain 1e-8
/// beside an `M̃` of gain 1 is as coprime as with gain 1).  A row whose scales are all zero
/// vanishes identically.  `Some((row, σ_min))` when `σ_min ≤ COPRIME_TOL`.
fn rank_drop(value: &DMatrix<Complex64>, scale: &DMatrix<f64>) -> Option<(usize, f64)> {
    let (p, q) = value.shape();
    let r: Vec<f64> = (0..p)
        .map(|i| (0..q).map(|j| scale[(i, j)]).fold(0.0, f64::max))
        .collect();
    if let Some(i) = r.iter().position(|x| !(*x > 0.0 && x.is_finite())) {
        return Some((i, 0.0));
    }
    let c: Vec<f64> = (0..q)
        .map(|j| (0..p).map(|i| scale[(i, j)] / r[i]).fold(0.0, f64::max))
        .collect();
    let rows = DMatrix::from_fn(p, q, |i, j| {
        if c[j] > 0.0 {
            value[(i, j)] / (r[i] * c[j])
        } else {
            Complex64::new(0.0, 0.0)
        }
    });
    let svd = rows.svd(true, false);
    let (k, smin) = svd
        .singular_values
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let ratio = smin;
    if ratio.is_finite() && ratio > COPRIME_TOL {
        return None;
    }
    let u = svd.u.as_ref()?;
    let row = (0..u.nrows())
        .max_by(|a, b| u[(*a, k)].norm().total_cmp(&u[(*b, k)].norm()))
        .unwrap_or(0);
    Some((row, ratio))
}

/// The first point of the closed right half-plane (or `∞`) where `[M̃ Ñ]` loses row rank;
/// `Ok(None)` when `M̃`, `Ñ` are left coprime.  The entries must be stable (see
/// [`check_stable`]).
pub fn common_zero(m: &TfMatrix, n: &TfMatrix) -> Result<Option<CommonZero>, String> {
    let p = m.rows();
    let all = |f: &dyn Fn(&TransferFunction) -> Complex64| {
        DMatrix::from_fn(p, p + n.cols(), |i, j| {
            if j < p {
                f(m.entry(i, j))
            } else {
                f(n.entry(i, j - p))
            }
        })
    };
    let inf = all(&|t| Complex64::new(t.at_infinity(), 0.0));
    if let Some((row, ratio)) = rank_drop(&inf, &inf.map(|x| x.norm())) {
        return Ok(Some(CommonZero {
            at: None,
            row,
            ratio,
        }));
    }
    for z in candidate_zeros(m)? {
        let value = all(&|t| t.eval(z));
        let scale = all(&|t| Complex64::new(scale_at(t, z), 0.0)).map(|x| x.re);
        if let Some((row, ratio)) = rank_drop(&value, &scale) {
            return Ok(Some(CommonZero {
                at: Some(z),
                row,
                ratio,
            }));
        }
    }
    Ok(None)
}

/// [`check_stable`] on both factors and [`common_zero`], with messages naming `table`
/// (`"[model]"`) and the keys `m_key`, `n_key`.
pub fn check_left_coprime(
    m: &TfMatrix,
    n: &TfMatrix,
    table: &str,
    keys: (&str, &str),
) -> Result<(), String> {
    let (mk, nk) = keys;
    let entry = |k: &str| {
        let (t, k) = (table.to_string(), k.to_string());
        move |i: usize, j: usize| {
            if k == "m_diag" {
                format!("{t} {k}[{}]", i + 1)
            } else {
                format!("{t} {k}[{}][{}]", i + 1, j + 1)
            }
        }
    };
    check_stable(m, &entry(mk), "M̃")?;
    check_stable(n, &entry(nk), "Ñ")?;
    report(
        common_zero(m, n)?,
        table,
        &format!("row {{}} of {mk} and {nk}"),
        "left",
    )
}

/// Right coprimeness of `K = N D⁻¹` (`N` `a×b`, `D` `b×b`): stable entries and `[D; N]` of
/// full column rank in the closed right half-plane.
pub fn check_right_coprime(
    n: &TfMatrix,
    d: &TfMatrix,
    table: &str,
    keys: (&str, &str),
) -> Result<(), String> {
    let (nk, dk) = keys;
    let entry = |k: &str| {
        let (t, k) = (table.to_string(), k.to_string());
        move |i: usize, j: usize| format!("{t} {k}[{}][{}]", i + 1, j + 1)
    };
    check_stable(n, &entry(nk), "the factor")?;
    check_stable(d, &entry(dk), "the factor")?;
    let (dt, nt) = (transpose(d), transpose(n));
    report(
        common_zero(&dt, &nt)?,
        table,
        &format!("column {{}} of {nk} and {dk}"),
        "right",
    )
}

fn report(z: Option<CommonZero>, table: &str, place: &str, side: &str) -> Result<(), String> {
    let Some(z) = z else { return Ok(()) };
    let place = place.replace("{}", &(z.row + 1).to_string());
    Err(match z.at {
        Some(s) => format!(
            "{table}: the factors have a common zero at s = {} (Re s ≥ 0, {place}; equilibrated σ_min = {:.1e} ≤ {COPRIME_TOL:.0e}): they are not {side} coprime; cancel the common factor",
            fmt_s(s),
            z.ratio
        ),
        None => format!(
            "{table}: the factors lose rank at s = ∞ ({place} vanish there): they are not {side} coprime; make M̃(∞) (the denominator factor at infinity) invertible"
        ),
    })
}

fn transpose(g: &TfMatrix) -> TfMatrix {
    let rows: Vec<Vec<TransferFunction>> = (0..g.cols())
        .map(|j| (0..g.rows()).map(|i| g.entry(i, j).clone()).collect())
        .collect();
    TfMatrix::from_rows(rows).expect("non-empty")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(num: &[f64], den: &[f64]) -> TfMatrix {
        TfMatrix::from_rows(vec![vec![TransferFunction::new(
            num.to_vec(),
            den.to_vec(),
        )]])
        .unwrap()
    }

    /// `(s − 1)(s + 1)^{-2}` times `(s − 1 − δ)`: the distance of Ñ's zero from M̃'s.
    fn near(delta: f64) -> Result<(), String> {
        let m = one(&[1.0, -1.0], &[1.0, 1.0]);
        let n = one(&[1.0, -1.0 - delta], &[1.0, 2.0, 1.0]);
        check_left_coprime(&m, &n, "[model]", ("m", "n"))
    }

    #[test]
    fn common_rhp_zero_is_refused_and_a_near_one_by_the_tolerance() {
        assert!(near(0.0).unwrap_err().contains("common zero at s = 1"));
        assert!(near(1e-9).is_err());
        // Closed form: at s = 1, Ñ(1) = −δ/4 with scale ≈ 1/2, so the equilibrated σ_min ≈ δ/2.
        assert!(near(1e-3).is_ok());
        assert!(near(-0.5).is_ok());
    }

    #[test]
    fn double_common_zero_and_axis_zero() {
        // (s − 1)² in both: a double root computed to ~√ε still fails the test.
        let m = one(&[1.0, -2.0, 1.0], &[1.0, 2.0, 1.0]);
        let n = one(&[1.0, -2.0, 1.0], &[1.0, 3.0, 3.0, 1.0]);
        assert!(check_left_coprime(&m, &n, "[model]", ("m", "n")).is_err());
        // A rigid body: M̃ = s²/(s+1)², Ñ = 1/(s+1)²: zero at the origin, coprime.
        let m = one(&[1.0, 0.0, 0.0], &[1.0, 2.0, 1.0]);
        let n = one(&[1.0], &[1.0, 2.0, 1.0]);
        assert!(check_left_coprime(&m, &n, "[model]", ("m", "n")).is_ok());
        // Both vanish at the origin: not coprime.
        let n = one(&[1.0, 0.0], &[1.0, 2.0, 1.0]);
        assert!(check_left_coprime(&m, &n, "[model]", ("m", "n")).is_err());
    }

    #[test]
    fn units_do_not_decide_coprimeness() {
        // Ñ of gain 1e-8 (or 1e8) beside M̃ = (s − 1)/(s + 1): coprime whatever the units.
        for g in [1e-8, 1e8] {
            let m = one(&[1.0, -1.0], &[1.0, 1.0]);
            let n = one(&[g], &[1.0, 2.0, 1.0]);
            assert!(
                check_left_coprime(&m, &n, "[model]", ("m", "n")).is_ok(),
                "{g}"
            );
            // … and a common zero stays common at any gain.
            let n = one(&[g, -g], &[1.0, 2.0, 1.0]);
            assert!(
                check_left_coprime(&m, &n, "[model]", ("m", "n")).is_err(),
                "{g}"
            );
        }
    }

    #[test]
    fn unstable_entry_is_named() {
        let m = one(&[1.0, 2.0], &[1.0, -1.0]);
        let n = one(&[1.0], &[1.0, 1.0]);
        let e = check_left_coprime(&m, &n, "[model]", ("m", "n")).unwrap_err();
        assert!(e.contains("[model] m[1][1]") && e.contains("s = 1"), "{e}");
    }

    #[test]
    fn mimo_common_zero_by_rows() {
        // M̃ = diag((s−2)/(s+1), 1), Ñ = [(s−2)/(s+1)², 1/(s+3)]ᵀ … row 1 all vanish at 2.
        let t = |n: &[f64], d: &[f64]| TransferFunction::new(n.to_vec(), d.to_vec());
        let m = TfMatrix::from_rows(vec![
            vec![t(&[1.0, -2.0], &[1.0, 1.0]), t(&[0.5], &[1.0, 4.0])],
            vec![t(&[0.0], &[1.0]), t(&[1.0], &[1.0])],
        ])
        .unwrap();
        let n = TfMatrix::from_rows(vec![
            vec![t(&[1.0, -2.0], &[1.0, 2.0, 1.0])],
            vec![t(&[1.0], &[1.0, 3.0])],
        ])
        .unwrap();
        // Row 1 of [M̃ Ñ] at s = 2 is [0, 0.5/6, 0]; row 2 is [0, 1, 1/5]: full rank.
        assert!(check_left_coprime(&m, &n, "[model]", ("m", "n")).is_ok());
        // With M̃₁₂ = 0 the first row vanishes at s = 2.
        let m0 = TfMatrix::from_rows(vec![
            vec![t(&[1.0, -2.0], &[1.0, 1.0]), t(&[0.0], &[1.0])],
            vec![t(&[0.0], &[1.0]), t(&[1.0], &[1.0])],
        ])
        .unwrap();
        let e = check_left_coprime(&m0, &n, "[model]", ("m", "n")).unwrap_err();
        assert!(e.contains("s = 2") && e.contains("row 1"), "{e}");
    }
}
