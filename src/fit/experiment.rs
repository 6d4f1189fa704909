//! Hidden switches for measuring the fit (issue 38, eleventh step): not a user setting, no
//! CLI flag, no serde.  Process-wide, read at every level LP, and meant to be set once
//! before a measurement (`tests/fit/fit_sweep.rs` reads `RSHAPE_SWEEP_PERM` and
//! `RSHAPE_SWEEP_FAST`); setting them while another thread fits changes that fit.
//!
//! * [`RowOrder`]: the order in which every LP's inequality rows are handed to Clarabel.
//!   The LP is the same set of constraints in every order, so its optimum set is the same;
//!   only the interior-point iterates (round-off, the KKT ordering) differ.  It measures
//!   how far the fit moves with *no* change of method: the noise floor against which the
//!   sweep's 0.002-decade rule judges a speedup.
//! * The cheap speedups of the earlier steps (each a flag).  [`Switches::ROUTE`], the
//!   default since issue 38's thirteenth step, is the three that pass the sweep's rule (the
//!   working set kept across cut rounds, refinement for the rest of a level, a budget of 30
//!   LPs per level); [`Switches::BASELINE`] (all off) is the route before it, kept for
//!   measurements (`RSHAPE_SWEEP_FAST=none`).  Their figures against the noise floor and the
//!   rule are in `docs/internals-fit-speed.md`, eleventh to thirteenth steps.

use std::sync::RwLock;

/// Order of an LP's inequality rows as handed to Clarabel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowOrder {
    /// As the fit builds them (grouped by kind, then frequency).
    AsBuilt,
    /// Reversed.
    Reversed,
    /// A fixed pseudo-random permutation per row count, from this seed.
    Seeded(u64),
}

/// The switches.  `Default` ([`Switches::ROUTE`]) is what the fit runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Switches {
    /// Row order of every LP (a perturbation, not a speedup).
    pub row_order: RowOrder,
    /// Keep the polynomial level LP's working set across rounds of cuts (rows matched by
    /// group, grid point and occurrence; new cut rows in) instead of growing it again from
    /// the initial points whenever a cut changes the row count.
    pub keep_working_set: bool,
    /// Once a working-set solve of a polynomial level stayed short of `Solved` with
    /// iterative refinement, solve the rest of that level (later working sets and cut
    /// rounds) with refinement at once, skipping the unrefined first try.
    pub refine_rest_of_level: bool,
    /// A level of the polynomial candidate that has cost this many LPs without a verdict is
    /// a doubt (`0`: no budget).
    pub level_budget: usize,
    /// Try first the disk-map centre and cut floor that found the previous order's chosen
    /// candidate (when it was the polynomial candidate).
    pub previous_centre_first: bool,
}

impl Switches {
    /// The route before issue 38's thirteenth step (main f77b84c to 4016b19): no speedup,
    /// rows as built.  For measurements only.
    pub const BASELINE: Self = Self {
        row_order: RowOrder::AsBuilt,
        keep_working_set: false,
        refine_rest_of_level: false,
        level_budget: 0,
        previous_centre_first: false,
    };

    /// The default route (`ws,refine,k30`, the twelfth step's candidate, the default since the
    /// thirteenth): the sweep's LPs −33 % against [`Self::BASELINE`], every order within the
    /// rule of `tests/fit/fit_sweep_rule.rs`, the reference sweep 240/240.  It became the
    /// default once the cutting-plane round kept A1 off by a larger back-off
    /// (`fit::cutting_plane`), which certifies the ζ = 0.01 arm's order 3 under either route.
    /// `previous_centre_first` stays off (only 0.0001 decade inside the rule).
    pub const ROUTE: Self = Self {
        row_order: RowOrder::AsBuilt,
        keep_working_set: true,
        refine_rest_of_level: true,
        level_budget: 30,
        previous_centre_first: false,
    };
}

impl Default for Switches {
    fn default() -> Self {
        Self::ROUTE
    }
}

static SWITCHES: RwLock<Option<Switches>> = RwLock::new(None);

/// The switches in force.
pub fn switches() -> Switches {
    SWITCHES.read().ok().and_then(|s| *s).unwrap_or_default()
}

/// Sets the switches for the whole process (measurements only).
pub fn set_switches(s: Switches) {
    if let Ok(mut w) = SWITCHES.write() {
        *w = Some(s);
    }
}

/// The order in which `m` rows are handed to the solver: `order[p]` is the row at position
/// `p`, or `None` for the rows as built.
pub(crate) fn row_permutation(m: usize) -> Option<Vec<usize>> {
    permutation(switches().row_order, m)
}

fn permutation(order: RowOrder, m: usize) -> Option<Vec<usize>> {
    match order {
        RowOrder::AsBuilt => None,
        RowOrder::Reversed => Some((0..m).rev().collect()),
        RowOrder::Seeded(seed) => {
            let mut idx: Vec<(u64, usize)> = (0..m)
                .map(|i| {
                    (
                        splitmix(seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)),
                        i,
                    )
                })
                .collect();
            idx.sort_unstable();
            Some(idx.into_iter().map(|(_, i)| i).collect())
        }
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): a fixed, well-mixed hash of the row index.
fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A seeded order is a permutation, fixed for its seed, different for another seed.
    #[test]
    fn seeded_order_is_a_fixed_permutation() {
        let p = |seed| permutation(RowOrder::Seeded(seed), 500).expect("a permutation");
        assert_eq!(
            permutation(RowOrder::Reversed, 3),
            Some(vec![2, 1, 0]),
            "reversed"
        );
        assert_eq!(permutation(RowOrder::AsBuilt, 3), None);
        let (a, b, c) = (p(1), p(1), p(2));
        assert_eq!(a, b);
        assert_ne!(a, c);
        let mut s = a.clone();
        s.sort_unstable();
        assert_eq!(s, (0..500).collect::<Vec<_>>());
        // Not the identity nor the reversal: a real shuffle (about 1/e fixed points at most).
        assert!(a.iter().enumerate().filter(|(i, v)| i == *v).count() < 20);
    }
}
