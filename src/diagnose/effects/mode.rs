//! An added mode `ρ_ch/(s² + 2ζω_n s + ω_n²)`: the modal model of docs/design/effects.md,
//! one `ω_n` and `ζ` shared by every channel and a residue per channel; θ = [ln ω_n, ln ζ,
//! ρ_1 … ρ_C].

use crate::diagnose::effects::effect::{
    clamp_zeta, fmt_w, last, log_grid, one, per_channel, sig, Band, Effect, Explain, Param,
    Resolution, Sel, Si, Site, Stands, Writer, ZETA_BOUNDS,
};
use crate::model::physical::{ModeSpec, PhysicalModel};
use num_complex::Complex64;

/// An added mode.
#[derive(Debug, Clone, Copy)]
pub struct Mode;

/// A mode's term `ρ/(s² + 2ζω s + ω²)` at `s = jω`.
pub fn mode_term(omega: f64, w: f64, z: f64, rho: f64) -> Complex64 {
    let s = Complex64::new(0.0, omega);
    rho / (s * s + 2.0 * z * w * s + w * w)
}

impl Effect for Mode {
    const NAME: &'static str = "mode";

    fn tried_on(_: Sel) -> Vec<Self> {
        vec![]
    }

    fn tried(_: &PhysicalModel) -> Vec<Self> {
        vec![Mode]
    }

    fn sel(&self) -> Option<Sel> {
        None
    }

    fn n_params(&self, n_ch: usize) -> usize {
        2 + n_ch
    }

    fn typ(&self, theta: &[f64], _: f64) -> Vec<f64> {
        let mut v = vec![1.0, 1.0];
        v.extend(theta[2..].iter().map(|x| x.abs().max(1e-300)));
        v
    }

    /// The mode resonates inside the band (an out-of-band one is a compliance or mass line:
    /// the feedthrough and rigid-body candidates), `ζ ∈ [ζ_lo, 0.7]` (`ζ_lo` the record's floor), residues free.
    fn bounds(&self, n_ch: usize, w_min: f64, w_max: f64, zeta_lo: f64) -> Vec<(f64, f64)> {
        let lz = (zeta_lo.max(ZETA_BOUNDS.0).ln(), ZETA_BOUNDS.1.ln());
        let mut v = vec![(w_min.ln(), w_max.ln()), lz];
        v.extend(std::iter::repeat_n(
            (f64::NEG_INFINITY, f64::INFINITY),
            n_ch,
        ));
        v
    }

    fn natural(&self, th: &[f64], nat: &mut [f64]) {
        nat[0] = th[0].exp();
        nat[1] = clamp_zeta(th[1].exp());
    }

    fn base_residue(&self, _: &PhysicalModel, _: (usize, usize)) -> f64 {
        0.0
    }

    fn modify(
        &self,
        nat: &[f64],
        _: f64,
        _: &PhysicalModel,
        omega: f64,
        ch: usize,
        _: (usize, usize),
        core: &mut Complex64,
        _: &mut Complex64,
    ) {
        *core += mode_term(omega, nat[0], nat[1], nat[2 + ch]);
    }

    fn si_params(&self, th: &[f64], entries: &[(usize, usize)]) -> Vec<(String, f64, f64)> {
        let mut v = one("omega_n", th[0].exp(), th[0].exp());
        let z = clamp_zeta(th[1].exp());
        v.extend(one("zeta", z, z));
        v.extend(per_channel("rho", th, 2, entries));
        v
    }

    fn write(&self, w: &mut Writer) {
        let (b, c) = w.gains(2);
        let spec = ModeSpec {
            name: Some(w.note.to_string()),
            omega_n: w.get("omega_n"),
            zeta: w.get("zeta"),
            mass: 1.0,
            input_gain: b,
            output_gain: c,
        };
        w.m.mode.push(spec);
    }

    fn explain(&self, x: &Explain) -> String {
        format!(
            "the misfit peaks at {} with a half-power width 2ζω_n = {} rad/s, and data/model shows a peak–notch pair: an unmodelled mode, ω_n = {}, ζ = {}, residue {}",
            fmt_w(x.p("omega_n")),
            sig(2.0 * x.p("zeta") * x.p("omega_n")),
            fmt_w(x.p("omega_n")),
            sig(x.p("zeta")),
            x.list("rho")
        )
    }

