//! Output-path (sensor) effects in the rational export `C·M̃⁻¹·Ñ·J` (Sec. IV-A).
//!
//! Let `O = diag(O_1 … O_p)` be the output-path effects, `O_i(s)` the product of the effects
//! on output `i`. Then `O·G = Σ_k O·C_{:,k}·M̃_kk⁻¹·Ñ_k·J`.
//!
//! * When every output carries the same chain `O_0`, `O = O_0·I` commutes with the plant and
//!   goes into every entry of `J` (the SISO case is this one).
//! * Otherwise the outputs are grouped by their chain, `P_g` the projection on group `g`, and
//!   `O·C_{:,k} = Σ_g P_g C_{:,k} O_g`: modal row `k` becomes one row per group `g` that sees
//!   it, with the same `M̃_kk`, the row `O_g·Ñ_k` and the column `P_g C_{:,k}` of `C`. `C`
//!   stays constant, and its rank is still `p` (its rows of group `g` use only that group's
//!   columns, which are the original columns restricted to those rows). Each new row is
//!   coprime when the old one is: `M̃_kk` is unchanged and `O_g` (delay Padé, lag, gain,
//!   all-pass) is stable with no zero where `M̃_kk` vanishes (`s = 0` for a rigid body).
//!   A sensor lag on output 2 of a 1×2 modal model with `n` modes thus gives `2n` rows.

use super::{EffectPath, PhysicalModel};
use crate::system::TransferFunction;

/// The rows of a special factorization being built: the diagonal of `M̃`, the rows of `Ñ`
/// and the columns of `C`.
pub(super) struct Rows {
    pub m: Vec<TransferFunction>,
    pub n: Vec<Vec<TransferFunction>>,
    pub c: Vec<Vec<f64>>,
}

impl PhysicalModel {
    /// Per output: the indices of the output-path effects acting on it and their product
    /// (Padé of order `order` for delays and holds).
    pub(super) fn output_chains(&self, order: usize) -> Vec<(Vec<usize>, TransferFunction)> {
        (0..self.n_outputs())
            .map(|i| {
                let mut idx = Vec::new();
                let mut tf = TransferFunction::gain(1.0);
                for (k, e) in self.effect.iter().enumerate() {
                    if e.path == EffectPath::Output && e.channel.is_none_or(|c| c == i + 1) {
                        idx.push(k);
                        tf = tf.mul(&e.to_tf(order));
                    }
                }
                (idx, tf)
            })
            .collect()
    }
}

/// Puts the output chains into the factorization (see the module docs): into `j` when all
/// outputs share one chain, else by splitting each modal row per group of outputs.
pub(super) fn split_rows(
    chains: Vec<(Vec<usize>, TransferFunction)>,
    rows: Rows,
    j: &mut [TransferFunction],
) -> Rows {
    if chains.iter().all(|c| c.0 == chains[0].0) {
        if !chains[0].0.is_empty() {
            for jk in j.iter_mut() {
                *jk = jk.mul(&chains[0].1);
            }
        }
        return rows;
    }
    // Groups of outputs with the same chain, in order of their first output.
    let mut groups: Vec<(Vec<usize>, &TransferFunction)> = Vec::new();
    for (i, (key, tf)) in chains.iter().enumerate() {
        match groups.iter_mut().find(|g| chains[g.0[0]].0 == *key) {
            Some(g) => g.0.push(i),
            None => groups.push((vec![i], tf)),
        }
    }
    let mut out = Rows {
        m: Vec::new(),
        n: Vec::new(),
        c: Vec::new(),
    };
    for ((mk, nk), ck) in rows.m.into_iter().zip(rows.n).zip(rows.c) {
        if ck.iter().all(|x| *x == 0.0) {
            // A row no output sees: kept once, unchanged.
            out.m.push(mk);
            out.n.push(nk);
            out.c.push(ck);
            continue;
        }
        for (outs, tf) in &groups {
            if outs.iter().all(|i| ck[*i] == 0.0) {
                continue;
            }
            out.m.push(mk.clone());
            out.n.push(nk.iter().map(|x| x.mul(tf)).collect());
            out.c.push(
                (0..ck.len())
                    .map(|i| if outs.contains(&i) { ck[i] } else { 0.0 })
                    .collect(),
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::model::physical::PhysicalModel;

    /// A 1×2 rigid body + mode with a sensor lag and a delay on output 2 only, and a gain on
    /// output 1: the rational export reproduces the exact evaluation (the Padé `[8/8]` of a
    /// 150 µs delay is exact to 1e-12 below 2000 rad/s), with one extra row per split mode.
    #[test]
    fn effects_on_one_output_split_the_modal_rows() {
        let ph: PhysicalModel = toml::from_str(
            r#"
            factor_pole = 10.0
            pade_order = 8
            [[rigid_body]]
            output_gain = [100.0, 100.0]
            [[mode]]
            omega_n = 480.0
            zeta = 0.02
            output_gain = [100.0, -100.0]
            [[effect]]
            kind = "lag"
            path = "output"
            channel = 2
            omega_c = 3000.0
            [[effect]]
            kind = "delay"
            path = "output"
            channel = 2
            tau_s = 1.5e-4
            [[effect]]
            kind = "gain"
            path = "output"
            channel = 1
            k = 0.9
            [[effect]]
            kind = "delay"
            tau_s = 1e-4
            "#,
        )
        .unwrap();
        let f = ph.to_factorization().unwrap();
        assert_eq!(f.c.ncols(), 4, "two rows per term, one per output group");
        for w in [0.5, 20.0, 470.0, 480.0, 490.0, 2000.0] {
            let exact = ph.eval(w);
            let got = f.plant(w).unwrap();
            for i in 0..2 {
                let (a, b) = (got[(i, 0)], exact[(i, 0)]);
                assert!((a - b).norm() <= 1e-9 * b.norm(), "{w} row {i}: {a} vs {b}");
            }
        }
        // Output 2 alone carries −ωτ − atan(ω/ω_c) of extra phase relative to output 1.
        let w = 1000.0;
        let g = f.plant(w).unwrap();
        let g0 = {
            let mut q = ph.clone();
            q.effect
                .retain(|e| e.path == crate::model::physical::EffectPath::Input);
            q.eval(w)
        };
        let extra = (g[(1, 0)] / g0[(1, 0)]).arg();
        let want = -w * 1.5e-4 - (w / 3000.0f64).atan();
        assert!((extra - want).abs() < 1e-9, "{extra} vs {want}");
        assert!(((g[(0, 0)] / g0[(0, 0)]) - 0.9).norm() < 1e-12);
    }

    /// The same effects on every output go into `J`: no row is split.
    #[test]
    fn effects_on_every_output_go_into_j() {
        let ph: PhysicalModel = toml::from_str(
            r#"
            factor_pole = 10.0
            [[rigid_body]]
            output_gain = [100.0, 100.0]
            [[mode]]
            omega_n = 480.0
            zeta = 0.02
            output_gain = [100.0, -100.0]
            [[effect]]
            kind = "lag"
            path = "output"
            omega_c = 3000.0
            "#,
        )
        .unwrap();
        let f = ph.to_factorization().unwrap();
        assert_eq!(f.c.ncols(), 2);
        for w in [1.0, 480.0, 5000.0] {
            let (a, b) = (f.plant(w).unwrap()[(1, 0)], ph.eval(w)[(1, 0)]);
            assert!((a - b).norm() <= 1e-12 * b.norm(), "{w}: {a} vs {b}");
        }
    }
}
