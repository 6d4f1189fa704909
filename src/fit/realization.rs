//! A well-scaled state-space realization of the fitted unit `r(s)` for `r.json`
//! (GitHub issue 11, defect 6).
//!
//! The companion form of `num/den` has coefficients spanning many decades for fits over a
//! wide band, and its frequency response drifted from `num/den` by up to 6e-8 relative.
//! Here `r = g·Π H_k` is realized as a cascade of biproper sections built from the poles and
//! zeros directly:
//!
//! * a real pole `p` with a real zero `z`: `(s − z)/(s − p) = 1 + (p − z)/(s − p)`;
//! * a complex pole pair `σ ± jω` with two zeros: `1 + (c₁s + c₀)/((s − σ)² + ω²)` in the
//!   real modal form `A = [[σ, ω], [−ω, σ]]`;
//! * two real poles with a complex zero pair: `A = [[p₁, 0], [α, p₂]]`, `α = √|p₁p₂|` (a chain);
//!
//! each with its input and output gains balanced (`|B| = |C|`), and the gain `g` spread
//! evenly over the sections.  The series connection is block lower triangular.

use super::spectral::Zpk;
use crate::system::StateSpace;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// One biproper section `D + C(sI − A)⁻¹B` of order 1 or 2.
struct Section {
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    c: DMatrix<f64>,
    d: f64,
}

/// Monic real quadratic `s² + q₁s + q₀` of two roots (a conjugate pair or two reals).
fn quad(r1: Complex64, r2: Complex64) -> (f64, f64) {
    (-(r1 + r2).re, (r1 * r2).re)
}

fn balanced(num: f64) -> (f64, f64) {
    let m = num.abs().sqrt();
    if m == 0.0 {
        (1.0, 0.0)
    } else {
        (m, num / m)
    }
}

fn first_order(z: f64, p: f64, k: f64) -> Section {
    // k(s − z)/(s − p) = k + k(p − z)/(s − p).
    let (b, c) = balanced(k * (p - z));
    Section {
        a: DMatrix::from_element(1, 1, p),
        b: DMatrix::from_element(1, 1, b),
        c: DMatrix::from_element(1, 1, c),
        d: k,
    }
}

fn second_order(z: (Complex64, Complex64), p: (Complex64, Complex64), k: f64) -> Section {
    let (b1, b0) = quad(z.0, z.1);
    let (a1, a0) = quad(p.0, p.1);
    // k(s² + b₁s + b₀)/(s² + a₁s + a₀) = k + (c₁s + c₀)/(s² + a₁s + a₀).
    let (c1, c0) = (k * (b1 - a1), k * (b0 - a0));
    if p.0.im != 0.0 {
        let (sig, om) = (p.0.re, p.0.im.abs());
        // B = [0; β], C = [γ₁, γ₂]: C adj(sI − A) B = β(γ₂ s − σγ₂ + ωγ₁).
        let g1b = (c0 + sig * c1) / om; // γ₁β
        let g2b = c1; // γ₂β
        let beta = (g1b.abs() + g2b.abs()).sqrt().max(f64::MIN_POSITIVE);
        Section {
            a: DMatrix::from_row_slice(2, 2, &[sig, om, -om, sig]),
            b: DMatrix::from_row_slice(2, 1, &[0.0, beta]),
            c: DMatrix::from_row_slice(1, 2, &[g1b / beta, g2b / beta]),
            d: k,
        }
    } else {
        let (p1, p2) = (p.0.re, p.1.re);
        // B = [β; 0], A = [[p₁, 0], [α, p₂]]: x₁ = β/(s − p₁), x₂ = αx₁/(s − p₂);
        // y = β(γ₁(s − p₂) + αγ₂)/((s − p₁)(s − p₂)).
        // The chain coupling α = √|p₁p₂| keeps both states of the order of the input.
        let alpha = (p1 * p2).abs().sqrt().max(f64::MIN_POSITIVE);
        let g1b = c1;
        let g2b = (c0 + c1 * p2) / alpha;
        let beta = (g1b.abs() + g2b.abs()).sqrt().max(f64::MIN_POSITIVE);
        Section {
            a: DMatrix::from_row_slice(2, 2, &[p1, 0.0, alpha, p2]),
            b: DMatrix::from_row_slice(2, 1, &[beta, 0.0]),
            c: DMatrix::from_row_slice(1, 2, &[g1b / beta, g2b / beta]),
            d: k,
        }
    }
}

/// Splits roots into conjugate pairs (upper half-plane member first) and reals.
fn split(roots: &[Complex64]) -> (Vec<(Complex64, Complex64)>, Vec<f64>) {
    let mut pairs = Vec::new();
    let mut reals = Vec::new();
    for r in roots {
        if r.im > 0.0 {
            pairs.push((*r, r.conj()));
        } else if r.im == 0.0 {
            reals.push(r.re);
        }
    }
    (pairs, reals)
}

