"""Adversarial tests of the coefficient-free certificates (kernels/ball.py, pencil.py, elimination.py,
certify.py and their use in block.decide_block).

Every check compares the kernels with an independent exact reference:
- ball arithmetic against exact rational arithmetic (``fractions.Fraction``: every float, and every
  point m + r (3 + 4i)/5 on a ball's circle, is an exact rational);
- inertia against Descartes' rule on the exact characteristic polynomial of the symmetric matrix
  (python-flint), determinants against exact Gaussian elimination in Q(i);
- Phi(x) against tests/reference.py (sympy restatement of docs/model.md) and
  Phi(z) T against the same matrices evaluated in mpmath at 80 digits;
- labels against ``exact.char_poly`` + ``exact.complex_pairs`` (FLINT, exact rationals).

Statuses 0 and 3 (the coefficient path) are checked too, wherever decide_block returns them.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import random
import subprocess
import sys
import textwrap
import zlib
from fractions import Fraction
from pathlib import Path

import flint
import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from stabmap import kernels
from stabmap.kernels import ball, certify, elimination, pencil
from stabmap.kernels.status import DECIDED_ALLATONCE, DECIDED_DISKS, DECIDED_FLOAT, DECIDED_INCLUSION, DECIDED_INERTIA
from stabmap.systems.gyroscopes import exact
from stabmap.systems.gyroscopes.points import PointArrays

import reference as ref

DECIDED = (DECIDED_FLOAT, DECIDED_INCLUSION, DECIDED_INERTIA, DECIDED_DISKS, DECIDED_ALLATONCE)
F = Fraction


# ---------------------------------------------------------------------------------------------
# point builders (kernel layout: body (npts, n, 6) = m, A, C, c, s, omega)


def make_points(body, joint, g, E, kappa, nmodes, free) -> PointArrays:
    body = np.ascontiguousarray(body, dtype=np.float64)
    npts, n = body.shape[:2]
    lmax = max(1, int(np.max(nmodes)) if len(nmodes) else 1)
    E = np.ascontiguousarray(np.broadcast_to(E, (npts, n, lmax)), dtype=np.float64)
    kappa = np.ascontiguousarray(np.broadcast_to(kappa, (npts, n, lmax)), dtype=np.float64)
    joint = np.ascontiguousarray(np.broadcast_to(joint, (npts, n)), dtype=np.float64)
    g = np.ascontiguousarray(np.broadcast_to(g, (npts,)), dtype=np.float64)
    return PointArrays(body, joint, g, E, kappa, np.asarray(nmodes, np.int64), bool(free))


def random_chain(rng: np.random.Generator, n: int, modes: int, free: bool, kind: str = "mixed", npts: int = 1,
                 omegas=None, e_scale=(1e-5, 3e-3)) -> PointArrays:
    """One random structure, npts points (omega from ``omegas`` or random).

    kind: mixed | identical (same parameters on every body: exactly repeated roots) | split (fixed,
    ideal joints, c_k = s_k = 0 above body 1 so a_k = 0, identical upper bodies) | zerok (ideal joints).
    """
    body1 = np.empty((n, 6))
    body1[:, 0] = rng.uniform(0.2, 3.0, n)
    body1[:, 1] = rng.uniform(0.005, 0.1, n)
    body1[:, 2] = rng.uniform(0.0, 0.1, n)
    body1[:, 3] = rng.uniform(-0.2, 0.4, n)
    body1[:, 4] = rng.uniform(0.05, 0.6, n)
    joint1 = rng.uniform(0, 200, n) * (rng.random(n) < 0.7)
    lmax = max(1, modes)
    E1 = rng.uniform(*e_scale, (n, lmax))
    kappa1 = rng.choice([-1, 1], (n, lmax)) * rng.uniform(1.05, 4.0, (n, lmax))
    if kind == "identical":
        body1[:] = body1[0]
        E1[:] = E1[0]
        kappa1[:] = kappa1[0]
        joint1[1:] = joint1[min(1, n - 1)]
    elif kind == "split" and n > 1:
        body1[1:] = body1[1]
        body1[1:, 3] = 0.0
        body1[1:, 4] = 0.0
        joint1[1:] = 0.0
        E1[1:] = E1[1]
        kappa1[1:] = kappa1[1]
    elif kind == "zerok":
        joint1[:] = 0.0
    if free:
        joint1[0] = 0.0
    if omegas is None:
        omegas = rng.uniform(-100, 100, npts)
    omegas = np.asarray(omegas, dtype=np.float64)
    body = np.repeat(body1[None], len(omegas), 0)
    body[:, :, 5] = omegas[:, None]
    g = 0.0 if free else float(rng.choice([9.81, -9.81, rng.uniform(-20, 20)]))
    return make_points(body, joint1, g, E1, kappa1, np.full(n, modes, np.int64), free)


def seed_of(*key) -> int:
    """A seed that does not depend on PYTHONHASHSEED."""
    return zlib.crc32(repr(key).encode())


def exact_nc(pts: PointArrays, p: int) -> int:
    a = pts.kernel_args()
    return exact.complex_pairs(exact.char_poly(a[0][p], a[1][p], a[2][p], a[3][p], a[4][p], a[5], a[6], a[7], a[8][p]))


def exact_poly(pts: PointArrays, p: int):
    a = pts.kernel_args()
    return exact.char_poly(a[0][p], a[1][p], a[2][p], a[3][p], a[4][p], a[5], a[6], a[7], a[8][p])


def run_decide(pts: PointArrays):
    npts = pts.body.shape[0]
    nc = np.empty(npts, np.int16)
    status = np.empty(npts, np.int8)
    kernels.decide_block(*pts.kernel_args(), nc, status)
    return nc, status


def run_certify(pts: PointArrays, grid: bool = True, ws=None):
    """certify_point on every point in order with one workspace (grid order: ``reuse`` as decide_block
    computes it), or a fresh workspace per point (``grid=False``: no neighbour at all)."""
    body, joint, g, E, kappa, nmodes, free, parent, at = pts.kernel_args()
    npts, n = body.shape[:2]
    out = []
    for p in range(npts):
        if ws is None or not grid:
            ws = certify.allocate(n, nmodes, parent)
        reuse = grid and p > 0 and bool(
            g[p] == g[p - 1] and (joint[p] == joint[p - 1]).all() and (at[p] == at[p - 1]).all()
            and (body[p, :, :5] == body[p - 1, :, :5]).all()
        )
        nc, status = certify.certify_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws, reuse)
        out.append((int(nc), int(status)))
    return out


def assert_decided_agree(pts: PointArrays, results, what: str):
    """results: list of (nc, status); every decided point must carry the exact label."""
    wrong = []
    for p, (nc, status) in enumerate(results):
        if status in DECIDED:
            e = exact_nc(pts, p)
            if nc != e:
                wrong.append((p, float(pts.body[p, 0, 5]), nc, e, status))
    assert not wrong, f"{what}: wrong labels (point, omega, N_c, exact, status): {wrong[:8]} ({len(wrong)} in all)"


def subset(pts: PointArrays, idx) -> PointArrays:
    idx = np.atleast_1d(idx)
    return PointArrays(pts.body[idx], pts.joint[idx], pts.g[idx], pts.E[idx], pts.kappa[idx], pts.nmodes, pts.free)


# ---------------------------------------------------------------------------------------------
# 1. ball arithmetic against exact rationals


def _fc(z) -> tuple[Fraction, Fraction]:
    z = complex(z)
    return F(z.real), F(z.imag)


def _in_real_ball(x: Fraction, m: float, r: float) -> bool:
    if not (math.isfinite(r) and math.isfinite(m)):
        return math.isinf(r) or math.isnan(r)  # a non-finite radius decides nothing: accepted
    return abs(x - F(m)) <= F(r)


def _in_complex_ball(x: tuple[Fraction, Fraction], m: complex, r: float) -> bool:
    if not (math.isfinite(r) and math.isfinite(m.real) and math.isfinite(m.imag)):
        return not math.isfinite(r)
    mr, mi = _fc(m)
    return (x[0] - mr) ** 2 + (x[1] - mi) ** 2 <= F(r) ** 2


def _real_points(m: float, r: float):
    return [F(m), F(m) + F(r), F(m) - F(r)]


# exact points on the circle |y - m| = r: m + r u with u in {1, i, -1, -i, (3+4i)/5, ...}
_UNIT = [(F(1), F(0)), (F(0), F(1)), (F(-1), F(0)), (F(0), F(-1)), (F(3, 5), F(4, 5)), (F(-4, 5), F(3, 5)),
         (F(-3, 5), F(-4, 5)), (F(5, 13), F(-12, 13)), (F(-12, 13), F(-5, 13))]


def _complex_points(m: complex, r: float):
    mr, mi = _fc(m)
    out = [(mr, mi)]
    if r:
        out += [(mr + F(r) * ur, mi + F(r) * ui) for ur, ui in _UNIT]
    return out


def _cmul(a, b):
    return a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]


def _cinv(b):
    d = b[0] ** 2 + b[1] ** 2
    return b[0] / d, -b[1] / d


def _random_real(rng: random.Random, lo=-150, hi=150) -> float:
    return rng.choice([-1, 1]) * 10 ** rng.uniform(lo, hi)


def _random_radius(rng: random.Random, m: float) -> float:
    return rng.choice([0.0, math.ulp(m), abs(m) * 1e-12, abs(m) * 1e-3, abs(m) * rng.uniform(0, 0.9), 1e-300])


def _real_cases(rng: random.Random, count: int, lo=-150, hi=150):
    for i in range(count):
        am = _random_real(rng, lo, hi)
        kind = i % 4
        if kind == 0:
            bm = _random_real(rng, lo, hi)
        elif kind == 1:  # near cancellation in a + b
            bm = -am * (1 + rng.choice([0.0, 1e-16, 2.0**-52, 1e-10, 1e-3]))
        elif kind == 2:  # similar magnitudes
            bm = am * rng.uniform(-2, 2)
        else:  # tiny partner
            bm = rng.choice([-1, 1]) * 10 ** rng.uniform(-320, -290)
        yield am, _random_radius(rng, am), bm, _random_radius(rng, bm)


def _add_mul_failures(am, ar, bm, br) -> list:
    """radd and rmul of two real balls: every exact sum and product of points of the inputs inside the result."""
    out = []
    for name, op, f in (("radd", ball.radd, lambda a, b: a + b), ("rmul", ball.rmul, lambda a, b: a * b)):
        m, r = op(am, ar, bm, br)
        for a in _real_points(am, ar):
            for b in _real_points(bm, br):
                if not _in_real_ball(f(a, b), m, r):
                    out.append((name, am, ar, bm, br))
    return out


def test_real_ball_ops_enclose_exact_results():
    rng = random.Random(1)
    failures = []
    for am, ar, bm, br in _real_cases(rng, 1500):
        failures += _add_mul_failures(am, ar, bm, br)
        if ball.excludes_zero(bm, br):
            assert all(b != 0 and (b > 0) == (bm > 0) for b in _real_points(bm, br))
            m, r = ball.rdiv(am, ar, bm, br)
            for a in _real_points(am, ar):
                for b in _real_points(bm, br):
                    if not _in_real_ball(a / b, m, r):
                        failures.append(("rdiv", am, ar, bm, br))
    assert not failures, failures[:5]


def test_real_ball_ops_subnormal_and_underflow():
    rng = random.Random(2)
    failures = []
    for am, ar, bm, br in _real_cases(rng, 600, -320, -280):
        failures += _add_mul_failures(am, ar, bm, br)
    assert not failures, failures[:5]


def _complex_cases(rng: random.Random, count: int, lo=-100, hi=100):  # |b| > 1e100: test_cinv_huge_magnitudes
    for i in range(count):
        mag = 10 ** rng.uniform(lo, hi)
        am = complex(mag * rng.uniform(-1, 1), mag * rng.uniform(-1, 1))
        kind = i % 3
        if kind == 0:
            mag2 = 10 ** rng.uniform(lo, hi)
            bm = complex(mag2 * rng.uniform(-1, 1), mag2 * rng.uniform(-1, 1))
        elif kind == 1:
            bm = -am * complex(1 + rng.choice([0.0, 1e-16, 1e-9]), rng.choice([0.0, 1e-15]))
        else:
            bm = complex(am.real, -am.imag)  # a b nearly real, a + b cancels in the imaginary part
        yield am, _random_radius(rng, abs(am)), bm, _random_radius(rng, abs(bm))


def test_complex_ball_ops_enclose_exact_results():
    rng = random.Random(3)
    failures = []
    for am, ar, bm, br in _complex_cases(rng, 500):
        A, B = _complex_points(am, ar), _complex_points(bm, br)
        m, r = ball.cadd(am, ar, bm, br)
        failures += [("cadd", am, ar, bm, br) for a in A for b in B if not _in_complex_ball((a[0] + b[0], a[1] + b[1]), m, r)]
        m, r = ball.cmul(am, ar, bm, br)
        failures += [("cmul", am, ar, bm, br) for a in A for b in B if not _in_complex_ball(_cmul(a, b), m, r)]
        if ball.excludes_zero(bm, br):
            assert all(b != (0, 0) for b in B)
            m, r = ball.cinv(bm, br)
            failures += [("cinv", bm, br) for b in B if not _in_complex_ball(_cinv(b), m, r)]
            m, r = ball.cdiv(am, ar, bm, br)
            failures += [("cdiv", am, ar, bm, br) for a in A for b in B if not _in_complex_ball(_cmul(a, _cinv(b)), m, r)]
    assert not failures, failures[:5]


@pytest.mark.parametrize("scale", [1e-150, 1e-100, 1e-30, 1.0, 1e30, 1e90])
def test_cinv_near_a_disk_through_zero(scale):
    """1/y over |y - b| <= r with r close to |b|: the image disk is huge and off-centre."""
    rng = random.Random(int(-math.log10(scale) * 10) + 7)
    failures = []
    for _ in range(200):
        b = complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * scale
        gap = rng.choice([1e-1, 1e-3, 1e-6, 1e-9, 1e-12, 2.0**-50])
        r = abs(b) * (1 - gap)
        if not ball.excludes_zero(b, r):
            continue
        m, rad = ball.cinv(b, r)
        failures += [(b, r) for y in _complex_points(b, r) if not _in_complex_ball(_cinv(y), m, rad)]
    assert not failures, failures[:5]


@pytest.mark.parametrize("scale", [1e110, 1e150])
def test_cinv_huge_magnitudes(scale):
    """|b| (|b|^2 - r^2) overflows here: the centre-shift term must not silently become 0."""
    rng = random.Random(11)
    failures = []
    for _ in range(100):
        b = complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * scale
        r = abs(b) * rng.choice([0.5, 0.9, 0.99])
        m, rad = ball.cinv(b, r)
        failures += [(b, r, m, rad) for y in _complex_points(b, r) if not _in_complex_ball(_cinv(y), m, rad)]
    assert not failures, f"cinv misses 1/y: (b, r, mid, rad) {failures[:3]}"


def test_excludes_zero_is_sound():
    rng = random.Random(5)
    for _ in range(3000):
        m = _random_real(rng, -300, 300)
        r = abs(m) * rng.choice([1.0, 1 - 2.0**-52, 1 + 2.0**-52, 0.5, 2.0])
        if ball.excludes_zero(m, r):
            assert F(r) < abs(F(m)), (m, r)
        z = complex(m, _random_real(rng, -300, 300))
        rz = abs(z) * rng.choice([1.0, 1 - 2.0**-52, 1 - 2.0**-50, 1 + 2.0**-52])
        if ball.excludes_zero(z, rz):
            zr, zi = _fc(z)
            assert F(rz) ** 2 < zr**2 + zi**2, (z, rz)
    assert not ball.excludes_zero(math.nan, 0.0)
    assert not ball.excludes_zero(1.0, math.nan)
    assert not ball.excludes_zero(complex(math.nan, 0.0), 0.0)
    assert not ball.excludes_zero(math.inf, math.inf)


# ---------------------------------------------------------------------------------------------
# 2. inertia, 3. determinant bounds


def _exact_negative_eigenvalues(S: list[list[Fraction]]) -> int:
    """Descartes' rule is exact for a polynomial with only real roots: the negative eigenvalues of S
    are the positive roots of det(x I + S) = charpoly(-S)(x)."""
    n = len(S)
    mat = flint.fmpq_mat(n, n, [flint.fmpq(-x.numerator, x.denominator) for row in S for x in row])
    coeffs = [c for c in mat.charpoly().coeffs() if c != 0]
    return sum(1 for a, b in zip(coeffs, coeffs[1:]) if (a > 0) != (b > 0))


def _is_singular(S) -> bool:
    n = len(S)
    return flint.fmpq_mat(n, n, [flint.fmpq(x.numerator, x.denominator) for row in S for x in row]).det() == 0


def _random_symmetric(rng: random.Random, n: int, kind: str) -> list[list[Fraction]]:
    """Exact symmetric matrices: B^T D B with integer-ish B and chosen signs/sizes in D."""
    B = [[F(rng.randint(-4, 4)) + (1 if i == j else 0) * 5 for j in range(n)] for i in range(n)]
    if kind == "random":
        return _sym([[F(rng.randint(-1000, 1000), rng.choice([1, 2, 8, 1024])) for _ in range(n)] for _ in range(n)])
    signs = {"definite": [1] * n, "negdef": [-1] * n}.get(kind, [rng.choice([-1, 1]) for _ in range(n)])
    sizes = [F(rng.randint(1, 50)) for _ in range(n)]
    if kind in ("nearly_singular", "graded"):
        k = rng.randrange(n)
        sizes[k] = F(1, 2 ** rng.choice([20, 30, 40, 45])) if kind == "nearly_singular" else sizes[k]
        if kind == "graded":
            sizes = [F(2) ** rng.randint(-30, 30) for _ in range(n)]
    if kind == "singular":
        sizes[rng.randrange(n)] = F(0)
    D = [s * x for s, x in zip(signs, sizes)]
    return [[sum(B[k][i] * D[k] * B[k][j] for k in range(n)) for j in range(n)] for i in range(n)]


def _sym(A):
    n = len(A)
    return [[A[max(i, j)][min(i, j)] for j in range(n)] for i in range(n)]


def _float_balls(S, extra=0.0):
    """Float midpoints and radii that enclose the exact S (rounding error plus ``extra`` relative)."""
    n = len(S)
    Sm = np.empty((n, n))
    Sr = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            m = float(S[i][j])
            err = abs(F(m) - S[i][j])
            r = float(err)
            if F(r) < err:
                r = math.nextafter(r, math.inf)
            Sm[i, j], Sr[i, j] = m, r + extra * abs(m)
    return Sm, Sr


@pytest.mark.parametrize("n", range(1, 9))
def test_inertia_matches_exact_count(n):
    rng = random.Random(100 + n)
    proved = 0
    for trial in range(40):
        kind = ["random", "definite", "negdef", "indefinite", "nearly_singular", "graded", "singular"][trial % 7]
        S = _random_symmetric(rng, n, kind)
        Sm, Sr = _float_balls(S, extra=rng.choice([0.0, 0.0, 1e-14, 1e-9]))
        nu = elimination.inertia(Sm.copy(), Sr.copy(), n)
        if _is_singular(S):
            assert nu == -1, (kind, S)
            continue
        if nu >= 0:
            proved += 1
            assert nu == _exact_negative_eigenvalues(S), (kind, S, nu)
    assert proved >= 10  # the test must exercise proofs, not only refusals


def test_inertia_reads_lower_triangle_and_pivots():
    # diagonal pivoting must pick the large diagonal; [[eps, 1], [1, 1]] has one negative eigenvalue
    S = [[F(1, 2**60), F(1)], [F(1), F(1)]]
    Sm, Sr = _float_balls(S)
    assert elimination.inertia(Sm, Sr, 2) == _exact_negative_eigenvalues(S) == 1
    # zero diagonal (indefinite, no diagonal pivot excludes zero): must refuse, never guess
    Sm, Sr = _float_balls([[F(0), F(1)], [F(1), F(0)]])
    assert elimination.inertia(Sm, Sr, 2) == -1
    # garbage in the (unread) upper triangle changes nothing
    S = _random_symmetric(random.Random(9), 5, "indefinite")
    Sm, Sr = _float_balls(S)
    Sm2 = Sm.copy()
    Sm2[np.triu_indices(5, 1)] = 1e300
    assert elimination.inertia(Sm.copy(), Sr.copy(), 5) == elimination.inertia(Sm2, Sr.copy(), 5) == _exact_negative_eigenvalues(S)


def _exact_abs_det2(A: list[list[tuple[Fraction, Fraction]]]) -> Fraction:
    """|det A|^2 exactly, Gaussian elimination in Q(i)."""
    n = len(A)
    A = [row[:] for row in A]
    det = (F(1), F(0))
    for c in range(n):
        p = next((r for r in range(c, n) if A[r][c] != (0, 0)), None)
        if p is None:
            return F(0)
        A[c], A[p] = A[p], A[c]
        det = _cmul(det, A[c][c])
        inv = _cinv(A[c][c])
        for r in range(c + 1, n):
            f = _cmul(A[r][c], inv)
            for j in range(c, n):
                t = _cmul(f, A[c][j])
                A[r][j] = (A[r][j][0] - t[0], A[r][j][1] - t[1])
    return det[0] ** 2 + det[1] ** 2


@pytest.mark.parametrize("n", range(1, 9))
def test_det_bound_brackets_exact_determinant(n):
    rng = np.random.default_rng(200 + n)
    checked = 0
    for trial in range(25):
        scale = 10.0 ** rng.uniform(-30, 30)
        cm = (rng.uniform(-1, 1, (n, n)) + 1j * rng.uniform(-1, 1, (n, n))) * scale
        if trial % 5 == 1:  # nearly singular: last row a near-combination of the others
            cm[-1] = cm[0] * 0.5 + (cm[1] if n > 1 else 0) * 0.25 + 1e-12 * scale
        if trial % 5 == 2:  # exactly singular (when n > 1): duplicated row
            cm[-1] = cm[0]
        if trial % 5 == 3:  # graded rows
            cm *= (10.0 ** rng.uniform(-20, 20, n))[:, None]
        cr = np.zeros((n, n)) if trial % 2 else np.abs(cm) * 2.0**-50
        exact_sq = _exact_abs_det2([[_fc(z) for z in row] for row in cm])
        ok, mant, expo = elimination.det_bound(cm.copy(), cr.copy(), n, False)
        if ok:
            up = F(mant) * F(2) ** expo
            assert exact_sq <= up * up, (trial, cm)
            checked += 1
        ok, mant, expo = elimination.det_bound(cm.copy(), cr.copy(), n, True)
        if ok:
            low = F(mant) * F(2) ** expo
            assert low > 0 and low * low <= exact_sq, (trial, cm)
            checked += 1
        elif trial % 5 == 2 and n > 1:
            pass
        if trial % 5 == 2 and n > 1:
            assert not ok  # a singular matrix can never get a positive lower bound
    assert checked >= 25


# ---------------------------------------------------------------------------------------------
# 4. the balls of Phi(x) and Phi(z) T against the exact matrices


def _reference_bodies(pts: PointArrays, p: int):
    body, joint, g, E, kappa, nmodes, free = (pts.body[p], pts.joint[p], pts.g[p], pts.E[p], pts.kappa[p], pts.nmodes, pts.free)
    bodies = [
        {"m": body[k, 0], "A": body[k, 1], "C": body[k, 2], "c": body[k, 3], "s": body[k, 4], "omega": body[k, 5],
         "E": list(E[k, : nmodes[k]]), "kappa": list(kappa[k, : nmodes[k]])}
        for k in range(body.shape[0])
    ]
    kw = {"bodies": bodies, "support": "free" if free else "fixed", "joints": list(joint[1:])}
    if not free:
        kw.update(g=float(g), K0=float(joint[0]))
    return kw


def _exact_pencil(pts: PointArrays, p: int):
    """(M, G, K) as Fractions and the liquid (beta, E) per body, from tests/reference.py."""
    kw = _reference_bodies(pts, p)
    M, G, K = ref.system_matrices(**kw)
    n = len(kw["bodies"])
    toF = lambda x: F(int(x.p), int(x.q))  # noqa: E731
    Mf = [[toF(M[i, j]) for j in range(n)] for i in range(n)]
    Gf = [toF(G[i, i]) for i in range(n)]
    Kf = [[toF(K[i, j]) for j in range(n)] for i in range(n)]
    liquid = []
    for k, b in enumerate(kw["bodies"]):
        w = F(b["omega"])
        liquid.append([(w - 2 * w / F(kap), F(e)) for e, kap in zip(b["E"], b["kappa"])])
    omega = [F(b["omega"]) for b in kw["bodies"]]
    return Mf, Gf, Kf, liquid, omega


def _exact_phi(pen, x):
    """Phi(x) exactly (x a Fraction, or an mpmath number: then in mpmath), None at a pole.

    A mode with beta = 0 (kappa = 2, or omega_k = 0) has no pole: x^2 (x + omega) e / x = x (x + omega) e."""
    M, G, K, liquid, omega = pen
    n = len(M)
    out = [[x * x * M[i][j] - K[i][j] for j in range(n)] for i in range(n)]
    for k in range(n):
        a, removable = 0, 0
        for beta, e in liquid[k]:
            if beta == 0:
                removable += e
                continue
            if x + beta == 0:
                return None
            a += e / (x + beta)
        out[k][k] += x * G[k] - x * x * (x + omega[k]) * a - x * (x + omega[k]) * removable
    return out


def _pencil_ws(pts: PointArrays, p: int):
    body, joint, g, E, kappa, nmodes, free, parent, at = pts.kernel_args()
    n = body.shape[1]
    ws = pencil.allocate(n, max(1, int(nmodes.max())), parent)
    m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws, False)
    return ws, m


PENCIL_CASES = [(n, modes, free, kind) for n in (1, 2, 3, 5) for modes in (0, 2) for free in (False, True)
                for kind in ("mixed", "identical")] + [(3, 1, False, "split"), (4, 1, True, "zerok"), (6, 4, False, "mixed")]


@pytest.mark.parametrize("n,modes,free,kind", PENCIL_CASES)
def test_real_matrix_encloses_exact_phi(n, modes, free, kind):
    rng = np.random.default_rng(seed_of(n, modes, free, kind))
    pts = random_chain(rng, n, modes, free, kind, npts=3)
    pts.body[2, :, 5] = 0.0 if kind != "mixed" else pts.body[2, :, 5]  # omega = 0 too
    Sm, Sr = np.empty((n, n)), np.empty((n, n))
    checked = 0
    for p in range(pts.body.shape[0]):
        pen = _exact_pencil(pts, p)
        ws, _ = _pencil_ws(pts, p)
        poles = [float(-b) for lq in pen[3] for b, _ in lq]
        xs = [float(x) for x in rng.uniform(-300, 300, 6)] + [0.0, 1e-7, -1e-9, 1e6]
        xs += [pl * (1 + 1e-9) for pl in poles] + [pl + 1e-12 for pl in poles]
        for x in xs:
            if not pencil.real_matrix(x, pts.body[p], pts.E[p], pts.nmodes, pts.parent, ws, Sm, Sr):
                continue
            phi = _exact_phi(pen, F(x))
            assert phi is not None
            for i in range(n):
                for j in range(i + 1):
                    assert abs(phi[i][j] - F(Sm[i, j])) <= F(Sr[i, j]), (p, x, i, j, float(phi[i][j]), Sm[i, j], Sr[i, j])
            checked += 1
    assert checked >= 20


@pytest.mark.parametrize("n,modes,free", [(1, 1, False), (2, 2, True), (3, 1, False), (4, 2, True)])
def test_reference_phi_agrees_with_exact_char_poly(n, modes, free):
    """The exact Phi of this file (tests/reference.py) and exact.char_poly are the same model:
    det Phi(x) prod Q(x) = p(x) at rational points (guards the references used above)."""
    rng = np.random.default_rng(7 * n + modes)
    pts = random_chain(rng, n, modes, free, "mixed", npts=1)
    pen = _exact_pencil(pts, 0)
    poly = exact_poly(pts, 0)
    for x in (F(3, 7), F(-11, 2), F(1001, 10)):
        phi = _exact_phi(pen, x)
        det = flint.fmpq_mat(n, n, [flint.fmpq(v.numerator, v.denominator) for row in phi for v in row]).det()
        q = F(1)
        for lq in pen[3]:
            for beta, _ in lq:
                q *= x + beta
        px = poly(flint.fmpq(x.numerator, x.denominator))
        assert F(int(px.p), int(px.q)) == F(int(det.p), int(det.q)) * q


def _shifts_exact(pen, n):
    """The exact zero columns of K T (T[i, j] = 1 for i >= j, a chain): each makes z divide column j of Phi(z) T."""
    M, G, K, liquid, omega = pen
    return [0 if any(sum(K[k][i] for i in range(j, n)) for k in range(n)) else 1 for j in range(n)]


def _mp_pencil(pen):
    toM = lambda v: mpmath.mpf(v.numerator) / v.denominator  # noqa: E731
    M, G, K, liquid, omega = pen
    return ([[toM(v) for v in row] for row in M], [toM(v) for v in G], [[toM(v) for v in row] for row in K],
            [[(toM(b), toM(e)) for b, e in lq] for lq in liquid], [toM(v) for v in omega])


def _mp_phi_derivative(pen_m, z):
    """Phi'(z) = 2 z M + diag(G - (3 z^2 + 2 z omega) a + z^2 (z + omega) b), a = sum E/(z+beta), b = sum E/(z+beta)^2."""
    M, G, K, liquid, omega = pen_m
    n = len(M)
    out = [[2 * z * M[i][j] for j in range(n)] for i in range(n)]
    for k in range(n):
        a = sum((e / (z + b) for b, e in liquid[k]), mpmath.mpf(0))
        bb = sum((e / (z + b) ** 2 for b, e in liquid[k]), mpmath.mpf(0))
        out[k][k] += G[k] - (3 * z * z + 2 * z * omega[k]) * a + z * z * (z + omega[k]) * bb
    return out


