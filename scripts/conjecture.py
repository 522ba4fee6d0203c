"""The paper's conjecture for chains of n identical free bodies, tested for n = 2..10.

    python scripts/conjecture.py                         # everything (about 6 minutes on 2 cores)
    python scripts/conjecture.py --plot docs/figures     # the same, and the figures docs/figures/conjecture-*.png
    python scripts/conjecture.py --quick                 # small samples (under 30 s; the test suite runs this)

The paper (after its (33), (34)) concludes that if the rotation of one free body with liquid
about its centre of mass is unstable, then a free chain of n identical such bodies (c_k = c,
s_k = 2c, one spin rate) is unstable too, and guesses this for every n. The script checks
(docs/conjecture.md has the proofs and the numbers):

1. **Ideal joints, every n.** The free chain's lever-arm Gram matrix S = J^T m J of identical bodies
   has the eigenvalues nu_j = m c^2 cot^2(j pi / 2n), j = 1..n (nu_n = 0). Its characteristic
   polynomial is checked against the closed form x R_n(x) / (2n) in exact rational arithmetic.
2. **The factorisation, exactly.** For random short-decimal parameters with one or two liquid
   modes and n = 2..10, the chain's p(lambda) is built exactly (python-flint, fraction-free
   determinant over Q[lambda], independent of the engine) and checked to equal
   sum_k e_k(S) (lambda^2 Q)^k p_1^(n-k), i.e. prod_j p_1(lambda; A + nu_j); and p_1, the single
   body's polynomial, divides it exactly.
3. **A counterexample family.** One dyadic body, unstable alone, whose chains of n = 2..10
   copies with stiff joints are stable: exact N_c (engine-independent) and the engine's, and
   every stiffness where the chain's N_c changes.
4. **Elastic joints: a certified random search.** Single bodies that are unstable are drawn over
   wide ranges; chains of n identical copies with random joint stiffnesses are decided by the
   engine (certified N_c). A chain with N_c = 0 is a counterexample to the conjecture. Counts are
   broken down by the dimensionless stiffness q = K / (A omega^2) and compared with the
   rigid-chain limit (a single body with A + m c^2 (n^2 - 1) / 3).
5. **Exact rechecks.** Counterexamples (and controls) from the search are recomputed exactly with
   the independent builder of step 2.
6. **Maps** (``--plot DIR``): ``conjecture-fraction.png`` (counterexample fraction against
   q = K / (A omega^2)), ``conjecture-K-omega.png`` (atlas stiffness x spin rate, n = 3) and
   ``conjecture-A-K.png`` (atlases inertia x stiffness, n = 2, 3, 5, 10), all from the engine.

Every parameter that reaches the engine is a short dyadic number (5 significant bits), so the
engine and the exact recheck see the very same rational point.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from fractions import Fraction
from pathlib import Path

import flint
import numpy as np

from stabmap.kernels import layout
from stabmap.systems.gyroscopes import decide as _decide
from stabmap.systems.gyroscopes.outputs import DECIDED_BY
from stabmap.systems.gyroscopes.paper import complex_pairs, det
from stabmap.systems.gyroscopes.points import PointArrays

#: Sampled region of the random search (docs/conjecture.md, "The search with joints").
RANGES = {
    "m": (0.1, 10.0),  # kg, log-uniform
    "c": (0.05, 1.0),  # m, log-uniform (s = 2c)
    "a": (1e-2, 1e2),  # A / (m c^2), log-uniform
    "C/A": (0.0, 1.95),  # uniform; C <= 2A for any rigid body
    "sumE/A": (0.0, 0.9),  # uniform; the liquid's modes never exceed the frozen inertia
    "|kappa|": (1.05, 10.0),  # log-uniform; |kappa| > 1 for every cavity (docs/cavities.md)
    "P(kappa>0)": 0.75,  # retrograde modes (kappa > 0) are the ones that destabilise
    "omega": (0.1, 1000.0),  # rad/s, log-uniform
    "q": (1e-5, 1e5),  # K / (A omega^2), log-uniform: joint stiffness against the body's own inertia
    "r": (0.25, 4.0),  # K_j = q r_j A omega^2 for the unequal-joint half of the sample
}
BITS = 5  # significant bits kept in every sampled parameter
Q_BINS = np.logspace(-5, 5, 11)  # one decade per bin of q = K / (A omega^2)
SOFT = 0.02  # a reference level of q / mu^2 for one table (not a threshold: counterexamples exist below it)

# One dyadic counterexample family (docs/conjecture.md): the single body (A, C, E, kappa) is unstable
# for 1 < A < 5 whatever omega, m and c; a chain of n >= 2 copies with stiff joints is stable.
FAMILY = {"m": 2, "c": 1, "A": 4, "C": 1, "omega": 1, "E": (Fraction(1, 2),), "kappa": (4,), "K": 1024}


# ----------------------------------------------------------------------------------------------
# Exact arithmetic (python-flint), independent of the engine's own exact path
# ----------------------------------------------------------------------------------------------
def _q(x) -> flint.fmpq:
    """An exact fmpq from an int, Fraction, decimal string or float (floats at their binary value)."""
    f = Fraction(x) if not isinstance(x, float) else Fraction(*x.as_integer_ratio())
    return flint.fmpq(f.numerator, f.denominator)


def _qpoly(coeffs) -> flint.fmpq_poly:
    """fmpq_poly from ascending coefficients."""
    return flint.fmpq_poly([_q(x) for x in coeffs])


LAM = flint.fmpq_poly([0, 1])


def gram_matrix(n: int) -> flint.fmpq_mat:
    """S / (m c^2) for n identical free bodies (c_k = c, s_k = 2c), built from J as docs/model.md defines it."""
    # Fixed-frame lever arms in units of c: y_k = c (theta_k + 2 sum_{i<k} theta_i).
    J = [[2 if i < k else (1 if i == k else 0) for i in range(n)] for k in range(n)]
    # Free support, equal masses: subtract every column's plain mean so the centre of mass stays put.
    Jq = [[flint.fmpq(J[k][i]) - flint.fmpq(sum(J[j][i] for j in range(n)), n) for i in range(n)] for k in range(n)]
    S = flint.fmpq_mat(n, n)
    for i in range(n):
        for j in range(n):
            S[i, j] = sum((Jq[k][i] * Jq[k][j] for k in range(n)), flint.fmpq(0))
    return S


def gram_charpoly_closed_form(n: int) -> flint.fmpq_poly:
    """x R_n(x) / (2n) with R_n(x) = sum_k (-1)^k binom(2n, 2k+1) x^(n-1-k).

    sin(2n t) / sin(t)^(2n) = cot(t) R_n(cot^2 t), so the roots of R_n are cot^2(j pi / 2n),
    j = 1..n-1, and x R_n(x) / (2n) is monic with the roots nu_j / (m c^2), j = 1..n.
    """
    R = [0] * n
    for k in range(n):
        R[n - 1 - k] = (-1) ** k * math.comb(2 * n, 2 * k + 1)
    return flint.fmpq_poly([0] + R) / (2 * n)


def nu_closed_form(n: int) -> list[float]:
    """nu_j / (m c^2) = cot^2(j pi / 2n), j = 1..n (the last is 0: the single body's own factor)."""
    return [0.0 if j == n else 1.0 / math.tan(j * math.pi / (2 * n)) ** 2 for j in range(1, n + 1)]


def liquid_parts(omega, E, kappa):
    """(Q, R) with Q = prod_l (lam + beta_l), R = sum_l E_l prod_{j != l} (lam + beta_j), beta = omega - 2 omega / kappa."""
    w = _q(omega)
    betas = [w - 2 * w / _q(k) for k in kappa]
    Q, R = flint.fmpq_poly([1]), flint.fmpq_poly([0])
    for beta, e in zip(betas, E):
        R = R * (LAM + beta) + _q(e) * Q
        Q = Q * (LAM + beta)
    return Q, R


def single_poly(A, C, omega, E=(), kappa=()) -> flint.fmpq_poly:
    """p_1 of one free body about its centre of mass: Q (A lam^2 + C omega lam) - lam^2 (lam + omega) R."""
    Q, R = liquid_parts(omega, E, kappa)
    w = _q(omega)
    return Q * (_q(A) * LAM**2 + _q(C) * w * LAM) - LAM**2 * (LAM + w) * R


def chain_poly(n: int, m, c, A, C, omega, E=(), kappa=(), joints=()) -> flint.fmpq_poly:
    """Exact p(lam) = det(diag(Q) Phi) of n identical free bodies (c_k = c, s_k = 2c), docs/model.md.

    ``joints`` are K_1..K_{n-1} (padded with zeros). Built here from J, M, G, K directly, with a
    fraction-free determinant, so that it shares no code with the engine's exact path
    (stabmap/systems/gyroscopes/exact.py interpolates determinants at integer points instead; stabmap.systems.gyroscopes.paper's Bareiss
    determinant is shared with the paper's printed forms, which start from other matrices).
    """
    Kj = [_q(k) for k in joints] + [flint.fmpq(0)] * (n - 1 - len(joints))
    M = gram_matrix(n) * (_q(m) * _q(c) ** 2)
    Q, R = liquid_parts(omega, E, kappa)
    w = _q(omega)
    Kmat = [[flint.fmpq(0)] * n for _ in range(n)]
    for j, k in enumerate(Kj):  # joint j+1 joins bodies j and j+1 (0-based)
        Kmat[j][j] += k
        Kmat[j + 1][j + 1] += k
        Kmat[j][j + 1] -= k
        Kmat[j + 1][j] -= k
    rows = []
    for i in range(n):
        row = []
        for j in range(n):
            entry = Q * (LAM**2 * M[i, j] - Kmat[i][j])
            if i == j:
                entry += Q * (_q(A) * LAM**2 + _q(C) * w * LAM) - LAM**2 * (LAM + w) * R
            row.append(entry)
        rows.append(row)
    return det(rows)


def factorised_poly(n: int, m, c, A, C, omega, E=(), kappa=()) -> flint.fmpq_poly:
    """sum_k e_k(S) (lam^2 Q)^k p_1^(n-k) = det(p_1 I + lam^2 Q S) = prod_j p_1(lam; A + nu_j).

    e_k(S) = (m c^2)^k e_k(S / m c^2) come from the exact characteristic polynomial of the Gram
    matrix, so this is the ideal-joint factorisation written without the irrational nu_j.
    """
    cp = gram_matrix(n).charpoly()  # det(x I - S~) = sum_k (-1)^k e_k x^(n-k)
    coeffs = cp.coeffs()  # ascending
    Q, _ = liquid_parts(omega, E, kappa)
    p1 = single_poly(A, C, omega, E, kappa)
    scale = _q(m) * _q(c) ** 2
    out = flint.fmpq_poly([0])
    for k in range(n + 1):
        e_k = (-1) ** k * coeffs[n - k] * scale**k
        out += e_k * (LAM**2 * Q) ** k * p1 ** (n - k)
    return out


# ----------------------------------------------------------------------------------------------
# The engine
# ----------------------------------------------------------------------------------------------
def chain_points(n: int, prm: dict, joints: np.ndarray | None = None) -> PointArrays:
    """The engine's per-point arrays for identical free chains.

    Parameters
    ----------
    n : int
        Number of bodies (1: the single free body about its centre of mass).
    prm : dict
        ``m, c, A, C, omega`` of shape (N,), ``E, kappa`` of shape (N, L).
    joints : ndarray, optional
        (N, n-1) stiffnesses K_1..K_{n-1}; zeros (ideal joints) if omitted.
    """
    N, L = prm["E"].shape
    body = np.empty((N, n, 6))
    for col, key in enumerate(("m", "A", "C", "c")):
        body[:, :, col] = prm[key][:, None]
    body[:, :, layout.S] = 2.0 * prm["c"][:, None]  # s = 2c, exact in binary
    body[:, :, layout.OMEGA] = prm["omega"][:, None]
    joint = np.zeros((N, n))
    if joints is not None and n > 1:
        joint[:, 1:] = joints
    E = np.ascontiguousarray(np.repeat(prm["E"][:, None, :], n, axis=1))
    kappa = np.ascontiguousarray(np.repeat(prm["kappa"][:, None, :], n, axis=1))
    return PointArrays(body, joint, np.zeros(N), E, kappa, np.full(n, L, dtype=np.int64), True)


def engine_counts(n: int, prm: dict, joints: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Certified (N_c, decided_by) of identical free chains (arguments as :func:`chain_points`)."""
    return _decide.decide(chain_points(n, prm, joints))


def engine_parallel(n: int, prm: dict, joints: np.ndarray | None, pool, chunk: int) -> tuple[np.ndarray, np.ndarray]:
    """``engine_counts`` over chunks on a process pool (the exact fallback holds the GIL, so threads would not help).

    The workers run ``stabmap.systems.gyroscopes.decide.decide`` itself, which pickles by reference whether this
    file runs as a script or through ``runpy``.
    """
    N = prm["E"].shape[0]
    if pool is None or N <= chunk:
        return engine_counts(n, prm, joints)
    bounds = [(a, min(a + chunk, N)) for a in range(0, N, chunk)]
    jobs = [chain_points(n, {k: v[a:b] for k, v in prm.items()}, None if joints is None else joints[a:b]) for a, b in bounds]
    parts = list(pool.map(_decide.decide, jobs))
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


# ----------------------------------------------------------------------------------------------
# Sampling
# ----------------------------------------------------------------------------------------------
def dyadic(x, bits: int = BITS):
    """Round positive or negative x to ``bits`` significant bits (exact short binary numbers)."""
    x = np.asarray(x, dtype=np.float64)
    mant, expo = np.frexp(x)
    return np.ldexp(np.round(mant * 2.0**bits), expo - bits)


def _loguniform(rng, lo, hi, size):
    return np.exp(rng.uniform(math.log(lo), math.log(hi), size))


def sample_bodies(rng, N: int, L: int) -> dict:
    """N bodies (with their m, c, omega) over RANGES, every parameter a short dyadic number."""
    m = dyadic(_loguniform(rng, *RANGES["m"], N))
    c = dyadic(_loguniform(rng, *RANGES["c"], N))
    A = dyadic(_loguniform(rng, *RANGES["a"], N) * m * c * c)
    C = dyadic(rng.uniform(*RANGES["C/A"], N) * A)
    total = rng.uniform(*RANGES["sumE/A"], N) * A
    share = rng.dirichlet(np.ones(L), N) if L > 1 else np.ones((N, 1))
    E = dyadic(total[:, None] * share)
    sign = np.where(rng.random((N, L)) < RANGES["P(kappa>0)"], 1.0, -1.0)
    kappa = dyadic(sign * _loguniform(rng, *RANGES["|kappa|"], (N, L)))
    omega = dyadic(_loguniform(rng, *RANGES["omega"], N))
    ok = (C > 0) & np.all(E > 0, axis=1)  # rounding to 5 bits never makes them 0, but say why we keep them
    return {key: v[ok] for key, v in dict(m=m, c=c, A=A, C=C, omega=omega, E=E, kappa=kappa).items()}


def unstable_bodies(rng, N: int, L: int, pool, chunk: int) -> tuple[dict, int, int]:
    """N bodies whose single free rotation is unstable (rejection sampling), how many of those were found, how many drawn."""
    kept, drawn = [], 0
    while sum(len(b["A"]) for b in kept) < N:
        batch = sample_bodies(rng, max(4 * N, 2000), L)
        nc, _ = engine_parallel(1, batch, None, pool, chunk)
        drawn += len(nc)
        kept.append({k: v[nc > 0] for k, v in batch.items()})
    out = {k: np.concatenate([b[k] for b in kept])[:N] for k in kept[0]}
    unstable = sum(len(b["A"]) for b in kept)
    return out, unstable, drawn


def sample_joints(rng, prm: dict, n: int) -> np.ndarray:
    """Joint stiffnesses K_j = q r_j A omega^2, shape (N, n-1); r_j = 1 (equal joints) for the first half."""
    N = len(prm["A"])
    q = _loguniform(rng, *RANGES["q"], N)
    r = _loguniform(rng, *RANGES["r"], (N, n - 1))
    r[: N // 2] = 1.0
    return dyadic(q[:, None] * r * (prm["A"] * prm["omega"] ** 2)[:, None])


def _times_linear(P: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rows of ascending coefficients times (lambda + b); the top coefficient must be free (zero)."""
    out = P * b
    out[:, 1:] += P[:, :-1]
    return out


def instability_margin(prm: dict) -> np.ndarray:
    """max |Im lambda| / |lambda| over the single body's roots (float eigenvalues: a diagnostic, not a proof).

    The roots of p_1 scale with omega, so this depends on A, C, E, kappa only. It measures how far the
    single body is from its stability boundary: 0 on it, about 1 for a violently unstable body.
    """
    N, L = prm["E"].shape
    w = prm["omega"]
    beta = w[:, None] - 2.0 * w[:, None] / prm["kappa"]
    # p_1 / lambda = Q (A lambda + C omega) - lambda (lambda + omega) R, coefficients ascending, per point.
    Q = np.zeros((N, L + 1))
    Q[:, 0] = 1.0
    R = np.zeros((N, L + 1))
    for l in range(L):
        b = beta[:, l : l + 1]
        R = _times_linear(R, b) + prm["E"][:, l : l + 1] * Q  # uses the old Q, as liquid_parts does
        Q = _times_linear(Q, b)
    r = np.zeros((N, L + 2))
    r[:, :-1] += Q * (prm["C"] * w)[:, None]
    r[:, 1:] += Q * prm["A"][:, None]
    r[:, 1:] -= R * w[:, None]
    r[:, 2:] -= R[:, :-1]
    # Roots from the companion matrices, all points at once (degree L + 1).
    lead = r[:, -1:]
    comp = np.zeros((N, L + 1, L + 1))
    comp[:, 1:, :-1] = np.eye(L)
    comp[:, :, -1] = -r[:, :-1] / lead
    roots = np.linalg.eigvals(comp)
    return np.max(np.abs(roots.imag) / np.maximum(np.abs(roots), 1e-300), axis=1)


def rigid_inertia(prm: dict, n: int):
    """A + m c^2 (n^2 - 1) / 3: per body, the inertia of the whole chain frozen straight about its centre of mass."""
    return prm["A"] + prm["m"] * prm["c"] ** 2 * (n * n - 1) / 3.0


def stiffness_measures(prm: dict, K: np.ndarray, n: int) -> dict:
    """Dimensionless stiffnesses from the geometric mean of the joints: against A, m c^2 and the rigid chain's inertia."""
    Kg = np.exp(np.mean(np.log(K), axis=1))
    w2 = prm["omega"] ** 2
    return {"q": Kg / (prm["A"] * w2), "k": Kg / (prm["m"] * prm["c"] ** 2 * w2), "kr": Kg / (rigid_inertia(prm, n) * w2)}


# ----------------------------------------------------------------------------------------------
# The steps
# ----------------------------------------------------------------------------------------------
def _fr(x) -> Fraction:
    """Fraction of a float at its exact binary value."""
    return Fraction(*float(x).as_integer_ratio())


def step_gram(ns) -> list[dict]:
    """Step 1: eigenvalues of S / (m c^2) and the exact check of their closed form."""
    print("\n## 1. Ideal joints: nu_j / (m c^2) = cot^2(j pi / 2n), the eigenvalues of S = J^T m J / (m c^2)\n")
    print("| n | charpoly == x R_n(x)/(2n) (exact) | nu_j / (m c^2), j = 1..n | paper's F~ roots (n-1)/n - nu_j/(m c^2) |")
    print("|---|---|---|---|")
    rows = []
    for n in ns:
        S = gram_matrix(n)
        exact_ok = S.charpoly() == gram_charpoly_closed_form(n)
        numeric = sorted(np.linalg.eigvalsh(np.array([[float(S[i, j].p) / float(S[i, j].q) for j in range(n)] for i in range(n)])))
        closed = sorted(nu_closed_form(n))
        assert np.allclose(numeric, closed, rtol=1e-10, atol=1e-10), (n, numeric, closed)
        paper = [(n - 1) / n - v for v in sorted(closed, reverse=True)]
        rows.append({"n": n, "exact": exact_ok, "nu": closed, "paper": paper})
        print(f"| {n} | {'yes' if exact_ok else 'NO'} | {', '.join(f'{v:.4g}' for v in closed)} | {', '.join(f'{v:.4g}' for v in paper)} |")
    return rows


def _random_rational_body(rng, L: int) -> dict:
    """Random short-decimal parameters (exact Fractions) of one body for the exact checks."""
    dec = lambda lo, hi: Fraction(int(rng.integers(lo, hi)), 100)  # noqa: E731 - two-digit decimals
    A = dec(5, 500)
    E = [dec(1, 100) * A / 2 / L for _ in range(L)]
    kappa = [Fraction(int(rng.choice([-1, 1, 1])) * int(rng.integers(105, 900)), 100) for _ in range(L)]
    return {"m": dec(10, 500), "c": dec(5, 100), "A": A, "C": dec(1, 195) * A / 100, "omega": dec(10, 900), "E": E, "kappa": kappa}


def step_factorisation(ns, trials: int, rng) -> list[dict]:
    """Step 2: exact factorisation of p for ideal joints, and p_1 | p."""
    print("\n## 2. Ideal joints, exact: p = prod_j p_1(A + nu_j) and p_1 divides p (python-flint)\n")
    print("| n | modes L | trials | deg p | p == sum_k e_k (lam^2 Q)^k p_1^(n-k) | p_1 divides p | N_c(p_1) | N_c(p) >= N_c(p_1) |")
    print("|---|---|---|---|---|---|---|---|")
    rows = []
    for n in ns:
        for L in (1, 2):
            ok_fact = ok_div = ok_ge = 0
            ncs1, deg = [], None
            for t in range(trials):
                # Every other trial is a body whose own rotation is unstable, so that the divisibility
                # is seen to carry an instability into the chain (N_c(p) >= N_c(p_1) >= 1).
                b = _random_rational_body(rng, L)
                while t % 2 and complex_pairs(single_poly(b["A"], b["C"], b["omega"], b["E"], b["kappa"])) == 0:
                    b = _random_rational_body(rng, L)
                p = chain_poly(n, b["m"], b["c"], b["A"], b["C"], b["omega"], b["E"], b["kappa"])
                p1 = single_poly(b["A"], b["C"], b["omega"], b["E"], b["kappa"])
                deg = p.degree()
                ok_fact += p == factorised_poly(n, b["m"], b["c"], b["A"], b["C"], b["omega"], b["E"], b["kappa"])
                ok_div += (p % p1) == 0
                n1 = complex_pairs(p1)
                ok_ge += complex_pairs(p) >= n1
                ncs1.append(n1)
            rows.append({"n": n, "L": L, "trials": trials, "factorised": ok_fact, "divides": ok_div, "ge": ok_ge})
            print(f"| {n} | {L} | {trials} | {deg} | {ok_fact}/{trials} | {ok_div}/{trials} | {sorted(set(ncs1))} | {ok_ge}/{trials} |")
    return rows


def step_family(ns) -> list[dict]:
    """Step 3: the dyadic counterexample family, exactly, for every n."""
    f = FAMILY
    print("\n## 3. A counterexample for every n, exactly (python-flint, engine-independent)\n")
    print(f"Every body: m = {f['m']}, c = {f['c']}, s = {2 * f['c']}, A = {f['A']}, C = {f['C']}, omega = {f['omega']}, "
          f"E = {[str(e) for e in f['E']]}, kappa = {list(f['kappa'])}; every joint K = {f['K']}.\n")
    p1 = single_poly(f["A"], f["C"], f["omega"], f["E"], f["kappa"])
    nc1 = complex_pairs(p1)
    print(f"single body: p_1 = {p1}, N_c = {nc1}\n")
    print("| n | deg p | N_c single | N_c chain, K = 0 | N_c chain, K = %d (exact) | N_c chain (engine) | decided_by |" % f["K"])
    print("|---|---|---|---|---|---|---|")
    rows = []
    for n in ns:
        p0 = chain_poly(n, f["m"], f["c"], f["A"], f["C"], f["omega"], f["E"], f["kappa"])
        pK = chain_poly(n, f["m"], f["c"], f["A"], f["C"], f["omega"], f["E"], f["kappa"], [f["K"]] * (n - 1))
        prm = {k: np.array([float(f[k])]) for k in ("m", "c", "A", "C", "omega")}
        prm["E"] = np.array([[float(e) for e in f["E"]]])
        prm["kappa"] = np.array([[float(k) for k in f["kappa"]]])
        nc_eng, by = engine_counts(n, prm, np.full((1, n - 1), float(f["K"])))
        row = {"n": n, "deg": pK.degree(), "single": nc1, "K0": complex_pairs(p0), "K": complex_pairs(pK),
               "engine": int(nc_eng[0]), "by": int(by[0])}
        rows.append(row)
        print(f"| {n} | {row['deg']} | {nc1} | {row['K0']} | {row['K']} | {row['engine']} | {_BY[row['by']]} |")
    print("\nWhere N_c of the family's chain changes along K (every joint, omega = 1, engine, bisection to 1e-6 "
          "relative); by the scaling symmetry N_c depends on K / omega^2 only, so these are q* = K*/(A omega^2) "
          f"times A omega^2 = {f['A']} omega^2:\n")
    print("| n | N_c at K = 1e-3 | changes: K* (N_c above) |")
    print("|---|---|---|")
    for row in rows:
        n = row["n"]
        row["changes"] = family_changes(n)
        first = family_counts(n, np.array([1e-3]))[0]
        print(f"| {n} | {first} | " + ", ".join(f"{K:.6g} ({nc})" for K, nc in row["changes"]) + " |")
    return rows


def family_counts(n: int, K: np.ndarray, omega: float = 1.0) -> np.ndarray:
    """Engine N_c of the family's n-chain with every joint K (array) at one spin rate."""
    f = FAMILY
    N = len(K)
    prm = {k: np.full(N, float(f[k])) for k in ("m", "c", "A", "C")}
    prm["omega"] = np.full(N, float(omega))
    prm["E"] = np.tile([float(e) for e in f["E"]], (N, 1))
    prm["kappa"] = np.tile([float(k) for k in f["kappa"]], (N, 1))
    return engine_counts(n, prm, np.repeat(np.asarray(K, dtype=np.float64)[:, None], n - 1, axis=1))[0]


def family_changes(n: int, lo: float = 1e-3, hi: float = 1e6, num: int = 181) -> list[tuple[float, int]]:
    """Every K in [lo, hi] (omega = 1) where the family's N_c changes, with the N_c just above it.

    A scan on ``num`` log-spaced values, then 30 bisection steps per change: changes closer than
    the scan's spacing can be missed, which the A x K and K x omega atlases would show.
    """
    K = np.geomspace(lo, hi, num)
    nc = family_counts(n, K)
    out = []
    for i in np.flatnonzero(nc[1:] != nc[:-1]):
        a, b = K[i], K[i + 1]
        for _ in range(30):
            mid = math.sqrt(a * b)
            if family_counts(n, np.array([mid]))[0] == nc[i]:
                a = mid
            else:
                b = mid
        out.append((b, int(nc[i + 1])))
    return out


_BY = dict(DECIDED_BY.flags)


def step_search(ns, sizes: dict, rng, pool, chunk: int, recheck: int) -> dict:
    """Step 4 (and 5): the certified random search with joints, and exact rechecks of its findings."""
    print("\n## 4. Elastic joints: certified random search (engine)\n")
    print("Region:", ", ".join(f"{k} in {v}" if isinstance(v, tuple) else f"{k} = {v}" for k, v in RANGES.items()),
          f"; every value rounded to {BITS} significant bits; L = 1 and L = 2 liquid modes, half each.\n")
    results = {}
    drawn_total = unstable_total = 0
    for n in ns:
        t0 = time.time()
        N = sizes[n]
        parts = []
        for L in (1, 2):
            prm, unstable, drawn = unstable_bodies(rng, N - N // 2 if L == 1 else N // 2, L, pool, chunk)
            unstable_total += unstable
            drawn_total += drawn
            K = sample_joints(rng, prm, n)
            nc, by = engine_parallel(n, prm, K, pool, chunk)
            # Ideal joints for the same bodies: the theorem says N_c >= 1 there, every time.
            nc0, _ = engine_parallel(n, prm, None, pool, chunk)
            # The rigid-chain limit: one body with A + m c^2 (n^2 - 1) / 3 (rounded to float: a prediction only).
            nc_rigid, _ = engine_parallel(1, dict(prm, A=rigid_inertia(prm, n)), None, pool, chunk)
            parts.append(dict(prm=prm, K=K, nc=nc, by=by, nc0=nc0, rigid=nc_rigid, L=np.full(len(nc), L),
                              equal=np.arange(len(nc)) < len(nc) // 2, mu=instability_margin(prm),
                              **stiffness_measures(prm, K, n)))
        keys = ("q", "k", "kr", "mu", "nc", "by", "nc0", "rigid", "L", "equal")
        res = {key: np.concatenate([p[key] for p in parts]) for key in keys}
        res["parts"] = parts
        res["seconds"] = time.time() - t0
        results[n] = res
        print(f"  n = {n}: {len(res['nc'])} chains in {res['seconds']:.0f} s", file=sys.stderr)
    print(f"Single bodies drawn: {drawn_total}, unstable: {unstable_total} "
          f"({100.0 * unstable_total / drawn_total:.1f} % of the region).\n")
    print("| n | chains (single unstable) | stable chains = counterexamples | fraction | equal joints | "
          "stable with K = 0 | decided sturm/exact/inclusion | s |")
    print("|---|---|---|---|---|---|---|---|")
    for n, res in results.items():
        st, eq = res["nc"] == 0, res["equal"]
        by = np.bincount(res["by"], minlength=3)
        print(f"| {n} | {st.size} | {st.sum()} | {st.mean():.3f} | {st[eq].sum()}/{eq.sum()} | {(res['nc0'] == 0).sum()} "
              f"| {by[0]}/{by[1]}/{by[2]} | {res['seconds']:.0f} |")

    print("\nChains that are stable although the single body is not (counterexamples) / chains, by "
          "q = K/(A omega^2) (K: geometric mean of the joints):\n")
    edges = Q_BINS
    print("| n | " + " | ".join(f"[{edges[i]:.0e}, {edges[i + 1]:.0e})" for i in range(len(edges) - 1)) + " |")
    print("|---|" + "---|" * (len(edges) - 1))
    for n, res in results.items():
        idx = np.clip(np.digitize(res["q"], edges) - 1, 0, len(edges) - 2)
        res["bins"] = [(int((idx == i).sum()), int((res["nc"][idx == i] == 0).sum())) for i in range(len(edges) - 1)]
        print(f"| {n} | " + " | ".join(f"{s}/{t}" for t, s in res["bins"]) + " |")

    print("\nSoft joints: the conjecture's regime. Smallest q = K/(A omega^2) and k = K/(m c^2 omega^2) of any "
          "counterexample, and the chains below q = 0.01:\n")
    print("| n | min q of a counterexample | min k of a counterexample | chains with q < 0.01 | of them stable |")
    print("|---|---|---|---|---|")
    for n, res in results.items():
        ce, soft = res["nc"] == 0, res["q"] < 0.01
        qmin = res["q"][ce].min() if ce.any() else float("nan")
        kmin = res["k"][ce].min() if ce.any() else float("nan")
        print(f"| {n} | {qmin:.3g} | {kmin:.3g} | {soft.sum()} | {(ce & soft).sum()} |")

    print("\nSoft joints against the single body's distance from its boundary, mu = max |Im lambda|/|lambda| of p_1 "
          f"(float roots, a diagnostic): the smallest q / mu^2 of any counterexample, and the chains below q / mu^2 = {SOFT}:\n")
    print(f"| n | min q/mu^2 of a counterexample | its q | its mu | chains with q/mu^2 < {SOFT} | of them stable |")
    print("|---|---|---|---|---|---|")
    for n, res in results.items():
        ce, ratio = res["nc"] == 0, res["q"] / res["mu"] ** 2
        i = np.flatnonzero(ce)[np.argmin(ratio[ce])] if ce.any() else None
        cells = ("-", "-", "-") if i is None else (f"{ratio[i]:.3g}", f"{res['q'][i]:.3g}", f"{res['mu'][i]:.3g}")
        print(f"| {n} | " + " | ".join(cells) + f" | {(ratio < SOFT).sum()} | {(ce & (ratio < SOFT)).sum()} |")

    print("\nRigid-chain limit: is the chain stable exactly when one body with A_r = A + m c^2 (n^2-1)/3 is? "
          "By k_r = K/(A_r omega^2):\n")
    print("| n | chains, k_r >= 100 | chain stable | A_r body stable | agree | chains, k_r >= 1e3 | agree |")
    print("|---|---|---|---|---|---|---|")
    for n, res in results.items():
        cs, rs = res["nc"] == 0, res["rigid"] == 0
        s2, s3 = res["kr"] >= 100, res["kr"] >= 1000
        print(f"| {n} | {s2.sum()} | {cs[s2].sum()} | {rs[s2].sum()} | {(cs == rs)[s2].sum()} | {s3.sum()} | {(cs == rs)[s3].sum()} |")

    print("\nCounterexamples split by the rigid-chain body A_r (engine, A_r rounded to float), all stiffnesses:\n")
    print("| n | A_r body unstable: chains | of them stable | A_r body stable: chains | of them stable |")
    print("|---|---|---|---|---|")
    for n, res in results.items():
        ru, cs = res["rigid"] > 0, res["nc"] == 0
        print(f"| {n} | {ru.sum()} | {(cs & ru).sum()} | {(~ru).sum()} | {(cs & ~ru).sum()} |")

    _recheck(results, recheck, rng)
    return results


def _exact_point(n: int, part: dict, i: int) -> dict:
    """Point i of a search part as exact rationals, with its exact N_c: single body, chain, rigid-chain body."""
    prm = part["prm"]
    m, c, A, C, w = (_fr(prm[k][i]) for k in ("m", "c", "A", "C", "omega"))
    E = [_fr(e) for e in prm["E"][i]]
    kap = [_fr(k) for k in prm["kappa"][i]]
    joints = [_fr(k) for k in part["K"][i]]
    A_r = A + m * c * c * Fraction(n * n - 1, 3)
    return {"m": m, "c": c, "A": A, "C": C, "omega": w, "E": E, "kappa": kap, "K": joints,
            "single": complex_pairs(single_poly(A, C, w, E, kap)),
            "chain": complex_pairs(chain_poly(n, m, c, A, C, w, E, kap, joints)),
            "rigid": complex_pairs(single_poly(A_r, C, w, E, kap))}


def _describe(p: dict) -> str:
    s = lambda xs: "[" + ", ".join(str(x) for x in xs) + "]"  # noqa: E731
    return (f"m = {p['m']}, c = {p['c']}, A = {p['A']}, C = {p['C']}, omega = {p['omega']}, E = {s(p['E'])}, "
            f"kappa = {s(p['kappa'])}, K = {s(p['K'])}")


def _recheck(results: dict, count: int, rng) -> None:
    """Step 5: recompute counterexamples and controls exactly (engine-independent builder)."""
    print(f"\n## 5. Exact recheck of the search (python-flint, fraction-free det, engine-independent): about {count} "
          "counterexamples and as many unstable chains per n, always including the softest counterexample "
          "and every counterexample whose A_r body the engine found unstable\n")
    print("| n | rechecked | single N_c > 0 exactly | chain N_c equal to the engine's | softest counterexample (smallest q), exact |")
    print("|---|---|---|---|---|")
    special = []
    for n, res in results.items():
        checked = single_ok = chain_ok = 0
        softest = None
        for part in res["parts"]:
            stable = part["nc"] == 0
            for want in (True, False):
                idx = np.flatnonzero(stable == want)
                pick = rng.permutation(idx)[: max(1, count // 4)]
                if want and idx.size:
                    pick = np.union1d(pick, idx[np.argmin(part["q"][idx])])
                    pick = np.union1d(pick, idx[part["rigid"][idx] > 0])
                for i in pick:
                    p = _exact_point(n, part, int(i))
                    checked += 1
                    single_ok += p["single"] > 0
                    chain_ok += p["chain"] == int(part["nc"][i])
                    if p["chain"] == 0 and (softest is None or part["q"][i] < softest[0]):
                        softest = (part["q"][i], p)
                    if want and part["rigid"][i] > 0:
                        special.append((n, part["q"][i], part["kr"][i], p))
        desc = "none" if softest is None else (f"q = {softest[0]:.3g}: {_describe(softest[1])}; "
                                               f"N_c single = {softest[1]['single']}, chain = {softest[1]['chain']}")
        print(f"| {n} | {checked} | {single_ok}/{checked} | {chain_ok}/{checked} | {desc} |")
    print("\nCounterexamples whose rigid-chain body A_r the engine found unstable, exactly (A_r exact here):\n")
    print("| n | q | k_r | N_c single | N_c A_r body | N_c chain | parameters |")
    print("|---|---|---|---|---|---|---|")
    for n, q, kr, p in special:
        print(f"| {n} | {q:.3g} | {kr:.3g} | {p['single']} | {p['rigid']} | {p['chain']} | {_describe(p)} |")
    if not special:
        print("| - | - | - | - | - | - | none found |")


# ----------------------------------------------------------------------------------------------
# Figures
# ----------------------------------------------------------------------------------------------
def _scene_text(n: int, grid: str, omega: float = 1.0, A: float | None = None, K: float | None = None) -> str:
    f = FAMILY
    body = (f"[[bodies]]\nm = {float(f['m'])}\nA = {float(A if A is not None else f['A'])}\nC = {float(f['C'])}\n"
            f"c = {float(f['c'])}\ns = {2.0 * f['c']}\n"
            f"fluid = {{ E = [{', '.join(str(float(e)) for e in f['E'])}], kappa = [{', '.join(str(float(k)) for k in f['kappa'])}] }}\n")
    joints = ", ".join([str(float(K if K is not None else f["K"]))] * (n - 1))
    return (f'title = "{n} identical free bodies, counterexample family"\nsupport = "free"\nomega = {omega}\n'
            f"joints = [{joints}]\n\n" + "\n".join([body] * n) + f"\n[grid]\n{grid}\n")


def plot_all(outdir: Path, results: dict | None, quick: bool, changes: list | None = None) -> list[Path]:
    """Figures: counterexample fraction vs q; atlas K x omega (n = 3); atlases A x K for n = 2, 3, 5, 10 (engine)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap

    import stabmap

    outdir.mkdir(parents=True, exist_ok=True)
    paths = []
    if results:
        fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=110)
        centres = np.sqrt(Q_BINS[:-1] * Q_BINS[1:])
        for n, res in results.items():
            frac = [s / t if t else np.nan for t, s in res["bins"]]
            ax.semilogx(centres, frac, marker="o", ms=3, lw=1.2, label=f"n = {n}", color=plt.cm.viridis((n - 2) / 8))
        ax.set_xlabel(r"joint stiffness $q = K/(A\,\omega^2)$ (decade bins)")
        ax.set_ylabel("fraction of chains stable\n(single body unstable)")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=3)
        ax.set_title("Counterexamples to the conjecture vs joint stiffness", fontsize=10)
        fig.tight_layout()
        paths.append(outdir / "conjecture-fraction.png")
        fig.savefig(paths[-1])
        plt.close(fig)

    cmap = ListedColormap(["#2b8cbe", "#fdd49e", "#fc8d59", "#d7301f", "#7f0000"])
    norm = BoundaryNorm([-0.5, 0.5, 1.5, 2.5, 3.5, 99], cmap.N)

    # Stiffness x spin rate for n = 3: the single body is unstable at every point of this map.
    num = (40, 40) if quick else (160, 140)
    text = _scene_text(3, f'omega = {{ start = 0.1, stop = 100.0, num = {num[0]}, scale = "log" }}\n'
                          f'K = {{ start = 1.0e-3, stop = 1.0e6, num = {num[1]}, scale = "log" }}')
    ds = stabmap.compute_atlas(stabmap.loads_scene(text))
    nc = ds["n_complex_pairs"].transpose("K", "omega").values
    fig, ax = plt.subplots(figsize=(6.0, 4.4), dpi=110)
    mesh = ax.pcolormesh(ds["omega"].values, ds["K"].values, nc, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
    w = ds["omega"].values
    for K1, nc_above in (changes or [])[-2:]:  # the last changes along omega = 1, continued as K = K* omega^2
        ax.plot(w, K1 * w**2, "k--" if nc_above == 0 else "k:", lw=0.8,
                label=f"K = {K1:.4g} ω² (q = {K1 / float(FAMILY['A']):.3g}), N_c = {nc_above} above")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(ds["K"].values[0], ds["K"].values[-1])
    ax.set_xlabel(r"spin rate $\omega$ [rad/s]")
    ax.set_ylabel(r"every joint's stiffness $K$ [N m/rad]")
    ax.set_title("n = 3 identical free bodies (m = 2, c = 1, A = 4, C = 1, E = 1/2, κ = 4):\n"
                 "N_c of the chain; the single body is unstable at every point", fontsize=9)
    cb = fig.colorbar(mesh, ax=ax, ticks=[0, 1, 2, 3, 4])
    cb.set_label(r"$N_c$ of the chain (0 = stable: counterexample)")
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    paths.append(outdir / "conjecture-K-omega.png")
    fig.savefig(paths[-1])
    plt.close(fig)

    # Inertia x stiffness for n = 2, 3, 5, 10: where the single body is unstable (1 < A < 5) and the chain is not.
    ns = (2, 3, 5, 10)
    fig, axes = plt.subplots(1, 4, figsize=(12.0, 3.8), dpi=100, sharey=True)
    fig.subplots_adjust(left=0.06, right=0.9, bottom=0.15, top=0.8, wspace=0.08)
    for ax, n in zip(axes, ns):
        grid_num = (24, 20) if quick else ((120, 100) if n <= 5 else (56, 44))
        text = _scene_text(n, f'A = {{ start = 0.6, stop = 8.0, num = {grid_num[0]} }}\n'
                              f'K = {{ start = 1.0e-3, stop = 1.0e5, num = {grid_num[1]}, scale = "log" }}')
        ds = stabmap.compute_atlas(stabmap.loads_scene(text))
        nc = ds["n_complex_pairs"].transpose("K", "A").values
        mesh = ax.pcolormesh(ds["A"].values, ds["K"].values, nc, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
        for a in (1.0, 5.0):  # the single body's instability band, from its discriminant (docs/conjecture.md)
            ax.axvline(a, color="k", lw=0.9)
        ax.set_yscale("log")
        ax.set_xlabel(r"$A$ [kg m²]")
        ax.set_title(f"n = {n}", fontsize=10)
    axes[0].set_ylabel(r"every joint's stiffness $K$")
    fig.colorbar(mesh, cax=fig.add_axes([0.92, 0.15, 0.012, 0.65]), ticks=[0, 1, 2, 3, 4], label=r"$N_c$ of the chain")
    fig.suptitle("Single body unstable between the black lines (1 < A < 5); blue between them = stable chain = counterexample\n"
                 "(m = 2, c = 1, s = 2, C = 1, E = 1/2, κ = 4, ω = 1; ideal-joint limit at the bottom)", fontsize=9)
    paths.append(outdir / "conjecture-A-K.png")
    fig.savefig(paths[-1])
    plt.close(fig)
    return paths


# ----------------------------------------------------------------------------------------------
def main(argv=None) -> dict:
    """Run every step; return the tables as plain data (the tests read them)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="small samples, no process pool (under 30 s)")
    ap.add_argument("--plot", metavar="DIR", type=Path, help="write the figures conjecture-*.png into DIR")
    ap.add_argument("--seed", type=int, default=2024, help="random seed (default 2024)")
    ap.add_argument("--workers", type=int, default=None, help="processes for the engine (default: all cores; 1 in --quick)")
    ap.add_argument("--max-n", type=int, default=10, help="largest chain (default 10)")
    args = ap.parse_args(argv)

    rng = np.random.default_rng(args.seed)
    ns = list(range(2, args.max_n + 1))
    if args.quick:
        sizes = {n: (200 if n <= 4 else 16) for n in ns}
        trials, recheck, workers = 2, 2, args.workers or 1
    else:
        sizes = {n: {2: 40000, 3: 40000, 4: 20000, 5: 12000, 6: 8000, 7: 5000, 8: 4000, 9: 3000, 10: 3000}.get(n, 2000) for n in ns}
        trials, recheck, workers = 4, 60, args.workers or os.cpu_count() or 1
    chunk = 512
    t0 = time.time()
    print(f"# The conjecture of the paper (after (33), (34)), n = {ns[0]}..{ns[-1]}"
          f"{' (--quick)' if args.quick else ''}, seed {args.seed}")
    out = {"gram": step_gram(ns), "factorisation": step_factorisation(ns, trials, rng), "family": step_family(ns)}
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) if workers > 1 else None
    try:
        out["search"] = step_search(ns, sizes, rng, pool, chunk, recheck)
    finally:
        if pool is not None:
            pool.shutdown()
    if args.plot:
        n3 = [r for r in out["family"] if r["n"] == 3]
        out["figures"] = plot_all(args.plot, out["search"], args.quick, n3[0]["changes"] if n3 else None)
        print("\nfigures:", ", ".join(str(p) for p in out["figures"]))
    print(f"\ntotal {time.time() - t0:.0f} s")
    return out


if __name__ == "__main__":
    main(sys.argv[1:])
    sys.exit(0)
