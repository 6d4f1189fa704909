"""Issue 33: the pyuff 51.5 Hz damping over the whole low band, and what a better estimator
or a measurement-chain effect could do for it.

A fit of tests/data/pyuff/frf_10_990.csv over 10-200 Hz (191 lines x 3 channels, n = 1146
real data), weights 1/sigma with sigma = 3 std/sqrt(2) (the noise of
tests/data/pyuff_rigid.toml), in rshape's modal model: per channel a real mass line (the
rigid body's accelerance), modes 1 (51.5 Hz) and 2 (142.2 Hz) with real residues and a
real upper residual -w^2 u (the modes above); the linear terms by least squares, the rest
(w_n, zeta of both modes, and a hypothesis' own parameter) by bounded trust-region least
squares from several starts (numpy + scipy, independent of rshape).  Hypotheses:
* real: rshape's model as it is;
* complex1: mode 1's residue complex (LSFD's model; 1 more per channel);
* cplxbg: the mass line and upper residual complex (a constant phase of the background);
* delay: e^{-s tau} on every channel (the catalogue's delay);
* hpF: a first-order high-pass (AC coupling) on the force channel, H (1 + w_c/s), a lag
  atan(w_c/w) on every channel (an ICP hammer's or a charge amplifier's time constant);
* hpX: the same on the response channel, H s/(s + w_c), a lead;
* phase: a constant phase e^{-j phi} on every channel over the band (not causal; the
  shape of a constant chain phase, for comparison);
* pair: a second real-residue mode near 51.5 Hz (two close modes, e.g. bending in two
  planes, unresolved at 1 Hz lines, look like one mode with a complex residue shared by
  every channel).
Then the profile of V over mode 1's zeta (every other parameter refit) for real,
complex1 and hpF.

Output (numpy 2.4.6, scipy 1.17.1; about 1 min of CPU):
    real     V 3359.8  zeta1 1e-06 (at its bound)
    complex1 V 1053.5  zeta1 0.000656
    cplxbg   V 2809.9  zeta1 1.58e-05
    delay    V 3180.2  zeta1 1e-06 (at its bound)  tau 4.03e-05 s
    hpF      V 2040.4  zeta1 5.24e-05  f_c 3.89 Hz
    hpX      V 3360.5  zeta1 1e-06 (at its bound)  f_c 0.001 Hz (at its bound)
    phase    V 2260.3  zeta1 0.00019  phi 4.14 deg
    pair     V 3046.6  zeta1 0.000709  (modes at 51.50 and 52.50 Hz, zeta 0.00071 and 0.1)
    profile real: 5e-05:0.8 0.00011:2.0 0.00024:5.8 0.00054:20.0 0.0012:77.6
    profile complex1: 5e-05:18.1 0.00011:14.7 0.00024:8.5 0.00054:0.7 0.0012:14.3
    profile hpF: 5e-05:0.0 0.00011:0.2 0.00024:1.7 0.00054:11.5 0.0012:63.0
(the profile: V minus the fit's V with mode 1's zeta held; the pair's second mode ends on
both its bounds, 52.5 Hz and zeta 0.1: a broad background term, not a close mode.)
Verdicts:
* No estimator of zeta under the real-residue model meets the reference: its profile rises
  monotonically from zeta -> 0 (the maximum of the likelihood is at the lower bound, not
  inside), so the estimate at the profile's maximum is the record's floor (7.6e-5 in
  rshape, 7.5x below the reference), and any point of the supported interval (its
  log-midpoint, a likelihood-weighted mean) is set by where the interval is cut (the
  floor, the threshold), not by the data.  Choosing one that lands on 5.67e-4 would be
  tuning to this mode.
* Only mode 1's complex residue identifies zeta (V 3360 -> 1054 for 3 parameters; its
  profile has an interior minimum at 6.6e-4, within 2x of LSCF's 5.67e-4).  No physical
  effect tried makes that phase: a delay (V 3180) and a response-side high-pass (no gain)
  do nothing; a force-side high-pass takes 57 % of the excess (V 2040) but leaves zeta at
  the floor; a close pair does not form (V 3047, its second mode a broad term on its
  bounds); a complex background (V 2810) is not the shape; even a constant (non-causal)
  phase on every channel (V 2260, 4.1 deg) gives zeta1 1.9e-4, 3x below the reference.
  The measurement-chain phase of mode 1 stays unexplained by physics rshape can offer, and
  rshape does not fit complex residues (issue 33: only physical effects), so the
  acceptance criterion (zeta within 2x) is not met for this mode.
Run from the repository root:
    python3 tests/data/ema_reference/low_band_hypotheses.py
"""
import numpy as np
from scipy.optimize import least_squares

D = np.loadtxt('tests/data/pyuff/frf_10_990.csv', delimiter=',', skiprows=1)
S = np.loadtxt('tests/data/pyuff/frf_10_990_std.csv', delimiter=',', skiprows=1)
sel = (D[:, 0] >= 10) & (D[:, 0] <= 200)
w = 2 * np.pi * D[sel, 0]
H = np.array([D[sel, 1 + 2 * j] + 1j * D[sel, 2 + 2 * j] for j in range(3)])
sig = 3 * S[sel, 1:4].T / np.sqrt(2)
s = 1j * w
T, L = 2 * np.pi, np.log


