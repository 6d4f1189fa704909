"""Reference values for tests/consistency/eq8_accuracy.rs: the minimum-norm ‖Δ‖ of Boulet & Francis 1998
eq. (8), r_min = sqrt(λ_max(U (I + Φ*Φ)^{-1} U*)), U = Ñ − M̃Φ, computed with mpmath at 60
digits from the exact double inputs printed below.  Run: python3 tests/reference/eq8_mpmath.py
(prints the Rust table pasted into the test).  the seed is fixed, so the output is stable."""
import random

import mpmath as mp

mp.mp.dps = 60


def rmin(M, N, Phi):
    M, N, Phi = mp.matrix(M), mp.matrix(N), mp.matrix(Phi)
    U = N - M * Phi
    G = mp.eye(Phi.cols) + Phi.H * Phi
    X = U * mp.inverse(G) * U.H
    X = (X + X.H) / 2
    return mp.sqrt(max(mp.eighe(X)[0]))


def cnormal(rng):
    return mp.mpc(rng.gauss(0, 1), rng.gauss(0, 1))


def unitary(rng, n):
    z = mp.matrix([[cnormal(rng) for _ in range(n)] for _ in range(n)])
    q, _ = mp.qr(z)
    return q


def to_double(a):
    return [[complex(float(mp.re(a[i, j])), float(mp.im(a[i, j]))) for j in range(a.cols)]
            for i in range(a.rows)]


def case(rng, p, m, smax, smin, good_model):
    """Φ (p×m) with singular values from smax down to smin; M̃ well conditioned; Ñ either
    random O(1) or a near-exact model Ñ ≈ M̃Φ (so U is small and suffers cancellation)."""
    k = min(p, m)
    S = mp.zeros(p, m)
    for i in range(k):
        S[i, i] = smax * (smin / smax) ** (mp.mpf(i) / (k - 1)) if k > 1 else smax
    Phi = to_double(unitary(rng, p) * S * unitary(rng, m).H)
    M = to_double(mp.eye(p) * 1.5 + mp.matrix([[0.3 * cnormal(rng) for _ in range(p)] for _ in range(p)]))
    N = mp.matrix([[cnormal(rng) for _ in range(m)] for _ in range(p)])
    if good_model:
        N = mp.matrix(M) * mp.matrix(Phi) + 0.1 * N
    return M, to_double(N), Phi


def rust(a):
    rows = []
    for row in a:
        rows.append(", ".join(f"({z.real!r}, {z.imag!r})" for z in row))
    return "&[" + ", ".join("&[" + r + "]" for r in rows) + "]"


cases = []
rng = random.Random(20261123)
for p, m in [(1, 1), (1, 2), (2, 2), (2, 3), (3, 2)]:
    for smax in [1e0, 1e3, 1e6, 1e9, 1e12]:
        for good in [False, True]:
            smin = 1e-3 if min(p, m) > 1 else smax
            cases.append(case(rng, p, m, smax, smin, good))
# The panic of the issue: Φ = [1e9, 1e9 + 1j], M̃ = 1.
cases.append(([[1.0 + 0j]], [[1.0 + 0j, -1.0 + 0j]], [[1e9 + 0j, 1e9 + 1j]]))

for M, N, Phi in cases:
    m = len(Phi[0])
    W = mp.matrix([[1 if i == j else 0 for j in range(m)] for i in range(m)] + Phi)
    sv = mp.svd_c(W, compute_uv=False)
    sv = sorted(float(x) for x in sv)[::-1]
    r = rmin(M, N, Phi)
    print("    Case {")
    print(f"        m: {rust(M)},")
    print(f"        n: {rust(N)},")
    print(f"        phi: {rust(Phi)},")
    print(f"        cond_w: {sv[0] / sv[-1]:.3e},")
    print(f"        r_min: {mp.nstr(r, 20)},")
    print("    },")
