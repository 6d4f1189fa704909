//! The closed-loop poles of the Theorem 1 loop (condition 1 of Theorem 1, internal
//! stability) from its structure, for a large diagonal `M̃`.
//!
//! The loop of [`theorem1_system`](super::theorem1_system) realizes each modal row as the
//! cascade `M̃ᵢᵢ⁻¹·[Ñᵢ  1]` (4 states per mode). Where every `Ñᵢⱼ` has the denominator `qᵢ`
//! of `M̃ᵢᵢ = dᵢ/qᵢ` (every `[physical]` mode), that cascade is `[b·sᵏ/qᵢ  1]` followed by
//! `qᵢ/dᵢ`: the poles `qᵢ = 0` of the first factor are zeros of the second, so those modes
//! are **unobservable** from `ξ`. A loop closed through `y = C·ξ` leaves unobservable modes
//! where they are (`A − B·K·C` maps the unobservable subspace into itself, as `A` does), and
//! the observable quotient is the minimal row `[b·sᵏ  qᵢ]/dᵢ` (2 states per mode, the row
//! realization of the norms). Hence
//!
//! `poles(loop) = eig(loop of the cancelled rows) ∪ ⋃ᵢ roots(qᵢ)`,
//!
//! the same set as the dense eigenvalues of the 4-states-per-mode loop, for an eigenproblem
//! of half the size (8× less work): 1000 modes, 2000 instead of 4000 states. The route is
//! taken only when the state counts agree (`states(loop) = states(cancelled loop) +
//! Σ deg qᵢ`, i.e. no other cancellation took place in either realization) and every `qᵢ`'s
//! roots converge; otherwise the dense eigenvalues of the whole loop.

use super::factor_loop::row_loop;
use crate::error::Result;
use crate::model::Factorization;
use crate::system::eig::eigenvalues;
use crate::system::StateSpace;
use num_complex::Complex64;

/// From this many loop states on (the loop of [`theorem1_system`](super::theorem1_system)),
/// [`loop_poles`] takes the structured route (the norms drop the hidden modes from the same
/// size on, `ROW_NORMS_FROM`); below it the dense eigenvalues (the figures of small models
/// unchanged to the last digit).
pub const POLES_BY_STRUCTURE_FROM: usize = 200;

/// The closed-loop poles of a loop, and how they were found.
#[derive(Debug, Clone)]
pub struct LoopPoles {
    /// The eigenvalues of the loop's `A` (the factors' hidden modes included).
    pub poles: Vec<Complex64>,
    /// When the structure was used: the loop of the cancelled rows (the norm system of
    /// `theorem1_norm_system`, the same `T`) and its own eigenvalues.
    pub row_loop: Option<(StateSpace, Vec<Complex64>)>,
}

/// The eigenvalues of `t.a`, `t` the Theorem 1 loop of `controller_gain` on `f`: by the
/// structure of the module docs when it applies (from [`POLES_BY_STRUCTURE_FROM`] states,
/// factors typed as transfer functions, diagonal `M̃`, every `Ñᵢⱼ` over the denominator of
/// `M̃ᵢᵢ`), else densely.
pub fn loop_poles(
    f: &Factorization,
    controller_gain: &StateSpace,
    t: &StateSpace,
) -> Result<LoopPoles> {
    loop_poles_told(f, controller_gain, t, &|_| ())
}

/// [`loop_poles`], telling `stage` the eigenproblem it solves once the route is decided.
pub(crate) fn loop_poles_told(
    f: &Factorization,
    controller_gain: &StateSpace,
    t: &StateSpace,
    stage: &dyn Fn(&str),
) -> Result<LoopPoles> {
    if let Some(done) = structured(f, controller_gain, t, stage)? {
        return Ok(done);
    }
    stage(&format!("closed-loop poles ({} states)", t.states()));
    Ok(LoopPoles {
        poles: eigenvalues(&t.a, "closed-loop poles")?,
        row_loop: None,
    })
}

/// `Σ deg qᵢ`, the hidden modes [`loop_poles`] takes from the factors' denominators, when
/// its structured route may apply to the loop `t`.
fn hidden_mode_count(f: &Factorization, t: &StateSpace) -> Option<usize> {
    applies(f, t).then(|| (0..f.states()).map(|i| f.m.entry(i, i).den.degree()).sum())
}

fn applies(f: &Factorization, t: &StateSpace) -> bool {
    t.states() >= POLES_BY_STRUCTURE_FROM
        && f.realization.is_none()
        && f.m.is_diagonal()
        && (0..f.states()).all(|i| {
            let q = &f.m.entry(i, i).den;
            (0..f.inputs()).all(|j| f.n.entry(i, j).den == *q)
        })
}

fn structured(
    f: &Factorization,
    k: &StateSpace,
    t: &StateSpace,
    stage: &dyn Fn(&str),
) -> Result<Option<LoopPoles>> {
    let Some(hidden) = hidden_mode_count(f, t) else {
        return Ok(None);
    };
    let reduced = row_loop(f, k)?;
    // Another cancellation (a mode with b = 0, a common root of d and q) would make the
    // quotient differ from the cancelled row: then the dense route.
    if reduced.states() + hidden != t.states() {
        return Ok(None);
    }
    let mut poles = Vec::with_capacity(t.states());
    for i in 0..f.states() {
        let roots = f.m.entry(i, i).den.roots();
        if !roots.converged || roots.roots.iter().any(|z| !z.is_finite()) {
            return Ok(None);
        }
        poles.extend(roots.roots);
    }
    let (n, r) = (t.states(), reduced.states());
    stage(&format!(
        "closed-loop poles ({n} states: the eigenvalues of the {r} x {r} loop of the cancelled \
         rows, and {hidden} hidden modes of the factors, the roots of their denominators)"
    ));
    let own = eigenvalues(&reduced.a, "closed-loop poles")?;
    poles.extend(own.iter().copied());
    Ok(Some(LoopPoles {
        poles,
        row_loop: Some((reduced, own)),
    }))
}
