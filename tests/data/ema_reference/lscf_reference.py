"""Independent modal references for issue 33's acceptance: LSCF stabilization + LSFD.

Runs sdypy-EMA (pip install sdypy-EMA; version printed in the output header) on two
measured accelerance FRFs and writes, per data set, the modes that are stable in the
stabilization diagram:

* ``pyfrf_20_1200.csv``: /work/shared/data/pyfrf-impact/frf_h1.csv, 20-1200 Hz (SISO);
* ``pyuff_10_990.csv``: tests/data/pyuff/frf_10_990.csv (1 output x 3 inputs, 10-990 Hz).

Stabilization (our own rule, on sdypy-EMA's LSCF poles of orders 2, 4, ..., 2*ORDERS):
a pole (positive imaginary part, 0 < zeta < 0.2, inside the band) is *stable* at order n
when order n-2 has a pole within 0.5 % in frequency and 10 % in damping.  Stable poles
are clustered by frequency (gap < 0.3 %); a cluster is a *mode* when it is stable at
least at MIN_SHARE of the orders.  Its f and zeta are the medians over the cluster; the
pole of the highest order nearest that median goes to sdypy-EMA's LSFD (lower and upper
residuals), which gives the complex modal constants A (receptance form:
H_acc = -w^2 * sum A/(jw - p) + conj).  The real residue of rshape's mode
c_o b_i / m is Re(2 j w_d A) (for a real mode Im(2 j w_d A) ~ 0; its share is written).

Columns: f_hz, zeta, stable_orders, orders, must, then per channel j: residue_j (real part of
2 j w_d A), residue_imag_share_j (|Im| / |.|).  Run from the repository root:
    python3 tests/data/ema_reference/lscf_reference.py
"""
import csv
import os
import sys

import numpy as np
import sdypy.EMA as ema
from importlib.metadata import version

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
ORDERS = 60           # pol_order_high: orders 2, 4, ..., 120
MIN_SHARE = 0.25      # written when stable at >= a quarter of the orders
MUST_SHARE = 0.5      # a mode every chain must find: stable at >= half of them
TOL_F, TOL_Z, GAP = 0.005, 0.10, 0.003


def read(path, ncol):
    rows = np.loadtxt(path, delimiter=",", skiprows=1)
    f = rows[:, 0]
    h = np.array([rows[:, 1 + 2 * j] + 1j * rows[:, 2 + 2 * j] for j in range(ncol)])
    return f, h


def stable_modes(f, h, lo, hi):
    keep = (f >= 0) & (f <= hi + 0.5)
    m = ema.Model(frf=h[:, keep], freq=f[keep], lower=lo, upper=hi + 0.5,
                  pol_order_high=ORDERS, frf_form="accelerance")
    m.get_poles(method="lscf", show_progress=False)
    prev = None
    pts = []  # (f, zeta, order index, pole index)
    for k, poles in enumerate(m.all_poles):
        fp, zp = ema.tools.complex_freq_to_freq_and_damp(poles)
        ok = (np.imag(poles) > 0) & (zp > 0) & (zp < 0.2) & (fp >= lo) & (fp <= hi)
        cur = [(fp[i], zp[i], i) for i in np.flatnonzero(ok)]
        if prev is not None:
            for (fi, zi, i) in cur:
                if any(abs(fi - fj) < TOL_F * fj and abs(zi - zj) < TOL_Z * zj
                       for (fj, zj, _) in prev):
                    pts.append((fi, zi, k, i))
        prev = cur
    n_orders = len(m.all_poles)
    pts.sort()
    clusters, cur = [], []
    for p in pts:
        if cur and p[0] - cur[-1][0] > GAP * cur[-1][0]:
            clusters.append(cur)
            cur = []
        cur.append(p)
    if cur:
        clusters.append(cur)
    modes = []
    for c in clusters:
        orders = {p[2] for p in c}
        if len(orders) < MIN_SHARE * n_orders:
            continue
        fm = float(np.median([p[0] for p in c]))
        zm = float(np.median([p[1] for p in c]))
        best = max(c, key=lambda p: (p[2], -abs(p[0] - fm)))
        modes.append((fm, zm, len(orders), n_orders, best[2], best[3]))
    m.pole_ind = np.array([[b, i] for (*_, b, i) in modes], dtype=int).reshape(-1, 2)
    m.get_constants(method="lsfd", whose_poles="own", f_upper=hi)
    poles = np.array([m.all_poles[b][i] for (*_, b, i) in modes])
    return modes, poles, m.A


def write(name, modes, poles, A, nch, src):
    out = os.path.join(HERE, name)
    with open(out, "w", newline="") as fh:
        fh.write(f"# sdypy-EMA {version('sdypy-EMA')} LSCF (orders 2..{2 * ORDERS}) + LSFD on {src}\n")
        w = csv.writer(fh)
        w.writerow(["f_hz", "zeta", "stable_orders", "orders", "must"]
                   + sum([[f"residue_{j + 1}", f"residue_imag_share_{j + 1}"] for j in range(nch)], []))
        for r, (fm, zm, ns, no, *_), p in zip(range(len(modes)), modes, poles):
            wd = abs(p.imag)
            row = [f"{fm:.6f}", f"{zm:.6e}", ns, no, int(ns >= MUST_SHARE * no)]
            for j in range(nch):
                z = 2j * wd * A[j, r]
                row += [f"{z.real:.6e}", f"{abs(z.imag) / max(abs(z), 1e-300):.3f}"]
            w.writerow(row)
    print(open(out).read())


f, h = read("/work/shared/data/pyfrf-impact/frf_h1.csv", 1)
modes, poles, A = stable_modes(f, h, 20.0, 1200.0)
write("pyfrf_20_1200.csv", modes, poles, A, 1, "pyfrf-impact frf_h1.csv, 20-1200 Hz")

f, h = read(os.path.join(ROOT, "tests/data/pyuff/frf_10_990.csv"), 3)
modes, poles, A = stable_modes(f, h, 10.0, 990.0)
write("pyuff_10_990.csv", modes, poles, A, 3, "tests/data/pyuff/frf_10_990.csv, 10-990 Hz")