def _mp_in(v, m, r):
    return abs(v - mpmath.mpc(complex(m).real, complex(m).imag)) <= mpmath.mpf(float(r)) * (1 + mpmath.mpf(10) ** -30)


COMPLEX_CASES = [(1, 2, False, "mixed"), (2, 1, True, "mixed"), (3, 2, False, "mixed"), (3, 2, True, "identical"),
                 (4, 1, False, "split"), (3, 0, True, "zerok"), (5, 3, False, "mixed")]


@pytest.mark.parametrize("n,modes,free,kind", COMPLEX_CASES)
def test_complex_matrix_and_derivative_enclose_exact(n, modes, free, kind):
    """Phi(z), Phi'(z) (original coordinates), prod (z + beta) and sum 1/(z + beta) in mpmath at 80
    digits; the number m of exact zero roots equals the zero columns of the exact K T (twice where G T
    vanishes there too)."""
    mpmath.mp.dps = 80
    rng = np.random.default_rng(seed_of("complex", n, modes, free, kind))
    pts = random_chain(rng, n, modes, free, kind, npts=1)
    pen = _exact_pencil(pts, 0)
    ws, m = _pencil_ws(pts, 0)
    assert m == sum(_shifts_exact(pen, n))
    pen_m = _mp_pencil(pen)
    omega = float(pts.body[0, 0, 5])
    zs = [complex(rng.uniform(-80, 80), rng.choice([0.0, rng.uniform(-80, 80), 1e-9])) for _ in range(10)]
    zs += [complex(-2 * omega / 3 * (1 + 1e-13), 0.0), complex(-omega * (1 - 1e-14), 1e-3)]  # cancellation in 3z + 2w, z + w
    zs += [complex(-float(b) * (1 + 1e-7), 0.0) for lq in pen[3] for b, _ in lq]  # next to the poles
    dm, dr = np.empty((n, n), np.complex128), np.empty((n, n))
    checked = 0
    for z in zs:
        ok, qm, qr = pencil.complex_matrix(z, 0.0, pts.body[0], pts.E[0], pts.nmodes, ws)
        if not ok:
            continue
        checked += 1
        zm = mpmath.mpc(z.real, z.imag)
        phi = _exact_phi(pen_m, zm)
        q = mpmath.mpf(1)
        for lq in pen_m[3]:
            for beta, _ in lq:
                q *= zm + beta
        assert _mp_in(q, qm, qr), z
        for k in range(n):
            for j in range(n):
                assert _mp_in(phi[k][j], ws.cm[k, j], ws.cr[k, j]), (z, k, j)
        lm, lr = pencil.complex_derivative(z, pts.body[0], pts.E[0], pts.nmodes, ws, dm, dr)
        if not math.isfinite(lr):
            continue
        logq = sum((1 / (zm + b) for lq in pen_m[3] for b, _ in lq), mpmath.mpf(0))
        assert _mp_in(logq, lm, lr), z
        dphi = _mp_phi_derivative(pen_m, zm)
        for k in range(n):
            for j in range(n):
                assert _mp_in(dphi[k][j], dm[k, j], dr[k, j]), ("derivative", z, k, j, complex(dphi[k][j]), dm[k, j], dr[k, j])
    assert checked >= 8


