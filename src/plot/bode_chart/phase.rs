//! The phase of a Bode figure: the model's phase unwrapped along its grid, each datum drawn on
//! the model's branch, the phase axis (multiples of 90°), a noise disk's phase span.  Both
//! figures follow these rules, whatever their magnitude axis and frequency unit (`run`: |G| on
//! a log axis against rad/s, as in the paper's Fig. 7; `compare`: dB against Hz, the unit
//! modes are quoted in).

use crate::plot::axis::{unwrap_deg, PhaseAxis};
use num_complex::Complex64;

/// The phase `p` (degrees) moved by whole turns to the branch nearest `to` (a datum at −179°
/// beside a model at +179° is drawn 2° from it, not 358°).
pub fn nearest_branch(p: f64, to: f64) -> f64 {
    p + 360.0 * ((to - p) / 360.0).round()
}

/// Half the phase span (degrees) of the disk `|G − z| ≤ r` around a point `z` with `|z| = a`:
/// `asin(r/a)`, or 180° (every phase) when the disk holds 0.
pub fn disk_half_span_deg(r: f64, a: f64) -> f64 {
    if r < a {
        (r / a).asin().to_degrees()
    } else {
        180.0
    }
}

/// The model's phase (degrees) along its grid, unwrapped, NaN where the model is unknown or
/// zero (no phase there).
pub fn model_phase<I: IntoIterator<Item = Complex64>>(g: I) -> Vec<f64> {
    let g: Vec<Complex64> = g
        .into_iter()
        .map(|z| {
            if z.norm() > 0.0 && z.norm().is_finite() {
                z
            } else {
                Complex64::new(f64::NAN, f64::NAN)
            }
        })
        .collect();
    unwrap_deg(&g)
}

/// Linear interpolation of `y(x)` at `x0` (`x` increasing), NaN outside.
pub fn interp(x: &[f64], y: &[f64], x0: f64) -> f64 {
    let k = x.partition_point(|v| *v < x0);
    if k < x.len() && x[k] == x0 {
        return y[k];
    }
    if k == 0 || k >= x.len() {
        return f64::NAN;
    }
    let t = (x0 - x[k - 1]) / (x[k] - x[k - 1]);
    y[k - 1] + t * (y[k] - y[k - 1])
}

/// The phase of each datum (degrees), given the model's unwrapped phase at the same
/// frequency (`reference`) and the data's noise radii (`radius`): on the branch nearest the
/// model where the datum lies within 90° of it, or where its noise disk holds 0 (its phase is
/// then not measured, and continuity would carry noise along); otherwise, of the two branches
/// on either side of the model, the one nearest the previous datum (a datum about 180° from
/// the model, past a resonance the model lacks, keeps the phase the data have lost instead of
/// jumping a turn).  Unwrapped along the data without a reference.
pub fn data_phase(g: &[Complex64], reference: Option<&[f64]>, radius: Option<&[f64]>) -> Vec<f64> {
    let Some(r) = reference else {
        return unwrap_deg(g);
    };
    let mut out: Vec<f64> = Vec::with_capacity(g.len());
    for (k, (z, m)) in g.iter().zip(r).enumerate() {
        let p = z.arg().to_degrees();
        let measured = radius.is_none_or(|r| r[k] < z.norm());
        let prev = out.last().copied().filter(|v| v.is_finite());
        let v = if m.is_finite() {
            let near = nearest_branch(p, *m);
            let other = if near < *m {
                near + 360.0
            } else {
                near - 360.0
            };
            match prev {
                Some(q) if measured && (near - m).abs() > 90.0 => {
                    if (other - q).abs() < (near - q).abs() {
                        other
                    } else {
                        near
                    }
                }
                _ => near,
            }
        } else {
            prev.map_or(p, |q| nearest_branch(p, q))
        };
        out.push(v);
    }
    out
}

/// The phase axis of a Bode figure: multiples of 90° covering the data's phases and the
/// model's phases inside the plotted band.
pub fn phase_axis<I: IntoIterator<Item = f64>>(data: &[f64], model_in_band: I) -> PhaseAxis {
    PhaseAxis::covering(data.iter().copied().chain(model_in_band))
}

/// The phase bar `(lo, hi)` of a datum at phase `ang` with `|G| = a` and noise radius `r`:
/// the disk's span `±asin(r/a)` (all phases when it holds 0), inside the axis.
pub fn disk_phase_bar(ang: f64, r: f64, a: f64, axis: &PhaseAxis) -> (f64, f64) {
    let half = disk_half_span_deg(r, a);
    (axis.clamp(ang - half), axis.clamp(ang + half))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn branches_and_disk_spans_match_their_closed_forms() {
        assert_eq!(nearest_branch(-179.0, 179.0), 181.0);
        assert_eq!(nearest_branch(10.0, -710.0), -710.0);
        assert_eq!(nearest_branch(45.0, 50.0), 45.0);
        // A disk of radius 1 at distance 2 is seen under ±30°.
        assert!((disk_half_span_deg(1.0, 2.0) - 30.0).abs() < 1e-12);
        assert_eq!(disk_half_span_deg(2.0, 2.0), 180.0);
        assert_eq!(disk_half_span_deg(3.0, 1.0), 180.0);
    }

    fn close(a: Vec<f64>, b: &[f64]) {
        assert!(
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9),
            "{a:?} vs {b:?}"
        );
    }

    /// A unit-magnitude datum at phase `deg`.
    fn at(deg: f64) -> Complex64 {
        Complex64::from_polar(1.0, deg.to_radians())
    }

    #[test]
    fn data_sit_on_the_model_branch_unless_measured_past_it() {
        // Near the model (within 90°): the branch nearest it, whatever came before.
        let g = [at(170.0), at(-170.0)];
        close(
            data_phase(&g, Some(&[-190.0, -190.0]), None),
            &[-190.0, -170.0],
        );
        // Past a resonance the model lacks: the data lose 180° more than the model
        // (−180°); measured (small disks), they keep the lost turn, −200° → −350° → −400°.
        let g = [at(-200.0), at(-350.0), at(-400.0)];
        let model = [-180.0; 3];
        let small = [0.1; 3];
        close(
            data_phase(&g, Some(&model), Some(&small)),
            &[-200.0, -350.0, -400.0],
        );
        // The same data with disks holding 0 (phase not measured): nearest the model.
        let large = [2.0; 3];
        close(
            data_phase(&g, Some(&model), Some(&large)),
            &[-200.0, -350.0, -40.0],
        );
        // Continuity picks between the two branches beside the model only: a long run of
        // measured data cannot wander turns away from it.
        let g: Vec<Complex64> = (0..40).map(|k| at(-100.0 - 25.0 * k as f64)).collect();
        let d = data_phase(&g, Some(&[0.0; 40]), None);
        assert!(d.iter().all(|p| p.abs() <= 360.0), "{d:?}");
        // Without a reference: unwrapped along the data.
        close(
            data_phase(&[at(170.0), at(-170.0)], None, None),
            &[170.0, 190.0],
        );
    }
}
