//! Output-path (sensor) effects in the rational export `C·M̃⁻¹·Ñ·J` (Sec. IV-A).
//!
//! Let `O = diag(O_1 … O_p)` be the output-path effects, `O_i(s)` the product of the effects
//! on output `i`. Then `O·G = Σ_k O·C_{:,k}·M̃_kk⁻¹·Ñ_k·J`.
//!
//! * A constant effect (gain, sign) on output `i` scales row `i` of `C`.
//! * When every output carries the same dynamic chain `O_0`, `O = O_0·I` commutes with the
//!   plant and goes into every entry of `J` (the SISO case is this one).
//! * Otherwise the outputs are grouped by their dynamic chain, `P_g` the projection on group `g`, and
//!   `O·C_{:,k} = Σ_g P_g C_{:,k} O_g`: modal row `k` becomes one row per group `g` that sees
//!   it, with the same `M̃_kk`, the row `O_g·Ñ_k` and the column `P_g C_{:,k}` of `C`. `C`
//!   stays constant, and its rank is still `p` (its rows of group `g` use only that group's
//!   columns, which are the original columns restricted to those rows). Each new row is
//!   coprime when the old one is: `M̃_kk` is unchanged and `O_g` (delay Padé, lag, gain,
//!   all-pass) is stable with no zero where `M̃_kk` vanishes (`s = 0` for a rigid body).
//!   A sensor lag on output 2 of a 1×2 modal model with `n` modes thus gives `2n` rows.

use super::{EffectKind, EffectPath, PhysicalModel};
use crate::system::TransferFunction;

/// The rows of a special factorization being built: the diagonal of `M̃`, the rows of `Ñ`
/// and the columns of `C`.
pub(super) struct Rows {
    pub m: Vec<TransferFunction>,
    pub n: Vec<Vec<TransferFunction>>,
    pub c: Vec<Vec<f64>>,
}

/// The output-path effects on one output: the indices of the dynamic ones and their
/// product, and the product of the constant ones (gain, sign).
pub(super) struct Chain {
    idx: Vec<usize>,
    tf: TransferFunction,
    gain: f64,
}

impl PhysicalModel {
    /// Per output: its output-path effects (Padé of order `order` for delays and holds).
    pub(super) fn output_chains(&self, order: usize) -> Vec<Chain> {
        (0..self.n_outputs())
            .map(|i| {
                let mut ch = Chain {
                    idx: Vec::new(),
                    tf: TransferFunction::gain(1.0),
                    gain: 1.0,
                };
                for (k, e) in self.effect.iter().enumerate() {
                    if e.path == EffectPath::Output && e.channel.is_none_or(|c| c == i + 1) {
                        match e.kind {
                            EffectKind::Gain => ch.gain *= e.k.unwrap_or(1.0),
                            EffectKind::Sign => ch.gain = -ch.gain,
                            _ => {
                                ch.idx.push(k);
                                ch.tf = ch.tf.mul(&e.to_tf(order));
                            }
                        }
                    }
                }
                ch
            })
            .collect()
    }
}

/// Puts the output chains into the factorization (see the module docs): constant gains into
/// the rows of `C`; dynamic effects into `j` when all outputs share them, else by splitting
/// each modal row per group of outputs.
pub(super) fn split_rows(chains: Vec<Chain>, mut rows: Rows, j: &mut [TransferFunction]) -> Rows {
    for ck in rows.c.iter_mut() {
        for (i, x) in ck.iter_mut().enumerate() {
            *x *= chains[i].gain;
        }
    }
    if chains.iter().all(|c| c.idx == chains[0].idx) {
        if !chains[0].idx.is_empty() {
            for jk in j.iter_mut() {
                *jk = jk.mul(&chains[0].tf);
            }
        }
        return rows;
    }
    // Groups of outputs with the same dynamic effects, in order of their first output.
    let mut groups: Vec<(Vec<usize>, &TransferFunction)> = Vec::new();
    for (i, ch) in chains.iter().enumerate() {
        match groups.iter_mut().find(|g| chains[g.0[0]].idx == ch.idx) {
            Some(g) => g.0.push(i),
            None => groups.push((vec![i], &ch.tf)),
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

    /// A gain on one output scales its row of `C`: no row is split.
    #[test]
    fn a_gain_on_one_output_scales_its_row_of_c() {
        let ph: PhysicalModel = toml::from_str(
            r#"
            [[rigid_body]]
            output_gain = [100.0, 100.0]
            [[mode]]
            omega_n = 480.0
            zeta = 0.02
            output_gain = [100.0, -100.0]
            [[effect]]
            kind = "gain"
            path = "output"
            channel = 2
            k = 0.8
            [[effect]]
            kind = "sign"
            path = "output"
            channel = 1
            "#,
        )
        .unwrap();
        let f = ph.to_factorization().unwrap();
        assert_eq!(f.c.ncols(), 2);
        // Columns: the mode, then the rigid body.
        assert_eq!(
            (f.c[(0, 0)], f.c[(1, 0)], f.c[(1, 1)]),
            (-100.0, -80.0, 80.0)
        );
        for w in [1.0, 480.0, 5000.0] {
            let (a, b) = (f.plant(w).unwrap(), ph.eval(w));
            for i in 0..2 {
                assert!((a[(i, 0)] - b[(i, 0)]).norm() <= 1e-12 * b[(i, 0)].norm());
            }
        }
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