# ---------------------------------------------------------------------------------------------
# 5. end to end: decide_block and certify_point against exact labels


E2E_FAST = [
    # (n, modes, free, kind, npts): degree > 16 puts certify first in decide_block
    (5, 2, False, "mixed", 6), (5, 2, True, "mixed", 6), (6, 1, False, "identical", 6), (5, 2, True, "identical", 6),
    (6, 1, True, "zerok", 6), (6, 1, False, "split", 6), (3, 2, False, "mixed", 10), (2, 1, True, "identical", 10),
]


@pytest.mark.parametrize("n,modes,free,kind,npts", E2E_FAST)
def test_decide_block_agrees_with_exact(n, modes, free, kind, npts):
    rng = np.random.default_rng(seed_of(n, modes, free, kind))
    pts = random_chain(rng, n, modes, free, kind, npts=npts)
    nc, status = run_decide(pts)
    assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), f"decide_block {n=} {modes=} {free=} {kind}")


CERTIFY_FAST = [(n, modes, free, kind) for n, modes in ((1, 0), (1, 2), (2, 1), (3, 0), (3, 2), (4, 1))
                for free in (False, True) for kind in ("mixed", "identical")] + [
    (3, 1, False, "split"), (4, 0, False, "split"), (3, 1, True, "zerok"), (4, 2, True, "zerok")]


