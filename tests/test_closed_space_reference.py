"""The spatial reference (tests/closed_space_reference.py) against itself, the planar reference
(tests/closed_reference.py), its own closed forms and known facts (Michell's twisted ring).  Nothing of stabmap."""

from __future__ import annotations

import random

import closed_reference as planar
import closed_space_reference as S
import mpmath as mp
import pytest

F = mp.mpf


def rnd(rng, a, b):
    return F(a) + (F(b) - F(a)) * F(rng.random())


# ------------------------------------------------------------------------------------------------ energy
def _quat(axis, t):
    q = [mp.cos(t / 2), F(0), F(0), F(0)]
    q[1 + axis] = mp.sin(t / 2)
    return q


def _qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]


def _quaternion_energy(x, c1sq, c2sq, h):
    """U from unit quaternions (another path): U_k = (2/h)[c1^2 (q1^2 + q2^2) + c2^2 q3^2] of q_(k-1)^* q_k."""
    th, ps, ph = S.unpack(x)
    qs = [_qmul(_qmul(_quat(0, a), _quat(1, b)), _quat(2, c)) for a, b, c in zip(th, ps, ph)]
    U = []
    for k in range(len(qs)):
        a = qs[k - 1]
        q = _qmul([a[0], -a[1], -a[2], -a[3]], qs[k])
        U.append(2 * (c1sq * (q[1] ** 2 + q[2] ** 2) + c2sq * q[3] ** 2) / h)
    return mp.fsum(U), qs


def test_the_matrix_energy_is_the_quaternion_energy_and_c1_equal_c2_is_one_minus_cos():
    rng = random.Random(3)
    with mp.workdps(S.DPS):
        for _ in range(20):
            n = rng.randint(3, 8)
            x = [rnd(rng, -3, 3) for _ in range(3 * n)]
            c1sq, c2sq, h = rnd(rng, 0.1, 5), rnd(rng, 0.1, 5), rnd(rng, 0.2, 2)
            Uq, qs = _quaternion_energy(x, c1sq, c2sq, h)
            assert abs(S.energy(x, c1sq, c2sq, h) - Uq) < F(10) ** -40
            A, B = S.energy_parts(x, h)
            assert abs(c1sq * A + c2sq * B - Uq) < F(10) ** -40
            # c1 = c2 = c: (c^2/h) sum (1 - cos alpha), alpha = 2 acos |q0| of the relative rotation
            alphas = []
            for k in range(n):
                a = qs[k - 1]
                q0 = _qmul([a[0], -a[1], -a[2], -a[3]], qs[k])[0]
                alphas.append(2 * mp.acos(min(F(1), abs(q0))))
            assert abs(S.energy(x, c1sq, c1sq, h) - c1sq / h * mp.fsum(1 - mp.cos(al) for al in alphas)) < F(10) ** -35


def test_in_the_plane_the_energy_is_the_planar_energy_for_every_c2():
    rng = random.Random(5)
    for _ in range(10):
        n = rng.randint(3, 9)
        theta = [rnd(rng, -4, 4) for _ in range(n)]
        c1sq, h = rnd(rng, 0.1, 5), rnd(rng, 0.2, 2)
        for c2sq in (F("0.01"), F(1), F(30)):
            assert abs(S.energy(S.pack(theta), c1sq, c2sq, h) - planar.energy(theta, c1sq, h)) < F(10) ** -35


def test_the_chart_and_the_closure_are_what_they_say():
    rng = random.Random(11)
    with mp.workdps(S.DPS):
        th, ps, ph = rnd(rng, -3, 3), rnd(rng, -1, 1), rnd(rng, -3, 3)
        Q = S.frames([th, ps, ph])[0]
        e3 = [mp.sin(ps), -mp.sin(th) * mp.cos(ps), mp.cos(th) * mp.cos(ps)]
        assert max(abs(Q[i][2] - e3[i]) for i in range(3)) < F(10) ** -45
        # Q^T Q = 1, det Q = 1
        assert max(abs(mp.fsum(Q[k][i] * Q[k][j] for k in range(3)) - (i == j)) for i in range(3) for j in range(3)) < F(10) ** -45
        assert abs(mp.det(mp.matrix(Q)) - 1) < F(10) ** -45
        # the analytic Jacobian against differences
        n = 5
        x = [rnd(rng, -2, 2) for _ in range(3 * n)]
        L = [rnd(rng, 0.5, 2) for _ in range(n)]
        loops = [[0, 1, 2, 3, 4]]
        J = S.closure_jacobian(x, L, loops)
        e = F(10) ** -20
        for c in range(3 * n):
            xp, xm = list(x), list(x)
            xp[c] += e
            xm[c] -= e
            d = [(a - b) / (2 * e) for a, b in zip(S.closure(xp, L, loops), S.closure(xm, L, loops))]
            assert max(abs(d[r] - J[r, c]) for r in range(3)) < F(10) ** -30


