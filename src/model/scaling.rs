//! Units scaling of the plant, the data and the controller: the `[scaling]` config key.
//!
//! Loop-shaping practice (Skogestad & Postlethwaite, *Multivariable Feedback Control*, §1.4
//! and §9.4; McFarlane & Glover) scales a plant before its normalized coprime factorization:
//! `G_s = D_o·G·D_i` with constant positive diagonal `D_o` (outputs, `y_s = D_o·y`) and `D_i`
//! (inputs, `u = D_i·u_s`).  Everything else follows the units:
//!
//! * the measured FRF: `Φ_s = D_o·Φ·D_i`, entry `(k, l)` times `d_o,k·d_i,l`; a noise disk
//!   radius (SISO) times `d_o·d_i`, since a radius or a standard deviation scales like the
//!   entry it bounds;
//! * a `[plant]`: its state space `(A, B·D_i, D_o·C, D_o·D·D_i)` is factored, so the
//!   normalized coprime factors, their A1 limit `σ_min(M̃_s)` and `r` are those of `G_s`;
//! * a `[model]` with the standard factorization `G = M̃⁻¹Ñ`: `M̃_s = D_o·M̃·D_o⁻¹`,
//!   `Ñ_s = D_o·Ñ·D_i` (the equations `M̃y = Ñu` in the new units, each row scaled as its
//!   output), so `G_s = M̃_s⁻¹Ñ_s`;
//! * a `[model]` with the special factorization `G = C·M̃⁻¹·Ñ·J`, or the factorization of a
//!   `[physical]` model: `C_s = D_o·C`, `J_s = J·D_i`; the modal factors `M̃`, `Ñ` and every
//!   perturbation of them are unchanged, so the Theorem 3 envelope (and the noisy one of
//!   Theorem 4) does not depend on the units; a `[physical]` model itself stays in the data
//!   file's units (`compare` evaluates `D_o·G·D_i`, `diagnose` works unscaled);
//! * a controller `K` of the loop `u = −K·y` for `G` is `K_s = D_i⁻¹·K·D_o⁻¹` for `G_s`
//!   (the loop gain `G_s·K_s = D_o·G·K·D_o⁻¹` is similar to `G·K`, the loop is the same).
//!
//! `r` then bounds the perturbations of the factors of the **scaled** plant.

use super::factorization::{Factorization, FactorizationKind};
use crate::data::FrfData;
use crate::system::{StateSpace, TfMatrix, TransferFunction};
use nalgebra::DMatrix;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// The `scaling` key as written: `scaling = "auto"`, or a `[scaling]` table.
///
/// ```toml
/// [scaling]                 # G_s = D_o·G·D_i, positive finite numbers
/// outputs = [1e-3, 1e-3]    # D_o = diag(outputs): y_s = D_o·y  (default all ones)
/// inputs = [1, 1]           # D_i = diag(inputs):  u = D_i·u_s  (default all ones)
/// ```
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum ScalingSpec {
    /// `scaling = "auto"` (a `[plant]` only): see [`auto_scaling`].
    Keyword(String),
    /// The `[scaling]` table.
    Diagonal(ScalingSection),
}

/// A string or a table, each with its own message (an untagged enum would only say that
/// nothing matched): `unknown field `output`, expected `outputs` or `inputs``.
impl<'de> Deserialize<'de> for ScalingSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ScalingSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("scaling = \"auto\" or a table [scaling] with outputs = [...] and inputs = [...]")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<ScalingSpec, E> {
                Ok(ScalingSpec::Keyword(v.to_string()))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<ScalingSpec, A::Error> {
                ScalingSection::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(ScalingSpec::Diagonal)
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// The `[scaling]` table: the diagonals of `D_o` and `D_i`.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScalingSection {
    /// Diagonal of `D_o` (one per plant output); default all ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outputs: Option<Vec<f64>>,
    /// Diagonal of `D_i` (one per plant input); default all ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<Vec<f64>>,
}

/// Resolved diagonal scalings `D_o`, `D_i` of `G_s = D_o·G·D_i` (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Scaling {
    /// Diagonal of `D_o`, one per output.
    pub outputs: Vec<f64>,
    /// Diagonal of `D_i`, one per input.
    pub inputs: Vec<f64>,
    /// Computed by `scaling = "auto"` ([`auto_scaling`]) rather than written.
    pub auto: bool,
}