@pytest.mark.parametrize("n,modes,free,kind", CERTIFY_FAST)
def test_certify_point_cold_agrees_with_exact(n, modes, free, kind):
    rng = np.random.default_rng(seed_of("cold", n, modes, free, kind))
    pts = random_chain(rng, n, modes, free, kind, npts=8)
    assert_decided_agree(pts, run_certify(pts, grid=False), f"certify cold {n=} {modes=} {free=} {kind}")


@pytest.mark.parametrize("n,modes,free,kind", [(3, 2, False, "mixed"), (3, 2, True, "identical"), (4, 1, False, "split"),
                                               (2, 2, True, "zerok"), (4, 2, False, "identical")])
def test_certify_point_along_an_omega_line(n, modes, free, kind):
    """Consecutive points are grid neighbours: the warm start and the two-point predictor are used."""
    rng = np.random.default_rng(seed_of("line", n, modes, free, kind))
    omegas = np.linspace(rng.uniform(-90, -20), rng.uniform(20, 90), 60)
    pts = random_chain(rng, n, modes, free, kind, omegas=omegas)
    line = run_certify(pts, grid=True)
    assert_decided_agree(pts, line, "line, two-point predictor")
    # one neighbour only: each point preceded by exactly one grid neighbour in a fresh workspace
    pairs = []
    for p in range(1, len(omegas), 3):
        pairs.append(run_certify(subset(pts, [p - 1, p]), grid=True)[1])
    sub = subset(pts, list(range(1, len(omegas), 3)))
    assert_decided_agree(sub, pairs, "one-neighbour predictor")
    # backwards along the line (poles and roots move the other way)
    rev = subset(pts, list(range(len(omegas) - 1, -1, -1)))
    assert_decided_agree(rev, run_certify(rev, grid=True), "line reversed")


