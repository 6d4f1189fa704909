"""Issue 33, the whole-band pyfrf walk: how many modes the data hold at 3650-3700 Hz.

A local fit of /work/shared/data/pyfrf-impact/frf_h1.csv over 3550-3800 Hz (251 lines,
1 Hz apart), weights 1/sigma with the radius of tests/diagnose/diagnose_pyfrf.rs
(r = 3 eps |H|, eps = sqrt((1 - coh)/(2 * 5 coh)), sigma = r/sqrt(2)): a free complex
background (constant + linear in frequency) plus 1, 2 or 3 accelerance modes
-w^2 R/(wn^2 - w^2 + 2j z wn w), R real (rshape's modal model) or complex; (wn, z) by
bounded trust-region least squares from several starts, the linear terms by least squares
(numpy + scipy, independent of rshape).

Output (numpy 2.4.6, scipy 1.17.1; a few seconds):
    real 1 modes V 780598.2 [(3664.68, 0.00066)]
    real 2 modes V 36944.2 [(3668.44, 0.000447), (3689.34, 0.000269)]
    real 3 modes V 17589.5 [(3665.08, 0.000867), (3668.94, 0.000202), (3689.3, 0.000254)]
    real 3 modes: residues [0.603, 1.2, -0.475]
    cplx 1 modes V 773435.9 [(3665.01, 0.000613)]
    cplx 2 modes V 14435.6 [(3668.66, 0.000386), (3689.51, 0.000247)]
    cplx 3 modes V 2283.0 [(3664.64, 0.000624), (3668.96, 0.000248), (3689.46, 0.000229)]
The data hold three modes here: a sharp one at 3668.9 Hz (peak 2965 at the 3669 Hz line),
one at 3689.3 Hz, and a broader, weaker one at 3665.1 Hz (zeta 8.7e-4, half-power band
6.4 Hz, the shoulder of the 3669 Hz peak at 3665-3667 Hz) whose residue has the sign of
its neighbour's (no cancelling pair): V falls 36944 -> 17590 with it (real residues).
A single mode's least-squares optimum is the compromise 3664.7 Hz, zeta 6.6e-4.
Run from the repository root:
    python3 tests/data/ema_reference/pyfrf_3665_local.py
"""
import numpy as np
from scipy.optimize import least_squares

h = np.loadtxt('/work/shared/data/pyfrf-impact/frf_h1.csv', delimiter=',', skiprows=1)
c = np.loadtxt('/work/shared/data/pyfrf-impact/frf_h1_coherence.csv', delimiter=',',
               skiprows=1)
sel = (h[:, 0] >= 3550) & (h[:, 0] <= 3800)
w = 2 * np.pi * h[sel, 0]
H = h[sel, 1] + 1j * h[sel, 2]
g2 = np.clip(c[sel, 1], 1e-6, 1 - 1e-9)
sig = 3 * np.sqrt((1 - g2) / (g2 * 10)) * abs(H) / np.sqrt(2)
T, L = 2 * np.pi, np.log


def solve(p, nm, cplx):
    x = (w - w.mean()) / w.mean()
    cols = [np.ones_like(w) + 0j, 1j * np.ones_like(w), x + 0j, 1j * x]
    for k in range(nm):
        wn, z = np.exp(p[2 * k:2 * k + 2])
        m = -w**2 / (wn**2 - w**2 + 2j * z * wn * w)
        cols += [m, 1j * m] if cplx else [m]
    a, y = np.array(cols).T / sig[:, None], H / sig
    ar, yr = np.vstack([a.real, a.imag]), np.concatenate([y.real, y.imag])
    coef, *_ = np.linalg.lstsq(ar, yr, rcond=None)
    return yr - ar @ coef, coef


STARTS = {1: [[3664], [3670], [3689]],
          2: [[3664, 3689], [3660, 3670], [3668, 3690]],
          3: [[3664, 3669, 3690], [3666, 3669, 3690], [3662, 3668.5, 3689.5]]}
for cplx in (False, True):
    for nm in (1, 2, 3):
        best = None
        for st in STARTS[nm]:
            for z in (3e-4, 1e-3, 3e-3):
                p0 = sum([[L(T * f), L(z)] for f in st], [])
                lb = sum([[L(T * 3600), L(1e-5)] for _ in st], [])
                ub = sum([[L(T * 3750), L(0.05)] for _ in st], [])
                r = least_squares(lambda p: solve(p, nm, cplx)[0], p0, bounds=(lb, ub),
                                  x_scale='jac', max_nfev=3000)
                v = np.sum(r.fun**2)
                if best is None or v < best[0]:
                    best = (v, r.x)
        v, p = best
        modes = sorted((round(float(np.exp(p[2 * k]) / T), 2),
                        float('%.3g' % np.exp(p[2 * k + 1]))) for k in range(nm))
        print('%s %d modes V %.1f %s' % ('cplx' if cplx else 'real', nm, v, modes))
        if nm == 3 and not cplx:
            order = np.argsort(p[::2])
            res = solve(p, nm, cplx)[1][4:][order]
            print('real 3 modes: residues [%s]' % ', '.join('%.3g' % x for x in res))
