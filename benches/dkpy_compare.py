"""Issue 38: rshape `fit --order N` against dkpy's `fit_uncertainty_weight` (log-Chebyshev
overbounding fit by cvxpy bisection) on the 24 envelopes of the random sweep.

Write the envelopes first (release build):

    RSHAPE_SWEEP_CSV=/tmp/sweep cargo test --release --test fit fit_sweep:: -- --ignored --nocapture

(or any directory of `omega_rad_s,r_min` CSV files), then, with dkpy installed
(`pip install dkpy`):

    python3 benches/dkpy_compare.py /tmp/sweep target/release/rshape [ORDER]

Prints per envelope: points, seconds and max log10 |W|/r_min for both, and dkpy's worst dip
below the envelope (negative: the fit is not an overbound there).  rshape's time is the
whole process (`rshape fit --envelope F --order N`), dkpy's the call alone.
"""

import glob
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def main():
    folder, binary = sys.argv[1], sys.argv[2]
    order = int(sys.argv[3]) if len(sys.argv) > 3 else 6
    import control
    import dkpy

    files = sorted(glob.glob(os.path.join(folder, "*.csv")))
    tot_r = tot_d = 0.0
    slower = tighter = dips = 0
    print(f"{'file':10} {'pts':>5} {'rshape s':>9} {'max':>7} {'dkpy s':>8} {'max':>7} {'dip':>8}")
    for f in files:
        data = np.loadtxt(f, delimiter=",", skiprows=1)
        omega, rmin = data[:, 0], data[:, 1]
        out = tempfile.mkdtemp()
        t = time.perf_counter()
        subprocess.run(
            [binary, "fit", "--envelope", f, "--order", str(order), "--out", out],
            check=True,
            capture_output=True,
        )
        tr = time.perf_counter() - t
        with open(os.path.join(out, "r.json")) as fh:
            rmax = json.load(fh)["certificate"]["max_log10_ratio"]
        resp = rmin.astype(complex)[:, None, None]
        t = time.perf_counter()
        w = dkpy.fit_uncertainty_weight(resp, omega, order)
        td = time.perf_counter() - t
        mag = np.abs(control.frequency_response(w, omega).complex).reshape(-1)
        ratio = np.log10(mag / rmin)
        dmax, dmin = ratio.max(), ratio.min()
        tot_r += tr
        tot_d += td
        slower += tr > td
        tighter += rmax < dmax
        dips += dmin < -1e-6
        print(
            f"{os.path.basename(f):10} {len(omega):5} {tr:9.2f} {rmax:7.3f} {td:8.2f} "
            f"{dmax:7.3f} {dmin:8.4f}"
        )
    print(
        f"total: rshape {tot_r:.1f} s, dkpy {tot_d:.1f} s; rshape slower on {slower} of "
        f"{len(files)}, tighter on {tighter}; dkpy below the envelope on {dips}"
    )


if __name__ == "__main__":
    main()
