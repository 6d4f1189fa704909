//! The plain-language explanation of each candidate effect: the signature it leaves in the
//! data (where the misfit peaks, how magnitude and phase move) and what it is physically,
//! in the terms of the measured quantity (receptance, mobility or accelerance).

use crate::diagnose::effects::candidates::{fmt_change, fmt_w, sig, Cand, Sel};
use crate::model::physical::{PhysicalModel, Quantity};

/// A plain-language explanation of the candidate's signature in the data.
pub fn explain(
    c: &Cand,
    th: &[f64],
    entries: &[(usize, usize)],
    base: &PhysicalModel,
    omega: &[f64],
) -> String {
    let si = c.si_params(th, entries);
    let p = |n: &str| {
        si.iter()
            .find(|x| x.0 == n)
            .map(|x| x.1)
            .unwrap_or(f64::NAN)
    };
    let list = |prefix: &str| {
        si.iter()
            .filter(|x| x.0.starts_with(prefix))
            .map(|x| sig(x.1))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let wmax = omega.last().copied().unwrap_or(1.0);
    let on = match c {
        Cand::Delay(s) | Cand::Lag(s) | Cand::Gain(s) | Cand::NmpZero(s) | Cand::Zoh(s) => {
            s.suffix()
        }
        _ => String::new(),
    };
    match c {
        Cand::Delay(_) => format!(
            "phase falls linearly with frequency while magnitude matches: a pure delay{on} of {} ms ({}° of extra lag at {})",
            sig(p("tau_s") * 1e3),
            sig((wmax * p("tau_s")).to_degrees()),
            fmt_w(wmax)
        ),
        Cand::Lag(sel) => format!(
            "magnitude droops and phase lags towards −90° above the corner, with no linear phase: a first-order lag{on} ({}) at ω_c = {}",
            match sel {
                Sel::Output(_) => "a sensor",
                Sel::Input(_) => "an actuator",
                Sel::All => "actuator or sensor",
            },
            fmt_w(p("omega_c"))
        ),
        Cand::Gain(_) => format!(
            "the ratio data/model is flat in magnitude with zero phase: a gain error{on}, k = {} ({})",
            sig(p("k")),
            fmt_change(p("k"))
        ),
        Cand::Sign(_) => "the data are the model rotated by 180° at every frequency with matching magnitude: a sign flip".into(),
        Cand::Mode => format!(
            "the misfit peaks at {} with a half-power width 2ζω_n = {} rad/s, and data/model shows a peak–notch pair: an unmodelled mode, ω_n = {}, ζ = {}, residue {}",
            fmt_w(p("omega_n")),
            sig(2.0 * p("zeta") * p("omega_n")),
            fmt_w(p("omega_n")),
            sig(p("zeta")),
            list("rho")
        ),
        Cand::ModeShift(i) => {
            let old = base.mode[*i].omega_n;
            format!(
                "the data resonate at {} where mode {} of the model resonates at {}: mode {} shifted by {}",
                fmt_w(p("omega_n")),
                i + 1,
                fmt_w(old),
                i + 1,
                fmt_change(p("omega_n") / old)
            )
        }
        Cand::Damping(i) => {
            let old = base.mode[*i].zeta;
            format!(
                "the error is symmetric about mode {} at {}: its damping is ζ = {} instead of {}",
                i + 1,
                fmt_w(base.mode[*i].omega_n),
                sig(p("zeta")),
                sig(old)
            )
        }
        Cand::Integrator(2) => match base.quantity {
            Quantity::Displacement => format!(
                "the error grows as 1/ω² towards low frequency (−40 dB/dec, phase of a double integrator): a missing rigid-body mode, or the lower residual (residual mass of modes below the band) c/s², c = {}",
                list("c")
            ),
            Quantity::Velocity => format!(
                "the error grows as 1/ω towards low frequency (−20 dB/dec, −90°: the mobility of a mass): a missing rigid-body mode, or the lower residual (modes below the band) c/s² in displacement, c = {}",
                list("c")
            ),
            Quantity::Acceleration => format!(
                "the error is a constant real term at low frequency (the mass line of an accelerance): a missing rigid-body mode (1/m = c), or the lower residual of modes below the band, c/s² in displacement, c = {}",
                list("c")
            ),
        },
        Cand::Integrator(_) => format!(
            "the error grows as 1/ω towards low frequency in displacement (−20 dB/dec, −90°): a missing integrator c/s, c = {}",
            list("c")
        ),
        Cand::Feedthrough => match base.quantity {
            Quantity::Displacement => format!(
                "the error is a constant real term, flat in frequency, that dominates where the model rolls off and moves the anti-resonances: the upper residual (residual flexibility of modes above the band) D = {}",
                list("d")
            ),
            q => format!(
                "the error rises as ω{} towards the band top and moves the anti-resonances: the upper residual of the {} (residual flexibility of modes above the band, D s{} with D = {})",
                if q == Quantity::Acceleration { "²" } else { "" },
                q.frf_name(),
                if q == Quantity::Acceleration { "²" } else { "" },
                list("d")
            ),
        },
        Cand::NmpZero(_) => format!(
            "magnitude matches but phase falls and saturates towards −180° (−90° at {}): a non-minimum-phase zero{on} at z = {}",
            fmt_w(p("z")),
            fmt_w(p("z"))
        ),
        Cand::Friction(i) => format!(
            "the phase leads −180° at low frequency by atan(p/ω) and the lead fades with frequency, while the magnitude follows the rigid body: viscous friction on rigid body {}, pole p = c_v/J = {}",
            i + 1,
            fmt_w(p("pole"))
        ),
        Cand::Zoh(_) => format!(
            "phase falls linearly (mean delay T/2 = {} ms) and magnitude droops like sinc(ωT/2) ({} dB at {}): a zero-order hold{on} with T = {} ms (fs = {} Hz)",
            sig(p("t_s") * 5e2),
            sig(20.0 * {
                let x = wmax * p("t_s") / 2.0;
                (x.sin() / x).abs().log10()
            }),
            fmt_w(wmax),
            sig(p("t_s") * 1e3),
            sig(1.0 / p("t_s"))
        ),
    }
}
