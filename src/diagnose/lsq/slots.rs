//! The parameter slots of a physical model that `retune` refits: the linear ones (output
//! gains, i.e. residues, and feedthrough: solved by least squares) and the nonlinear ones
//! (ω_n and ζ of every mode, friction poles, input gains of several inputs, path-effect
//! parameters: moved by Levenberg–Marquardt), with their boxes and the weighted design matrix
//! of the linear ones (the variable projection of [`crate::diagnose::lsq::retune`]).

use crate::diagnose::effects::candidates::ADDED_NOTE;
use crate::diagnose::lsq::channels::Channels;
use crate::diagnose::lsq::shapes::path_at;
use crate::model::physical::{EffectKind, Feedthrough, Gains, PhysicalModel};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Term {
    Rigid(usize),
    Int(usize),
    Mode(usize),
}

#[derive(Debug, Clone, Copy)]
pub(crate) enum Lin {
    Out(Term, usize),
    Feed(usize, usize),
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Nl {
    ModeW(usize),
    ModeZ(usize),
    RigidPole(usize),
    In(Term, usize),
    Delay(usize),
    LogEffect(usize),
}

pub(crate) fn gains_of(m: &PhysicalModel, t: Term) -> (&Gains, &Gains, f64) {
    match t {
        Term::Rigid(i) => {
            let r = &m.rigid_body[i];
            (&r.output_gain, &r.input_gain, r.mass)
        }
        Term::Int(i) => {
            let r = &m.integrator[i];
            (&r.output_gain, &r.input_gain, r.mass)
        }
        Term::Mode(i) => {
            let r = &m.mode[i];
            (&r.output_gain, &r.input_gain, r.mass)
        }
    }
}

pub(crate) fn gains_mut(m: &mut PhysicalModel, t: Term) -> (&mut Gains, &mut Gains) {
    match t {
        Term::Rigid(i) => {
            let r = &mut m.rigid_body[i];
            (&mut r.output_gain, &mut r.input_gain)
        }
        Term::Int(i) => {
            let r = &mut m.integrator[i];
            (&mut r.output_gain, &mut r.input_gain)
        }
        Term::Mode(i) => {
            let r = &mut m.mode[i];
            (&mut r.output_gain, &mut r.input_gain)
        }
    }
}

pub(crate) fn set_entry(g: &mut Gains, n: usize, idx: usize, x: f64) {
    let mut v = g.to_vec(n);
    v[idx] = x;
    *g = if n == 1 {
        Gains::Scalar(v[0])
    } else {
        Gains::Vector(v)
    };
}

pub(crate) fn terms(m: &PhysicalModel) -> Vec<Term> {
    (0..m.rigid_body.len())
        .map(Term::Rigid)
        .chain((0..m.integrator.len()).map(Term::Int))
        .chain((0..m.mode.len()).map(Term::Mode))
        .collect()
}

/// The slots of `m` on the outputs the data observe.
pub(crate) fn slots(m: &PhysicalModel, data: &Channels) -> (Vec<Lin>, Vec<Nl>) {
    let (p, n_in) = (m.n_outputs(), m.n_inputs());
    let outs: Vec<usize> = (0..p)
        .filter(|o| data.entries.iter().any(|e| e.0 == *o))
        .collect();
    let mut lin = Vec::new();
    let mut nl = Vec::new();
    for t in terms(m) {
        let (c, b, _) = gains_of(m, t);
        let (c, b) = (c.to_vec(p), b.to_vec(n_in));
        for o in &outs {
            if c[*o] != 0.0 {
                lin.push(Lin::Out(t, *o));
            }
        }
        if n_in > 1 {
            let first = b.iter().position(|x| *x != 0.0);
            for (i, x) in b.iter().enumerate() {
                if *x != 0.0 && Some(i) != first && data.entries.iter().any(|e| e.1 == i) {
                    nl.push(Nl::In(t, i));
                }
            }
        }
    }
    for (i, r) in m.rigid_body.iter().enumerate() {
        if r.friction_pole.is_some_and(|p| p > 0.0) {
            nl.push(Nl::RigidPole(i));
        }
    }
    for i in 0..m.mode.len() {
        nl.push(Nl::ModeW(i));
        nl.push(Nl::ModeZ(i));
    }
    if m.feedthrough.is_some() {
        for e in &data.entries {
            lin.push(Lin::Feed(e.0, e.1));
        }
    }
    for (i, e) in m.effect.iter().enumerate() {
        // A delay is refit as τ; a lag, NMP zero or hold in the logarithm of its parameter
        // (`EffectSpec::log_param`); a gain or sign is not refit.
        if e.kind == EffectKind::Delay {
            if e.tau_s.is_some() {
                nl.push(Nl::Delay(i));
            }
        } else if e.log_param().is_some_and(|x| x > 0.0) {
            nl.push(Nl::LogEffect(i));
        }
    }
    (lin, nl)
}

pub(crate) fn get_nl(m: &PhysicalModel, s: Nl) -> f64 {
    match s {
        Nl::ModeW(i) => m.mode[i].omega_n.ln(),
        Nl::ModeZ(i) => m.mode[i].zeta.ln(),
        Nl::RigidPole(i) => m.rigid_body[i].friction_pole.unwrap_or(1.0).ln(),
        Nl::In(t, i) => gains_of(m, t).1.to_vec(m.n_inputs())[i],
        Nl::Delay(i) => m.effect[i].tau_s.unwrap_or(0.0),
        Nl::LogEffect(i) => m.effect[i].log_param().unwrap_or(1.0).ln(),
    }
}

pub(crate) fn set_nl(m: &mut PhysicalModel, s: Nl, x: f64) {
    let n_in = m.n_inputs();
    match s {
        Nl::ModeW(i) => m.mode[i].omega_n = x.exp(),
        Nl::ModeZ(i) => m.mode[i].zeta = x.exp(),
        Nl::RigidPole(i) => m.rigid_body[i].friction_pole = Some(x.exp()),
        Nl::In(t, i) => set_entry(gains_mut(m, t).1, n_in, i, x),
        Nl::Delay(i) => m.effect[i].tau_s = Some(x),
        Nl::LogEffect(i) => {
            if let Some(v) = m.effect[i].log_param_mut() {
                *v = Some(x.exp());
            }
        }
    }
}

pub(crate) fn set_lin(m: &mut PhysicalModel, s: Lin, x: f64) {
    let (p, n_in) = (m.n_outputs(), m.n_inputs());
    match s {
        Lin::Out(t, o) => set_entry(gains_mut(m, t).0, p, o, x),
        Lin::Feed(o, i) => {
            m.feedthrough = Some(match m.feedthrough.take() {
                Some(Feedthrough::Matrix(mut r)) => {
                    r[o][i] = x;
                    Feedthrough::Matrix(r)
                }
                _ if p * n_in == 1 => Feedthrough::Scalar(x),
                _ => {
                    let mut r = vec![vec![0.0; n_in]; p];
                    r[o][i] = x;
                    Feedthrough::Matrix(r)
                }
            })
        }
    }
}

/// A configured mode's ω_n may move by this factor either way from its configured value (a
/// rough start 20 % off either way, `1/0.8 = 1.25`, with a margin).
pub const MODE_BOX: f64 = 1.3;

/// The value a nonlinear slot of `m` is bounded around: its value in `anchor` (the
/// configured model `m` was built from: configured terms and effects come first in every
/// list) when the slot is a configured one, else its value in `m` (an added effect).
pub(crate) fn anchor_value(anchor: &PhysicalModel, m: &PhysicalModel, s: Nl) -> f64 {
    let configured = match s {
        Nl::ModeW(i) | Nl::ModeZ(i) => i < anchor.mode.len(),
        Nl::RigidPole(i) => anchor
            .rigid_body
            .get(i)
            .is_some_and(|r| r.friction_pole.is_some_and(|p| p > 0.0)),
        Nl::In(t, _) => match t {
            Term::Rigid(i) => i < anchor.rigid_body.len(),
            Term::Int(i) => i < anchor.integrator.len(),
            Term::Mode(i) => i < anchor.mode.len(),
        },
        Nl::Delay(i) | Nl::LogEffect(i) => anchor
            .effect
            .get(i)
            .is_some_and(|e| e.kind == m.effect[i].kind && get_nl(anchor, s).is_finite()),
    };
    get_nl(if configured { anchor } else { m }, s)
}

/// `(lo, hi, typ)` of a nonlinear slot bounded around `x0` (see [`anchor_value`]); `ζ`
/// from the record's floor at the mode, `zeta_lo(ω_n)` ([`super::resolution::zeta_range`]:
/// below it the lines around the mode do not see its damping), to 0.7.
pub(crate) fn bounds(
    m: &PhysicalModel,
    s: Nl,
    x0: f64,
    (w_min, w_max): (f64, f64),
    zeta_lo: &dyn Fn(f64) -> f64,
) -> (f64, f64, f64) {
    match s {
        Nl::ModeW(i) => {
            let (mut lo, mut hi) = (x0 - MODE_BOX.ln(), x0 + MODE_BOX.ln());
            let name = m.mode[i].name.as_deref();
            let added = name.is_some_and(|n| n.starts_with(ADDED_NOTE));
            if crate::diagnose::effects::residual_mode_below::is_pseudo_mode_below(name) {
                // A pseudo-mode below the band (a residual term) stays below it.
                hi = hi.min((crate::diagnose::effects::residual_mode_below::BELOW.1 * w_min).ln());
                lo = lo.min(hi);
            } else if crate::diagnose::effects::residual_mode::is_pseudo_mode(name) {
                // A pseudo-mode above the band (a residual term) stays above it.
                lo = lo.max((crate::diagnose::effects::residual_mode::ABOVE.0 * w_max).ln());
                hi = hi.max(lo);
            } else if added {
                lo = lo.max(w_min.ln());
                hi = hi.min(w_max.ln()).max(lo);
            }
            (lo, hi, 1.0)
        }
        Nl::ModeZ(i) => (zeta_lo(m.mode[i].omega_n).ln(), 0.7f64.ln(), 1.0),
        Nl::RigidPole(_) | Nl::LogEffect(_) => (x0 - 10f64.ln(), x0 + 10f64.ln(), 1.0),
        Nl::In(..) => {
            let (a, b) = (x0 / 100.0, 100.0 * x0);
            (a.min(b), a.max(b), x0.abs().max(1e-300))
        }
        Nl::Delay(_) => (0.0, 10.0 * x0.abs() + 1.0 / w_max, 1.0 / w_max),
    }
}

pub(crate) fn design(
    m: &PhysicalModel,
    lin: &[Lin],
    data: &Channels,
    mask: &[usize],
) -> (DMatrix<f64>, DVector<f64>) {
    let n_in = m.n_inputs();
    let rows = 2 * mask.len() * data.n_ch();
    let n = lin.len();
    let mut a = DMatrix::<f64>::zeros(rows, n);
    let mut y = DVector::<f64>::zeros(rows);
    // The denominator of each column's term `(d₂ s² + d₁ s + d₀)` with `d₂ = 0` for an
    // integrator, `None` for a feedthrough; its input gains over its mass.
    let zero = Complex64::new(0.0, 0.0);
    let cols: Vec<(Option<[f64; 3]>, Vec<f64>)> = lin
        .iter()
        .map(|l| match l {
            Lin::Out(t, _) => {
                let (_, b, mass) = gains_of(m, *t);
                let den = match t {
                    Term::Rigid(i) => [1.0, m.rigid_body[*i].friction_pole.unwrap_or(0.0), 0.0],
                    Term::Int(_) => [0.0, 1.0, 0.0],
                    Term::Mode(i) => {
                        let md = &m.mode[*i];
                        [1.0, 2.0 * md.zeta * md.omega_n, md.omega_n * md.omega_n]
                    }
                };
                (Some(den), b.to_vec(n_in).iter().map(|x| x / mass).collect())
            }
            Lin::Feed(..) => (None, vec![]),
        })
        .collect();
    let mut row = 0;
    for (ch, e) in data.entries.iter().enumerate() {
        // Which columns act on this channel, with their gain.
        let on: Vec<Option<f64>> = lin
            .iter()
            .zip(&cols)
            .map(|(l, (_, b))| match l {
                Lin::Out(_, o) if *o == e.0 => Some(b[e.1]),
                Lin::Feed(o, i) if (*o, *i) == *e => Some(1.0),
                _ => None,
            })
            .collect();
        for &k in mask {
            let w = data.omega[k];
            let s = Complex64::new(0.0, w);
            let wt = std::f64::consts::SQRT_2 / data.radius[ch][k];
            let path = path_at(m, w, *e);
            for (j, (gain, (den, _))) in on.iter().zip(&cols).enumerate() {
                let v = match (gain, den) {
                    (Some(g), Some([d2, d1, d0])) => path * (s * (s * *d2 + *d1) + *d0).inv() * *g,
                    (Some(g), None) => path * *g,
                    _ => zero,
                };
                a[(row, j)] = v.re * wt;
                a[(row + 1, j)] = v.im * wt;
            }
            let g = data.g[ch][k];
            y[row] = g.re * wt;
            y[row + 1] = g.im * wt;
            row += 2;
        }
    }
    (a, y)
}

/// The current value of a linear slot of `m`.
pub(crate) fn get_lin(m: &PhysicalModel, s: Lin) -> f64 {
    let (p, n_in) = (m.n_outputs(), m.n_inputs());
    match s {
        Lin::Out(t, o) => gains_of(m, t).0.to_vec(p)[o],
        Lin::Feed(o, i) => match &m.feedthrough {
            Some(Feedthrough::Scalar(x)) if p * n_in == 1 => *x,
            Some(Feedthrough::Matrix(r)) => r[o][i],
            _ => 0.0,
        },
    }
}

/// The rows of the design matrix `a` that belong to channels `chs` (each channel owns
/// `rows_per_ch` consecutive rows) and the sub-matrix of those rows and columns `cols`: one
/// block of the block-diagonal least-squares problem of [`blocks`].
pub(crate) fn block_matrix(
    a: &DMatrix<f64>,
    chs: &[usize],
    cols: &[usize],
    rows_per_ch: usize,
) -> (Vec<usize>, DMatrix<f64>) {
    let rows: Vec<usize> = chs
        .iter()
        .flat_map(|ch| ch * rows_per_ch..(ch + 1) * rows_per_ch)
        .collect();
    let ab = DMatrix::from_fn(rows.len(), cols.len(), |i, j| a[(rows[i], cols[j])]);
    (rows, ab)
}

/// The independent blocks of the linear least squares: groups of channels that share no
/// linear slot with the other groups (an output gain acts on the channels of its output, a
/// feedthrough on one channel), each with the slots acting on it.  With one input every
/// output is its own block, so the QR factors a few small matrices instead of one large.
pub(crate) fn blocks(lin: &[Lin], data: &Channels) -> Vec<(Vec<usize>, Vec<usize>)> {
    let n_ch = data.n_ch();
    let acts = |l: &Lin, ch: usize| {
        let e = data.entries[ch];
        match l {
            Lin::Out(_, o) => *o == e.0,
            Lin::Feed(o, i) => (*o, *i) == e,
        }
    };
    // Union-find over the channels, joined through the slots they share.
    let mut parent: Vec<usize> = (0..n_ch).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for l in lin {
        let chs: Vec<usize> = (0..n_ch).filter(|ch| acts(l, *ch)).collect();
        for w in chs.windows(2) {
            let (a, b) = (root(&mut parent, w[0]), root(&mut parent, w[1]));
            parent[a] = b;
        }
    }
    let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
    for ch in 0..n_ch {
        let r = root(&mut parent, ch);
        match groups.iter_mut().find(|g| g.0 == r) {
            Some(g) => g.1.push(ch),
            None => groups.push((r, vec![ch])),
        }
    }
    groups
        .into_iter()
        .map(|(_, chs)| {
            let cols = (0..lin.len())
                .filter(|j| chs.iter().any(|ch| acts(&lin[*j], *ch)))
                .collect();
            (chs, cols)
        })
        .collect()
}