fn check_side(v: &[f64], key: &str, n: usize, side: &str) -> Result<(), String> {
    if v.len() != n {
        return Err(format!(
            "[scaling] {key} has {} entries, the plant has {n} {side}: give one positive number per {}",
            v.len(),
            side.trim_end_matches('s')
        ));
    }
    if let Some((k, x)) = v
        .iter()
        .enumerate()
        .find(|(_, x)| !(x.is_finite() && **x > 0.0))
    {
        return Err(format!(
            "[scaling] {key}[{}] = {x}: every scaling must be a positive finite number (a unit change, e.g. 1e-3 for mm → m)",
            k + 1
        ));
    }
    Ok(())
}

impl ScalingSpec {
    /// The scalings for a plant of `outputs × inputs`; `plant` (the state space of a
    /// `[plant]`) is needed by `"auto"`, which is refused without it.
    pub fn resolve(
        &self,
        outputs: usize,
        inputs: usize,
        plant: Option<&StateSpace>,
    ) -> Result<Scaling, String> {
        match self {
            ScalingSpec::Keyword(k) if k == "auto" => match plant {
                Some(ss) => auto_scaling(ss),
                None => Err("scaling = \"auto\" needs the model as a [plant]; give the diagonals instead: [scaling] outputs = [...], inputs = [...]".into()),
            },
            ScalingSpec::Keyword(k) => Err(format!(
                "scaling = \"{k}\": write scaling = \"auto\", or a table [scaling] with outputs = [...] and inputs = [...]"
            )),
            ScalingSpec::Diagonal(s) => {
                let outs = s.outputs.clone().unwrap_or_else(|| vec![1.0; outputs]);
                let ins = s.inputs.clone().unwrap_or_else(|| vec![1.0; inputs]);
                check_side(&outs, "outputs", outputs, "outputs")?;
                check_side(&ins, "inputs", inputs, "inputs")?;
                Ok(Scaling {
                    outputs: outs,
                    inputs: ins,
                    auto: false,
                })
            }
        }
    }
}

impl Scaling {
    /// `D_o·G·D_i` of a state space: `(A, B·D_i, D_o·C, D_o·D·D_i)`.
    pub fn plant(&self, g: &StateSpace) -> StateSpace {
        let mut s = g.clone();
        for (j, d) in self.inputs.iter().enumerate() {
            s.b.column_mut(j).scale_mut(*d);
            s.d.column_mut(j).scale_mut(*d);
        }
        for (i, d) in self.outputs.iter().enumerate() {
            s.c.row_mut(i).scale_mut(*d);
            s.d.row_mut(i).scale_mut(*d);
        }
        s
    }

    /// `K_s = D_i⁻¹·K·D_o⁻¹` of a controller `K` (`inputs × outputs` of the plant):
    /// `(A, B·D_o⁻¹, D_i⁻¹·C, D_i⁻¹·D·D_o⁻¹)`.
    pub fn controller(&self, k: &StateSpace) -> StateSpace {
        let inverse = Scaling {
            outputs: self.inputs.iter().map(|x| 1.0 / x).collect(),
            inputs: self.outputs.iter().map(|x| 1.0 / x).collect(),
            auto: self.auto,
        };
        inverse.plant(k)
    }

    /// `K = D_i·K_s·D_o`: a controller of the scaled plant back in the plant's own units
    /// (the inverse of [`Scaling::controller`]), for the controller files `synthesize` writes.
    pub fn unscale_controller(&self, k_s: &StateSpace) -> StateSpace {
        Scaling {
            outputs: self.inputs.clone(),
            inputs: self.outputs.clone(),
            auto: self.auto,
        }
        .plant(k_s)
    }

