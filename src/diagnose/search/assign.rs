//! Which modes of a refit model are the configured ones and which were added: an optimal
//! assignment, never the slot index.
//!
//! A joint refit may move a configured mode within its box (×1.3 in `ω_n`) onto the peak an
//! added mode was meant for, and the added mode's slot onto the configured mode's peak; the
//! model is the same sum of terms, but read slot by slot the report would say the configured
//! mode was added and the new one was "moved".  So after every joint refit the modes are
//! matched to the configured ones by the minimum-cost assignment (Kuhn 1955; Munkres 1957)
//! with the cost `|ln(ω_f/ω_b)| + w·(1 − MAC)` (the frequency first, the shape — the
//! residue vector over every channel, compared by the modal assurance criterion — to tell
//! close modes apart), and reordered: the matched modes first, in the configured order and
//! with the configured names, then the added ones, in the order their effects were chosen
//! (matched to the frequencies they were fitted at when added).  Everything that reads the
//! model slot by slot (the moved-parameter table, the chosen effects' final values, the
//! per-peak account, the written file's notes) then tells the truth.

use crate::diagnose::effects::candidates::Cand;
use crate::diagnose::effects::candidates::ADDED_NOTE;
use crate::diagnose::effects::residual_mode::is_pseudo_mode;
use crate::diagnose::effects::residual_mode_below::is_pseudo_mode_below;
use crate::model::physical::{ModeSpec, PhysicalModel};

/// Weight of the shape term `1 − MAC` against `|ln(ω_f/ω_b)|`: two modes 5 % apart with
/// orthogonal shapes cost the same as one 5 % + 5 % apart with equal shapes.
const SHAPE_WEIGHT: f64 = 0.05;

