//! A node of the search: an effect set written into the model and jointly refit.

use crate::diagnose::effects::candidates::{Cand, ADDED_NOTE};
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::measures::Measures;
use crate::diagnose::report::Step;
use crate::model::physical::PhysicalModel;

/// A node: an effect set written into the model and jointly refit.
#[derive(Debug, Clone)]
pub struct Node {
    /// The effects and their parameters when they were added (fitted alone).
    pub effects: Vec<(Cand, Vec<f64>)>,
    /// The jointly refit model.
    pub model: PhysicalModel,
    /// Its measures (of the polished model when the polish made it consistent).
    pub measures: Measures,
    /// Cost `V` of the least-squares fit (the BIC's; the polish may raise `measures.v`).
    pub v_fit: f64,
    /// Number of parameters of the model (configured and added).
    pub n_params: usize,
    /// `2V + n_θ ln(2F)`.
    pub bic: f64,
    /// The path that led here.
    pub steps: Vec<Step>,
    /// The model is the configured one, not refit: a child's joint refit starts with the
    /// mode grid of a rough start.
    pub configured: bool,
}

impl Node {
    /// Labels of the effects, in order.
    pub fn labels(&self) -> Vec<String> {
        self.effects.iter().map(|(c, _)| c.label()).collect()
    }
}

/// Writes effect `c` with parameters `th` into `m`.
/// An effect on a term `m` lacks (friction on a rigid body that an effect left out of a
/// holdout or elimination set had added) is not written: it has nothing to act on.
pub fn add_effect(m: &PhysicalModel, c: &Cand, th: &[f64], data: &Channels) -> PhysicalModel {
    let mut next = m.clone();
    let missing = c.lacks_its_term(m);
    if missing {
        return next;
    }
    c.apply_to(
        th,
        &data.entries,
        &mut next,
        &format!("{ADDED_NOTE}: {}", c.label()),
    );
    next
}
