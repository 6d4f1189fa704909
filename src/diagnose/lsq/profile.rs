//! The profile likelihood of a mode's damping at the record's floor (issue 33: "a parameter
//! that ends at a bound is 'not identified' only where the likelihood is flat there").
//!
//! A lightly damped mode between coarse lines ([`super::resolution`]) is seen on its flanks
//! only; its fit may end with `ζ` on the record's floor `ζ_f`.  That says the data prefer a
//! small damping only when the likelihood rises above the floor.  The profile
//! `V_p(ζ) = min_{θ′} V(ζ, θ′)` (every other parameter refit jointly with `ζ` held,
//! [`super::retune::retune_holding`]) is followed upward from `ζ_f` by factors of `√2`
//! until `V_p(ζ) − V_p(ζ_f)` exceeds `½ χ²₁(0.95) · s` (the likelihood-ratio 95 % interval,
//! `−2 ln L = 2V`; `s = max(1, V/F)` widens it where the residual itself exceeds the stated
//! noise, a quasi-likelihood scale; `V/F` is taken as the larger of the whole band's and that
//! of the lines around the mode, [`near_lines`], where a local lack of fit says as much).  The supported interval is `[ζ_f, ζ_u]`, `ζ_u` by linear
//! interpolation in `ln ζ` between the last point inside and the first outside.
//!
//! The damping is **not identified** when `ζ_u/ζ_f > exp(1.96/3)` — a 95 % interval wider
//! than that of a relative σ of 1/3, the covariance rule of
//! [`crate::diagnose::admissible`].  Every `ζ` of the interval is then equally supported;
//! the one written is its log-midpoint `√(ζ_f ζ_u)`, at most `√(ζ_u/ζ_f)` away from any of
//! them (the floor itself would be `ζ_u/ζ_f` away from the interval's top), and the report
//! says "not identified: measure denser lines around f".

use super::channels::Channels;
use super::resolution::{spacing_at, zeta_range};
use super::retune::{cost, retune_holding};
use super::slots::Nl;
use crate::model::physical::PhysicalModel;

/// `½ χ²₁(0.95)`: the rise of `V = −ln L` that bounds the 95 % likelihood-ratio interval.
pub const HALF_CHI2_1_95: f64 = 0.5 * 3.841_458_820_694_124;
/// Step of the profile grid (a factor in `ζ`).
const STEP: f64 = std::f64::consts::SQRT_2;
/// Most profile points (a factor `√2^24 = 4096` above the floor).
const MAX_POINTS: usize = 24;
/// A fitted `ζ` this close to its floor (a factor) counts as at the bound.
pub const AT_FLOOR: f64 = 1.05;
/// Ratio `ζ_u/ζ_f` above which `ζ` is not identified: `exp(1.96 · 1/3)`.
pub fn flat_ratio() -> f64 {
    (1.959_963_984_540_054 / 3.0f64).exp()
}
/// Half-width of the lines that see a mode, in line spacings (at least 2 % of its frequency).
const NEAR_LINES: f64 = 10.0;
/// No profile above this damping (the refit's own upper bound is 0.7).
const ZETA_TOP: f64 = 0.5;

/// The profile of mode `k`'s damping (see the module docs).
#[derive(Debug, Clone)]
pub struct ZetaProfile {
    /// Its natural frequency, rad/s.
    pub omega_n: f64,
    /// The record's floor at the mode (where the profile starts).
    pub floor: f64,
    /// The top of the supported interval (`ZETA_TOP` when the profile never left it).
    pub upper: f64,
    /// `(ζ, V_p(ζ) − V_p(ζ_f))` at every point profiled.
    pub points: Vec<(f64, f64)>,
    /// The rise of `V` that bounds the interval (`½ χ²₁(0.95) · s`).
    pub threshold: f64,
}

impl ZetaProfile {
    /// The likelihood is flat over more than the covariance rule allows: `ζ` not identified.
    pub fn flat(&self) -> bool {
        self.upper / self.floor > flat_ratio()
    }

    /// The damping written when it is not identified: the interval's log-midpoint.
    pub fn midpoint(&self) -> f64 {
        (self.floor * self.upper).sqrt()
    }
}

/// The modes of `m` whose damping is at the record's floor (within [`AT_FLOOR`]).
pub fn modes_at_floor(m: &PhysicalModel, data: &Channels) -> Vec<usize> {
    let (lo, hi) = (data.omega[0], *data.omega.last().expect("data"));
    (0..m.mode.len())
        .filter(|&k| {
            let md = &m.mode[k];
            (lo..=hi).contains(&md.omega_n)
                && md.zeta <= AT_FLOOR * zeta_range(data, md.omega_n).floor
        })
        .collect()
}

/// The lines that see a mode at `w` (rad/s): within `max(2 %, NEAR_LINES spacings)` of it.
pub fn near_lines(data: &Channels, w: f64) -> Vec<usize> {
    let half = (0.02 * w).max(NEAR_LINES * spacing_at(&data.omega, w));
    (0..data.omega.len())
        .filter(|&i| (data.omega[i] - w).abs() <= half)
        .collect()
}

