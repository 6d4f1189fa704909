//! The plain-language explanation of each candidate effect: the signature it leaves in the
//! data (where the misfit peaks, how magnitude and phase move) and what it is physically,
//! in the terms of the measured quantity (receptance, mobility or accelerance).  Each
//! effect's text is its own ([`crate::diagnose::effects::effect::Effect::explain`]).

use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::effects::effect::Explain;
use crate::model::physical::PhysicalModel;

/// A plain-language explanation of the candidate's signature in the data.
pub fn explain(
    c: &Cand,
    th: &[f64],
    entries: &[(usize, usize)],
    base: &PhysicalModel,
    omega: &[f64],
) -> String {
    c.explain_with(&Explain {
        si: c.si_params(th, entries),
        base,
        wmax: omega.last().copied().unwrap_or(1.0),
    })
}