    /// The scaled factorization of a `[model]` (see the module doc): standard
    /// `(D_o·M̃·D_o⁻¹, D_o·Ñ·D_i)`, special `(D_o·C, M̃, Ñ, J·D_i)`.  Factors given by a
    /// realization (a `[plant]`) are scaled before they are computed, never here.
    pub fn factorization(&self, f: &Factorization) -> Result<Factorization, String> {
        if f.realization.is_some() {
            return Err("a [plant]'s factors are scaled through its state space".into());
        }
        let gain = |t: &TransferFunction, k: f64| t.mul(&TransferFunction::gain(k));
        let entrywise = |m: &TfMatrix, row: &dyn Fn(usize) -> f64, col: &dyn Fn(usize) -> f64| {
            let rows = (0..m.rows())
                .map(|i| {
                    (0..m.cols())
                        .map(|j| gain(m.entry(i, j), row(i) * col(j)))
                        .collect()
                })
                .collect();
            TfMatrix::from_rows(rows).expect("same shape")
        };
        let d_o = |i: usize| self.outputs[i];
        let d_i = |j: usize| self.inputs[j];
        match f.kind {
            FactorizationKind::Standard => {
                let m = entrywise(&f.m, &d_o, &|j| 1.0 / self.outputs[j]);
                let n = entrywise(&f.n, &d_o, &d_i);
                Factorization::standard(m, n).map_err(|e| format!("[scaling]: {e}"))
            }
            FactorizationKind::Special => {
                let mut c = f.c.clone();
                for (i, d) in self.outputs.iter().enumerate() {
                    c.row_mut(i).scale_mut(*d);
                }
                let j =
                    f.j.iter()
                        .zip(&self.inputs)
                        .map(|(t, d)| gain(t, *d))
                        .collect();
                Factorization::special(c, f.m.clone(), f.n.clone(), j)
                    .map_err(|e| format!("[scaling]: {e}"))
            }
        }
    }

    /// `Φ_s = D_o·Φ·D_i` for every datum.  The data's `noise_radius` column stays in the
    /// file's units: the noise is resolved on the file's units and its radii scaled by
    /// [`Scaling::entry_factor`] ([`crate::model::resolve_noise_for_channel`]).  The sizes
    /// must be the plant's.
    pub fn frf(&self, mut data: FrfData) -> Result<FrfData, String> {
        let (p, m) = (data.outputs(), data.inputs());
        if (p, m) != (self.outputs.len(), self.inputs.len()) && !data.is_empty() {
            return Err(format!(
                "the data are {p}×{m} and [scaling] is for a {}×{} plant (outputs × inputs): give one scaling per output and input of the data the model is compared with",
                self.outputs.len(),
                self.inputs.len()
            ));
        }
        let w = self.entry_weights();
        for h in &mut data.response {
            h.zip_apply(&w, |x, k| *x *= k);
        }
        Ok(data)
    }

    /// `Φ = D_o⁻¹·Φ_s·D_i⁻¹`: data back in the file's units.
    pub fn unscale_frf(&self, mut data: FrfData) -> FrfData {
        let w = self.entry_weights();
        for h in &mut data.response {
            h.zip_apply(&w, |x, k| *x /= k);
        }
        data
    }

    /// `d_o,k·d_i,l` for every entry `(k, l)`.
    fn entry_weights(&self) -> DMatrix<Complex64> {
        DMatrix::from_fn(self.outputs.len(), self.inputs.len(), |i, j| {
            Complex64::new(self.outputs[i] * self.inputs[j], 0.0)
        })
    }

    /// The factor `d_o,k·d_i,l` of entry `(k, l)` (0-based): that of its noise radius or
    /// standard deviation too, which scale like the entry they bound.
    pub fn entry_factor(&self, (k, l): (usize, usize)) -> f64 {
        self.outputs[k] * self.inputs[l]
    }

    /// The `[scaling]` table of these diagonals (what a written config carries: a revision
    /// of `scaling = "auto"` gets the values it resolved to).
    pub fn spec(&self) -> ScalingSpec {
        ScalingSpec::Diagonal(ScalingSection {
            outputs: Some(self.outputs.clone()),
            inputs: Some(self.inputs.clone()),
        })
    }

    /// `D_o = diag(..), D_i = diag(..)` for messages, each number as written in a config.
    pub fn describe(&self) -> String {
        let list = |v: &[f64]| v.iter().map(|x| short(*x)).collect::<Vec<_>>().join(", ");
        format!(
            "D_o = diag({}), D_i = diag({})",
            list(&self.outputs),
            list(&self.inputs)
        )
    }

    /// The key to copy into a config in place of `scaling = "auto"`:
    /// `scaling = { outputs = [..], inputs = [..] }` (an inline table, valid where the
    /// top-level key was).
    pub fn as_toml(&self) -> String {
        let list = |v: &[f64]| v.iter().map(|x| short(*x)).collect::<Vec<_>>().join(", ");
        format!(
            "scaling = {{ outputs = [{}], inputs = [{}] }}",
            list(&self.outputs),
            list(&self.inputs)
        )
    }
}

