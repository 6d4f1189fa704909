//! Issue 20, defect 5: backward elimination.  A chosen set that holds a vacuous effect — a
//! lag with its corner 100× above the band, beside the hidden mode the data need — loses the
//! lag and keeps the mode; a set of needed effects loses nothing.

use crate::hidden;

use hidden::{data, servo, SEEDS};
use rshape::diagnose::eliminate;
use rshape::diagnose::ErrorMeasures;
use rshape::diagnose::{add_effect, Node};
use rshape::diagnose::{retune_within, Channels};
use rshape::diagnose::{Cand, Sel};

fn node_with(effects: Vec<(Cand, Vec<f64>)>, ch: &Channels) -> Node {
    let (base, _) = servo();
    let mut m = base.clone();
    for (c, th) in &effects {
        m = add_effect(&m, c, th, ch);
    }
    let r = retune_within(&m, &base, ch, None, false);
    let (misfit_rms, invalid_fraction) = rshape::diagnose::misfit_channels(&r.model, ch);
    Node {
        effects,
        model: r.model,
        measures: ErrorMeasures {
            v: r.v_after,
            misfit_rms,
            invalid_fraction,
        },
        v_fit: r.v_after,
        n_params: r.n_params,
        bic: 0.0,
        steps: vec![],
        configured: false,
    }
}

#[test]
fn a_vacuous_lag_is_eliminated_and_the_needed_mode_kept() {
    let (base, w) = servo();
    let w_max = *w.last().unwrap();
    let rho = 0.3 * base.eval_siso(900.0).norm() * 2.0 * 0.02 * 900.0 * 900.0;
    let mut truth = base.clone();
    truth.mode.push(hidden::mode(900.0, 0.02, rho));
    for seed in SEEDS {
        let ch = Channels::from_siso(&data(&truth, &w, seed)).unwrap();
        let mode = (Cand::Mode, vec![900f64.ln(), 0.02f64.ln(), rho]);
        let lag = (Cand::Lag(Sel::All), vec![(100.0 * w_max).ln()]);
        let mut node = node_with(vec![mode.clone(), lag], &ch);
        let dropped = eliminate(&base, &mut node, &[], &ch, 10.0).unwrap();
        assert_eq!(dropped, ["lag"], "seed {seed}");
        assert_eq!(node.labels(), ["mode"]);
        assert_eq!(node.model.effect.len(), 0);
        // The needed mode alone: nothing is dropped.
        let mut node = node_with(vec![mode], &ch);
        assert!(eliminate(&base, &mut node, &[], &ch, 10.0)
            .unwrap()
            .is_empty());
        assert_eq!(node.model.mode.len(), 3);
    }
}