/// The profile of mode `k`'s damping in `m` (a least-squares fit on every datum of `data`,
/// built from `anchor`, whose boxes every refit keeps), from the record's floor upward.
pub fn zeta_profile(
    m: &PhysicalModel,
    anchor: &PhysicalModel,
    data: &Channels,
    k: usize,
) -> ZetaProfile {
    let w = m.mode[k].omega_n;
    let floor = zeta_range(data, w).floor;
    // Each point refit from the last (a continuation): every parameter but ζ_k.
    let at = |start: &PhysicalModel, z: f64| {
        let mut t = start.clone();
        t.mode[k].zeta = z;
        let r = retune_holding(&t, anchor, data, &[Nl::ModeZ(k)]);
        (r.model, r.v_after)
    };
    let (m0, v0) = at(m, floor);
    let v0 = v0.min(cost(m, data, &(0..data.len()).collect::<Vec<_>>()));
    // The residual's level where ζ is seen (the lines around the mode) may exceed the
    // whole band's: a term the model lacks there (pyuff's 51.5 Hz mode, whose data carry a
    // phase no real-residue term makes) makes the likelihood's curvature overstate what the
    // data say of ζ.  The larger of the two levels widens the interval.
    let near = near_lines(data, w);
    let f_near = (near.len() * data.n_ch()).max(1) as f64;
    let scale = (v0 / data.n_data() as f64)
        .max(cost(&m0, data, &near) / f_near)
        .max(1.0);
    let threshold = HALF_CHI2_1_95 * scale;
    let mut points = vec![(floor, 0.0)];
    let mut upper = ZETA_TOP;
    let mut start = m0;
    let mut z = floor;
    for _ in 0..MAX_POINTS {
        let zn = z * STEP;
        if zn > ZETA_TOP {
            break;
        }
        let (mm, v) = at(&start, zn);
        let dv = v - v0;
        points.push((zn, dv));
        if dv > threshold {
            // Interpolated in ln ζ between the last point inside and this one.
            let d0 = points[points.len() - 2].1.max(0.0);
            let s = ((threshold - d0) / (dv - d0)).clamp(0.0, 1.0);
            upper = z * STEP.powf(s);
            break;
        }
        start = mm;
        z = zn;
    }
    ZetaProfile {
        omega_n: w,
        floor,
        upper,
        points,
        threshold,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::physical::{Gains, ModeSpec};
    use num_complex::Complex64;

    const TAU: f64 = std::f64::consts::TAU;

    fn one_mode(w: f64, z: f64, rho: f64) -> PhysicalModel {
        PhysicalModel {
            mode: vec![ModeSpec {
                omega_n: w,
                zeta: z,
                mass: 1.0,
                output_gain: Gains::Scalar(rho),
                input_gain: Gains::Scalar(1.0),
                name: None,
            }],
            ..Default::default()
        }
    }

    /// `min_{ω_n, ρ} V` at `ζ` by brute force: the residue in closed form (real weighted least
    /// squares), `ω_n` over a fine grid, from the transfer function directly (not the refit).
    fn brute_v(data: &Channels, w0: f64, z: f64) -> f64 {
        (-400..=400)
            .map(|j| {
                let w = w0 * (1.0 + 2.5e-7 * j as f64);
                let s: Vec<Complex64> = data
                    .omega
                    .iter()
                    .map(|x| one_mode(w, z, 1.0).eval(*x)[(0, 0)])
                    .collect();
                let (g, r) = (&data.g[0], &data.radius[0]);
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..s.len() {
                    let wk = 2.0 / (r[k] * r[k]);
                    num += wk * (s[k].conj() * g[k]).re;
                    den += wk * s[k].norm_sqr();
                }
                let rho = num / den;
                (0..s.len())
                    .map(|k| 2.0 * ((g[k] - rho * s[k]).norm() / r[k]).powi(2))
                    .sum::<f64>()
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_damping_below_the_lines_has_a_flat_profile_matching_brute_force() {
        // A mode midway between 1 Hz lines, far less damped than the lines can see, 1 % noise.
        let w = TAU * 460.5;
        let truth = one_mode(w, 1e-6, 2.0e5);
        let omega: Vec<f64> = (430..=490).map(|k| TAU * k as f64).collect();
        let data = Channels::of_model(&truth, omega, vec![(0, 0)], 1.0, (0.01, 0.0));
        let floor = zeta_range(&data, w).floor;
        let mut m = truth.clone();
        m.mode[0].zeta = floor;
        assert_eq!(modes_at_floor(&m, &data), vec![0]);
        let p = zeta_profile(&m, &m, &data, 0);
        assert_eq!(p.threshold, HALF_CHI2_1_95, "noise-free data: no widening");
        // The interval's top against the brute-force profile's crossing (bisection in ln ζ).
        let v0 = brute_v(&data, w, floor);
        let rise = |z: f64| brute_v(&data, w, z) - v0 - HALF_CHI2_1_95;
        let (mut a, mut b) = (floor, 100.0 * floor);
        assert!(rise(a) < 0.0 && rise(b) > 0.0);
        for _ in 0..40 {
            let c = (a * b).sqrt();
            if rise(c) < 0.0 {
                a = c
            } else {
                b = c
            }
        }
        assert!(
            (p.upper / a - 1.0).abs() < 0.1,
            "profile top {} vs brute force {a} (floor {floor}, points {:?})",
            p.upper,
            p.points
        );
        // Below the record's resolution by construction (the floor is half of it): the
        // supported interval spans more than the covariance rule allows.
        assert!(p.flat(), "{p:?}");
        assert!((p.midpoint() - (floor * p.upper).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn a_lack_of_fit_around_the_mode_widens_the_interval_by_its_own_level() {
        // A mode at 460.5 Hz between 1 Hz lines whose data carry a residue rotated by 0.15
        // rad (no real-residue term makes it), beside a well-modelled mode at 800 Hz that
        // dominates most of the band 300–1000 Hz: the lack of fit sits around 460 Hz.
        let (w1, w2) = (TAU * 460.5, TAU * 800.0);
        let omega: Vec<f64> = (300..=1000).map(|k| TAU * k as f64).collect();
        let mut model = one_mode(w1, 1e-6, 2.0e4);
        model.mode.push(one_mode(w2, 0.01, 2.0e6).mode[0].clone());
        let rot = Complex64::from_polar(1.0, 0.15);
        let g: Vec<Complex64> = omega
            .iter()
            .map(|w| {
                let s = Complex64::new(0.0, *w);
                2.0e4 * rot / (s * s + 2e-6 * w1 * s + w1 * w1)
                    + 2.0e6 / (s * s + 0.02 * w2 * s + w2 * w2)
            })
            .collect();
        let radius: Vec<f64> = g.iter().map(|x| 0.01 * x.norm()).collect();
        let data = Channels {
            path: "test".into(),
            radius_source: vec![String::new()],
            omega: omega.clone(),
            entries: vec![(0, 0)],
            g: vec![g.clone()],
            radius: vec![radius.clone()],
        };
        let floor = zeta_range(&data, w1).floor;
        let mut m = model.clone();
        m.mode[0].zeta = floor;
        let p = zeta_profile(&m, &m, &data, 0);
        // The level of the lines within ±10 Hz, by brute force: the 800 Hz mode as
        // generated, the 460 Hz mode at the floor with ω_n on a grid and its real residue in
        // closed form (weighted least squares).
        let near: Vec<usize> = (0..omega.len())
            .filter(|&k| (omega[k] - w1).abs() <= TAU * 10.0 + 1e-9)
            .collect();
        let local = (-400..=400)
            .map(|j| {
                let w = w1 * (1.0 + 2.5e-7 * j as f64);
                let (mut num, mut den) = (0.0, 0.0);
                let basis = |k: usize| one_mode(w, floor, 1.0).eval(omega[k])[(0, 0)];
                let rest = |k: usize| one_mode(w2, 0.01, 2.0e6).eval(omega[k])[(0, 0)];
                for &k in &near {
                    let wk = 2.0 / (radius[k] * radius[k]);
                    num += wk * (basis(k).conj() * (g[k] - rest(k))).re;
                    den += wk * basis(k).norm_sqr();
                }
                let rho = num / den;
                near.iter()
                    .map(|&k| 2.0 * ((g[k] - rest(k) - rho * basis(k)).norm() / radius[k]).powi(2))
                    .sum::<f64>()
            })
            .fold(f64::INFINITY, f64::min)
            / near.len() as f64;
        assert!(local > 10.0, "the construction: local V/F {local}");
        let scale = p.threshold / HALF_CHI2_1_95;
        // The refit also moves the 800 Hz mode a little: within 10 %.
        assert!(
            (scale / local - 1.0).abs() < 0.1,
            "scale {scale} vs local V/F {local}"
        );
        // Far above the whole band's own level (most lines fit).
        let whole = cost(&m, &data, &(0..data.len()).collect::<Vec<_>>()) / data.n_data() as f64;
        assert!(
            scale > 3.0 * whole.max(1.0),
            "scale {scale}, whole band {whole}"
        );
    }

    #[test]
    fn a_damping_the_lines_resolve_is_not_at_the_floor() {
        let w = TAU * 460.5;
        let omega: Vec<f64> = (430..=490).map(|k| TAU * k as f64).collect();
        let truth = one_mode(w, 1e-3, 2.0e5);
        let data = Channels::of_model(&truth, omega, vec![(0, 0)], 1.0, (0.01, 0.0));
        assert!(modes_at_floor(&truth, &data).is_empty());
        // A mode outside the band is never profiled.
        let mut out = truth.clone();
        out.mode[0].omega_n = TAU * 600.0;
        out.mode[0].zeta = 1e-12;
        assert!(modes_at_floor(&out, &data).is_empty());
    }
}
