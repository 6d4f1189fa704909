//! The chosen model's last refit (after the holdout and the backward elimination): a joint
//! refit of every parameter, kept when it lowers the cost; every damping that ended on the
//! record's floor profiled ([`crate::diagnose::lsq::profile`]), the interval's log-midpoint
//! set where the likelihood is flat there (the rest refit with it held); then the
//! consistency polish ([`super::polish`]).

use super::node::Node;
use super::polish::settle;
use crate::diagnose::effects::candidates::sig;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::profile::{modes_at_floor, zeta_profile};
use crate::diagnose::lsq::retune::{retune_holding, retune_within};
use crate::diagnose::lsq::slots::Nl;
use crate::diagnose::report::DampingInterval;
use crate::error::Result;
use crate::model::physical::PhysicalModel;

/// A last joint refit of the chosen model, kept when it lowers the cost; a damping that
/// ended on the record's floor profiled ([`crate::diagnose::lsq::profile`]: where the
/// likelihood is flat the interval's log-midpoint is written and the rest refit with it
/// held); then the consistency polish ([`crate::diagnose::search::polish`]).  Returns the
/// dampings not identified.
pub(crate) fn final_refit(
    node: &mut Node,
    base: &PhysicalModel,
    data: &Channels,
) -> Result<Vec<DampingInterval>> {
    let refit = retune_within(&node.model, base, data, None, false);
    if refit.v_after < node.v_fit {
        node.v_fit = refit.v_after;
        node.model = refit.model;
    }
    let mut flat = Vec::new();
    for k in modes_at_floor(&node.model, data) {
        let p = zeta_profile(&node.model, base, data, k);
        if !p.flat() {
            continue;
        }
        let mut m = node.model.clone();
        m.mode[k].zeta = p.midpoint();
        let held: Vec<Nl> = flat
            .iter()
            .map(|(k, _): &(usize, _)| Nl::ModeZ(*k))
            .collect();
        node.model = retune_holding(&m, base, data, &[held, vec![Nl::ModeZ(k)]].concat()).model;
        flat.push((k, p));
    }
    let model = std::mem::replace(&mut node.model, base.clone());
    (node.model, node.measures) = settle(model, base, data)?;
    Ok(flat
        .into_iter()
        .map(|(k, p)| {
            let f = p.omega_n / std::f64::consts::TAU;
            let z = node.model.mode[k].zeta;
            DampingInterval {
                frequency_hz: f,
                zeta_floor: p.floor,
                zeta_upper: p.upper,
                zeta_written: z,
                profile: p.points.iter().map(|(z, v)| [*z, *v]).collect(),
                threshold: p.threshold,
                reason: format!(
                    "ζ of the mode at {} Hz not identified: the likelihood is flat from the record's floor {} to {} (95 %), set to {} (the log-midpoint); measure denser lines around {} Hz",
                    sig(f),
                    sig(p.floor),
                    sig(p.upper),
                    sig(z),
                    sig(f)
                ),
            }
        })
        .collect())
}
