//! The set `diagnose` keeps (issue 20, issue 33): the search's chosen set passes the final
//! holdout ([`super::holdout`]) and the backward elimination ([`super::backward`]); when
//! either drops part of it, the set kept instead is the best **admissible** set among the
//! reduced chosen set and the search's next-best sets that pass both rules as they are
//! (nothing dropped), compared by the BIC of their joint refits — never the chosen set
//! itself, and never a set equal to the reduced one.  The search's nodes are admissible by
//! construction ([`super::child`]), one step at a time; the reduced set is a subset of an
//! admissible one, refit, and its refit can break a rule: it is re-checked whole
//! ([`super::recheck`], issue 33, stop 46), and an effect refused there is removed (the rest
//! refit, the backward elimination run again, the set re-checked; at most
//! [`MAX_RECHECKS`] rounds, after which nothing is kept of it).  The next-best sets are
//! re-checked whole too before one is kept.
//!
//! Before issue 33's stop 45 only larger sets were tried after a holdout drop, the first that
//! passed won whatever its BIC, and none after an elimination: a reduced set could be kept
//! though a next-best set that passes scored better.

use crate::diagnose::admissible::Refusal;
use crate::diagnose::report::Holdout;
use crate::diagnose::search::holdout::same_set;
use crate::diagnose::search::node::Node;
use crate::error::Result;

/// How many next-best effect sets (scoring better than the reduced chosen set) are tried when
/// the holdout or the elimination drops part of the chosen set.
pub const MAX_ALTERNATIVES: usize = 3;

/// Most effects the admissibility re-check removes from a reduced set (each removal costs a
/// refit per effect left); a set still refused after that many keeps none of its effects.
pub const MAX_RECHECKS: usize = 3;

/// The set kept after the holdout and the backward elimination.
#[derive(Debug, Clone)]
pub struct Passing {
    /// The node kept (its path restated when it is the reduced chosen set).
    pub node: Node,
    /// The holdout rows of the kept set.
    pub holdout: Vec<Holdout>,
    /// Labels the holdout dropped from the search's chosen set.
    pub dropped: Vec<String>,
    /// Labels the backward elimination dropped from it (after the holdout's).
    pub eliminated: Vec<String>,
    /// The index in the search's nodes of the set kept instead of the reduced chosen one,
    /// when one was (issue 20: a spurious chosen mode must not cost a whole step).
    pub replaced_by: Option<usize>,
    /// The search's node holding the kept set, when one does (the chosen node when nothing
    /// was dropped).
    pub set_node: Option<usize>,
    /// The effects of the reduced set the admissibility re-check refused and removed, each
    /// with the step it had in the chosen path.
    pub refused: Vec<(usize, Refusal)>,
}

impl Passing {
    /// Something was dropped from the search's chosen set.
    pub fn reduced(&self) -> bool {
        !self.dropped.is_empty() || !self.eliminated.is_empty() || !self.refused.is_empty()
    }
}

/// The next-best effect sets after `chosen`: the search's nodes with effects, by BIC, not
/// the chosen set ([`same_set`]), one per set.
pub fn alternatives(nodes: &[Node], chosen: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..nodes.len())
        .filter(|i| *i != chosen && !nodes[*i].configured && !nodes[*i].effects.is_empty())
        .filter(|i| !same_set(&nodes[*i].effects, &nodes[chosen].effects))
        .collect();
    order.sort_by(|a, b| nodes[*a].bic.total_cmp(&nodes[*b].bic));
    let mut out: Vec<usize> = Vec::new();
    for i in order {
        if !out
            .iter()
            .any(|o| same_set(&nodes[*o].effects, &nodes[i].effects))
        {
            out.push(i);
        }
    }
    out
}

