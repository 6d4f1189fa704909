//! The mains rule of [`super::check`]: when a line-narrow mode at 50/60 Hz or a harmonic is
//! electrical interference, and when the data show it is a resonance (issue 33).
//!
//! Interference is a tone at `h·f0`: in an FRF it is a spectral *line*, living in the data
//! line(s) at the harmonic.  A structural mode narrower than a line still shows its skirts on
//! the lines beside it (its contribution `≈ ρ/(2ω_n·i(ω − ω_n))`, falling as `1/|ω − ω_n|`,
//! of opposite sign on either side).  Two tests, either refuses:
//!
//! * **a spectral line** (every harmonic): the mode's evidence on the lines *outside* the
//!   mains tolerance — `ΔBIC_out = 2ΔV_out − p·ln(2N_out)` with
//!   `ΔV_out = 2 Σ_ch Σ_i [(|g − g_rest|/r)² − (|g − g_model|/r)²]` over those lines, `g_rest`
//!   the refit model without the mode, `p` its parameters (the search's BIC,
//!   [`delta_bic`]) — is at most the search's acceptance threshold
//!   ([`crate::diagnose::SearchSettings::min_delta_bic`], 10 by default): the lines beside it
//!   do not support it;
//! * **a stable harmonic** (low `h`): the mains fundamental wanders from its nominal value by
//!   up to [`MAINS_DRIFT_HZ`] during a measurement, its `h`-th harmonic by `h` times that.
//!   While `h·δf0` is within the tolerance the harmonic stays on its line, and a tone there,
//!   off the line's centre, leaks under a rectangular window into the lines beside it as
//!   `sin(πδ)/(π(δ − k))` — the `1/Δ` shape, constant phase and sign change of a resonance's
//!   skirts: the skirts cannot tell it apart, and the coincidence decides (the rule before
//!   this one).  Above, the nominal harmonic's position is not known to the resolution
//!   (`h·δf0` > tolerance: at 44 × 60 Hz, 2.2 Hz against 0.5–0.7 Hz), a coincidence with it
//!   is no evidence, and only the spectral-line test judges.
//!
//! The tolerance is the mode's resolution: half the local line spacing, or its own half-power
//! half-width `ζf` when wider; the rule applies only to a mode narrower than a line
//! (`ζf < Δf`).

use super::{spacing_at, MAINS_HZ};
use crate::diagnose::effects::candidates::{sig, Cand};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::delta_bic;
use crate::model::physical::PhysicalModel;
use std::f64::consts::TAU;

/// How far the mains fundamental wanders from its nominal 50/60 Hz during a measurement
/// (Hz): interconnected grids hold it within ±0.05 Hz in normal operation (ENTSO-E's
/// standard frequency range ±50 mHz; North American grids, ±36 mHz at 1σ).
pub const MAINS_DRIFT_HZ: f64 = 0.05;

/// A mains harmonic a mode sits on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// The fundamental, Hz.
    pub f0: f64,
    /// The harmonic number.
    pub h: f64,
    /// The tolerance, Hz: `max(½Δf, ζf)`.
    pub tol: f64,
}

impl Harmonic {
    /// The harmonic's nominal frequency, Hz.
    pub fn hz(&self) -> f64 {
        self.h * self.f0
    }

    /// The harmonic stays within the tolerance of its nominal frequency while the
    /// fundamental wanders by [`MAINS_DRIFT_HZ`].
    pub fn stable(&self) -> bool {
        self.h * MAINS_DRIFT_HZ <= self.tol
    }
}

/// The mains harmonics within the tolerance of a mode at `f` Hz with damping `z`, the local
/// line spacing `df` Hz; none when the mode is not narrower than a line.
pub fn harmonics_at(f: f64, z: f64, df: f64) -> Vec<Harmonic> {
    if z * f >= df {
        return vec![];
    }
    let tol = (0.5 * df).max(z * f);
    MAINS_HZ
        .iter()
        .map(|&f0| Harmonic {
            f0,
            h: (f / f0).round().max(1.0),
            tol,
        })
        .filter(|hm| (f - hm.hz()).abs() <= tol)
        .collect()
}

/// What the lines outside a mains window say of mode `k` of `m`.
#[derive(Debug, Clone, Copy)]
pub struct OffLine {
    /// `ΔBIC_out` (module docs).
    pub delta_bic: f64,
    /// Lines left out (within the tolerance of the harmonic).
    pub n_out: usize,
}

/// Mode `k`'s evidence on the lines of `data` farther than `tol` Hz from `centre` Hz.
pub fn off_line_support(
    m: &PhysicalModel,
    k: usize,
    data: &Channels,
    centre: f64,
    tol: f64,
) -> OffLine {
    let mut rest = m.clone();
    rest.mode.remove(k);
    let (mut dv, mut n, mut n_out) = (0.0, 0usize, 0usize);
    for (i, w) in data.omega.iter().enumerate() {
        if (w / TAU - centre).abs() <= tol {
            n_out += 1;
            continue;
        }
        let (ga, gr) = (m.eval(*w), rest.eval(*w));
        for (ch, e) in data.entries.iter().enumerate() {
            let (g, r) = (data.g[ch][i], data.radius[ch][i]);
            // Measures::v is 2Σ(|e|/r)².
            dv += 2.0 * (((g - gr[*e]).norm() / r).powi(2) - ((g - ga[*e]).norm() / r).powi(2));
            n += 1;
        }
    }
    OffLine {
        delta_bic: delta_bic(dv, Cand::Mode.n_params(data.entries.len()), n.max(1)),
        n_out,
    }
}

/// The mains refusal of mode `k` of `m`, if any (module docs); `min_delta_bic` is the
/// search's acceptance threshold.
pub(super) fn refusal(
    m: &PhysicalModel,
    k: usize,
    data: &Channels,
    min_delta_bic: f64,
) -> Option<String> {
    let md = &m.mode[k];
    let f = md.omega_n / TAU;
    let df = spacing_at(&data.omega, md.omega_n) / TAU;
    for hm in harmonics_at(f, md.zeta, df) {
        let at = format!(
            "at {} Hz, within the resolution ({} Hz) of {} Hz ({}× {} Hz mains) and narrower than a line",
            sig(f),
            sig(hm.tol),
            sig(hm.hz()),
            hm.h,
            hm.f0
        );
        let off = off_line_support(m, k, data, hm.hz(), hm.tol);
        if off.delta_bic <= min_delta_bic {
            return Some(format!(
                "{at}; the lines beside it do not show a resonance's skirts (its ΔBIC without the {} line{} within {} Hz of {} Hz: {} ≤ {}): a spectral line, probable electrical interference, not a mode of the structure (--allow-mains writes it)",
                off.n_out,
                if off.n_out == 1 { "" } else { "s" },
                sig(hm.tol),
                sig(hm.hz()),
                sig(off.delta_bic),
                min_delta_bic
            ));
        }
        if hm.stable() {
            return Some(format!(
                "{at}; at this harmonic the mains stays within {} Hz of it ({}× a {MAINS_DRIFT_HZ} Hz wander of the fundamental), and a tone off a line's centre leaks into the lines beside it as a resonance's skirts would: probable electrical interference, not a mode of the structure (--allow-mains writes it)",
                sig(hm.h * MAINS_DRIFT_HZ),
                hm.h
            ));
        }
    }
    None
}