def _identical_tiny_liquid(n, modes, omegas, e_rel, free=False):
    """Identical bodies whose liquid is almost massless: n real roots sit within e_rel of each
    n-fold pole -beta, on the same side of it (closer than the certificate's separator fence)."""
    npts = len(omegas)
    body = np.empty((npts, n, 6))
    body[...] = (1.5, 0.03, 0.045, 0.125, 0.25, 0.0)
    body[..., 5] = np.asarray(omegas)[:, None]
    kap = np.array([1.5, -2.7, 3.3, -1.2])[: max(1, modes)]
    return make_points(body, np.zeros(n), 0.0 if free else 9.81, np.full((n, max(1, modes)), 0.03 * e_rel),
                       np.broadcast_to(kap, (n, max(1, modes))), np.full(n, modes, np.int64), free)


@pytest.mark.parametrize("n,modes,e_rel", [(2, 1, 1e-10), (3, 2, 1e-10), (4, 1, 1e-9)])
def test_certify_identical_bodies_with_nearly_massless_liquid(n, modes, e_rel):
    """Regression: roots closer to a pole than FENCE put separators out of order (x_i+1 < x_i);
    the inertia count then counts the same roots more than once and proves wrong labels."""
    pts = _identical_tiny_liquid(n, modes, np.linspace(0.5, 80, 40), e_rel)
    assert_decided_agree(pts, run_certify(pts, grid=False), "cold")
    assert_decided_agree(pts, run_certify(pts, grid=True), "grid")


