"""The sign-aware (Krein-type) count of real roots (kernels/certify.py: ``nu_h``, ``_krein_count``) against exact
arithmetic.

nu_H(x) = nu(Phi(x)) + #{kl : c_kl (x + beta_kl) < 0} is the inertia of the pole-free bordered form H(x)
(Haynsworth's inertia additivity; docs/certification.md, section 4).  Checked here, independently of the kernels:
- nu_H against the exact inertia of H(x) built in rationals from tests/reference.py (Descartes' rule on its exact
  characteristic polynomial, python-flint), and the kernel's sign of c_kl against the exact c_kl;
- the count across an interval against the exact real roots of p inside it, with multiplicity (square-free
  factors and exact Sturm sequences), for separators at random, next to roots (1e-12 relative), next to poles,
  on chains whose Krein types interleave (kappa = 2, identical bodies, halves of identical bodies), free chains,
  omega -> 0, E -> 0 and modes with E exactly 0;
- that a cluster of real roots of one type is counted whole from plain float approximations (the low-spin roots
  of paper-n3-fixed: no separator inside the cluster).
"""

from __future__ import annotations

import math
import random
from fractions import Fraction

import flint
import numpy as np
import pytest
from test_certify import _exact_negative_eigenvalues, _exact_pencil, _is_singular, exact_poly, make_points, random_chain, seed_of

from stabmap.kernels import approximations, certify, disks, pencil
from stabmap.systems.gyroscopes.points import PointArrays

F = Fraction


def _exact_h(pen, x: Fraction):
    """H(x) exactly, and the exact c_kl in the kernel's mode order (0 where the mode has no row in H)."""
    M, G, K, liquid, omega = pen
    n = len(M)
    rows = [(k, beta, e) for k in range(n) for beta, e in liquid[k] if beta != 0 and e != 0]
    N = n + len(rows)
    H = [[F(0)] * N for _ in range(N)]
    for i in range(n):
        for j in range(n):
            H[i][j] = x * x * M[i][j] - K[i][j]
        H[i][i] += x * G[i]
    cs = []
    for k in range(n):
        for beta, e in liquid[k]:
            if beta == 0:  # no pole: x^2 (x + omega) e / x
                H[k][k] -= x * (x + omega[k]) * e
                cs.append(F(0))
            elif e == 0:
                cs.append(F(0))
            else:
                w = omega[k] - beta
                cs.append(e * beta * beta * w)
    for r, (k, beta, e) in enumerate(rows):
        w = omega[k] - beta
        c = e * beta * beta * w
        H[k][k] -= e * (x * x + w * x - beta * w)
        H[k][n + r] = H[n + r][k] = c
        H[n + r][n + r] = c * (x + beta)
    return H, cs


def _workspace(pts: PointArrays, p: int = 0):
    body, joint, g, E, kappa, nmodes, free, parent, at = pts.kernel_args()
    n = body.shape[1]
    ws = certify.allocate(n, nmodes, parent)
    m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws.pws, False)
    return ws, m, (body[p], E[p], nmodes, parent)


def _exact_roots_in(p: flint.fmpq_poly, a: Fraction, b: Fraction) -> int:
    """Real roots of p in the open interval (a, b), with multiplicity: Sturm sequences of the square-free factors."""
    total = 0
    for f, mult in p.factor_squarefree()[1]:
        chain = [f, f.derivative()]
        while chain[-1].degree() > 0:
            r = -(chain[-2] % chain[-1])
            if r == 0:
                break
            chain.append(r)

        total += mult * (_sign_changes(chain, a) - _sign_changes(chain, b))
    return total


def _sign_changes(chain: list, x: Fraction) -> int:
    q = flint.fmpq(x.numerator, x.denominator)
    signs = [v > 0 for v in (c(q) for c in chain) if v != 0]
    return sum(1 for s, t in zip(signs, signs[1:], strict=False) if s != t)


def _value(p: flint.fmpq_poly, x: Fraction):
    return p(flint.fmpq(x.numerator, x.denominator))


