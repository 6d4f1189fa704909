//! What the record can resolve of a mode's damping (issue 33: bounds from the data, not
//! constants).
//!
//! A mode `ρ/(ω_n² − ω² + 2jζω_nω)` seen at a line `ω` at distance `δ = |ω − ω_n|` from its
//! peak (`δ ≫ ζω_n`) has the magnitude `|ρ|/(2ω_nδ)` whatever `ζ`, and a phase that departs
//! from the undamped `0°/180°` by `atan(ζω_n/δ) ≈ ζω_n/δ`.  Between lines `Δω` apart the
//! nearest line is at most `Δω/2` from the peak, so a damping is visible in the data only
//! when `ζω_n/(Δω/2)` exceeds the phase resolution `ε` of the lines around the peak (the
//! noise `σ/|G|`, `σ = r/√2`, combined over the two lines and every channel):
//!
//! * the **floor** `ζ_floor = ½ · ε · (Δω/2)/ω_n`: below it the likelihood is flat in `ζ`
//!   (a margin of 2 below the resolution, so that a damping the lines can see is never held
//!   at the bound); a refit's lower bound on `ζ`;
//! * the **resolved** damping `ζ_res = MIN_LINES·Δω/(2ω_n)`: the half-power band `2ζω_n`
//!   holds `MIN_LINES` lines wherever the peak falls between them, so `ζ` is measured by the
//!   band itself; below it, `ζ` may be bounded by the flanks' phase only.
//!
//! `Δω` is the local line spacing at `ω_n` (the data may be dense around peaks), so both
//! follow the record, not a constant.

use super::channels::Channels;

/// Fewest data lines in a mode's half-power band for its `ζ` to be measured by the band
/// (the admissibility rule "unresolved", [`crate::diagnose::admissible`]).
pub const MIN_LINES_IN_BAND: usize = 3;

/// No floor below this (the model refuses `ζ < 1e-12`; a refit that wants less is at
/// rounding level).
pub const ZETA_FLOOR_MIN: f64 = crate::diagnose::effects::effect::ZETA_BOUNDS.0;
/// The floor lies this factor below the damping the lines can resolve.
pub const FLOOR_MARGIN: f64 = 0.5;

/// The dampings the record resolves for a mode at `ω_n` (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZetaRange {
    /// Local line spacing at `ω_n`, rad/s.
    pub spacing: f64,
    /// Phase resolution of the lines around `ω_n` (radians, combined over lines and channels).
    pub phase_resolution: f64,
    /// Below this the likelihood is flat in `ζ`: a refit's lower bound.
    pub floor: f64,
    /// From this up the half-power band holds [`MIN_LINES_IN_BAND`] lines, wherever the
    /// peak falls.
    pub resolved: f64,
}

/// The local line spacing at `w` (rad/s): the gap between the lines around it (at either end
/// of the band, the last gap inside; infinite with fewer than two lines).
pub fn spacing_at(omega: &[f64], w: f64) -> f64 {
    if omega.len() < 2 {
        return f64::INFINITY;
    }
    let k = omega.partition_point(|x| *x < w).clamp(1, omega.len() - 1);
    omega[k] - omega[k - 1]
}

/// The dampings the record `data` resolves for a mode at `w` (rad/s).
pub fn zeta_range(data: &Channels, w: f64) -> ZetaRange {
    let om = &data.omega;
    let dw = spacing_at(om, w);
    // The two lines around the peak, every channel: the phase noise `σ/|G|` of each (at most
    // 1 rad: a line in the noise says nothing), combined as independent looks (÷√n).
    let k = om.partition_point(|x| *x < w);
    let lines: Vec<usize> = [k.wrapping_sub(1), k]
        .into_iter()
        .filter(|i| *i < om.len())
        .collect();
    let mut sum_inv = 0.0;
    for i in &lines {
        for ch in 0..data.n_ch() {
            let g = data.g[ch][*i].norm();
            let s = data.radius[ch][*i] / std::f64::consts::SQRT_2;
            let e = if g > 0.0 { (s / g).min(1.0) } else { 1.0 };
            // Inverse-variance combination of the looks.
            sum_inv += 1.0 / (e * e).max(1e-300);
        }
    }
    let eps = if sum_inv > 0.0 {
        (1.0 / sum_inv).sqrt()
    } else {
        1.0
    };
    let floor = if dw.is_finite() && w > 0.0 {
        (FLOOR_MARGIN * eps * 0.5 * dw / w).max(ZETA_FLOOR_MIN)
    } else {
        ZETA_FLOOR_MIN
    };
    ZetaRange {
        spacing: dw,
        phase_resolution: eps,
        floor,
        resolved: MIN_LINES_IN_BAND as f64 * dw / (2.0 * w),
    }
}