def test_decide_block_identical_bodies_nearly_massless_liquid_degree_20():
    """The same at degree 20, through decide_block (certify goes first above degree 16)."""
    pts = _identical_tiny_liquid(5, 2, [24.96, 27.0, 40.0], 1e-10)
    nc, status = run_decide(pts)
    assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), "decide_block")


def test_decide_block_does_not_reuse_a_stale_certify_workspace():
    """Regression: at degree <= 16 certify runs only where the Sturm path fails, but decide_block
    passes it ``reuse`` computed from point p-1, whose structure certify may never have seen."""
    body = np.zeros((3, 1, 6))
    body[0, 0] = (1.0, 0.02, 0.03, -0.1, 0.25, 1e-190)  # hanging top, spin too small for the coefficient path
    body[1, 0] = (1.0, 0.02, 0.03, 0.1, 0.25, 100.0)  # standing top: Sturm decides it, certify not called
    body[2, 0] = (1.0, 0.02, 0.03, 0.1, 0.25, 1e-190)  # same structure as point 1: certify gets reuse=True
    pts = make_points(body, np.zeros(1), 9.81, np.zeros((1, 1)), np.ones((1, 1)), np.zeros(1, np.int64), False)
    nc, status = run_decide(pts)
    assert [exact_nc(pts, p) for p in range(3)] == [0, 0, 1]
    assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), "decide_block")


def test_certify_special_exact_zeros():
    """omega = 0 (beta = 0: a pole at the origin), kappa = 2 (beta exactly 0), free chains with K = 0
    (multiple lambda = 0 roots) and g = 0."""
    rng = np.random.default_rng(77)
    cases = []
    pts = random_chain(rng, 3, 2, True, "zerok", omegas=[0.0, 5.0, -7.0])
    cases.append(pts)
    pts = random_chain(rng, 3, 2, False, "mixed", omegas=[13.0, -40.0])
    pts.kappa[:, :, 0] = 2.0
    cases.append(pts)
    pts = random_chain(rng, 4, 1, False, "mixed", omegas=[20.0, 60.0])
    pts.g[:] = 0.0
    cases.append(pts)
    pts = random_chain(rng, 4, 0, True, "identical", omegas=[0.0, 33.0])
    cases.append(pts)
    for pts in cases:
        assert_decided_agree(pts, run_certify(pts, grid=False), "special cold")
        assert_decided_agree(pts, run_certify(pts, grid=True), "special grid")
        nc, status = run_decide(pts)
        assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), "special decide_block")


# ---------------------------------------------------------------------------------------------
# 6. near spin-rate boundaries


def _with_omega(pts: PointArrays, omegas) -> PointArrays:
    q = subset(pts, [0] * len(omegas))
    q.body[:, :, 5] = np.asarray(omegas)[:, None]
    return q


def _bisect_boundary(pts: PointArrays, lo: float, hi: float) -> float:
    """A float omega at a change of the exact N_c between lo and hi (relative width 1e-15)."""
    f = lambda w: exact_nc(_with_omega(pts, [w]), 0)  # noqa: E731
    flo = f(lo)
    assert f(hi) != flo
    while abs(hi - lo) > 1e-15 * abs(lo):
        mid = 0.5 * (lo + hi)
        if f(mid) == flo:
            lo = mid
        else:
            hi = mid
    return lo


OFFSETS = [s * r for r in (1e-4, 1e-8, 1e-10, 1e-12) for s in (-1, 1)] + [0.0]


def _check_near(pts: PointArrays, w_star: float):
    q = _with_omega(pts, [w_star * (1 + r) for r in OFFSETS])
    nc, status = run_decide(q)
    assert_decided_agree(q, list(zip(nc.tolist(), status.tolist())), f"decide_block near {w_star}")
    assert_decided_agree(q, run_certify(q, grid=False), f"certify cold near {w_star}")
    assert_decided_agree(q, run_certify(q, grid=True), f"certify line near {w_star}")


@pytest.mark.parametrize("m,A,C,c,g", [(1.0, 0.02, 0.03, 0.1, 9.81), (2.5, 0.07, 0.011, 0.33, 9.81), (0.3, 1e-3, 1e-3, 0.05, 1.0)])
def test_near_maievskii_boundary(m, A, C, c, g):
    w_star = math.sqrt(4 * (A + m * c * c) * m * c * g) / C  # C^2 w^2 = 4 (A + m c^2) m c g
    body = np.array([[[m, A, C, c, 0.25, w_star]]])
    pts = make_points(body, np.zeros(1), g, np.zeros((1, 1)), np.ones((1, 1)), np.zeros(1, np.int64), False)
    q = _with_omega(pts, [w_star * (1 - 1e-3), w_star * (1 + 1e-3)])
    assert [exact_nc(q, 0), exact_nc(q, 1)] == [1, 0]
    _check_near(pts, w_star)


