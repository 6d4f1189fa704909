//! Prescaling, the rational basis for `|r(jω)|²`, and the constraint grid.
//!
//! **Prescaling** (as MATLAB's `fitmagfrd` does): frequencies are divided by
//! `ω₀ = √(ω_min·ω_max)` and magnitudes by `ρ`, the geometric mean of the positive finite
//! `r_min`, so the solver sees numbers of order one.  Everything in this module works on the
//! scaled variable `x = (ω/ω₀)²`.
//!
//! **Basis.**  `|r(jω)|² = A(x)/B(x)` with `A`, `B` real polynomials of degree `N` in `x`.
//! Both are written over a fixed *reference* polynomial `D(x) = Π_k (x + q_k²)`, with the
//! reference poles `q_k` log-spaced over the (scaled) data band:
//!
//! `A(x)/D(x) = a₀ + Σ_k a_k·q_k²/(x + q_k²)`, and likewise for `B`.
//!
//! Every basis function lies in `[0, 1]` for `x ≥ 0`, unlike raw monomials in `x`, whose
//! values span `2N` times the number of decades.  Partial fractions over distinct `q_k` span
//! all polynomials of degree ≤ `N` divided by `D`, so the choice of `q_k` affects only the
//! conditioning, never which `r` can be represented: the poles of `r` stay free.

/// Frequency and magnitude scales of a fit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Scaling {
    /// Frequency scale `ω₀` in rad/s: `ω̂ = ω/ω₀`.
    pub omega0: f64,
    /// Magnitude scale `ρ`: `|r̂| = |r|/ρ`.
    pub rho: f64,
}

impl Scaling {
    /// `ω₀ = √(ω_min·ω_max)` and `ρ` the geometric mean of the positive finite `r_min`
    /// (1 when there is none).
    pub fn from_data(omega: &[f64], r_min: &[f64]) -> Self {
        let lo = omega.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = omega.iter().copied().fold(0.0, f64::max);
        let omega0 = if lo.is_finite() && hi > 0.0 {
            (lo * hi).sqrt()
        } else {
            1.0
        };
        let logs: Vec<f64> = r_min
            .iter()
            .filter(|r| r.is_finite() && **r > 0.0)
            .map(|r| r.ln())
            .collect();
        let rho = if logs.is_empty() {
            1.0
        } else {
            (logs.iter().sum::<f64>() / logs.len() as f64).exp()
        };
        Self { omega0, rho }
    }
}

/// Reference poles `q_k` (scaled frequency units): `n` points log-spaced over the data band
/// widened by a factor 3 on each side (one point at the geometric centre when `n = 1`).
pub fn reference_poles(n: usize, w_lo: f64, w_hi: f64) -> Vec<f64> {
    let (lo, hi) = ((w_lo / 3.0).ln(), (w_hi * 3.0).ln());
    match n {
        0 => Vec::new(),
        1 => vec![(0.5 * (lo + hi)).exp()],
        _ => (0..n)
            .map(|k| (lo + (hi - lo) * k as f64 / (n - 1) as f64).exp())
            .collect(),
    }
}

/// The basis row `[1, q_1²/(x+q_1²), …, q_N²/(x+q_N²)]` at `x = ω̂²`; `x = ∞` gives `[1, 0, …]`.
pub fn basis_row(q: &[f64], x: f64) -> Vec<f64> {
    let mut row = Vec::with_capacity(q.len() + 1);
    row.push(1.0);
    for qk in q {
        let q2 = qk * qk;
        row.push(if x.is_infinite() { 0.0 } else { q2 / (x + q2) });
    }
    row
}

/// Value of `c₀ + Σ c_k q_k²/(x+q_k²)` at `x`.
#[cfg(test)]
pub fn basis_eval(q: &[f64], c: &[f64], x: f64) -> f64 {
    basis_row(q, x).iter().zip(c).map(|(a, b)| a * b).sum()
}

/// What a grid point stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointKind {
    /// A datum of the envelope.
    Datum,
    /// A dense-grid point inside the data band.
    Band,
    /// A dense-grid point outside the data band (two decades on each side).
    Outside,
    /// `ω = ∞`.
    Infinity,
}