/// The cascade realization of `r` (see the module doc).  Conjugate-symmetric roots are
/// assumed (the units rshape builds are); a biproper `r` of order `N` gives `N` states.
pub fn realize(r: &Zpk) -> StateSpace {
    let (mut zp, mut zr) = split(&r.zeros);
    let (pp, mut pr) = split(&r.poles);
    let n_sec = pp.len() + pr.len();
    // Sections are built with unit gain; |g| is spread evenly over them below.
    let k = 1.0;
    let sign = r.gain.signum();
    let mut secs: Vec<Section> = Vec::new();
    // Each section pairs poles with the zeros nearest in modulus, so that every section
    // stays close to its feedthrough and the cascade loses no accuracy to cancellation.
    let dist = |a: f64, b: f64| (a.abs().max(1e-300) / b.abs().max(1e-300)).ln().abs();
    let take_real = |zr: &mut Vec<f64>, m: f64| -> f64 {
        let i = (0..zr.len())
            .min_by(|i, j| dist(zr[*i], m).total_cmp(&dist(zr[*j], m)))
            .unwrap_or(usize::MAX);
        if i == usize::MAX {
            -m.abs()
        } else {
            zr.swap_remove(i)
        }
    };
    // Complex pole pairs take the nearest zero pair, else the two nearest real zeros.
    for p in &pp {
        let m = p.0.norm();
        let iz = (0..zp.len())
            .min_by(|i, j| dist(zp[*i].0.norm(), m).total_cmp(&dist(zp[*j].0.norm(), m)));
        let pair_ok = iz.is_some_and(|i| zr.len() < 2 || dist(zp[i].0.norm(), m) <= dist(zr[0], m));
        let z = match iz {
            Some(i) if pair_ok || zr.len() < 2 => zp.swap_remove(i),
            _ => {
                let a = take_real(&mut zr, m);
                let b = take_real(&mut zr, m);
                (Complex64::new(a, 0.0), Complex64::new(b, 0.0))
            }
        };
        secs.push(second_order(z, *p, k));
    }
    // Remaining zero pairs take the two nearest real poles.
    while let Some(z) = zp.pop() {
        let m = z.0.norm();
        let a = take_real(&mut pr, m);
        let b = take_real(&mut pr, m);
        secs.push(second_order(
            z,
            (Complex64::new(a, 0.0), Complex64::new(b, 0.0)),
            k,
        ));
    }
    pr.sort_by(|a, b| b.total_cmp(a));
    while let Some(p) = pr.pop() {
        let z = take_real(&mut zr, p);
        secs.push(first_order(z, p, k));
    }
    if n_sec == 0 {
        return StateSpace {
            a: DMatrix::zeros(0, 0),
            b: DMatrix::zeros(0, 1),
            c: DMatrix::zeros(1, 0),
            d: DMatrix::from_element(1, 1, r.gain),
        };
    }
    let kk = r.gain.abs().powf(1.0 / secs.len() as f64);
    for s in secs.iter_mut() {
        s.c *= kk;
        s.d *= kk;
    }
    if let Some(last) = secs.last_mut() {
        last.c *= sign;
        last.d *= sign;
    }
    // Series connection: u → section 1 → section 2 → … → y.
    let mut a = DMatrix::<f64>::zeros(0, 0);
    let mut b = DMatrix::<f64>::zeros(0, 1);
    let mut c = DMatrix::<f64>::zeros(1, 0);
    let mut d = 1.0;
    for s in secs {
        let (n1, n2) = (a.nrows(), s.a.nrows());
        let mut a2 = DMatrix::zeros(n1 + n2, n1 + n2);
        a2.view_mut((0, 0), (n1, n1)).copy_from(&a);
        a2.view_mut((n1, n1), (n2, n2)).copy_from(&s.a);
        a2.view_mut((n1, 0), (n2, n1)).copy_from(&(&s.b * &c));
        let mut b2 = DMatrix::zeros(n1 + n2, 1);
        b2.view_mut((0, 0), (n1, 1)).copy_from(&b);
        b2.view_mut((n1, 0), (n2, 1)).copy_from(&(&s.b * d));
        let mut c2 = DMatrix::zeros(1, n1 + n2);
        c2.view_mut((0, 0), (1, n1)).copy_from(&(&c * s.d));
        c2.view_mut((0, n1), (1, n2)).copy_from(&s.c);
        a = a2;
        b = b2;
        c = c2;
        d *= s.d;
    }
    StateSpace {
        a,
        b,
        c,
        d: DMatrix::from_element(1, 1, d),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cascade_matches_the_poles_and_zeros() {
        let c = |re: f64, im: f64| Complex64::new(re, im);
        let r = Zpk {
            gain: 3.0,
            zeros: vec![c(-0.01, 5.0), c(-0.01, -5.0), c(-2.0, 0.0), c(-1e3, 0.0)],
            poles: vec![c(-0.5, 0.0), c(-7.0, 0.0), c(-2.0, 4.5), c(-2.0, -4.5)],
        };
        let ss = realize(&r);
        assert_eq!(ss.a.nrows(), 4);
        for w in crate::system::logspace(1e-3, 1e6, 400) {
            let want = {
                let s = c(0.0, w);
                let num: Complex64 = r.zeros.iter().map(|z| s - z).product();
                let den: Complex64 = r.poles.iter().map(|p| s - p).product();
                num / den * r.gain
            };
            let got = ss.freq(w).unwrap()[(0, 0)];
            assert!(
                (got - want).norm() <= 1e-12 * want.norm(),
                "{w}: {got} vs {want}"
            );
        }
    }
}