/// The rules a set must pass, and the restatement of a reduced set.
pub trait Rules {
    /// The final holdout: drops the failing effects of `node` (refitting the rest) and
    /// returns its rows and the labels dropped.
    fn holdout(&mut self, node: &mut Node) -> Result<(Vec<Holdout>, Vec<String>)>;
    /// The backward elimination: drops the effects the data do not need; the labels dropped.
    fn eliminate(&mut self, node: &mut Node) -> Result<Vec<String>>;
    /// Restates the path and BIC of `node`, reduced from `orig`; the node of the search that
    /// holds the same set, if any ([`super::path::restate_path`]).
    fn restate(&mut self, node: &mut Node, orig: &Node) -> Result<Option<usize>>;
    /// The first effect of `node` an admissibility rule refuses on its refit, with the
    /// refusal ([`super::recheck`]).
    fn refusal(&mut self, node: &Node) -> Result<Option<(usize, Refusal)>>;
    /// Removes effect `j` of `node` and its step, the rest refit.
    fn remove(&mut self, node: &mut Node, j: usize) -> Result<()>;
}

/// Re-checks the reduced set `node` (see the module docs): each refused effect is removed,
/// its refusal recorded with the step it had (`refused`), the rest refit and eliminated again
/// (`eliminated`); after [`MAX_RECHECKS`] removals a set still refused is emptied.
fn admit<R: Rules>(
    node: &mut Node,
    rules: &mut R,
    refused: &mut Vec<(usize, Refusal)>,
    eliminated: &mut Vec<String>,
) -> Result<()> {
    for round in 0..=MAX_RECHECKS {
        let Some((j, r)) = rules.refusal(node)? else {
            return Ok(());
        };
        let step = node.steps.get(j).map_or(j + 1, |s| s.step);
        refused.push((step, r));
        if round == MAX_RECHECKS {
            while !node.effects.is_empty() {
                rules.remove(node, 0)?;
            }
            return Ok(());
        }
        rules.remove(node, j)?;
        eliminated.extend(rules.eliminate(node)?);
    }
    Ok(())
}