def mode(wn, z):
    return -w**2 / (wn**2 - w**2 + 2j * z * wn * w)


def cols(p, kind):
    wn1, z1, wn2, z2 = np.exp(p[:4])
    c = [np.ones_like(w) + 0j, mode(wn1, z1), mode(wn2, z2), -w**2 / (T * 300)**2 + 0j]
    if kind == 'complex1':
        c.append(1j * c[1])
    elif kind == 'cplxbg':
        c += [1j * c[0], 1j * c[3]]
    elif kind == 'pair':
        c.append(mode(np.exp(p[4]), np.exp(p[5])))
    elif kind == 'delay':
        c = [x * np.exp(-s * p[4]) for x in c]
    elif kind == 'hpF':
        c = [x * (1 + np.exp(p[4]) / s) for x in c]
    elif kind == 'phase':
        c = [x * np.exp(-1j * p[4]) for x in c]
    elif kind == 'hpX':
        c = [x * s / (s + np.exp(p[4])) for x in c]
    return c


def resid(p, kind):
    out = []
    C = np.array(cols(p, kind)).T
    for j in range(3):
        a, y = C / sig[j][:, None], H[j] / sig[j]
        ar, yr = np.vstack([a.real, a.imag]), np.concatenate([y.real, y.imag])
        x, *_ = np.linalg.lstsq(ar, yr, rcond=None)
        out.append(yr - ar @ x)
    return np.concatenate(out)


LB = [L(T * 51), L(1e-6), L(T * 141), L(1e-6)]
UB = [L(T * 52), L(0.1), L(T * 143), L(0.1)]
EXTRA = {'real': ([], [], [[]]), 'complex1': ([], [], [[]]), 'cplxbg': ([], [], [[]]),
         'delay': ([-1e-3], [1e-3], [[1e-5], [-1e-5]]),
         'hpF': ([L(T * 1e-3)], [L(T * 50)], [[L(T * f)] for f in (0.5, 2, 5, 10)]),
         'hpX': ([L(T * 1e-3)], [L(T * 50)], [[L(T * f)] for f in (0.5, 2, 5, 10)]),
         'phase': ([-0.5], [0.5], [[0.0], [0.15], [-0.15]]),
         'pair': ([L(T * 50.5), L(1e-6)], [L(T * 52.5), L(0.1)],
                  [[L(T * f), L(z)] for f in (51.2, 51.4, 51.6, 51.8) for z in (1e-4, 5e-4)])}


def fit(kind, hold=None, start=None):
    lo, hi, ext = EXTRA[kind]
    lb, ub = np.array(LB + lo), np.array(UB + hi)
    best = None
    for z1 in ([hold] if hold else [1e-4, 5e-4, 1e-3]):
        for e in ([start] if start is not None else ext):
            p0 = np.array([L(T * 51.515), L(z1), L(T * 142.176), L(3.6e-4)] + list(e))
            keep = np.ones(len(p0), bool)
            if hold:
                keep[1] = False

            def f(q):
                p = p0.copy()
                p[keep] = q
                return resid(p, kind)
            r = least_squares(f, np.clip(p0[keep], lb[keep] + 1e-9, ub[keep] - 1e-9),
                              bounds=(lb[keep], ub[keep]), x_scale='jac', max_nfev=2000)
            p = p0.copy()
            p[keep] = r.x
            v = np.sum(r.fun**2)
            if best is None or v < best[0]:
                best = (v, p)
    return best


found = {}
for kind in ['real', 'complex1', 'cplxbg', 'delay', 'hpF', 'hpX', 'phase', 'pair']:
    v, p = fit(kind)
    found[kind] = (v, p)
    z1 = np.exp(p[1])
    line = '%-8s V %.1f  zeta1 %.3g%s' % (kind, v, z1, ' (at its bound)' if z1 < 1.01e-6 else '')
    if kind == 'delay':
        line += '  tau %.3g s' % p[4]
    if kind == 'phase':
        line += '  phi %.2f deg' % np.degrees(p[4])
    if kind in ('hpF', 'hpX'):
        fc = np.exp(p[4]) / T
        line += '  f_c %.3g Hz%s' % (fc, ' (at its bound)' if fc < 1.01e-3 else '')
    if kind == 'pair':
        line += '  (modes at %.2f and %.2f Hz, zeta %.2g and %.2g)' % (
            np.exp(p[0]) / T, np.exp(p[4]) / T, z1, np.exp(p[5]))
    print(line)
for kind in ['real', 'complex1', 'hpF']:
    v0, p = found[kind]
    pts = []
    for z in [5e-5, 1.1e-4, 2.4e-4, 5.4e-4, 1.2e-3]:
        v, _ = fit(kind, hold=z, start=list(p[4:]))
        pts.append('%.2g:%.1f' % (z, v - v0))
    print('profile %s: %s' % (kind, ' '.join(pts)))
