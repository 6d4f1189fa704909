//! The catalogue of physical effects (docs/design/effects.md): the bottom layer of
//! [`crate::diagnose`], using nothing of the layers above.
//! * `candidates`: the effects the search can add and how each modifies the model;
//! * `explain`: what each means in the data;
//! * `lscf`: mode proposals from the residual by an LSCF stabilization diagram.
pub(crate) mod candidates;
pub(crate) mod explain;
pub(crate) mod lscf;
