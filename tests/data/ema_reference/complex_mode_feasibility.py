"""Issue 33, task disc33x: would a complex-mode effect (a residue phase per channel on a
mode already in the model) hold up on the pyuff beam over the whole band, and is the phase
of the 51.5 Hz mode the mode's own or a phase shared by every mode (a measurement chain)?

Independent of rshape (numpy + scipy).  Data: tests/data/pyuff/frf_10_990.csv, 10-990 Hz,
981 lines x 3 channels, weights 1/sigma, sigma = 3 std/sqrt(2) (tests/data/pyuff_rigid.toml's
noise).  Model (accelerance): per channel a real mass line, the seven modes of the LSCF
reference (pyuff_10_990.csv) with real residues, and a real upper residual -w^2 D; linear
terms by least squares per channel (variable projection), the 14 (ln w_n, ln zeta) by
bounded trust-region least squares.  The complex mode k: its term rho/d(s) becomes
(rho + sigma s/w_n)/d(s) -- the conjugate pair R/(s-lam) + conj(R)/(s-conj(lam)) with a
complex residue R (Ewins, Modal Testing, 2nd ed., sec. 2.7 / 4.4: non-proportional damping)
-- so one more linear column per channel, (s/w_n) times the mode's term; the residue's phase
at the resonance is phi = atan2(sigma, rho).

Printed: the real-residue fit (V, zeta of every mode), then for each mode k made complex:
dV, misfit_rms change, zeta_k, and per channel phi with its sigma (delta method from the
linear least squares' covariance, nonlinear parameters held), plus whether the phases are
identified (|phi|/sigma_phi >= 3, i.e. relative sigma <= 1/3 on every channel).
Two forms of the complex mode's extra column (see `columns`): 's', the causal complex mode
of the receptance (what an rshape effect 'complex mode' would write: a numerator s-term),
and 'a', LSFD's complex residue on the accelerance itself.  'a' is 's' plus a term c*s on
the accelerance (c/s on the receptance) whose c is tied to sigma: with the real residue's
column free, span{s^2/d, s w_n/d} = span{s^2/d, s/w_n - s^3/(w_n d)}.

Output (numpy 2.4.6, scipy 1.17.1; several minutes of CPU; form 'a' modes 3-7 from a second
run with FORMS=a MODES=3,4,5,6,7):
  real residues: V 4568.4  misfit_rms 0.881
    zeta: 52 Hz 1e-06 142 Hz 0.000386 279 Hz 0.00016 460 Hz 0.000197 687 Hz 0.000167
          901 Hz 0.00107 959 Hz 0.000138
  form s (mode: dV, misfit_rms change, zeta of that mode, phases deg per channel, identified)
    1  51.5 Hz  141.9  -1.6 %  1e-06 (floor)  -0.1+-0.0 -0.1+-0.0 -0.3+-0.0  True
    2 142.2 Hz   74.3  -0.8 %  3.97e-4        +0.2+-0.1 +0.3+-0.1 +3.1+-0.6  True
    3 278.7 Hz   63.5  -0.7 %  1.70e-4        -0.2+-0.1 -0.8+-0.2 -1.1+-0.2  False
    4 460.4 Hz  102.1  -1.1 %  1.96e-4        -1.0+-0.1 -0.6+-0.3 -1.0+-0.2  False
    5 687.2 Hz  195.3  -2.2 %  1.63e-4        -1.0+-0.2 -1.4+-0.2 -1.5+-0.2  True
    6 900.5 Hz   15.7  -0.2 %  1.05e-3        -48+-15   +47+-15   -2.5+-3.1  False
    7 958.5 Hz  140.5  -1.5 %  1.37e-4        -1.1+-0.2 -1.5+-0.2 -1.7+-0.2  True
  form a
    1  51.5 Hz 2961.0 -40.7 %  6.16e-4        +10.2+-0.3 +9.4+-0.3 +9.9+-0.3  True
    2 142.2 Hz   72.8  -0.8 %  4.05e-4        -1.0+-0.2 -1.5+-0.2 -2.4+-0.6  True
    3 278.7 Hz  118.3  -1.3 %  1.71e-4        +0.1+-0.2 +1.0+-0.2 +2.2+-0.2  False
    4 460.4 Hz  143.5  -1.6 %  1.95e-4        +2.0+-0.2 +0.3+-0.3 +0.7+-0.2  False
    5 687.2 Hz  257.5  -2.9 %  1.62e-4        +1.0+-0.2 +1.5+-0.2 +1.9+-0.2  True
    6 900.5 Hz   17.7  -0.2 %  1.05e-3        +49+-15   -48+-14   +3.8+-3.1  False
    7 958.5 Hz   78.7  -0.9 %  1.36e-4        +1.0+-0.2 +0.8+-0.2 +1.1+-0.2  True
Verdicts:
* The causal complex mode ('s', the effect issue 33 asked to build) does not identify the
  51.5 Hz damping over the whole band: zeta stays at the floor and the phase is -0.1..-0.3
  deg (on 10-200 Hz alone it reaches zeta 3.4e-4, V 3360 -> 2071: its growing c*s tail
  above the mode is what the band above refuses).  Yet it passes the admissibility rules
  (phases identified, misfit_rms down >= 1 %) on modes 1, 5 and 7 with 0.1-1.7 deg: a term
  that fits small misfits everywhere without the physics the criterion wants.  Not built.
* Only LSFD's form ('a') identifies zeta 6.16e-4 (within 2x of LSCF's 5.67e-4; misfit
  -40.7 %) with the same +10 deg on all three channels (+-0.3) and 1-2 deg on the other
  modes: a phase specific to that mode, not a chain phase shared by every mode.  But that
  form is the causal term plus c*s on the accelerance (c/s on the receptance), the
  integrator rshape refuses as implausible on an accelerance (no structural term gives
  it), and it too passes the rules on mode 5 (+1..+1.9 deg, -2.9 %).
Run from the repository root: python3 tests/data/ema_reference/complex_mode_feasibility.py
"""
import os
import numpy as np
from scipy.optimize import least_squares