/// One constraint point in scaled units; all bounds are on `|r̂|²`.
#[derive(Debug, Clone, Copy)]
pub struct GridPoint {
    /// Scaled frequency `ω̂` (`inf` for the point at infinity).
    pub w: f64,
    /// `x = ω̂²`.
    pub x: f64,
    /// Lower bound on `|r̂|²` (the data bound, the no-dip bound between data, or the floor).
    pub lower: f64,
    /// Envelope for the upper bound: `|r̂|² ≤ t·upper` (`None`: no such bound).
    pub upper: Option<f64>,
    /// A1 limit on `|r̂|²` (`None`: unknown).
    pub a1: Option<f64>,
    /// What the point stands for.
    pub kind: PointKind,
    /// Index of the datum for `Datum` points.
    pub datum: Option<usize>,
}

/// Log-spaced grid with at least `per_decade` points per decade from `lo` to `hi`.
pub fn dense_grid(lo: f64, hi: f64, per_decade: usize) -> Vec<f64> {
    let decades = (hi / lo).log10().max(0.0);
    let n = ((decades * per_decade as f64).ceil() as usize).max(1) + 1;
    crate::system::logspace(lo, hi, n)
}

/// Inputs of the grid construction, in scaled units.
pub struct GridSpec<'a> {
    /// Scaled data frequencies, increasing.
    pub w: &'a [f64],
    /// Scaled lower bounds `((1+margin)·r_min/ρ)²` per datum (0: no bound).
    pub lower: &'a [f64],
    /// A1 limit `(σ_min(M̃)/ρ)²` as a function of the scaled frequency, if known.
    pub a1: Option<&'a dyn Fn(f64) -> f64>,
    /// A1 limit per datum (scaled, squared), used when no function is given.
    pub a1_data: Option<&'a [f64]>,
    /// Floor on `|r̂|²` everywhere.
    pub floor: f64,
    /// Points per decade of the dense grid.
    pub per_decade: usize,
    /// Decades added on each side of the data band.
    pub extend_decades: f64,
    /// Enforce `|r| ≥ min(neighbouring data bounds)` between data (no dips).
    pub no_dip: bool,
    /// Scaled frequencies where A1 may notch between grid points (the lightly damped zeros
    /// of `M̃`, [`crate::model::Factorization::a1_dips`]); empty: the grid alone.
    pub a1_dips: &'a [f64],
    /// Scaled frequencies added as constraint points by the cutting-plane round
    /// ([`super::cutting_plane`]): where a candidate broke a bound between grid points.
    /// Empty: the grid of the first round.
    pub cuts: &'a [f64],
}

/// A dip gets its own constraint point when A1 there is below this share of A1 at the dense
/// grid's spacing on either side: the grid would let `|r|` through the notch, and the
/// certificate, which evaluates A1 at the dips, would then refuse every candidate.
const DIP_DEPTH: f64 = 0.95;