def chain_with_boundary(rng, n: int, modes: int, grid, tries: int):
    """(points, changes): a random fixed chain whose exact N_c changes between grid[i] and grid[i + 1] of omega
    for each i in ``changes``; the test is skipped if ``tries`` chains show none."""
    for _ in range(tries):
        pts = random_chain(rng, n, modes, False, "mixed", omegas=[1.0])
        labels = [exact_nc(_with_omega(pts, [w]), 0) for w in grid]
        changes = [i for i in range(len(grid) - 1) if labels[i] != labels[i + 1]]
        if changes:
            return pts, changes
    pytest.skip("no boundary found")


@pytest.mark.parametrize("n,modes,seed", [(2, 1, 1), (2, 2, 2), (3, 1, 3), (3, 2, 4)])
def test_near_liquid_boundaries(n, modes, seed):
    grid = np.linspace(1.0, 100.0, 10)
    pts, changes = chain_with_boundary(np.random.default_rng(seed), n, modes, grid, 20)
    for i in changes[:2]:
        _check_near(pts, _bisect_boundary(pts, grid[i], grid[i + 1]))


# ---------------------------------------------------------------------------------------------
# 7. hypothesis: random small chains, every decided label equals the exact one


@st.composite
def small_chains(draw):
    n = draw(st.integers(1, 4))
    modes = draw(st.integers(0, 2))
    free = draw(st.booleans())
    kind = draw(st.sampled_from(["mixed", "identical", "zerok", "split"] if not free else ["mixed", "identical", "zerok"]))
    seed = draw(st.integers(0, 2**32 - 1))
    e_exp = draw(st.sampled_from([-5.0, -3.0, -8.0, -10.0, -1.0, -13.0]))
    line = draw(st.booleans())
    return n, modes, free, kind, seed, e_exp, line


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(small_chains())
def test_property_decided_labels_are_exact(case):
    n, modes, free, kind, seed, e_exp, line = case
    rng = np.random.default_rng(seed)
    e = 10.0**e_exp
    omegas = np.linspace(-60, 60, 5) + rng.uniform(-1, 1) if line else rng.uniform(-100, 100, 3)
    pts = random_chain(rng, n, modes, free, kind, omegas=omegas, e_scale=(0.5 * e, 2 * e))
    nc, status = run_decide(pts)
    assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), f"decide_block {case}")
    assert_decided_agree(pts, run_certify(pts, grid=True), f"certify {case}")


@st.composite
def corner_chains(draw):
    """Structural corners random draws never produce (issue 32): kappa = 2 (beta = 0: a root at 0, no pole) in some
    bodies, one cavity shape shared by some or all bodies, lines through omega = 0, ideal joints, free chains."""
    n = draw(st.integers(2, 8))
    modes = draw(st.integers(1, 3))
    free = draw(st.booleans())
    kind = draw(st.sampled_from(["mixed", "identical", "zerok"]))
    corner = draw(st.sampled_from(["kappa2", "shared", "some-shared", "kappa2-shared"]))
    return n, modes, free, kind, corner, draw(st.integers(0, 2**32 - 1))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(corner_chains())
def test_property_corner_labels_are_exact(case):
    n, modes, free, kind, corner, seed = case
    rng = np.random.default_rng(seed)
    pts = random_chain(rng, n, modes, free, kind, omegas=np.linspace(-60, 60, 5))  # omega = 0 is the middle point
    if corner.startswith("kappa2"):
        pts.kappa[:, ::2, 0] = 2.0
    if corner.endswith("shared"):
        upto = n if corner in ("shared", "kappa2-shared") else max(1, n // 2)
        pts.kappa[:, :upto] = pts.kappa[:, :1]
    nc, status = run_decide(pts)
    assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), f"decide_block {case}")
    assert_decided_agree(pts, run_certify(pts, grid=True), f"certify {case}")


def test_kappa_two_is_decided_by_the_kernels_not_exactly():
    """The sphere's mode (kappa = 2) in one body of eight: its beta is 0, so prod Q has a root at 0 that Phi does
    not (no pole there).  Counted among the exact zero roots, it leaves the inertia count whole: no point goes to
    exact arithmetic (before, every one did, at ~40 ms a point)."""
    rng = np.random.default_rng(seed_of("kappa2", 8))
    pts = random_chain(rng, 8, 3, False, "mixed", omegas=np.linspace(1, 150, 12))
    pts.kappa[:, 3, 0] = 2.0
    nc, status = run_decide(pts)
    assert not np.any(status == kernels.UNDECIDED)
    assert nc.tolist() == [exact_nc(pts, p) for p in range(12)]


def test_tiny_liquid_modes_are_decided_by_the_kernels_not_exactly():
    """E -> 0 (issue 32's corner): each liquid root sits within a few hundred ulps of its pole, too close for a
    separator between them.  The sign change of p across the pole's interval proves the root; before, a fifth of
    such points at n = 8 went to exact arithmetic.  Every label against exact arithmetic."""
    rng = np.random.default_rng(seed_of("tinyE", 8))  # a chain whose line crosses N_c = 0, 1, 2, 3
    pts = random_chain(rng, 6, 3, False, "mixed", omegas=np.linspace(-150, 150, 24), e_scale=(1e-14, 3e-12))
    nc, status = run_decide(pts)
    assert not np.any(status == kernels.UNDECIDED)
    assert nc.tolist() == [exact_nc(pts, p) for p in range(24)]
    assert len(set(nc.tolist())) > 1


def _real_bounds(pts: PointArrays, p: int, z_of):
    """(exact real roots of p, the cheap count, the full count, suspects left by the cheap count) for the
    approximations ``z_of(z, d, poles)`` (z: the linearisation's eigenvalues without the m exact zeros)."""
    body, joint, g, E, kappa, nmodes, free, parent, at = pts.kernel_args()
    n = body.shape[1]
    ws = certify.allocate(n, nmodes, parent)
    pws, C, Mo, wr, wi, vdummy, z, Sm, Sr, feat, done = ws.pws, ws.C, ws.Mo, ws.wr, ws.wi, ws.vdummy, ws.z, ws.Sm, ws.Sr, ws.feat, ws.done
    m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, pws, False)
    degree = C.shape[0]
    d = degree - m
    assert pencil.linearisation(body[p], E[p], nmodes, parent, pws, C, Mo)
    assert kernels.approximations.eigenvalues(C, wr, wi, vdummy, z, degree, m)
    poles = np.array([-pws.beta[0, k, l] for k in range(n) for l in range(nmodes[k])])
    z[:d] = z_of(z[:d].copy(), d, poles)
    lead_nu = kernels.disks.lead_bound(pws, n, Sm, Sr)[3]
    args = (z, d, m, lead_nu, body[p], E[p], nmodes, parent, pws, feat, Sm, Sr, done)
    cheap = max(m, certify._real_roots_at_least(*args, certify.COARSE)[0])
    suspects = int(done[:d].sum())
    full = max(m, max(certify._real_roots_at_least(*args, placement)[0] for placement in (certify.FINE, certify.POLES)))
    return exact.count_real_roots(exact_poly(pts, p)), cheap, full, suspects


@pytest.mark.parametrize("kind,e_scale", [("mixed", (1e-5, 3e-3)), ("identical", (1e-5, 3e-3)), ("mixed", (1e-14, 3e-12)),
                                          ("zerok", (1e-5, 3e-3))])