def _chain(rng, kind: str) -> PointArrays:
    """Random chains of the kinds named in the module docstring (one point each)."""
    n = int(rng.integers(1, 5))
    modes = int(rng.integers(1, 4))
    free = kind == "free"
    base = {"kappa2": "mixed", "halfsame": "identical", "free": "mixed", "omega0": "mixed", "tinyE": "mixed",
            "E0": "mixed"}.get(kind, kind)
    e_scale = (1e-14, 3e-12) if kind == "tinyE" else (1e-5, 3e-3)
    omegas = [0.0] if kind == "omega0" else None
    pts = random_chain(rng, n, modes, free, base, npts=1, omegas=omegas, e_scale=e_scale)
    body, E, kappa = pts.body.copy(), pts.E.copy(), pts.kappa.copy()
    if kind == "kappa2":
        kappa[:, ::2, 0] = 2.0
    elif kind == "halfsame" and n > 1:  # the lower half its own bodies, the upper half identical
        body[:, : n // 2] = rng.uniform(0.05, 1.0, (n // 2, 6)) * [3, 0.1, 0.1, 0.4, 0.6, 0] + [0.2, 0, 0, 0, 0, 0]
        body[:, :, 5] = body[0, -1, 5]
    elif kind == "E0":
        E[:, rng.integers(0, n), 0] = 0.0
    # rebuilt, so that the lengths derived from the bodies are those of the new ones
    return make_points(body, pts.joint[0], pts.g[0], E, kappa, pts.nmodes, pts.free)


KINDS = ("mixed", "identical", "halfsame", "kappa2", "free", "zerok", "split", "omega0", "tinyE", "E0")


@pytest.mark.parametrize("kind", KINDS)
def test_nu_h_is_the_exact_inertia_of_the_bordered_form(kind):
    rng = np.random.default_rng(seed_of("nu_h", kind))
    checked = 0
    for _ in range(6):
        pts = _chain(rng, kind)
        ws, m, (body, E, nmodes, parent) = _workspace(pts)
        pen = _exact_pencil(pts, 0)
        _, cs = _exact_h(pen, F(1))
        signs = [int(ws.pws.krein[k, l]) for k in range(body.shape[0]) for l in range(nmodes[k])]
        assert signs == [(c > 0) - (c < 0) for c in cs], (kind, signs, cs)
        scale = 1.0 + float(np.abs(pts.body[0, :, 5]).max())
        for x in rng.uniform(-2 * scale, 2 * scale, 8):
            H, _ = _exact_h(pen, F(float(x)))
            if _is_singular(H):
                continue
            nu, _ = certify.nu_h(float(x), body, E, nmodes, parent, ws.pws, ws.Sm, ws.Sr)
            if nu >= 0:
                assert nu == _exact_negative_eigenvalues(H), (kind, float(x))
                checked += 1
    assert checked >= 20  # proofs, not only refusals


def _separators(rng, p: flint.fmpq_poly, pen, scale: float) -> list[float]:
    """Separators at random, within 1e-12 (relative) of the exact real roots, and next to the poles."""
    near = []
    for root, _ in p.numer().complex_roots():
        if root.imag.is_zero():
            r = float(root.real.mid())
            near += [r * (1 - 1e-12) - 1e-300, r * (1 + 1e-12) + 1e-300]
    for modes in pen[3]:
        for beta, _ in modes:
            if beta != 0:
                near += [float(-beta) * (1 + s) for s in (1e-9, -1e-9, 1e-3, -1e-3)]
    picks = list(rng.uniform(-2 * scale, 2 * scale, 6)) + near
    return sorted(set(random.Random(int(rng.integers(1 << 30))).sample(picks, min(len(picks), 10))))


@pytest.mark.parametrize("kind", KINDS)
def test_count_across_an_interval_never_exceeds_its_exact_real_roots(kind):
    rng = np.random.default_rng(seed_of("krein interval", kind))
    intervals = exact_hits = 0
    for _ in range(5):
        pts = _chain(rng, kind)
        ws, m, (body, E, nmodes, parent) = _workspace(pts)
        pen = _exact_pencil(pts, 0)
        p = exact_poly(pts, 0)
        scale = 1.0 + float(np.abs(pts.body[0, :, 5]).max())
        seps = [-math.inf] + _separators(rng, p, pen, scale) + [math.inf]
        lead_nu = disks.lead_bound(ws.pws, body.shape[0], ws.Sm, ws.Sr)[3]
        bound = 10 ** 9  # beyond every root: the ends +-inf take their nu_H from the leading matrix
        d = ws.C.shape[0] - m  # deg p less the exact zero roots: the sign of p at -inf depends on it
        z = np.full(d, 1j)  # no approximations near the axis (they only mark suspects)
        for a, b in zip(seps, seps[1:], strict=False):
            fa, fb = F(max(a, -bound)), F(min(b, bound))
            if _value(p, fa) == 0 or _value(p, fb) == 0 or not a < b:
                continue
            sep = np.array([a, b])
            got, _ = certify._krein_count(z, d, m, lead_nu, body, E, nmodes, parent, ws.pws, sep, 2, ws.Sm, ws.Sr, ws.done)
            exact = _exact_roots_in(p, fa, fb)
            assert got <= exact, (kind, a, b, got, exact)
            intervals += 1
            exact_hits += got == exact and exact > 0
    assert intervals >= 15
    assert exact_hits >= 3  # the count proves roots, not only bounds them


def _approximations(pts: PointArrays, ws, m):
    """The linearisation's float eigenvalues (no polishing), as the cold start has them."""
    body, joint, g, E, kappa, nmodes, free, parent, at = pts.kernel_args()
    degree = ws.C.shape[0]
    assert pencil.linearisation(body[0], E[0], nmodes, parent, ws.pws, ws.C, ws.Mo)
    assert approximations.eigenvalues(ws.C, ws.wr, ws.wi, ws.vdummy, ws.z, degree, m)
    return degree - m


def test_a_cluster_of_one_type_is_counted_whole_at_low_spin():
    """paper-n3-fixed at omega in [1, 10]: its three liquid roots lie about 1e-6 apart (relative) with their triple
    pole.  Separators between groups of approximations alone (COARSE) prove every real root at nearly every point,
    and never more than the exact count."""
    import stabmap
    from stabmap.systems.gyroscopes.points import point_arrays

    scene = stabmap.example("paper-n3-fixed")
    rng = np.random.default_rng(seed_of("low spin"))
    omegas, masses = rng.uniform(1, 10, 30), 10 ** rng.uniform(-1, 1, 30)
    whole = evaluations = 0
    for om, m2 in zip(omegas, masses, strict=True):
        pts = point_arrays(scene, {"omega": np.array([om]), "m_2": np.array([m2])})
        ws, m, (body, E, nmodes, parent) = _workspace(pts)
        d = _approximations(pts, ws, m)
        lead_nu = disks.lead_bound(ws.pws, body.shape[0], ws.Sm, ws.Sr)[3]
        real, placed = certify._real_roots_at_least(ws.z, d, m, lead_nu, body, E, nmodes, parent, ws.pws, ws.feat, ws.Sm,
                                                    ws.Sr, ws.done, certify.COARSE)
        evaluations += placed
        exact = _exact_roots_in(exact_poly(pts, 0), F(-(10**9)), F(10**9))
        assert max(m, real) <= exact
        whole += max(m, real) == exact
    assert whole >= 27, whole
    assert evaluations <= 6 * len(omegas)  # separators only where the type changes (12 real roots at most)