/// Builds the constraint points: every datum, a dense grid over the data band (no-dip lower
/// bound, local upper envelope), the two extensions (floor only, upper envelope from the
/// nearest decade of data), `ω = 0` and `ω = ∞`.
pub fn build_grid(spec: &GridSpec) -> Vec<GridPoint> {
    let n = spec.w.len();
    let (w_lo, w_hi) = (spec.w[0], spec.w[n - 1]);
    let ext = 10f64.powf(spec.extend_decades);
    let a1_at = |w: f64| -> Option<f64> {
        match (spec.a1, spec.a1_data) {
            (Some(f), _) => Some(f(w)),
            (None, Some(d)) => Some(interp_loglog(spec.w, d, w)?),
            _ => None,
        }
    };
    let edge_upper = |at_low: bool| -> f64 {
        let mut m: f64 = 0.0;
        for (wi, li) in spec.w.iter().zip(spec.lower) {
            let near = if at_low {
                *wi <= w_lo * 10.0
            } else {
                *wi >= w_hi / 10.0
            };
            if near {
                m = m.max(*li);
            }
        }
        m.max(spec.floor)
    };
    let (up_lo, up_hi) = (edge_upper(true), edge_upper(false));
    let mut pts = Vec::with_capacity(n + 8 * spec.per_decade);
    for i in 0..n {
        pts.push(GridPoint {
            w: spec.w[i],
            x: spec.w[i] * spec.w[i],
            lower: spec.lower[i].max(spec.floor),
            // A datum with r_min = 0 (explained by the noise alone) bounds nothing: it must
            // not set the level either (GitHub issue 11, defect 4).
            upper: (spec.lower[i] > 0.0).then_some(spec.lower[i]),
            a1: match (spec.a1, spec.a1_data) {
                (Some(f), _) => Some(f(spec.w[i])),
                (None, Some(d)) => Some(d[i]),
                _ => None,
            },
            kind: PointKind::Datum,
            datum: Some(i),
        });
    }
    let mut ws = dense_grid(w_lo / ext, w_hi * ext, spec.per_decade);
    let mut dips: Vec<f64> = Vec::new();
    if let (Some(a1), Some(&first), Some(&last)) = (spec.a1, ws.first(), ws.last()) {
        // A notch of A1 narrower than the grid's spacing (a mode of ζ = 0.01 is ~1 % wide,
        // the spacing at 50 points per decade 4.7 %): its bottom becomes a constraint point.
        let g = 10f64.powf(1.0 / spec.per_decade as f64);
        let deep = |d: f64| a1(d) < DIP_DEPTH * a1(d / g).min(a1(d * g));
        dips.extend(
            spec.a1_dips
                .iter()
                .copied()
                .filter(|d| d.is_finite() && *d > first && *d < last && deep(*d)),
        );
        dips.sort_by(f64::total_cmp);
        ws.extend(&dips);
        ws.sort_by(f64::total_cmp);
        ws.dedup();
    }
    // The cuts of the cutting-plane round, anywhere on the axis (inside the band they get
    // the no-dip bound of their interval, outside it the floor, as grid points do there).
    let mut cuts: Vec<f64> = spec
        .cuts
        .iter()
        .copied()
        .filter(|c| c.is_finite() && *c > 0.0)
        .collect();
    if !cuts.is_empty() {
        cuts.sort_by(f64::total_cmp);
        ws.extend(&cuts);
        ws.sort_by(f64::total_cmp);
        ws.dedup();
    }
    let mut j = 0; // index of the datum at or below w
    for w in ws {
        let (lower, upper, kind) = if w < w_lo {
            (spec.floor, up_lo, PointKind::Outside)
        } else if w > w_hi {
            (spec.floor, up_hi, PointKind::Outside)
        } else {
            while j + 1 < n && spec.w[j + 1] <= w {
                j += 1;
            }
            let k = (j + 1).min(n - 1);
            // Skip grid points that coincide with a datum (relative 1e-9).
            if (w / spec.w[j] - 1.0).abs() < 1e-9 || (w / spec.w[k] - 1.0).abs() < 1e-9 {
                continue;
            }
            let (a, b) = (spec.lower[j], spec.lower[k]);
            let lower = if spec.no_dip { a.min(b) } else { 0.0 };
            // Between two zero data there is no envelope to stay close to.
            let upper = a.max(b);
            (lower.max(spec.floor), upper, PointKind::Band)
        };
        // A notch below the bound no r may dip under between these data: no r meets both,
        // at any level. Left to the certificate, which names it, rather than to a search
        // of every level up to its cap (a cut there likewise).
        let a1 = a1_at(w);
        let added = |v: &[f64]| v.binary_search_by(|d| d.total_cmp(&w)).is_ok();
        if (added(&dips) || added(&cuts)) && a1.is_some_and(|v| v <= lower) {
            continue;
        }
        pts.push(GridPoint {
            w,
            x: w * w,
            lower,
            upper: (upper > 0.0).then_some(upper),
            a1,
            kind,
            datum: None,
        });
    }
    // ω = 0: the floor holds at DC too (a root of A at x = 0 is a zero at s = 0).
    pts.push(GridPoint {
        w: 0.0,
        x: 0.0,
        lower: spec.floor,
        upper: Some(up_lo),
        a1: match (spec.a1, spec.a1_data) {
            (Some(f), _) => Some(f(w_lo / ext / 10.0)),
            _ => None,
        },
        kind: PointKind::Outside,
        datum: None,
    });
    // ω = ∞: A1 from a frequency far above the band (the factors are proper, so the limit
    // settles), when a function is known.
    pts.push(GridPoint {
        w: f64::INFINITY,
        x: f64::INFINITY,
        lower: spec.floor,
        upper: Some(up_hi),
        a1: spec.a1.map(|f| f(w_hi * 1e6)),
        kind: PointKind::Infinity,
        datum: None,
    });
    pts
}