def test_separators_between_roots_alone_count_no_more_than_the_exact_real_roots(kind, e_scale):
    """The cheap count (separators between the approximations that may be real, none beside the poles) is a
    lower bound of the real roots whatever the approximations: accurate ones (then it finds them all, or
    leaves suspects for the count with the poles fenced), and approximations put on the poles and at random
    (a pole's jump in nu must never be counted as a root)."""
    rng = np.random.default_rng(seed_of("separators", kind, e_scale))
    found = 0
    for trial in range(10):
        pts = random_chain(rng, int(rng.integers(2, 6)), int(rng.integers(1, 4)), bool(trial % 2), kind,
                           npts=1, e_scale=e_scale)
        real, cheap, full, suspects = _real_bounds(pts, 0, lambda z, d, poles: z)
        assert cheap <= real and full <= real, (kind, trial, real, cheap, full)
        assert cheap == real or suspects > 0, (kind, trial, real, cheap, suspects)
        found += cheap == real

        def on_poles(z, d, poles):
            out = rng.uniform(-200, 200, d) + 0j
            k = min(d, 2 * len(poles))
            out[:k] = np.repeat(poles, 2)[:k] * (1 + np.tile([1e-9, -1e-9], len(poles))[:k])
            return out

        real, cheap, full, _ = _real_bounds(pts, 0, on_poles)
        assert cheap <= real and full <= real, ("on the poles", kind, trial, real, cheap, full)
    assert found >= 5  # the cheap count is not only safe but finds the real roots of most points


# ---------------------------------------------------------------------------------------------
# slow: a larger sweep and a bounds-checked run


SLOW_SWEEP = [(n, modes, free, kind) for n, modes in ((6, 2), (6, 4), (8, 2), (8, 4), (10, 2), (12, 2))
              for free in (False, True) for kind in ("mixed", "identical")] + [(8, 3, False, "split"), (8, 2, True, "zerok"),
                                                                              (6, 2, False, "identical-tiny-liquid"), (8, 4, True, "identical-tiny-liquid"),
                                                                              (16, 2, False, "mixed"), (16, 2, True, "identical")]


@pytest.mark.slow
@pytest.mark.parametrize("n,modes,free,kind", SLOW_SWEEP)
def test_slow_sweep_decide_block_agrees_with_exact(n, modes, free, kind):
    rng = np.random.default_rng(seed_of("slow", n, modes, free, kind))
    tiny = kind.endswith("tiny-liquid")
    pts = random_chain(rng, n, modes, free, kind.split("-")[0], omegas=np.linspace(-80, 80, 20) + rng.uniform(-1, 1),
                       e_scale=(1e-12, 1e-11) if tiny else (1e-5, 3e-3))
    nc, status = run_decide(pts)
    assert_decided_agree(pts, list(zip(nc.tolist(), status.tolist())), f"slow decide_block {n=} {modes=} {free=} {kind}")


_BOUNDSCHECK_SCRIPT = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    sys.path.insert(0, {scripts!r})
    from bench_kernel import random_points
    from stabmap import kernels
    out = {{}}
    for n, modes in ((3, 2), (6, 4), (8, 4)):
        pts = random_points(np.random.default_rng(n * 10 + modes), 50, n, modes)
        nc = np.empty(50, np.int16); st = np.empty(50, np.int8)
        kernels.decide_block(*pts.kernel_args(), nc, st)
        out[f"{{n}},{{modes}}"] = [nc.tolist(), st.tolist()]
    print(json.dumps(out))
    """
)


@pytest.mark.slow
def test_bounds_checked_run_agrees_with_normal_run(tmp_path, monkeypatch):
    scripts = str(Path(__file__).resolve().parent.parent / "scripts")
    script = _BOUNDSCHECK_SCRIPT.format(scripts=scripts)
    # The checked build's cost is its compilation; LLVM's optimisation passes are a third of it and change no index
    # checked (the checks are emitted before them) nor any IEEE operation (fastmath is off): NUMBA_OPT=0.
    env = dict(os.environ, STABMAP_NUMBA_CACHE="0", NUMBA_BOUNDSCHECK="1", NUMBA_OPT="0")
    checked = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=1800)
    assert checked.returncode == 0, checked.stderr[-3000:]
    # The normal run in this process, whose kernels are compiled or loaded already: a second interpreter would only
    # load them again.
    normal = io.StringIO()
    monkeypatch.setattr(sys, "path", list(sys.path))  # the script prepends scripts/
    with contextlib.redirect_stdout(normal):
        exec(compile(script, "boundscheck-script", "exec"), {"__name__": "__normal_run__"})
    assert json.loads(checked.stdout.strip().splitlines()[-1]) == json.loads(normal.getvalue().strip().splitlines()[-1])


def test_a_point_refused_before_prepare_leaves_no_stale_structure():
    # Review finding: certify returned before preparing a point with an extreme parameter, and the next point
    # of the same structure reused the workspace's M and K of an earlier point (another g): a proved wrong N_c.
    base = random_chain(np.random.default_rng(5), 4, 3, False, npts=1, omegas=[3.0])  # degree 20: no Sturm first
    E = np.repeat(base.E, 3, 0).copy()
    E[1, 0, 0] = 1e-60  # outside the certificate's range: left to the coefficient path and exact arithmetic
    pts = PointArrays(np.repeat(base.body, 3, 0), np.repeat(base.joint, 3, 0), np.array([9.81, -9.81, -9.81]), E,
                      np.repeat(base.kappa, 3, 0), base.nmodes, False)
    nc, st = run_decide(pts)
    for p in range(3):
        if st[p] != kernels.UNDECIDED:
            assert nc[p] == exact_nc(pts, p), (p, nc, st)
    assert st[2] in (DECIDED_INERTIA, DECIDED_DISKS, DECIDED_ALLATONCE)


def test_root_inclusion_bound_does_not_underflow_on_clustered_roots():
    # Second review: 12 identical free bodies, every pole near 0 (omega = -7.2e-4): clusters of roots near 1e-4.
    # |p(z)| was bounded as sqrt(re^2 + im^2), whose squares underflowed, so the coefficient path's disks came out
    # too small and "proved" 12 pairs that do not exist (exact: 0).
    n = 12
    body = np.empty((1, n, 6))
    body[...] = (2.4186391540356604, 1.5368970226939508e-02, 4.5347205456361020e-02, 1.3465430947798251e-01,
                 2.6930861895596503e-01, -7.2225599429387444e-04)
    joint = np.full((1, n), 74.48807794494027)
    joint[0, 0] = 0.0
    E = np.full((1, n, 2), 3.287220276322821e-10)
    kappa = np.broadcast_to(np.array([-1.8625132868234333, 1.744097794022779]), (1, n, 2)).copy()
    pts = PointArrays(body, joint, np.zeros(1), E, kappa, np.full(n, 2, np.int64), True)
    exact_label = exact_nc(pts, 0)
    assert exact_label == 0
    for decide in (kernels.decide_block, kernels.count_block):
        nc, st = np.empty(1, np.int16), np.empty(1, np.int8)
        decide(*pts.kernel_args(), nc, st)
        assert st[0] == kernels.UNDECIDED or nc[0] == exact_label, (decide, nc, st)
