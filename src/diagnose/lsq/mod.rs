//! The least squares of [`crate::diagnose`]: a model with candidate effects fitted to the data
//! channels (cost `V`, Levenberg–Marquardt, variable projection).  Uses only
//! [`crate::diagnose::effects`] (and the leaf `compare`).
//! * `channels`: the data channels, each with its noise radius and model entry;
//! * `measures`: error measures (`V`, `misfit_rms`, `invalid_fraction`);
//! * `shapes`: a model's path effects at a datum and a mode's shape;
//! * `problem`: the least-squares problem (base model, candidate effects, cost `V`);
//! * `starts`: each candidate's starting points;
//! * `lm`: Levenberg–Marquardt;
//! * `slots`: the configured model's parameters `retune` refits;
//! * `covariance`: the covariance of every slot at a refit (σ, correlations);
//! * `varpro`: the variable-projection Jacobian;
//! * `mode_grid`: the cost as one mode moves (the retune's rough placement);
//! * `retune`: the joint refit of the configured model's own parameters;
//! * `resolution`: what the record resolves of a mode's damping (ζ's floor from the lines);
//! * `profile`: the profile likelihood of a damping at that floor (flat: not identified);
//! * `whiteness`: is the normalized residual the stated noise (level, Ljung–Box).
pub(crate) mod channels;
pub(crate) mod covariance;
pub(crate) mod lm;
pub(crate) mod measures;
pub(crate) mod mode_grid;
pub(crate) mod problem;
pub(crate) mod profile;
pub(crate) mod resolution;
pub(crate) mod retune;
pub(crate) mod shapes;
pub(crate) mod slots;
pub(crate) mod starts;
pub(crate) mod varpro;
pub(crate) mod whiteness;