/// A scaling as one would write it: `0.001`, `250`, `1e-6`, `2.5e-7` (shortest round trip).
fn short(x: f64) -> String {
    if (1e-3..1e4).contains(&x) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Number of frequencies of the grid of [`auto_scaling`].
pub const AUTO_POINTS: usize = 200;

/// `scaling = "auto"`: diagonal scalings that bring the plant's peak gains near 1.
///
/// Why the peak: for normalized coprime factors `σ_min(M̃) ≈ 1/√(1 + ‖G‖²)`, so where the
/// scaled gain is large the A1 limit leaves `r` a notch (a lightly damped mode of gain 2e6
/// leaves 5e-7); with every peak near 1 the limit stays near `1/√2` or above and `r` is
/// close to the additive misfit.  (A geometric mean near 1 leaves the peaks large.)
///
/// Per entry the peak `g_kl` of `|G_kl(jω)|` over `AUTO_POINTS` (200) log-spaced
/// frequencies from a decade below the slowest to a decade above the fastest nonzero pole
/// of the plant (0.1 to 10 rad/s for a static gain); entries below `1e-12·max g` (structural
/// zeros) are left out.  Then `log d_o,k + log d_i,l = −log g_kl` is solved in least squares
/// (alternating exact minimizations, capped at 200 sweeps), the free common factor split so
/// that `D_o` and `D_i` have the same geometric mean, and each `d` rounded to 3 significant
/// digits, so that the printed table is exactly what was used.  SISO: `d_o = d_i = 1/√g`.
/// The band comes from the model, not the data: a peak outside the data's band counts.
pub fn auto_scaling(g: &StateSpace) -> Result<Scaling, String> {
    let (p, m) = (g.d.nrows(), g.d.ncols());
    let poles = if g.a.nrows() == 0 {
        Vec::new()
    } else {
        crate::system::eig::eigenvalues(&g.a, "scaling = \"auto\"").map_err(|e| e.to_string())?
    };
    let mags: Vec<f64> = poles
        .iter()
        .map(|z| z.norm())
        .filter(|w| *w > 1e-12)
        .collect();
    let (lo, hi) = if mags.is_empty() {
        (0.1, 10.0)
    } else {
        (
            mags.iter().copied().fold(f64::INFINITY, f64::min) / 10.0,
            mags.iter().copied().fold(0.0, f64::max) * 10.0,
        )
    };
    let mut peak = DMatrix::<f64>::zeros(p, m);
    let mut count = 0usize;
    for w in crate::system::logspace(lo, hi, AUTO_POINTS) {
        // A frequency on a pole of the imaginary axis is skipped.
        let Some(h) = g.freq(w) else { continue };
        peak.zip_apply(&h, |x, v| *x = x.max(v.norm()));
        count += 1;
    }
    if count == 0 || peak.iter().any(|x| !x.is_finite()) {
        return Err("scaling = \"auto\": the plant cannot be evaluated on its band; give [scaling] outputs and inputs".into());
    }
    let log_g = peak.map(|x| x.max(f64::MIN_POSITIVE).ln());
    let top = log_g.max();
    let used = log_g.map(|x| x > top + (1e-12f64).ln());
    let solved = solve_log_scalings(&log_g, &used)
        .ok_or("scaling = \"auto\": some output or input of the plant has zero gain everywhere; give [scaling] outputs and inputs")?;
    let round = |x: f64| format!("{:.2e}", x).parse::<f64>().unwrap_or(x);
    Ok(Scaling {
        outputs: solved.0.iter().map(|x| round(x.exp())).collect(),
        inputs: solved.1.iter().map(|x| round(x.exp())).collect(),
        auto: true,
    })
}

/// Least squares `x_k + y_l ≈ −L_kl` over the used entries, by alternating exact
/// minimizations (a convex quadratic: each sweep does not increase the residual), then the
/// common shift fixed by `mean x = mean y`.  `None` when a row or column has no used entry.
fn solve_log_scalings(l: &DMatrix<f64>, used: &DMatrix<bool>) -> Option<(Vec<f64>, Vec<f64>)> {
    let (p, m) = l.shape();
    if (0..p).any(|i| (0..m).all(|j| !used[(i, j)]))
        || (0..m).any(|j| (0..p).all(|i| !used[(i, j)]))
    {
        return None;
    }
    let mut x = vec![0.0; p];
    let mut y = vec![0.0; m];
    for _ in 0..200 {
        let mut change: f64 = 0.0;
        for i in 0..p {
            let js: Vec<usize> = (0..m).filter(|&j| used[(i, j)]).collect();
            let v = js.iter().map(|&j| -l[(i, j)] - y[j]).sum::<f64>() / js.len() as f64;
            change = change.max((v - x[i]).abs());
            x[i] = v;
        }
        for j in 0..m {
            let is: Vec<usize> = (0..p).filter(|&i| used[(i, j)]).collect();
            let v = is.iter().map(|&i| -l[(i, j)] - x[i]).sum::<f64>() / is.len() as f64;
            change = change.max((v - y[j]).abs());
            y[j] = v;
        }
        if change < 1e-12 {
            break;
        }
    }
    let mx = x.iter().sum::<f64>() / p as f64;
    let my = y.iter().sum::<f64>() / m as f64;
    let t = (my - mx) / 2.0;
    Some((
        x.iter().map(|v| v + t).collect(),
        y.iter().map(|v| v - t).collect(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The alternating least squares against the closed form of a rank-one log-gain table:
    /// `L_kl = a_k + b_l` is met exactly, with equal means of `x` and `y`.
    #[test]
    fn log_scalings_meet_a_rank_one_table() {
        let a = [1.0, -2.0, 0.5];
        let b = [3.0, 0.25];
        let l = DMatrix::from_fn(3, 2, |i, j| a[i] + b[j]);
        let used = DMatrix::from_element(3, 2, true);
        let (x, y) = solve_log_scalings(&l, &used).expect("solvable");
        for i in 0..3 {
            for j in 0..2 {
                assert!((x[i] + y[j] + l[(i, j)]).abs() < 1e-9, "entry ({i},{j})");
            }
        }
        let mx = x.iter().sum::<f64>() / 3.0;
        let my = y.iter().sum::<f64>() / 2.0;
        assert!((mx - my).abs() < 1e-9);
    }

    /// SISO `k/(s+1)`: the peak of `|G|` on the grid (at its first point, 0.1 rad/s),
    /// computed here in closed form, gives `d_o = d_i = 1/√g` (to the 3 digits kept).
    #[test]
    fn auto_siso_is_inverse_square_root_of_peak_gain() {
        let k = 2.5e6;
        let g = StateSpace {
            a: DMatrix::from_element(1, 1, -1.0),
            b: DMatrix::from_element(1, 1, 1.0),
            c: DMatrix::from_element(1, 1, k),
            d: DMatrix::zeros(1, 1),
        };
        let s = auto_scaling(&g).expect("auto");
        let peak = k / (1.0f64 + 0.1 * 0.1).sqrt();
        let d = 1.0 / peak.sqrt();
        assert!(
            (s.outputs[0] / d - 1.0).abs() < 5e-3,
            "{} vs {d}",
            s.outputs[0]
        );
        assert_eq!(s.outputs, s.inputs);
    }

    /// Zero, negative, non-finite and wrongly sized scalings are refused with the key.
    #[test]
    fn bad_scalings_name_the_key() {
        let spec = |o: Vec<f64>, i: Vec<f64>| {
            ScalingSpec::Diagonal(ScalingSection {
                outputs: Some(o),
                inputs: Some(i),
            })
        };
        let e = spec(vec![1.0, 0.0], vec![1.0])
            .resolve(2, 1, None)
            .unwrap_err();
        assert!(e.contains("[scaling] outputs[2] = 0"), "{e}");
        let e = spec(vec![1.0], vec![-2.0]).resolve(1, 1, None).unwrap_err();
        assert!(e.contains("[scaling] inputs[1] = -2"), "{e}");
        let e = spec(vec![1.0], vec![1.0, 1.0])
            .resolve(1, 1, None)
            .unwrap_err();
        assert!(
            e.contains("[scaling] inputs has 2 entries, the plant has 1 inputs"),
            "{e}"
        );
        let e = ScalingSpec::Keyword("auto".into())
            .resolve(1, 1, None)
            .unwrap_err();
        assert!(e.contains("[plant]"), "{e}");
    }
}