D = np.loadtxt('tests/data/pyuff/frf_10_990.csv', delimiter=',', skiprows=1)
S = np.loadtxt('tests/data/pyuff/frf_10_990_std.csv', delimiter=',', skiprows=1)
w = 2 * np.pi * D[:, 0]
H = np.array([D[:, 1 + 2 * j] + 1j * D[:, 2 + 2 * j] for j in range(3)])
sig = 3 * S[:, 1:4].T / np.sqrt(2)
s = 1j * w
T = 2 * np.pi
REF = [51.517197, 142.176439, 278.662584, 460.394851, 687.165968, 900.521561, 958.528835]
ZREF = [5.67e-4, 3.67e-4, 1.91e-4, 1.88e-4, 1.66e-4, 5.07e-4, 1.32e-4]
NM = len(REF)


def mode(wn, z):
    return -w**2 / (wn**2 - w**2 + 2j * z * wn * w)


def columns(p, cplx):
    c = [np.ones_like(w) + 0j]
    for k in range(NM):
        c.append(mode(np.exp(p[2 * k]), np.exp(p[2 * k + 1])))
    c.append(-w**2 / (T * 1000)**2 + 0j)
    for k in cplx:
        wn = np.exp(p[2 * k])
        # 's': the receptance's complex mode (rho + sigma s/w_n)/d(s), times s^2;
        # 'a': a complex residue of the accelerance's own pole-residue expansion (LSFD's
        # model on these data), sigma s w_n/d(s): the 's' term plus a receptance 1/s term.
        c.append(s / wn * c[1 + k] if FORM == 's' else wn / s * c[1 + k])
    return np.array(c).T


def solve(p, cplx):
    C = columns(p, cplx)
    out, coef, covs = [], [], []
    for j in range(3):
        a, y = C / sig[j][:, None], H[j] / sig[j]
        ar, yr = np.vstack([a.real, a.imag]), np.concatenate([y.real, y.imag])
        x, *_ = np.linalg.lstsq(ar, yr, rcond=None)
        out.append(yr - ar @ x)
        coef.append(x)
        covs.append(np.linalg.pinv(ar.T @ ar))
    return np.concatenate(out), coef, covs


def fit(cplx, p0):
    lb = np.array([v for k in range(NM) for v in (np.log(T * REF[k] * 0.995), np.log(1e-6))])
    ub = np.array([v for k in range(NM) for v in (np.log(T * REF[k] * 1.005), np.log(0.1))])
    best = None
    for scale in (1.0, 0.5, 2.0):
        q0 = p0.copy()
        q0[1::2] += np.log(scale)
        r = least_squares(lambda q: solve(q, cplx)[0], np.clip(q0, lb + 1e-9, ub - 1e-9),
                          bounds=(lb, ub), x_scale='jac', max_nfev=3000)
        v = np.sum(r.fun**2)
        if best is None or v < best[0]:
            best = (v, r.x)
    return best


n = 3 * len(w)
for FORM in os.environ.get('FORMS', 's,a').split(','):
  print('form', FORM)
  p0 = np.array([v for k in range(NM) for v in (np.log(T * REF[k]), np.log(ZREF[k]))])
  v0, p_real = fit([], p0)
  print('real residues: V %.1f  misfit_rms %.3f' % (v0, np.sqrt(v0 / 2 / n)))
  print('  zeta: ' + ' '.join('%.0f Hz %.3g' % (np.exp(p_real[2 * k]) / T, np.exp(p_real[2 * k + 1]))
                              for k in range(NM)))
  for k in [int(x) - 1 for x in os.environ.get('MODES', '1,2,3,4,5,6,7').split(',')]:
      v, p = fit([k], p_real)
      _, coef, covs = solve(p, [k])
      phis = []
      for j in range(3):
          a, b = coef[j][1 + k], coef[j][-1]
          ca = covs[j]
          ia, ib = 1 + k, len(coef[j]) - 1
          # phi = atan2(b, a): gradient (-b, a)/(a^2 + b^2)
          g = np.zeros(len(coef[j]))
          g[ia], g[ib] = -b / (a * a + b * b), a / (a * a + b * b)
          phis.append((np.degrees(np.arctan2(b, a)), np.degrees(np.sqrt(g @ ca @ g))))
      # the phase as the residue's shift: fold to (-90, 90] so a sign of rho does not count
      fold = [((ph + 90) % 180) - 90 for ph, _ in phis]
      ident = all(abs(f) >= 3 * sd for f, (_, sd) in zip(fold, phis))
      print('complex mode %d (%.1f Hz): dV %.1f  misfit_rms %.3f -> %.3f (%.1f %%)  zeta %.3g (real %.3g)  '
            'phase deg %s  identified %s' % (
                k + 1, REF[k], v0 - v, np.sqrt(v0 / 2 / n), np.sqrt(v / 2 / n),
                100 * (1 - np.sqrt(v / v0)), np.exp(p[2 * k + 1]), np.exp(p_real[2 * k + 1]),
                ', '.join('%+.1f+-%.1f' % (f, sd) for f, (_, sd) in zip(fold, phis)), ident))
