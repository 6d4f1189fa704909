//! The search of [`crate::diagnose`] over effect sets: screening, beam search with joint
//! refits, hold-out, ties, elimination.  Uses [`crate::diagnose::effects`],
//! [`crate::diagnose::lsq`] and the vocabulary beside the engine (`report`, `changes`,
//! `admissible`, `compare`), never the engine.
//! * `rank`: screening and physical plausibility;
//! * `node`: an effect set written into the model and jointly refit;
//! * `beam`: the beam search over effect sets;
//! * `expand`: a node's screen and the candidates it sends to joint refits;
//! * `settings`: the search's settings;
//! * `first_level`: the root's candidates ranked;
//! * `polish`: the consistency polish;
//! * `ties`: sets the data cannot tell apart;
//! * `holdout`: the final set checked on held-out data;
//! * `choice`: the set kept after the holdout and the elimination (a next-best set when they drop part of it);
//! * `path`: the chosen path and the runner-ups once the holdout or the elimination dropped effects;
//! * `backward`: backward elimination;
//! * `recheck`: the reduced set re-checked for admissibility;
//! * `peaks`: every peak of the residual and its fate;
//! * `peak_modes`: a mode proposed at every peak that would pass the screen;
//! * `multi_mode`: those modes proposed together, in one step;
//! * `child`: a joint refit judged (likelihood, admissibility) and made a node;
//! * `assign`: configured and added modes matched to the refit's;
//! * `final_effects`: the effects the written model has and the input did not;
//! * `final_refit`: the chosen model's last refit (dampings at the floor profiled).
pub(crate) mod assign;
pub(crate) mod backward;
pub(crate) mod beam;
pub(crate) mod child;
pub(crate) mod choice;
pub(crate) mod expand;
pub(crate) mod final_effects;
pub(crate) mod final_refit;
pub(crate) mod first_level;
pub(crate) mod holdout;
pub(crate) mod multi_mode;
pub(crate) mod node;
pub(crate) mod path;
pub(crate) mod peak_modes;
pub(crate) mod peaks;
pub(crate) mod polish;
pub(crate) mod rank;
pub(crate) mod recheck;
pub(crate) mod settings;
pub(crate) mod ties;
