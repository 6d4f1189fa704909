//! A node's expansion for the beam search ([`super::beam`]): every candidate fitted alone
//! on the node's model (the screen), the modes proposed at the residual's other peaks
//! ([`super::peak_modes`]) and together ([`super::multi_mode`]), and which of them get a
//! joint refit.

use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::problem::Problem;
use crate::diagnose::search::node::Node;
use crate::diagnose::search::rank::{candidate_list, Screened};
use crate::diagnose::search::settings::SearchSettings;
use crate::error::Result;
use crate::model::physical::PhysicalModel;

/// One node's screen: every candidate fitted alone (best first), which of them get a joint
/// refit (the `beam + 1` best promising ones), and the cost the children are measured
/// against.
pub(super) struct Expansion {
    pub(super) screened: Vec<Screened>,
    /// `screened[..n_screen]` is the catalogue's screen, the rest peaks' mode proposals.
    pub(super) n_screen: usize,
    pub(super) refit: Vec<bool>,
    /// The modes proposed together ([`super::multi_mode`]).
    pub(super) multi: Option<Vec<Screened>>,
    pub(super) ref_v: f64,
}

/// Screens node `ni` of `nodes` (see [`Expansion`]).
/// `screened`, when given, is the node's screen done beforehand ([`screen_configured`]).
pub(super) fn expand(
    nodes: &[Node],
    ni: usize,
    data: &Channels,
    s: &SearchSettings,
    screened: Option<Vec<Screened>>,
) -> Result<Expansion> {
    let node = &nodes[ni];
    // A node that has used the effect budget (a group of modes counts each) is not expanded.
    if node.effects.len() >= s.max_effects {
        return Ok(Expansion {
            screened: vec![],
            n_screen: 0,
            refit: vec![],
            multi: None,
            ref_v: node.v_fit,
        });
    }
    let mut screened = match screened {
        Some(sc) => sc,
        None => {
            let p = Problem::new(&node.model, data)?;
            let used: Vec<Cand> = node.effects.iter().map(|e| e.0).collect();
            let cands: Vec<Cand> = candidate_list(&node.model, data)
                .into_iter()
                .filter(|c| *c == Cand::Mode || !used.contains(c))
                .collect();
            p.screen(&cands, node.measures)
        }
    };
    // Every peak proposed ([`super::peak_modes`]): the modes at the residual's other peaks
    // that would pass the screen, each refit (beyond the beam's share), so that one refused
    // mode candidate does not hide the others; with the modes that pass only on the lines
    // around their peak, they are also proposed together ([`super::multi_mode`]).  A mode
    // candidate of the screen that would not pass hides no peak.
    let n_screen = screened.len();
    let taken: Vec<f64> = screened
        .iter()
        .filter(|sc| {
            sc.cand == Cand::Mode
                && sc.no_fit.is_none()
                && sc.flags.is_empty()
                && sc.delta_bic > s.min_delta_bic
        })
        .map(|sc| sc.mods.theta[0].exp())
        .collect();
    let (singles, local_only) =
        super::peak_modes::peak_modes(&node.model, data, node.measures, &taken, s.min_delta_bic)?;
    let multi = super::multi_mode::proposal(
        &node.model,
        &screened,
        &singles,
        &local_only,
        s.min_delta_bic,
        s.max_effects.saturating_sub(node.effects.len()),
    );
    screened.extend(singles);
    let mut tried = 0;
    let refit = screened
        .iter()
        .enumerate()
        .map(|(i, sc)| {
            let promising =
                sc.no_fit.is_none() && sc.flags.is_empty() && sc.delta_bic > s.min_delta_bic;
            let go = promising && (tried <= s.beam || i >= n_screen);
            tried += usize::from(go && i < n_screen);
            go
        })
        .collect();
    // Against the best of the node and (for the configured model) its retune.
    let ref_v = if node.configured {
        nodes[1].v_fit.min(node.v_fit)
    } else {
        node.v_fit
    };
    Ok(Expansion {
        screened,
        n_screen,
        refit,
        multi,
        ref_v,
    })
}

/// The configured model's screen (every catalogue candidate fitted alone on it), as the
/// search's first level does it: it does not depend on the retune, so `diagnose` runs it
/// beside the retune and hands it to [`search`].
pub(crate) fn screen_configured(base: &PhysicalModel, data: &Channels) -> Result<Vec<Screened>> {
    let p = Problem::new(base, data)?;
    let m0 = p.measures(&Default::default());
    Ok(p.screen(&candidate_list(base, data), m0))
}