/// The minimum-cost assignment of the rows of `cost` (n rows, m ≥ n columns) to distinct
/// columns (the Hungarian method with potentials, O(n²m)); `out[r]` is row r's column.
pub fn min_cost_assignment(cost: &[Vec<f64>]) -> Vec<usize> {
    let n = cost.len();
    if n == 0 {
        return vec![];
    }
    let m = cost[0].len();
    assert!(m >= n, "more rows than columns");
    // 1-based arrays of the classical formulation; p[j] = row matched to column j.
    let (mut u, mut v) = (vec![0.0f64; n + 1], vec![0.0f64; m + 1]);
    let (mut p, mut way) = (vec![0usize; m + 1], vec![0usize; m + 1]);
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0usize;
        let mut minv = vec![f64::INFINITY; m + 1];
        let mut used = vec![false; m + 1];
        // Each pass fixes one column; at most m passes per row.
        for _ in 0..=m {
            used[j0] = true;
            let i0 = p[j0];
            let (mut delta, mut j1) = (f64::INFINITY, 0usize);
            for j in 1..=m {
                if used[j] {
                    continue;
                }
                let c = cost[i0 - 1][j - 1];
                let c = if c.is_finite() { c } else { 1e300 };
                let cur = c - u[i0] - v[j];
                if cur < minv[j] {
                    minv[j] = cur;
                    way[j] = j0;
                }
                if minv[j] < delta {
                    delta = minv[j];
                    j1 = j;
                }
            }
            for j in 0..=m {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        // Augment along the alternating path.
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut out = vec![0usize; n];
    for j in 1..=m {
        if p[j] > 0 {
            out[p[j] - 1] = j - 1;
        }
    }
    out
}

/// The residue vector of a mode over every (output, input) pair: `c_o b_i / m`.
fn shape(md: &ModeSpec, p: usize, n_in: usize) -> Vec<f64> {
    let (c, b) = (md.output_gain.to_vec(p), md.input_gain.to_vec(n_in));
    c.iter()
        .flat_map(|co| b.iter().map(move |bi| co * bi / md.mass))
        .collect()
}

/// Modal assurance criterion of two real shapes (1 for parallel, 0 for orthogonal; ½ when
/// either is zero: no information).
fn mac(a: &[f64], b: &[f64]) -> f64 {
    let ab: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let (aa, bb): (f64, f64) = (a.iter().map(|x| x * x).sum(), b.iter().map(|x| x * x).sum());
    if aa > 0.0 && bb > 0.0 {
        ab * ab / (aa * bb)
    } else {
        0.5
    }
}

/// Cost of reading mode `f` of a refit model as configured (or chosen) mode `b`.
fn mode_cost(b: &ModeSpec, f: &ModeSpec, p: usize, n_in: usize) -> f64 {
    (f.omega_n / b.omega_n).ln().abs()
        + SHAPE_WEIGHT * (1.0 - mac(&shape(b, p, n_in), &shape(f, p, n_in)))
}

/// For every configured mode, the index of its mode in `m` (see the module docs; `None` when
/// `m` has fewer modes), with the cost summed over several readings of the configured
/// modes (`refs`, each with `base`'s modes in the same order: as configured, and where the
/// retune put them): from a rough start a configured mode may lie nearer an added one than
/// the mode it became, and the retune alone may have moved a configured slot onto a missing
/// mode; the sum decides by both.
pub fn configured_modes_from(refs: &[&PhysicalModel], m: &PhysicalModel) -> Option<Vec<usize>> {
    let base = refs.first()?;
    if m.mode.len() < base.mode.len() || refs.iter().any(|r| r.mode.len() != base.mode.len()) {
        return None;
    }
    let (p, n_in) = (m.n_outputs(), m.n_inputs());
    let cost: Vec<Vec<f64>> = (0..base.mode.len())
        .map(|b| {
            m.mode
                .iter()
                .map(|f| refs.iter().map(|r| mode_cost(&r.mode[b], f, p, n_in)).sum())
                .collect()
        })
        .collect();
    Some(min_cost_assignment(&cost))
}

/// The configured modes and the added ones read in `m` by one assignment, when `m` has
/// exactly one mode for each (`None` otherwise): rows are the configured modes (cost summed
/// over the readings of `refs`, as in [`configured_modes_from`]) and the added modes (cost
/// `|ln(ω_f/ω_added)|` to the frequency each was fitted at, weighted like one reading per
/// ref). Assigning both at once keeps a configured mode from taking the peak an added mode
/// was fitted to when the configured mode itself moved far in the joint refit (a shifted
/// mode plus a new one: read configured-first, the shifted mode took the new peak and the
/// new mode was reported where the shifted one went).
fn joint_assignment(
    refs: &[&PhysicalModel],
    m: &PhysicalModel,
    added_w: &[f64],
) -> Option<(Vec<usize>, Vec<usize>)> {
    let base = refs.first()?;
    let n_conf = base.mode.len();
    if added_w.is_empty()
        || n_conf + added_w.len() != m.mode.len()
        || refs.iter().any(|r| r.mode.len() != n_conf)
    {
        return None;
    }
    let (p, n_in) = (m.n_outputs(), m.n_inputs());
    let weight = refs.len() as f64;
    let cost: Vec<Vec<f64>> = (0..n_conf)
        .map(|b| {
            m.mode
                .iter()
                .map(|f| refs.iter().map(|r| mode_cost(&r.mode[b], f, p, n_in)).sum())
                .collect()
        })
        .chain(added_w.iter().map(|w| {
            m.mode
                .iter()
                .map(|f| weight * (f.omega_n / w).ln().abs())
                .collect()
        }))
        .collect();
    let a = min_cost_assignment(&cost);
    Some((a[..n_conf].to_vec(), a[n_conf..].to_vec()))
}

/// `m` with its modes reordered (see the module docs): the modes matched to `base`'s first,
/// in `base`'s order and with its names; then the added ones in the order of the `Mode`
/// effects of `effects` (matched by the frequency each was fitted at when added, `θ[0] =
/// ln ω_n`), named as added.  Other terms are left as they are (they are appended after the
/// configured ones and have no frequency to be confused by).
pub fn align(
    base: &PhysicalModel,
    m: &PhysicalModel,
    effects: &[(Cand, Vec<f64>)],
) -> PhysicalModel {
    align_from(&[base], m, effects)
}

/// As [`align`], the configured modes read in every model of `refs` (the first gives the
/// names; see [`configured_modes_from`]).
pub fn align_from(
    refs: &[&PhysicalModel],
    m: &PhysicalModel,
    effects: &[(Cand, Vec<f64>)],
) -> PhysicalModel {
    let base = refs[0];
    // The added modes, and the pseudo-modes above or below the band (residual terms), each
    // named by its own effect.
    let added: Vec<(Cand, f64)> = effects
        .iter()
        .filter(|(c, th)| {
            matches!(c, Cand::Mode | Cand::ResidualMode | Cand::ResidualModeBelow) && !th.is_empty()
        })
        .map(|(c, th)| (*c, th[0].exp()))
        .collect();
    let added_w: Vec<f64> = added.iter().map(|a| a.1).collect();
    let (matched, unmatched, by_effect) = match joint_assignment(refs, m, &added_w) {
        Some((a, b)) => (a, b, true),
        None => {
            let Some(matched) = configured_modes_from(refs, m) else {
                return m.clone();
            };
            let unmatched = (0..m.mode.len()).filter(|j| !matched.contains(j)).collect();
            (matched, unmatched, false)
        }
    };
    let mut out = m.clone();
    out.mode = matched
        .iter()
        .zip(&base.mode)
        .map(|(&j, b)| ModeSpec {
            name: b.name.clone(),
            ..m.mode[j].clone()
        })
        .chain(unmatched.iter().enumerate().map(|(k, &j)| {
            // Without the joint assignment a pseudo-mode keeps its name: it lies above or
            // below the band, where no configured or added mode is.
            let cand = if by_effect {
                added[k].0
            } else if is_pseudo_mode_below(m.mode[j].name.as_deref()) {
                Cand::ResidualModeBelow
            } else if is_pseudo_mode(m.mode[j].name.as_deref()) {
                Cand::ResidualMode
            } else {
                Cand::Mode
            };
            ModeSpec {
                name: Some(format!("{ADDED_NOTE}: {}", cand.label())),
                ..m.mode[j].clone()
            }
        }))
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over every injective map of rows to columns.
    fn brute(cost: &[Vec<f64>]) -> f64 {
        fn go(cost: &[Vec<f64>], r: usize, used: &mut Vec<bool>) -> f64 {
            if r == cost.len() {
                return 0.0;
            }
            let mut best = f64::INFINITY;
            for j in 0..used.len() {
                if !used[j] {
                    used[j] = true;
                    best = best.min(cost[r][j] + go(cost, r + 1, used));
                    used[j] = false;
                }
            }
            best
        }
        go(cost, 0, &mut vec![false; cost[0].len()])
    }

    #[test]
    fn assignment_is_optimal_against_brute_force() {
        // A deterministic pseudo-random sweep of rectangular matrices.
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in 1..=5 {
            for m in n..=6 {
                for _ in 0..20 {
                    let cost: Vec<Vec<f64>> =
                        (0..n).map(|_| (0..m).map(|_| rnd()).collect()).collect();
                    let a = min_cost_assignment(&cost);
                    let mut cols = a.clone();
                    cols.sort();
                    cols.dedup();
                    assert_eq!(cols.len(), n, "columns not distinct: {a:?}");
                    let got: f64 = a.iter().enumerate().map(|(r, &c)| cost[r][c]).sum();
                    assert!(
                        (got - brute(&cost)).abs() < 1e-12,
                        "{got} vs {}",
                        brute(&cost)
                    );
                }
            }
        }
    }

    fn mode(w: f64, c: f64, name: &str) -> ModeSpec {
        ModeSpec {
            name: Some(name.into()),
            omega_n: w,
            zeta: 0.01,
            mass: 1.0,
            input_gain: crate::model::physical::Gains::Scalar(1.0),
            output_gain: crate::model::physical::Gains::Scalar(c),
        }
    }

    #[test]
    fn a_swapped_refit_is_read_by_frequency_not_by_slot() {
        // Configured: one mode at 900 (named "cfg"). The refit moved slot 0 to 810 and the
        // added slot 1 landed at 902: the configured mode is the one at 902.
        let mut base = PhysicalModel::default();
        base.mode.push(mode(900.0, 1.0, "cfg"));
        let mut m = base.clone();
        m.mode[0] = mode(810.0, 0.4, "cfg");
        m.mode
            .push(mode(902.0, 1.1, "added by rshape diagnose: mode"));
        let a = align(&base, &m, &[(Cand::Mode, vec![(815f64).ln()])]);
        assert_eq!(a.mode[0].omega_n, 902.0);
        assert_eq!(a.mode[0].name.as_deref(), Some("cfg"));
        assert_eq!(a.mode[1].omega_n, 810.0);
        assert_eq!(
            a.mode[1].name.as_deref(),
            Some("added by rshape diagnose: mode")
        );
        // Two added modes come in the order they were chosen.
        m.mode.push(mode(500.0, 0.2, "x"));
        let a = align(
            &base,
            &m,
            &[
                (Cand::Mode, vec![(490f64).ln()]),
                (Cand::Mode, vec![(800f64).ln()]),
            ],
        );
        let w: Vec<f64> = a.mode.iter().map(|x| x.omega_n).collect();
        assert_eq!(w, vec![902.0, 500.0, 810.0]);
    }
}