    fn prior(&self) -> usize {
        10
    }

    /// `ω_n` candidates: the local maxima of the worst channel's `|e|/r` (five dampings
    /// each), plus the LSCF proposals; residues by least squares per channel.
    fn starts(&self, site: &dyn Site) -> Vec<Vec<f64>> {
        let (wmin, wmax) = site.band();
        let om = site.omega();
        let cw = site.worst_misfit();
        let f = cw.len();
        let mut peaks: Vec<(f64, f64)> = (0..f)
            .filter(|&k| (k == 0 || cw[k] >= cw[k - 1]) && (k + 1 == f || cw[k] >= cw[k + 1]))
            .map(|k| (cw[k], om[k]))
            .collect();
        peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
        let zetas = [0.005, 0.02, 0.06, 0.2, 0.5];
        let mut points: Vec<(f64, f64)> = peaks
            .iter()
            .take(4)
            .flat_map(|p| zetas.map(|z| (p.1, z)))
            .collect();
        // The poles of the residual stable across the orders of an LSCF diagram
        // (`crate::diagnose::effects::lscf`), at their own damping; the log grid over the
        // band only when the diagram has none.
        let proposals = site.mode_proposals();
        if proposals.is_empty() {
            points.extend(
                log_grid(wmin, wmax, 30)
                    .iter()
                    .flat_map(|x| zetas.map(|z| (x.exp(), z))),
            );
        }
        points.extend(proposals);
        let mut trials: Vec<(f64, Vec<f64>)> = Vec::new();
        for (w, z) in points {
            let th = site.mode_theta(w, z);
            trials.push((site.cost(&th), th));
        }
        trials.sort_by(|a, b| a.0.total_cmp(&b.0));
        trials.into_iter().take(4).map(|t| t.1).collect()
    }

    fn flags(
        &self,
        th: &[f64],
        at: &dyn Fn(usize) -> bool,
        _: &Si,
        band: Band,
        out: &mut Vec<String>,
    ) {
        if at(0) {
            let w = th[0].exp();
            let edge = if w < (band.w_min * band.w_max).sqrt() {
                "below: the lower residual of modes below the band, see the integrator candidate of order 2"
            } else {
                "above: the upper residual of modes above the band, see the feedthrough candidate"
            };
            out.push(format!(
                "ω_n at the band edge {}: the resonance is not inside the measured band ({edge})",
                fmt_w(w)
            ));
        }
        if at(1) {
            let z = th[1].exp().clamp(band.zeta_lo, ZETA_BOUNDS.1);
            out.push(format!(
                "ζ at its {} bound {}: not identified",
                if z < 0.01 { "lower" } else { "upper" },
                sig(z)
            ));
        }
    }

    fn stands(&self) -> Stands {
        Stands::AddedMode
    }

    fn lacks_its_term(&self, _: &PhysicalModel) -> bool {
        false
    }

    /// The added mode is the last.
    fn its_mode(&self, m: &PhysicalModel) -> Option<usize> {
        last(m.mode.len())
    }

    fn term_alone(&self, _: &PhysicalModel) -> Option<PhysicalModel> {
        None
    }

    fn below_resolution(&self, _: &PhysicalModel, _: &Resolution) -> Option<String> {
        None
    }

    /// Its `ω_n`, `ζ`, input gains and residues.
    fn owns(&self, m: &PhysicalModel) -> Vec<Param> {
        last(m.mode.len())
            .map(|i| {
                vec![
                    Param::ModeOmega(i),
                    Param::ModeZeta(i),
                    Param::ModeInputs(i),
                    Param::ModeResidues(i),
                ]
            })
            .unwrap_or_default()
    }

    /// `|Δ ln ω_n|`: two added modes are the same when their frequencies are.
    fn apart(&self, a: &[f64], b: &[f64]) -> f64 {
        (a[0] - b[0]).abs()
    }
}