# ------------------------------------------------------------------------------------------------ the planar block
PLANAR_CASES = [("figure-eight-4", "0.5", None, 1), ("figure-eight-6", "5.5", None, 1), ("figure-eight-6", "7", None, 1), ("hinge", "1.2", None, 1), ("hinge", "1.6", None, 1), ("hinge-straight", "1.0", None, 1)]
PLANAR_CASES += [("ring", "1", n, j) for n in range(5, 13) for j in range(1, (n + 1) // 2)]
PLANAR_CASES += [("ring", "0.5", n, 1) for n in (6, 8, 10, 12)] + [("ring", "2.5", 6, 2)]


@pytest.mark.parametrize("fam,ratio,n,j", PLANAR_CASES)
def test_the_in_plane_block_is_the_planar_probe(fam, ratio, n, j):
    x, L, loops = S.family(fam, F(ratio), n, j)
    theta = S.unpack(x)[0]
    Qp = planar.probe(theta, L, loops)
    inp, _ = S.split_basis(x, L, loops)
    assert len(inp) == Qp.rows + 1  # + the rotation about x
    red = S.remove_symmetries(inp, x)
    assert len(red) == len(inp) - 1
    Q = S.probe(x, L, loops, 1, F("0.37"), 1, red)  # c1^2 = h = 1: the planar probe's units; c2 plays no part
    ev, evp = S.eigenvalues(Q), S.eigenvalues(Qp)
    assert max([abs(a - b) for a, b in zip(ev, evp)] + [0]) < F(10) ** -14
    full = S.probe(x, L, loops, 1, F("0.37"), 1, inp)
    assert S.inertia(full, 1) == planar.inertia(Qp)


@pytest.mark.parametrize("fam,ratio", [("figure-eight-4", "0.5"), ("figure-eight-6", "7"), ("hinge", "1.2"), ("hinge-straight", "1.0")])
def test_the_planar_equilibria_are_equilibria_in_space_with_the_planar_forces(fam, ratio):
    c1sq, h = F("2.5"), F("0.7")
    L = planar.lengths_of(fam, F(ratio))
    theta, forces = planar.closed_form(fam, L, c1sq=c1sq, h=h)
    loops = planar.loops_of(fam, len(L))
    for c2sq in (F("0.2"), F(4)):
        R, res = S.multipliers(S.pack(theta), L, loops, c1sq, c2sq, h)
        assert res < F(10) ** -30
        for Ri, (Ry, Rz) in zip(R, forces):
            assert abs(Ri[0]) < F(10) ** -30 and abs(Ri[1] - Ry) < F(10) ** -30 and abs(Ri[2] - Rz) < F(10) ** -30


# ------------------------------------------------------------------------------------------------ symmetries, split
def _zero_space_is_the_symmetries(x, L, loops, c1sq, c2sq):
    basis = S.tangent_basis(x, L, loops)
    Q = S.probe(x, L, loops, c1sq, c2sq, None, basis)
    ev = S.eigenvalues(Q)
    zeros = [e for e in ev if abs(e) <= S.TOL]
    assert len(zeros) == 4 and max(abs(e) for e in zeros) < F(10) ** -17
    assert min(abs(e) for e in ev if abs(e) > S.TOL) > F(10) ** -3
    # the symmetry vectors lie in the tangent space and the probe kills them
    for s in S.symmetry_vectors(x):
        coef = mp.matrix([mp.fsum(a * b for a, b in zip(s, v)) for v in basis])
        back = [mp.fsum(coef[i] * basis[i][c] for i in range(len(basis))) for c in range(len(s))]
        assert max(abs(a - b) for a, b in zip(s, back)) < F(10) ** -30
        assert mp.norm(Q * coef) < F(10) ** -17
    return Q


def test_exactly_four_symmetry_zeros_at_a_stable_twisted_ring():
    x, L, loops = S.twisted_ring(7, 1, 1)  # Gamma = 0.7/1.3, below the critical value (0.83 < Gamma_c(7) < 1.38)
    Q = _zero_space_is_the_symmetries(x, L, loops, F("1.3"), F("0.7"))
    assert S.inertia(Q, 4) == (0, 0)


def test_exactly_four_symmetry_zeros_at_a_stable_figure_eight_and_the_reflection_split():
    x, L, loops = S.family("figure-eight-6", F(7))
    _zero_space_is_the_symmetries(x, L, loops, F(1), F(2))
    # In the basis in-plane + out-of-plane the probe is block diagonal (reflection x -> -x) and the inertias add.
    inp, outp = S.split_basis(x, L, loops)
    c2sq = F("0.3")
    Q = S.probe(x, L, loops, 1, c2sq, None, inp + outp)
    a = len(inp)
    assert max(abs(Q[i, k]) for i in range(a) for k in range(a, Q.rows)) < F(10) ** -17
    (pi, pn), (oi, on) = S.split_inertia(x, L, loops, 1, c2sq)
    assert S.inertia(Q, 4) == (pi + oi, pn + on) == (1, 0)


# ------------------------------------------------------------------------------------------------ observations
def _split(fam, ratio, c2values, n=None, j=1):
    """split inertias for several c2^2 (c1^2 = 1) from one probe of A and B per block."""
    x, L, loops = S.family(fam, F(ratio), n, j)
    inp, outp = S.split_basis(x, L, loops)
    A1, B1 = S.probe_parts(x, L, loops, None, inp)
    A2, B2 = S.probe_parts(x, L, loops, None, outp)
    return [(S.inertia(A1 + F(c) * B1, 1), S.inertia(A2 + F(c) * B2, 3)) for c in c2values]


@pytest.mark.parametrize("j,expected", [(1, ((0, 0), (0, 0))), (2, ((0, 0), (2, 0)))])
def test_ring_10_in_space(j, expected):
    assert _split("ring", 1, ("0.1", "1", "10"), 10, j) == [expected] * 3
    assert S.ring_split_inertia_formula(10, j) == expected


def test_figure_eight_6_at_7_and_hinge_at_1_2_out_of_the_plane():
    assert _split("figure-eight-6", 7, ("0.1", "1")) == [((0, 0), (1, 0)), ((0, 0), (0, 0))]
    assert _split("hinge", "1.2", ("1", "10")) == [((0, 0), (1, 0)), ((0, 0), (0, 0))]


@pytest.mark.parametrize("fam,ratio,lo,hi,value", [("figure-eight-6", "7", "0.1", "1", "0.602110465649"), ("hinge", "1.2", "1", "10", "2.664")])
def test_critical_c2sq_of_figure_eight_6_and_hinge(fam, ratio, lo, hi, value):
    c = S.family_critical_c2sq(fam, F(ratio), lo=lo, hi=hi)
    assert F(lo) < c < F(hi) and abs(c - F(value)) < F(10) ** -12
    # unstable below, stable above, one more zero at it; the same for another c1^2 (only the ratio matters)
    for c1sq in (F(1), F("3.5")):
        below, at, above = (S.family_split_inertia(fam, F(ratio), c1sq * c * f, c1sq) for f in (1 - F(10) ** -7, 1, 1 + F(10) ** -7))
        assert (below[1], above[1]) == ((1, 0), (0, 0))
        assert at == ((0, 0), (0, 1))


# ------------------------------------------------------------------------------------------------ ring closed forms
def test_the_second_order_joint_energy_of_the_docstring():
    """U2_k (module docstring) against mp.diff of the matrix energy of one joint, random data."""
    rng = random.Random(17)
    with mp.workdps(S.DPS):
        for _ in range(8):
            d, c1sq, c2sq, h = rnd(rng, -3, 3), rnd(rng, 0.1, 4), rnd(rng, 0.1, 4), rnd(rng, 0.3, 2)
            a0, b0, a1, b1 = (rnd(rng, -1, 1) for _ in range(4))

            def U(t):
                x = [F(0), d, t * a0, t * a1, t * b0, t * b1]  # two bodies: theta (0, d), psi, phi
                Q = S.frames(x)
                omc, tw = S._joint_parts(Q[0], Q[1])
                return (c1sq * omc + (c2sq - c1sq) * tw) / h

            u2 = c1sq / (2 * h) * ((a1 - a0) ** 2 - (1 - mp.cos(d)) * (a0**2 + a1**2)) + c2sq / (2 * h) * (mp.cos(d / 2) * (b1 - b0) + mp.sin(d / 2) * (a0 + a1)) ** 2
            assert abs(mp.diff(U, 0, 2) / 2 - u2) < F(10) ** -25


@pytest.mark.parametrize("n,j,c1sq,c2sq,h", [(10, 2, "1", "3", "1"), (7, 1, "2", "0.5", "0.8"), (9, 3, "1", "1", "1")])
def test_ring_closed_forms_against_the_split_probe(n, j, c1sq, c2sq, h):
    x, L, loops = S.family("ring", 1, n, j)
    P, O = S.split_probe(x, L, loops, F(c1sq), F(c2sq), F(h))
    inp, outp = S.ring_spectrum(n, j, F(c1sq), F(c2sq), F(h))
    assert max(abs(a - b) for a, b in zip(S.eigenvalues(P) + S.eigenvalues(O), inp + outp)) < F(10) ** -17
    assert (S.inertia(P, 1), S.inertia(O, 3)) == S.ring_split_inertia_formula(n, j)


@pytest.mark.parametrize("n", range(5, 13))
def test_ring_closed_forms_against_the_fourier_blocks(n):
    for j in range(1, (n + 1) // 2):
        c1sq, c2sq = F("1.7"), F("0.45")
        inp, outp = S.ring_spectrum(n, j, c1sq, c2sq, 1)
        ev = S.ring_spectrum_probe(n, j, 0, c1sq, c2sq)
        assert max(abs(a - b) for a, b in zip(ev, sorted(inp + outp))) < F(10) ** -17
        (pi, pn), (oi, on) = S.ring_split_inertia_formula(n, j)
        assert S.inertia(mp.diag(ev), 4) == (pi + oi, pn + on)
        assert oi == 2 * (j - 1)
        for p in range(1, n):  # the determinant of K(p)
            a, b, c = S.ring_K(n, j, p, c1sq, c2sq, 1)
            d, mu = 2 * mp.pi * j / n, 2 * mp.pi * p / n
            assert abs(a * c - b**2 - 2 * c1sq * c2sq * (1 + mp.cos(d)) * (1 - mp.cos(mu)) * (mp.cos(d) - mp.cos(mu))) < F(10) ** -35


# ------------------------------------------------------------------------------------------------ twisted ring
def test_the_fourier_blocks_are_the_full_probe_of_a_twisted_ring():
    x, L, loops = S.twisted_ring(8, 1, 1)
    c1sq, c2sq = F("1.2"), F("0.8")
    ev = S.eigenvalues(S.probe(x, L, loops, c1sq, c2sq))
    assert max(abs(a - b) for a, b in zip(ev, S.ring_spectrum_probe(8, 1, 1, c1sq, c2sq))) < F(10) ** -17


PROTOTYPE = {(6, 1): "0.8348", (8, 1): "1.3793", (12, 1): "1.60746", (12, 2): "1.59777", (16, 1): "1.66674", (24, 1): "1.70438"}
GAMMA = {}


@pytest.mark.parametrize("n,m", list(PROTOTYPE))
def test_critical_gamma_of_the_twisted_ring(n, m):
    g = S.critical_gamma(n, 1, m)
    GAMMA[(n, m)] = g
    assert abs(g - F(PROTOTYPE[(n, m)])) < F(10) ** -4
    assert g < mp.sqrt(3)
    # stable just below, unstable just above (the blocks, symmetries removed)
    r = g / m
    blocks = S.ring_blocks(n, 1, m, symmetries=False)
    for f, stable in ((1 - F(10) ** -6, True), (1 + F(10) ** -6, False)):
        neg = sum(S.inertia(QA + r * f * QB)[0] for _, QA, QB in blocks)
        assert (neg == 0) == stable


def test_critical_gamma_increases_with_n_towards_sqrt_3():
    gs = [S.critical_gamma(n, 1, 1) for n in (6, 8, 10, 12, 16, 20)]
    assert all(a < b for a, b in zip(gs, gs[1:])) and gs[-1] < mp.sqrt(3) and mp.sqrt(3) - gs[-1] < F("0.05")


@pytest.mark.slow
def test_critical_gamma_up_to_48_bodies():
    gs = [S.critical_gamma(n, 1, 1) for n in (24, 32, 48)]
    assert all(a < b for a, b in zip(gs, gs[1:])) and gs[-1] < mp.sqrt(3) and mp.sqrt(3) - gs[-1] < F("0.01")


@pytest.mark.parametrize("n,j,m,c1sq,c2sq,h", [(8, 1, 1, "1", "1", "1"), (8, 1, 1, "2", "0.3", "0.7"), (12, 1, 2, "0.5", "3", "1"), (9, 2, 1, "1", "2.5", "2"), (7, 3, 2, "4", "0.1", "1.5")])
def test_the_twisted_ring_force_is_normal_and_independent_of_c1(n, j, m, c1sq, c2sq, h):
    x, L, loops = S.twisted_ring(n, j, m)
    (R,), res = S.multipliers(x, L, loops, F(c1sq), F(c2sq), F(h))
    assert res < F(10) ** -30  # an equilibrium for every c1, c2
    exp = S.twisted_ring_force(n, j, m, F(c1sq), F(c2sq), F(h))
    assert max(abs(a - b) for a, b in zip(R, exp)) < F(10) ** -30