/// The set kept (see the module docs): the chosen node through the holdout and the
/// elimination; when they drop part of it, the reduced set re-checked for admissibility
/// (refused effects removed), then the first of the next [`MAX_ALTERNATIVES`] sets scoring
/// better than it ([`alternatives`] below its BIC, in BIC order) that both rules leave whole
/// and the re-check admits whole, else the reduced set.
pub fn keep<R: Rules>(nodes: &[Node], chosen: usize, rules: &mut R) -> Result<Passing> {
    let orig = &nodes[chosen];
    let mut node = orig.clone();
    let (holdout, dropped) = rules.holdout(&mut node)?;
    let mut eliminated = rules.eliminate(&mut node)?;
    let mut out = Passing {
        node,
        holdout,
        dropped,
        eliminated: vec![],
        replaced_by: None,
        set_node: Some(chosen),
        refused: vec![],
    };
    if !out.reduced() && eliminated.is_empty() {
        return Ok(out);
    }
    admit(&mut out.node, rules, &mut out.refused, &mut eliminated)?;
    out.eliminated = eliminated;
    out.set_node = rules.restate(&mut out.node, orig)?;
    let better: Vec<usize> = alternatives(nodes, chosen)
        .into_iter()
        .filter(|i| nodes[*i].bic < out.node.bic)
        .filter(|i| !same_set(&nodes[*i].effects, &out.node.effects))
        .take(MAX_ALTERNATIVES)
        .collect();
    for i in better {
        let mut alt = nodes[i].clone();
        let (alt_holdout, alt_dropped) = rules.holdout(&mut alt)?;
        if !alt_dropped.is_empty()
            || !rules.eliminate(&mut alt)?.is_empty()
            || rules.refusal(&alt)?.is_some()
        {
            continue;
        }
        out.node = alt;
        out.holdout = alt_holdout;
        out.replaced_by = Some(i);
        out.set_node = Some(i);
        break;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::admissible::Rule;
    use crate::diagnose::effects::candidates::Cand;
    use crate::diagnose::lsq::measures::Measures;
    use crate::model::physical::PhysicalModel;

    /// A node holding one added mode per frequency of `f_hz`, with BIC `bic`.
    fn node(f_hz: &[f64], bic: f64) -> Node {
        Node {
            effects: f_hz
                .iter()
                .map(|f| (Cand::Mode, vec![(std::f64::consts::TAU * f).ln(), -7.0]))
                .collect(),
            model: PhysicalModel::default(),
            measures: Measures {
                v: bic,
                misfit_rms: 2.0,
                invalid_fraction: 0.5,
            },
            v_fit: bic,
            n_params: 3,
            bic,
            steps: vec![],
            configured: false,
        }
    }

    fn f_of(n: &Node) -> Vec<f64> {
        n.effects
            .iter()
            .map(|e| (e.1[0].exp() / std::f64::consts::TAU).round())
            .collect()
    }

    /// Fake rules: the holdout drops every mode not at a frequency of `pass`; the
    /// elimination drops the modes at a frequency of `vacuous`; a reduced set's BIC is read
    /// from `bic_of` (by its frequencies); the sets the holdout saw are recorded.
    struct Fake<'a> {
        pass: &'a [f64],
        vacuous: &'a [f64],
        bic_of: &'a [(&'a [f64], f64)],
        seen: Vec<Vec<f64>>,
        /// Modes the admissibility re-check refuses.
        refuse: &'a [f64],
        /// The sets the re-check saw.
        checked: Vec<Vec<f64>>,
    }

    impl Rules for Fake<'_> {
        fn holdout(&mut self, n: &mut Node) -> Result<(Vec<Holdout>, Vec<String>)> {
            let fs = f_of(n);
            self.seen.push(fs.clone());
            let rows = fs
                .iter()
                .map(|f| Holdout {
                    effect: "mode".into(),
                    interleaved_ok: self.pass.contains(f),
                    extrapolation_ok: None,
                })
                .collect();
            let keep: Vec<bool> = fs.iter().map(|f| self.pass.contains(f)).collect();
            let dropped = keep
                .iter()
                .filter(|k| !**k)
                .map(|_| "mode".into())
                .collect();
            let mut k = keep.iter();
            n.effects.retain(|_| *k.next().unwrap());
            Ok((rows, dropped))
        }
        fn eliminate(&mut self, n: &mut Node) -> Result<Vec<String>> {
            let before = n.effects.len();
            let v = self.vacuous;
            n.effects
                .retain(|e| !v.contains(&(e.1[0].exp() / std::f64::consts::TAU).round()));
            Ok(vec!["mode".into(); before - n.effects.len()])
        }
        fn restate(&mut self, n: &mut Node, _orig: &Node) -> Result<Option<usize>> {
            let fs = f_of(n);
            n.bic = self
                .bic_of
                .iter()
                .find(|(f, _)| *f == fs.as_slice())
                .map(|x| x.1)
                .expect("a BIC for every reduced set");
            Ok(None)
        }
        fn refusal(&mut self, n: &Node) -> Result<Option<(usize, Refusal)>> {
            let fs = f_of(n);
            self.checked.push(fs.clone());
            Ok(fs.iter().position(|f| self.refuse.contains(f)).map(|j| {
                (
                    j,
                    Refusal {
                        effect: "mode".into(),
                        frequency_hz: Some(fs[j]),
                        rule: Rule::Artefact,
                        reason: "constructed".into(),
                    },
                )
            }))
        }
        fn remove(&mut self, n: &mut Node, j: usize) -> Result<()> {
            n.effects.remove(j);
            if j < n.steps.len() {
                n.steps.remove(j);
            }
            Ok(())
        }
    }

    fn fake<'a>(pass: &'a [f64], vacuous: &'a [f64], bic_of: &'a [(&'a [f64], f64)]) -> Fake<'a> {
        Fake {
            pass,
            vacuous,
            bic_of,
            seen: vec![],
            refuse: &[],
            checked: vec![],
        }
    }

    fn root() -> Node {
        let mut r = node(&[], 50.0);
        r.configured = true;
        r
    }

    /// A chosen mode the holdout drops: the next sets scoring better than what is left are
    /// tried in BIC order (a duplicate of the chosen set and the roots skipped) and the first
    /// that passes is kept.
    #[test]
    fn a_dropped_chosen_mode_gives_way_to_the_next_passing_set() {
        let nodes = vec![
            root(),
            node(&[824.0], 0.0),
            node(&[1000.0], 1.0),
            node(&[824.5], 1.5), // the chosen set again (within 1 % in frequency)
            node(&[500.0], 2.0),
            node(&[300.0], 3.0),
        ];
        let mut r = fake(&[500.0, 300.0], &[], &[(&[], 50.0)]);
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert_eq!(p.replaced_by, Some(4));
        assert_eq!(f_of(&p.node), [500.0]);
        assert_eq!(p.dropped, vec!["mode".to_string()]);
        assert!(p.holdout.iter().all(|h| h.interleaved_ok));
        assert_eq!(r.seen, vec![vec![824.0], vec![1000.0], vec![500.0]]);
    }

    /// At most [`MAX_ALTERNATIVES`] sets are tried; when none passes the reduced chosen set
    /// stays, and a chosen set that passes is kept without trying anything else.
    #[test]
    fn alternatives_are_capped_and_a_passing_chosen_set_is_kept() {
        let nodes: Vec<Node> = [824.0, 1000.0, 700.0, 600.0, 500.0]
            .iter()
            .enumerate()
            .map(|(k, f)| node(&[*f], k as f64))
            .collect();
        assert_eq!(alternatives(&nodes, 0)[..3], [1, 2, 3]);
        let mut r = fake(&[500.0], &[], &[(&[], 10.0)]);
        let p = keep(&nodes, 0, &mut r).unwrap();
        assert_eq!(p.replaced_by, None);
        assert!(p.node.effects.is_empty());
        let seen: Vec<f64> = r.seen.iter().map(|s| s[0]).collect();
        assert_eq!(seen, [824.0, 1000.0, 700.0, 600.0]);
        let mut r = fake(&[824.0, 500.0], &[], &[]);
        let p = keep(&nodes, 0, &mut r).unwrap();
        assert_eq!((p.replaced_by, p.dropped.len()), (None, 0));
        assert_eq!(p.set_node, Some(0));
        assert_eq!(r.seen, vec![vec![824.0]]);
    }

    /// Issue 33: the holdout drops one mode of a two-mode chosen set; a next-best set of one
    /// mode that passes and scores better than the mode left is kept (the old rule tried
    /// only larger sets and kept the worse one), and a larger set that passes but scores
    /// worse than the mode left is not.
    #[test]
    fn a_better_runner_up_of_the_same_size_beats_the_reduced_set() {
        let nodes = vec![
            root(),
            node(&[824.0, 60.0], 0.0), // chosen; 60 Hz fails the holdout
            node(&[824.0, 60.0, 300.0], 0.5), // fails too
            node(&[700.0], 2.0),       // passes, better than {824}
            node(&[824.0, 300.0], 4.0), // passes, larger, worse than {824}
        ];
        let mut r = fake(&[824.0, 700.0, 300.0], &[], &[(&[824.0], 3.0)]);
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert_eq!(p.replaced_by, Some(3), "{:?}", f_of(&p.node));
        assert_eq!(f_of(&p.node), [700.0]);
        // Worse than the reduced set: kept as it is; the larger set was never tried.
        let mut r = fake(&[824.0, 300.0], &[], &[(&[824.0], 3.0)]);
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert_eq!((p.replaced_by, f_of(&p.node)), (None, vec![824.0]));
        assert!(!r.seen.contains(&vec![824.0, 300.0]), "{:?}", r.seen);
    }

    /// After an elimination alone the next-best sets are tried too, and one the elimination
    /// would reduce is not kept.
    #[test]
    fn after_an_elimination_a_passing_better_set_is_kept() {
        let nodes = vec![
            root(),
            node(&[824.0, 999.0], 0.0), // chosen; 999 Hz vacuous
            node(&[824.0, 60.0], 1.0),  // passes the holdout, reduced by the elimination
            node(&[900.0], 2.0),        // passes both
        ];
        let mut r = fake(
            &[824.0, 999.0, 60.0, 900.0],
            &[999.0, 60.0],
            &[(&[824.0], 3.0)],
        );
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert_eq!((p.dropped.len(), p.eliminated.len()), (0, 1));
        assert_eq!((p.replaced_by, f_of(&p.node)), (Some(3), vec![900.0]));
    }

    /// Issue 33, stop 46: the elimination leaves {824, 60} of {824, 999, 60}; the re-check
    /// refuses 60 Hz on that refit, so it is removed (its step and refusal reported) and
    /// {824} re-checked and kept; a better-scoring next-best set the re-check refuses whole
    /// is not kept; a reduced set the re-check admits is kept as before, checked once.
    #[test]
    fn an_inadmissible_reduced_set_loses_the_refused_effect() {
        let nodes = vec![
            root(),
            node(&[824.0, 999.0, 60.0], 0.0),
            node(&[824.0, 60.0], 1.0),  // passes both rules, refused whole
            node(&[700.0, 300.0], 9.0), // passes, worse than {824}
        ];
        let bic_of: &[(&[f64], f64)] = &[(&[824.0], 5.0), (&[824.0, 60.0], 1.0)];
        let mut r = fake(&[824.0, 999.0, 60.0, 700.0, 300.0], &[999.0], bic_of);
        r.refuse = &[60.0];
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert_eq!(f_of(&p.node), [824.0]);
        assert_eq!(p.replaced_by, None);
        assert_eq!(p.refused.len(), 1);
        assert_eq!(p.refused[0].1.frequency_hz, Some(60.0));
        assert_eq!(p.eliminated.len(), 1);
        assert!(p.reduced());
        // {824, 60} checked (refused), {824} checked (admitted), the runner-up {824, 60}
        // checked whole (refused); {700, 300} scores worse and is never tried.
        assert_eq!(
            r.checked,
            vec![vec![824.0, 60.0], vec![824.0], vec![824.0, 60.0]]
        );
        // The same search without the refusal keeps {824, 60}: the re-check passed it once
        // and the runner-up (the same set) is not tried.
        let mut r = fake(&[824.0, 999.0, 60.0, 700.0, 300.0], &[999.0], bic_of);
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert_eq!((f_of(&p.node), p.refused.len()), (vec![824.0, 60.0], 0));
        assert_eq!(r.checked, vec![vec![824.0, 60.0]]);
    }

    /// The cap: a reduced set whose every effect is refused loses [`MAX_RECHECKS`] of them
    /// one at a time, then the rest at once (no refit round per effect beyond the cap).
    #[test]
    fn the_recheck_is_capped() {
        let fs = [100.0, 200.0, 300.0, 400.0, 500.0, 999.0];
        let nodes = vec![root(), node(&fs, 0.0)];
        let mut r = fake(&fs, &[999.0], &[(&[], 50.0)]);
        r.refuse = &fs;
        let p = keep(&nodes, 1, &mut r).unwrap();
        assert!(p.node.effects.is_empty(), "{:?}", f_of(&p.node));
        assert_eq!(r.checked.len(), MAX_RECHECKS + 1);
        assert_eq!(p.refused.len(), MAX_RECHECKS + 1);
        let refused: Vec<f64> = p
            .refused
            .iter()
            .map(|x| x.1.frequency_hz.unwrap())
            .collect();
        assert_eq!(refused, [100.0, 200.0, 300.0, 400.0]);
    }
}