/// Log-log linear interpolation of `y(w)` inside `[w_0, w_n]`; `None` outside.
pub fn interp_loglog(w: &[f64], y: &[f64], at: f64) -> Option<f64> {
    let n = w.len();
    if n == 0 || at < w[0] || at > w[n - 1] {
        return None;
    }
    if n == 1 {
        return Some(y[0]);
    }
    let k = w.partition_point(|v| *v <= at).clamp(1, n - 1);
    let (w0, w1, y0, y1) = (w[k - 1], w[k], y[k - 1], y[k]);
    if y0 <= 0.0 || y1 <= 0.0 || w1 == w0 {
        return Some(y0.min(y1));
    }
    let t = (at / w0).ln() / (w1 / w0).ln();
    Some((y0.ln() + t * (y1 / y0).ln()).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_spans_polynomials() {
        // (x + 2)/(x + 1) with q = 1: a0 = 1, a1·1/(x+1) = 1/(x+1) → a1 = 1.
        let q = [1.0];
        for x in [0.0, 0.5, 3.0, 100.0] {
            assert!((basis_eval(&q, &[1.0, 1.0], x) - (x + 2.0) / (x + 1.0)).abs() < 1e-14);
        }
    }

    /// Three data a decade apart, 50 band points per decade, two decades outside.
    fn three_data<'a>(a1: Option<&'a dyn Fn(f64) -> f64>, cuts: &'a [f64]) -> GridSpec<'a> {
        GridSpec {
            w: &[0.1, 1.0, 10.0],
            lower: &[4.0, 1.0, 0.25],
            a1,
            a1_data: None,
            floor: 1e-6,
            per_decade: 50,
            extend_decades: 2.0,
            no_dip: true,
            a1_dips: &[],
            cuts,
        }
    }

    #[test]
    fn grid_has_data_band_outside_and_infinity() {
        let g = build_grid(&three_data(None, &[]));
        assert_eq!(g.iter().filter(|p| p.kind == PointKind::Datum).count(), 3);
        assert!(g.iter().any(|p| p.kind == PointKind::Infinity));
        assert!(g.iter().filter(|p| p.kind == PointKind::Band).count() >= 95);
        let lo = g
            .iter()
            .map(|p| p.w)
            .filter(|w| *w > 0.0)
            .fold(f64::INFINITY, f64::min);
        assert!(g.iter().any(|p| p.w == 0.0));
        assert!((lo - 1e-3).abs() < 1e-12);
    }

    /// Cuts add their points, each with the bounds of its place (the no-dip bound of its
    /// interval in the band, the floor outside it), and leave every other point as it was.
    #[test]
    fn cuts_add_points_and_change_nothing_else() {
        let a1 = |x: f64| 100.0 + x;
        let spec = |cuts: &'static [f64]| three_data(Some(&a1), cuts);
        let base = build_grid(&spec(&[]));
        let cut = build_grid(&spec(&[0.3333, 500.0]));
        assert_eq!(cut.len(), base.len() + 2);
        let key = |p: &GridPoint| (p.w, p.lower, p.upper, p.a1, p.kind);
        for p in &base {
            assert!(cut.iter().any(|q| key(q) == key(p)), "{p:?} lost");
        }
        let at = |x: f64| cut.iter().find(|p| p.w == x).expect("cut point");
        assert_eq!(at(0.3333).lower, 1.0);
        assert_eq!(at(0.3333).kind, PointKind::Band);
        assert!((at(0.3333).a1.unwrap() - 100.3333).abs() < 1e-12);
        assert_eq!(at(500.0).lower, 1e-6);
        assert_eq!(at(500.0).kind, PointKind::Outside);
    }
}
