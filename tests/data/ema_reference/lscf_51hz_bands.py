"""Issue 33: how sharp is the LSCF reference damping of the pyuff 51.5 Hz mode?

sdypy-EMA's LSCF (orders 2..120) on tests/data/pyuff/frf_10_990.csv over three bands; for each
order, the pole nearest 51.52 Hz (within 0.3 Hz, 0 < zeta): the percentiles of its zeta over
the orders. The lines are 1 Hz apart and the half-power band 2*zeta*f is 0.02-0.06 Hz, so no
line lies inside it. Run from the repository root:
    python3 tests/data/ema_reference/lscf_51hz_bands.py
Output (sdypy-EMA 0.31.0, numpy 2.4.6):
    10-990 Hz: 53 orders, zeta pct 10/25/50/75/90: 5.45e-4 5.60e-4 5.67e-4 5.73e-4 5.84e-4
    10-200 Hz: 59 orders, zeta pct 10/25/50/75/90: 4.76e-4 5.07e-4 5.28e-4 5.60e-4 5.72e-4
    30-80 Hz: 37 orders, zeta pct 10/25/50/75/90: 3.36e-4 4.13e-4 5.20e-4 4.21e-3 7.13e-3
"""
import numpy as np
import sdypy.EMA as ema

rows = np.loadtxt("tests/data/pyuff/frf_10_990.csv", delimiter=",", skiprows=1)
f = rows[:, 0]
h = np.array([rows[:, 1 + 2 * j] + 1j * rows[:, 2 + 2 * j] for j in range(3)])
for lo, hi in [(10, 990), (10, 200), (30, 80)]:
    keep = f <= hi + 0.5
    m = ema.Model(frf=h[:, keep], freq=f[keep], lower=lo, upper=hi + 0.5,
                  pol_order_high=60, frf_form="accelerance")
    m.get_poles(method="lscf", show_progress=False)
    zs = []
    for p in m.all_poles:
        fp, zp = ema.tools.complex_freq_to_freq_and_damp(p)
        ok = (np.imag(p) > 0) & (abs(fp - 51.52) < 0.3) & (zp > 0)
        if ok.any():
            zs.append(zp[ok][np.argmin(abs(fp[ok] - 51.52))])
    pct = " ".join(f"{v:.2e}" for v in np.percentile(zs, [10, 25, 50, 75, 90]))
    print(f"{lo}-{hi} Hz: {len(zs)} orders, zeta pct 10/25/50/75/90: {pct}")
