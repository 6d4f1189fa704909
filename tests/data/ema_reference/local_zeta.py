"""Issue 33: every pyuff mode's damping from a local fit, a second reference beside LSCF.

For each mode of pyuff_10_990.csv (sdypy-EMA's LSCF/LSFD), a local fit of
tests/data/pyuff/frf_10_990.csv over f0 +- max(10 Hz, 2 % f0), all three channels, weights
1/sigma with sigma = 3 std/sqrt(2) (the noise of tests/data/pyuff_rigid.toml): per channel
a free complex background (constant + linear in frequency) plus one accelerance mode
-w^2 R/(wn^2 - w^2 + 2j z wn w), R real (rshape's modal model) or complex (LSFD's).  The
profile over z (log grid, 40 points per decade; wn on a 5e-5 f0 grid, f0 +- 0.1 %, the
linear terms by least squares) gives the estimate and the 95 % likelihood-ratio interval
V - V_min <= 1.92 s, s = max(1, V_min/n) (n real data: the local lack of fit widens it).
Independent of rshape (numpy only).

Output (pyuff_local_zeta.csv): every mode the diagram stabilizes agrees with LSCF within
10 % with either residue, except 51.5 Hz, where only the complex residue fits (V 598 -> 115
for n = 120; real: zeta 4.5e-4 with the interval from the grid's bottom 3e-5 to 9.5e-4,
not identified; complex: 5.3e-4, 3.4-7.1e-4, LSCF 5.67e-4).

Why rshape offers no complex residue for it (issue 33: only physical effects): a complex
residue of a mode is non-proportional damping, and for a separated mode its imaginary share
is bounded by the damping.  With symmetric M, C >= 0, K and mass-normalized real shapes
phi_s, first-order perturbation gives psi_r = phi_r + sum_s j w_r c_sr/(w_r^2 - w_s^2)
phi_s, c_sr = phi_s' C phi_r, |c_sr| <= sqrt(c_ss c_rr), c_rr = 2 zeta_r w_r.  Mode 1
(w_1 = 324 rad/s, c_11 = 0.37) against mode 2 (142 Hz, zeta 3.7e-4, c_22 = 0.66): share
<= 2.3e-4; against a suspension mode below 5 Hz even with zeta_s = 0.5 (c_ss <= 31):
share <= 1.1e-2 (0.6 deg).  The data ask for 0.15 (9 deg), the same on all three channels:
not mode complexity, a term of the measurement that rshape's catalogue cannot name.

Run from the repository root:
    python3 tests/data/ema_reference/local_zeta.py > tests/data/ema_reference/pyuff_local_zeta.csv
The judge of tests/diagnose/diagnose_ema_reference.rs uses the complex-residue row for a
mode the stabilization diagram does not stabilize (must = 0 in pyuff_10_990.csv): LSCF's
pole there is not a reference (900.5 Hz: stable at 15 of 60 orders, zeta 5.1e-4, outside
this fit's interval 1.0-1.3e-3 with either residue).
"""
import numpy as np

D = np.loadtxt('tests/data/pyuff/frf_10_990.csv', delimiter=',', skiprows=1)
S = np.loadtxt('tests/data/pyuff/frf_10_990_std.csv', delimiter=',', skiprows=1)
R = [l.split(',') for l in open('tests/data/ema_reference/pyuff_10_990.csv')
     if not l.startswith('#')][1:]


def profile(f0, cplx):
    half = max(10.0, 0.02 * f0)
    sel = (D[:, 0] >= f0 - half) & (D[:, 0] <= f0 + half)
    w = 2 * np.pi * D[sel, 0]
    h = np.array([D[sel, 1 + 2 * j] + 1j * D[sel, 2 + 2 * j] for j in range(3)])
    sig = 3 * S[sel, 1:4].T / np.sqrt(2)
    x = (w - w.mean()) / w.mean()
    one = np.ones_like(w) + 0j

    def v(wn, z):
        tot = 0.0
        m = -w**2 / (wn**2 - w**2 + 2j * z * wn * w)
        cols = [one, 1j * one, x + 0j, 1j * x, m] + ([1j * m] if cplx else [])
        for j in range(3):
            a = np.array(cols).T / sig[j][:, None]
            y = h[j] / sig[j]
            ar = np.vstack([a.real, a.imag])
            yr = np.concatenate([y.real, y.imag])
            c, *_ = np.linalg.lstsq(ar, yr, rcond=None)
            tot += np.sum((yr - ar @ c) ** 2)
        return tot

    zs = 10 ** np.arange(np.log10(3e-5), np.log10(1e-2) + 1e-9, 1 / 40)
    fs = f0 * (1 + 5e-5 * np.arange(-20, 21))
    grid = np.array([[v(2 * np.pi * fn, z) for fn in fs] for z in zs])
    prof = grid.min(axis=1)
    i = prof.argmin()
    n = 6 * sel.sum()
    s = max(1.0, prof[i] / n)
    ok = zs[prof - prof[i] <= 1.92 * s]
    f_hat = fs[grid[i].argmin()]
    return f_hat, zs[i], ok.min(), ok.max(), prof[i], n


print('f_lscf_hz,residue,f_hz,zeta,zeta_lo95,zeta_hi95,v,n')
for r in R:
    f0 = float(r[0])
    for cplx in (False, True):
        f, z, lo, hi, vmin, n = profile(f0, cplx)
        print('%.6f,%s,%.4f,%.3e,%.3e,%.3e,%.1f,%d'
              % (f0, 'complex' if cplx else 'real', f, z, lo, hi, vmin, n))