/// The lowest [`ZetaRange::floor`] over the lines of `data`: the lower bound on `ζ` of every
/// refit and screen (a mode may sit anywhere in the band; below its own floor the
/// likelihood is flat anyway).  Replaces the fixed bound 1e-4 that held real modes of
/// ζ ≈ 1e-4 measured on dense lines (issue 33).
pub fn band_floor(data: &Channels) -> f64 {
    data.omega
        .iter()
        .map(|w| zeta_range(data, *w).floor)
        .fold(f64::INFINITY, f64::min)
        .max(ZETA_FLOOR_MIN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::physical::{Gains, ModeSpec, PhysicalModel};
    use num_complex::Complex64;

    fn one_mode(w: f64, z: f64) -> PhysicalModel {
        PhysicalModel {
            mode: vec![ModeSpec {
                omega_n: w,
                zeta: z,
                mass: 1.0,
                output_gain: Gains::Scalar(1.0),
                input_gain: Gains::Scalar(1.0),
                name: None,
            }],
            ..Default::default()
        }
    }

    fn phase_change_at_nearest(w: f64, z: f64, omega: &[f64]) -> f64 {
        // The phase a damping z adds, against an undamped mode, at the line nearest the peak:
        // from the transfer function directly (an independent route to the module's argument).
        let m = one_mode(w, z);
        let u = one_mode(w, 1e-15);
        let k = omega
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - w).abs().total_cmp(&(b.1 - w).abs()))
            .unwrap()
            .0;
        let r: Complex64 = m.eval(omega[k])[(0, 0)] / u.eval(omega[k])[(0, 0)];
        r.arg().abs()
    }

    #[test]
    fn spacing_follows_the_local_lines() {
        // 1 rad/s lines with 0.01 rad/s lines between 100 and 101.
        let mut om: Vec<f64> = (50..=150).map(|k| k as f64).collect();
        om.extend((1..100).map(|k| 100.0 + 0.01 * k as f64));
        om.sort_by(f64::total_cmp);
        assert!((spacing_at(&om, 70.3) - 1.0).abs() < 1e-12);
        assert!((spacing_at(&om, 100.505) - 0.01).abs() < 1e-9);
        assert!((spacing_at(&om, 10.0) - 1.0).abs() < 1e-12);
        assert!((spacing_at(&om, 1e4) - 1.0).abs() < 1e-12);
        assert!(spacing_at(&[1.0], 1.0).is_infinite());
    }

    #[test]
    fn the_floor_is_where_the_nearest_line_stops_seeing_the_damping() {
        // 1 Hz lines, a mode midway between two (the worst place), relative noise 1 %.
        let tau = std::f64::consts::TAU;
        let omega: Vec<f64> = (10..=990).map(|k| tau * k as f64).collect();
        let w = tau * 460.5;
        let truth = one_mode(w, 1e-3);
        let data = Channels::of_model(&truth, omega.clone(), vec![(0, 0)], 1.0, (0.01, 0.0));
        let zr = zeta_range(&data, w);
        assert!((zr.spacing - tau).abs() < 1e-9);
        // σ/|G| = 0.01/√2 per line, two lines: ε = 0.005.
        assert!((zr.phase_resolution - 0.005).abs() < 1e-4, "{zr:?}");
        // At the floor the damping's phase at the nearest line is half the resolution; at 4×
        // the floor it is twice the resolution (checked on the transfer function).
        let at_floor = phase_change_at_nearest(w, zr.floor, &omega);
        assert!(
            (at_floor / zr.phase_resolution - FLOOR_MARGIN).abs() < 0.02,
            "{at_floor} vs {}",
            zr.phase_resolution
        );
        let above = phase_change_at_nearest(w, 4.0 * zr.floor, &omega);
        assert!(above > 1.9 * zr.phase_resolution, "{above}");
        // Resolved: 3 lines in the half-power band from ζ = 1.5 Δω/ω_n up (the peak midway
        // between lines is the worst place).
        assert!((zr.resolved - 1.5 / 460.5).abs() < 1e-9);
        let band = |z: f64| omega.iter().filter(|x| (**x - w).abs() <= z * w).count();
        assert!(band(1.01 * zr.resolved) >= MIN_LINES_IN_BAND);
        assert!(band(0.6 * zr.resolved) < MIN_LINES_IN_BAND);
    }

    #[test]
    fn dense_lines_and_quiet_data_lower_the_floor() {
        let tau = std::f64::consts::TAU;
        let w = tau * 110.0;
        let coarse: Vec<f64> = (0..1632).map(|k| tau * (20.0 + 0.625 * k as f64)).collect();
        let mut dense = coarse.clone();
        dense.extend((0..8).map(|k| w * (1.0 + 0.6e-4 * (k as f64 - 3.7))));
        dense.sort_by(f64::total_cmp);
        let truth = one_mode(w, 1.2e-4);
        let d_coarse = Channels::of_model(&truth, coarse, vec![(0, 0)], 1.0, (0.01, 0.0));
        let d_dense = Channels::of_model(&truth, dense, vec![(0, 0)], 1.0, (0.01, 0.0));
        let d_quiet = Channels::of_model(
            &truth,
            d_coarse.omega.clone(),
            vec![(0, 0)],
            1.0,
            (0.001, 0.0),
        );
        let (a, b, c) = (
            zeta_range(&d_coarse, w),
            zeta_range(&d_dense, w),
            zeta_range(&d_quiet, w),
        );
        // The fixed bound 1e-4 held ζ = 1.2e-4 modes near it; the record's floor is far below.
        assert!(a.floor < 1e-4 && b.floor < a.floor / 50.0, "{a:?} {b:?}");
        assert!((c.floor / a.floor - 0.1).abs() < 1e-6, "{a:?} {c:?}");
        // Dense lines resolve ζ = 1.2e-4 (its band holds ≥ 3 lines); 0.625 Hz lines do not.
        assert!(b.resolved < 1.2e-4 && a.resolved > 1.2e-4, "{a:?} {b:?}");
    }
}
