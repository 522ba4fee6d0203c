"""Independent reference for closed chains of elastic joints IN SPACE, written from the model's description and
nothing of stabmap (mpmath, 50 digits; it imports only the planar reference tests/closed_reference.py).

The model.  Body k (k = 0..n-1 here) has a frame Q_k in SO(3) and an axis e3_k = Q_k z of length h_k; every loop
closes, sum_{k in loop} h_k e3_k = 0.  Joint k joins bodies k-1 and k (cyclically); with P_k = Q_(k-1)^T Q_k,
cos a = (tr P - 1)/2 and u3 sin a = (P[1,0] - P[0,1])/2, its energy is

    U_k = (1/h) [ c1^2 (1 - cos a) + (c2^2 - c1^2) (P[1,0] - P[0,1])^2 / (4 (1 + cos a)) ]
        = (1/h) (1 - cos a) [ c1^2 (1 - u3^2) + c2^2 u3^2 ].

So U = c1^2 A + c2^2 B (A, B below do not depend on c1, c2): every second difference of U is the same
combination of those of A and B, which ``probe_parts`` returns once for all stiffnesses.

The chart.  Three angles per body, Q_k = Rx(theta_k) Ry(psi_k) Rz(phi_k); coordinates are flat lists of 3n numbers,
block by block: x[0:n] = theta, x[n:2n] = psi, x[2n:3n] = phi (``pack``/``unpack``).  psi = phi = 0 is the planar
twist-free configuration Q_k = Rx(theta_k), e3_k = (0, -sin theta_k, cos theta_k).  Its chart velocities are the
world angular velocities  w = theta' x + psi' Rx(theta) y + phi' e3 ; at psi = 0 these three axes are orthonormal
for every theta, so the chart is regular at every planar configuration.  (The order Ry(psi) Rx(theta) Rz(phi)
suggested with the model is NOT: at theta = +-pi/2 the axis of Ry and the axis e3 = -+y coincide (gimbal lock), and
the figure-eight-4 and the hinges have bodies at theta = +-pi/2.)  The reflection x -> -x acts as (theta, psi, phi)
-> (theta, -psi, -phi): at a planar twist-free point the in-plane directions are theta's, the out-of-plane ones
(psi, phi)'s, and the closures' Jacobian is block diagonal (theta moves y, z; psi moves x; phi moves nothing).

The probe.  ``probe`` is the matrix of second derivatives of U along curves kept closed by minimum-norm
Gauss-Newton (``project``), in an orthonormal basis of the closures' tangent space (``tangent_basis``, from an SVD),
by central second differences (diagonal) and 4-point mixed differences (off the diagonal), step eps = 1e-15 at 50
digits: truncation ~eps^2 = 1e-30, rounding ~1e-50/eps^2 = 1e-20, projection residual < 1e-45: entries good to
~1e-19 absolute (U and its second derivatives are O(1) here).  No multiplier and no Hessian formula enters; at an
equilibrium the curve's second-order part drops out (it is the Lagrangian's Hessian on the tangent space, in the
chart's Euclidean metric).  Zero eigenvalues: |ev| <= TOL = 1e-12.

The symmetries: the rigid rotations Q_k -> G Q_k (3) and the uniform spin Q_k -> Q_k Rz(s) (phi_k += s): the
reduced Hessian has 4 symmetry zeros, spatial nullity = zeros - 4.  At a planar twist-free equilibrium the rotation
about x is in-plane (theta_k += s), the rotations about y, z and the spin out-of-plane.

The rings (``ring_spectrum``), n equal bodies h_k = 1, winding j, delta = 2 pi j / n, no twist, no force.  Second
order in the out-of-plane coordinates (sympy, then by hand), per joint:

    U2_k = (c1^2/2h) [ (psi_k - psi_(k-1))^2 - (1 - cos delta)(psi_(k-1)^2 + psi_k^2) ]
         + (c2^2/2h) [ cos(delta/2) (phi_k - phi_(k-1)) + sin(delta/2) (psi_(k-1) + psi_k) ]^2 .

(bending of the axis, whose curvature is the angle between consecutive axes; twist = the frame's turn about the
axis, which a tilt of two consecutive bodies out of the plane of a bent joint changes by sin(delta/2) (psi sum)).
The closure force is zero, so the reduced Hessian is the Hessian of U on the tangent space; it is circulant, the
closure removes the constant psi (sum psi_k = 0, mode p = 0).  With psi_k = a w^k, phi_k = b w^k, w = exp(i mu),
mu = 2 pi p / n, the Hessian acts on mode p as the Hermitian 2x2 matrix

    K(p) = (1/h) [[ 2 c1^2 (cos delta - cos mu) + c2^2 (1 - cos delta)(1 + cos mu),  i c2^2 sin delta sin mu ],
                  [ -i c2^2 sin delta sin mu,  c2^2 (1 + cos delta)(1 - cos mu) ]],
    det K(p) = 2 c1^2 c2^2 (1 + cos delta)(1 - cos mu)(cos delta - cos mu) / h^2,

p = 1..n-1, and p = 0 contributes only phi = const (the spin, 0).  In the plane (theta_k = delta k + t_k): the
Hessian (c1^2/h) cos delta (cycle Laplacian), eigenvalues (2 c1^2/h) cos delta (1 - cos mu) for p != 0, +-j (the
closure removes p = +-j, p = 0 is the rotation about x).  Hence: out-of-plane index = #{p: cos mu > cos delta} =
2 (j - 1) for every c1, c2 > 0 (the trace is > 0), the zeros at p = +-j are the rotations about y and z (the other
eigenvalue there is 2 c2^2 sin^2 delta / h); in-plane index = n - 3 if cos delta < 0, else 0.  The untwisted ring
is stable in space iff j = 1 and cos(2 pi / n) > 0 (n >= 5).

The twisted ring Q_k = Rx(delta k) Rz(2 pi m k / n) is carried into itself by (shift k -> k+1, theta += delta,
phi += 2 pi m/n), which the chart turns into a plain shift of the coordinates: the reduced Hessian commutes with
the shift and is block diagonal on the real Fourier modes p = 0..n/2 (``ring_blocks``, checked against the full
probe in the tests).  Its force is normal to the plane, R = (R_x, 0, 0) with (sympy, then
5 sin b + 4 sin 2b + sin 3b = 4 sin b (1 + cos b)^2)

    R_x = dU/dpsi_k / h_k = c2^2 sin(2 pi j / n) sin(2 pi m / n) / (h h_1),

independent of c1 (``twisted_ring_force``; the grad U = R . grad closure of ``multipliers`` checks it).
"""

from __future__ import annotations

import functools

import mpmath as mp

import closed_reference as planar

DPS = 50
TOL = mp.mpf("1e-12")  # |eigenvalue| <= TOL counts as zero (the probe is good to ~1e-19)
EPS = mp.mpf("1e-15")  # the probe's step
SYMMETRIES = 4


def _dps(f):
    @functools.wraps(f)
    def wrapped(*args, **kwargs):
        with mp.workdps(max(DPS, mp.mp.dps)):
            return f(*args, **kwargs)

    return wrapped


# ------------------------------------------------------------------------------------------------ rotations
def Rx(t):
    c, s = mp.cos(t), mp.sin(t)
    return [[mp.mpf(1), mp.mpf(0), mp.mpf(0)], [mp.mpf(0), c, -s], [mp.mpf(0), s, c]]


def Ry(t):
    c, s = mp.cos(t), mp.sin(t)
    return [[c, mp.mpf(0), s], [mp.mpf(0), mp.mpf(1), mp.mpf(0)], [-s, mp.mpf(0), c]]


def Rz(t):
    c, s = mp.cos(t), mp.sin(t)
    return [[c, -s, mp.mpf(0)], [s, c, mp.mpf(0)], [mp.mpf(0), mp.mpf(0), mp.mpf(1)]]


def matmul(A, B):
    return [[mp.fsum(A[i][l] * B[l][j] for l in range(3)) for j in range(3)] for i in range(3)]


def pack(theta, psi=None, phi=None):
    n = len(theta)
    psi = [0] * n if psi is None else psi
    phi = [0] * n if phi is None else phi
    return [mp.mpf(t) for t in theta] + [mp.mpf(t) for t in psi] + [mp.mpf(t) for t in phi]


def unpack(x):
    n = len(x) // 3
    return list(x[:n]), list(x[n : 2 * n]), list(x[2 * n :])


def frames(x):
    """Q_k = Rx(theta_k) Ry(psi_k) Rz(phi_k), as 3x3 nested lists."""
    th, ps, ph = unpack(x)
    return [matmul(matmul(Rx(a), Ry(b)), Rz(c)) for a, b, c in zip(th, ps, ph)]


def axes(x):
    return [[Q[0][2], Q[1][2], Q[2][2]] for Q in frames(x)]


# ------------------------------------------------------------------------------------------------ energy
def _joint_parts(Qa, Qb):
    """(1 - cos a, (1 - cos a) u3^2) of P = Qa^T Qb, from the trace and P[1,0] - P[0,1]."""
    tr = mp.fsum(Qa[i][j] * Qb[i][j] for i in range(3) for j in range(3))
    p10 = mp.fsum(Qa[i][1] * Qb[i][0] for i in range(3))
    p01 = mp.fsum(Qa[i][0] * Qb[i][1] for i in range(3))
    one_minus_cos = (3 - tr) / 2
    cos_a = (tr - 1) / 2
    twist = (p10 - p01) ** 2 / (4 * (1 + cos_a))
    return one_minus_cos, twist


@_dps
def energy_parts(x, h=1):
    """(A, B) with U = c1^2 A + c2^2 B: A = sum (1 - cos a)(1 - u3^2) / h, B = sum (1 - cos a) u3^2 / h."""
    Q = frames(x)
    n = len(Q)
    A, B = [], []
    for k in range(n):
        omc, tw = _joint_parts(Q[k - 1], Q[k])
        A.append(omc - tw)
        B.append(tw)
    h = mp.mpf(h)
    return mp.fsum(A) / h, mp.fsum(B) / h


@_dps
def energy(x, c1sq=1, c2sq=1, h=1):
    """U = sum_k (1/h)[c1^2 (1 - cos a_k) + (c2^2 - c1^2)(P[1,0] - P[0,1])^2 / (4 (1 + cos a_k))]."""
    Q = frames(x)
    n = len(Q)
    c1sq, c2sq = mp.mpf(c1sq), mp.mpf(c2sq)
    terms = []
    for k in range(n):
        omc, tw = _joint_parts(Q[k - 1], Q[k])
        terms.append(c1sq * omc + (c2sq - c1sq) * tw)
    return mp.fsum(terms) / mp.mpf(h)


def _h(lengths, h):
    return min(mp.mpf(v) for v in lengths) if h is None else mp.mpf(h)


# ------------------------------------------------------------------------------------------------ closure
@_dps
def closure(x, lengths, loops):
    """sum_{k in loop} h_k e3_k, three components per loop (a flat list)."""
    E = axes(x)
    out = []
    for loop in loops:
        out += [mp.fsum(mp.mpf(lengths[k]) * E[k][c] for k in loop) for c in range(3)]
    return out


@_dps
def closure_jacobian(x, lengths, loops):
    """d closure / d x (3 rows per loop, 3n columns); e3 = (sin psi, -sin theta cos psi, cos theta cos psi)."""
    n = len(x) // 3
    th, ps, _ = unpack(x)
    J = mp.matrix(3 * len(loops), 3 * n)
    for i, loop in enumerate(loops):
        for k in loop:
            L = mp.mpf(lengths[k])
            ct, st, cp, sp = mp.cos(th[k]), mp.sin(th[k]), mp.cos(ps[k]), mp.sin(ps[k])
            # d/dtheta
            J[3 * i + 1, k] = -L * ct * cp
            J[3 * i + 2, k] = -L * st * cp
            # d/dpsi
            J[3 * i + 0, n + k] = L * cp
            J[3 * i + 1, n + k] = L * st * sp
            J[3 * i + 2, n + k] = -L * ct * sp
    return J


@_dps
def project(x, lengths, loops, steps=60):
    """x moved back onto the closures by minimum-norm Gauss-Newton steps x -= J^T (J J^T)^-1 g."""
    x = [mp.mpf(v) for v in x]
    tol = mp.mpf(10) ** (-(mp.mp.dps - 5))
    for _ in range(steps):
        g = mp.matrix(closure(x, lengths, loops))
        if mp.norm(g) < tol:
            return x
        J = closure_jacobian(x, lengths, loops)
        step = J.T * mp.lu_solve(J * J.T, g)
        x = [x[i] - step[i] for i in range(len(x))]
    raise ArithmeticError("projection onto the closures did not converge")


def _null_space(M, tol=None):
    """Orthonormal basis (list of lists) of the null space of M (rows x cols), from a full SVD."""
    tol = mp.mpf(10) ** (-(mp.mp.dps // 2)) if tol is None else tol
    if M.rows == 0:
        return [[mp.mpf(int(i == k)) for k in range(M.cols)] for i in range(M.cols)]
    _, S, V = mp.svd_r(M, full_matrices=True)
    rank = sum(1 for i in range(len(S)) if S[i] > tol * max(1, S[0]))
    return [[V[i, k] for k in range(M.cols)] for i in range(rank, M.cols)]


def _columns(M, cols):
    out = mp.matrix(M.rows, len(cols))
    for a, c in enumerate(cols):
        for r in range(M.rows):
            out[r, a] = M[r, c]
    return out


def _embed(vectors, cols, size):
    out = []
    for v in vectors:
        w = [mp.mpf(0)] * size
        for c, val in zip(cols, v):
            w[c] = val
        out.append(w)
    return out


@_dps
def tangent_basis(x, lengths, loops):
    """An orthonormal basis (3n-vectors) of the closures' tangent space (symmetries included)."""
    return _null_space(closure_jacobian(x, lengths, loops))


def is_planar(x, tol=None):
    tol = mp.mpf(10) ** (-30) if tol is None else tol
    _, ps, ph = unpack(x)
    return all(abs(v) <= tol for v in ps + ph)


@_dps
def split_basis(x, lengths, loops):
    """(in-plane basis, out-of-plane basis) of the tangent space at a planar twist-free x: the null spaces of the
    closures' Jacobian on the theta columns, and on the (psi, phi) columns (the Jacobian is block diagonal)."""
    assert is_planar(x), "the split needs psi = phi = 0"
    n = len(x) // 3
    J = closure_jacobian(x, lengths, loops)
    inp, outp = list(range(n)), list(range(n, 3 * n))
    for r in range(J.rows):  # the cross blocks vanish at psi = 0
        assert all(J[r, c] == 0 for c in inp) or all(J[r, c] == 0 for c in outp)
    return _embed(_null_space(_columns(J, inp)), inp, 3 * n), _embed(_null_space(_columns(J, outp)), outp, 3 * n)


@_dps
def symmetry_vectors(x):
    """The chart velocities of the 4 symmetries (rotations about world x, y, z; the spin), as 3n-vectors.  Per
    body, the world angular velocity of (theta', psi', phi') is theta' x + psi' Rx(theta) y + phi' e3."""
    n = len(x) // 3
    th, ps, ph = unpack(x)
    out = [[mp.mpf(0)] * (3 * n) for _ in range(4)]
    for k in range(n):
        Q = matmul(matmul(Rx(th[k]), Ry(ps[k])), Rz(ph[k]))
        b = [mp.mpf(0), mp.cos(th[k]), mp.sin(th[k])]  # Rx(theta) y
        M = mp.matrix([[mp.mpf(1), b[0], Q[0][2]], [mp.mpf(0), b[1], Q[1][2]], [mp.mpf(0), b[2], Q[2][2]]])
        for a in range(3):
            w = mp.matrix([mp.mpf(int(a == i)) for i in range(3)])
            c = mp.lu_solve(M, w)
            for i in range(3):
                out[a][i * n + k] = c[i]
        out[3][2 * n + k] = mp.mpf(1)
    return out


def _orthonormal(vectors, tol=None):
    tol = mp.mpf(10) ** (-(mp.mp.dps // 2)) if tol is None else tol
    ortho = []
    for v in vectors:
        v = list(v)
        for _ in range(2):
            for u in ortho:
                d = mp.fsum(a * b for a, b in zip(v, u))
                v = [a - d * b for a, b in zip(v, u)]
        norm = mp.sqrt(mp.fsum(a * a for a in v))
        if norm > tol:
            ortho.append([a / norm for a in v])
    return ortho


@_dps
def remove_symmetries(basis, x):
    """An orthonormal basis of span(basis) orthogonal to the symmetry vectors that lie in it (up to 1e-25)."""
    sym = []
    d = len(basis)
    for s in symmetry_vectors(x):
        coef = [mp.fsum(a * b for a, b in zip(s, v)) for v in basis]
        inside = [mp.fsum(coef[i] * basis[i][c] for i in range(d)) for c in range(len(s))]
        if mp.sqrt(mp.fsum((a - b) ** 2 for a, b in zip(s, inside))) < mp.mpf(10) ** -25 and max(abs(c) for c in coef + [0]) > 0:
            sym.append(coef)
    # Complement of the symmetries in the basis' coordinates, then back.
    ortho = _orthonormal(sym + [[mp.mpf(int(i == k)) for k in range(d)] for i in range(d)])
    rest = ortho[len(_orthonormal(sym)) :]
    return [[mp.fsum(r[i] * basis[i][c] for i in range(d)) for c in range(len(x))] for r in rest]


# ------------------------------------------------------------------------------------------------ the probe
@_dps
def probe_parts(x, lengths, loops, h=None, basis=None, eps=None):
    """(QA, QB): second differences of A and B (U = c1^2 A + c2^2 B) along closed curves through x, in ``basis``
    (default ``tangent_basis``): Q[i][i] = (F(+e_i) - 2 F(0) + F(-e_i)) / eps^2,
    Q[i][j] = (F(+e_i+e_j) - F(+e_i-e_j) - F(-e_i+e_j) + F(-e_i-e_j)) / (4 eps^2),  F(y) = (A, B)(project(x + eps y))."""
    eps = EPS if eps is None else mp.mpf(eps)
    h = _h(lengths, h)
    basis = tangent_basis(x, lengths, loops) if basis is None else basis
    d = len(basis)
    x = [mp.mpf(v) for v in x]

    def F(*terms):
        point = list(x)
        for c, v in terms:
            point = [p + c * eps * w for p, w in zip(point, v)]
        return energy_parts(project(point, lengths, loops), h)

    F0 = F()
    QA, QB = mp.matrix(d, d), mp.matrix(d, d)
    for i in range(d):
        p, m = F((1, basis[i])), F((-1, basis[i]))
        QA[i, i] = (p[0] - 2 * F0[0] + m[0]) / eps**2
        QB[i, i] = (p[1] - 2 * F0[1] + m[1]) / eps**2
        for j in range(i + 1, d):
            vi, vj = basis[i], basis[j]
            pp, pm, mp_, mm = F((1, vi), (1, vj)), F((1, vi), (-1, vj)), F((-1, vi), (1, vj)), F((-1, vi), (-1, vj))
            QA[i, j] = QA[j, i] = (pp[0] - pm[0] - mp_[0] + mm[0]) / (4 * eps**2)
            QB[i, j] = QB[j, i] = (pp[1] - pm[1] - mp_[1] + mm[1]) / (4 * eps**2)
    return QA, QB


@_dps
def probe(x, lengths, loops, c1sq=1, c2sq=1, h=None, basis=None, eps=None):
    """The reduced Hessian of U on the closures (second differences along closed curves) in ``basis``."""
    QA, QB = probe_parts(x, lengths, loops, h, basis, eps)
    return mp.mpf(c1sq) * QA + mp.mpf(c2sq) * QB


def eigenvalues(Q):
    if Q.rows == 0:
        return []
    ev = mp.eigsy(Q, eigvals_only=True)
    return sorted(ev[i] for i in range(Q.rows))


def inertia(Q, symmetries=0, tol=TOL):
    """(negatives, zeros - symmetries) of a symmetric matrix; zero means |ev| <= tol."""
    ev = eigenvalues(Q)
    zeros = sum(1 for e in ev if abs(e) <= tol)
    assert zeros >= symmetries, (zeros, symmetries)
    return sum(1 for e in ev if e < -tol), zeros - symmetries


@_dps
def spatial_inertia(x, lengths, loops, c1sq=1, c2sq=1, h=None, tol=TOL):
    """(index, nullity) of U on the closures in space: eigenvalues of ``probe`` on the whole tangent space,
    nullity = zeros - 4 (the rotations and the spin)."""
    return inertia(probe(x, lengths, loops, c1sq, c2sq, h), SYMMETRIES, tol)


@_dps
def split_probe(x, lengths, loops, c1sq=1, c2sq=1, h=None):
    """(in-plane probe, out-of-plane probe) at a planar twist-free x (each on its own part of the tangent space)."""
    inp, outp = split_basis(x, lengths, loops)
    return probe(x, lengths, loops, c1sq, c2sq, h, inp), probe(x, lengths, loops, c1sq, c2sq, h, outp)


@_dps
def split_inertia(x, lengths, loops, c1sq=1, c2sq=1, h=None, tol=TOL):
    """((planar index, planar nullity), (out-of-plane index, out-of-plane nullity)) at a planar twist-free x;
    symmetry zeros removed: 1 in the plane (rotation about x), 3 out of it (rotations about y, z; spin)."""
    P, O = split_probe(x, lengths, loops, c1sq, c2sq, h)
    return inertia(P, 1, tol), inertia(O, 3, tol)


# ------------------------------------------------------------------------------------------------ forces
@_dps
def gradient(x, c1sq=1, c2sq=1, h=1, eps=None):
    """grad U in the chart (central differences, eps = 1e-17 at 50 digits: error ~1e-33)."""
    eps = mp.mpf("1e-17") if eps is None else mp.mpf(eps)
    g = []
    for i in range(len(x)):
        xp, xm = list(x), list(x)
        xp[i] += eps
        xm[i] -= eps
        g.append((energy(xp, c1sq, c2sq, h) - energy(xm, c1sq, c2sq, h)) / (2 * eps))
    return g


@_dps
def multipliers(x, lengths, loops, c1sq=1, c2sq=1, h=None):
    """(forces, residual): the least-squares R with grad U = R . grad closure (one 3-vector per loop) and the
    largest |grad U - J^T R| (small iff x is an equilibrium)."""
    h = _h(lengths, h)
    g = mp.matrix(gradient(x, c1sq, c2sq, h))
    J = closure_jacobian(x, lengths, loops)
    R = mp.lu_solve(J * J.T, J * g)
    res = g - J.T * R
    return [[R[3 * i + c] for c in range(3)] for i in range(len(loops))], max(abs(res[i]) for i in range(res.rows))


# ------------------------------------------------------------------------------------------------ families
@_dps
def family(family_name, ratio, n=None, j=1):
    """(x, lengths, loops) of a planar family (tests/closed_reference.closed_form) as a twist-free x."""
    L = planar.lengths_of(family_name, ratio, n)
    theta, _ = planar.closed_form(family_name, L, j=j)
    return pack(theta), L, planar.loops_of(family_name, len(L))


def family_split_inertia(family_name, ratio, c2sq, c1sq=1, n=None, j=1, h=None):
    x, L, loops = family(family_name, ratio, n, j)
    return split_inertia(x, L, loops, c1sq, c2sq, h)


def family_spatial_inertia(family_name, ratio, c2sq, c1sq=1, n=None, j=1, h=None):
    x, L, loops = family(family_name, ratio, n, j)
    return spatial_inertia(x, L, loops, c1sq, c2sq, h)


def _first_crossing(blocks, lo, hi, grid=60, tol=mp.mpf("1e-14")):
    """The smallest r in (lo, hi] at which min over blocks of the least eigenvalue of QA + r QB turns negative
    (scan on a grid, then bisection on the block that turns first).  None if it stays >= 0."""
    lo, hi = mp.mpf(lo), mp.mpf(hi)

    def least(QA, QB, r):
        return eigenvalues(QA + r * QB)[0] if QA.rows else mp.inf

    assert all(least(QA, QB, lo) > TOL for QA, QB in blocks), "not stable at the lower end"
    prev = lo
    for s in range(1, grid + 1):
        r = lo + (hi - lo) * s / grid
        bad = [b for b in blocks if least(b[0], b[1], r) < 0]
        if bad:
            a, c = prev, r
            while c - a > tol * c:
                mid = (a + c) / 2
                if any(least(QA, QB, mid) < 0 for QA, QB in bad):
                    c = mid
                else:
                    a = mid
            return (a + c) / 2
        prev = r
    return None


@_dps
def critical_c2sq(x, lengths, loops, c1sq=1, h=None, lo="1e-3", hi=100):
    """The c2^2 at which a planar twist-free equilibrium's out-of-plane block loses (or gains) stability: the
    least out-of-plane eigenvalue off the symmetries crosses zero.  B is >= 0 with its minimum at every planar
    twist-free point, so QB >= 0 and the eigenvalues of c1^2 QA + c2^2 QB grow with c2^2: one crossing at most
    (the stable side is above it).  Found on the reduced out-of-plane probe by bisection (~1e-14 relative)."""
    _, outp = split_basis(x, lengths, loops)
    red = remove_symmetries(outp, x)
    QA, QB = probe_parts(x, lengths, loops, h, red)
    QA = mp.mpf(c1sq) * QA
    f = lambda c: eigenvalues(QA + c * QB)[0]
    a, c = mp.mpf(lo), mp.mpf(hi)
    assert f(a) < 0 < f(c), "no crossing in [lo, hi]"
    while c - a > mp.mpf("1e-15") * c:
        mid = (a + c) / 2
        if f(mid) < 0:
            a = mid
        else:
            c = mid
    return (a + c) / 2


def family_critical_c2sq(family_name, ratio, c1sq=1, n=None, j=1, h=None, lo="1e-3", hi=100):
    x, L, loops = family(family_name, ratio, n, j)
    return critical_c2sq(x, L, loops, c1sq, h, lo, hi)


# ------------------------------------------------------------------------------------------------ rings
@_dps
def twisted_ring(n, j=1, m=0):
    """(x, lengths, loops): Q_k = Rx(2 pi j k/n) Rz(2 pi m k/n), k = 1..n, h_k = 1."""
    theta = [2 * mp.pi * j * k / n for k in range(1, n + 1)]
    phi = [2 * mp.pi * m * k / n for k in range(1, n + 1)]
    return pack(theta, None, phi), [mp.mpf(1)] * n, [list(range(n))]


@_dps
def twisted_ring_force(n, j, m, c1sq=1, c2sq=1, h=1, h1=1):
    """The closed form R = (c2^2 sin(2 pi j/n) sin(2 pi m/n) / (h h1), 0, 0) (module docstring)."""
    return [mp.mpf(c2sq) * mp.sin(2 * mp.pi * j / n) * mp.sin(2 * mp.pi * m / n) / (mp.mpf(h) * mp.mpf(h1)), mp.mpf(0), mp.mpf(0)]


def ring_blocks(n, j=1, m=0, h=None, symmetries=True):
    """[(p, QA_p, QB_p)] for the (twisted) ring of n equal bodies: the probe on the tangent vectors of real Fourier
    mode p (cos and sin of 2 pi p k / n in each of theta, psi, phi), p = 0..n/2, symmetries removed unless
    ``symmetries``; the full reduced Hessian is their direct sum (the shift symmetry, module docstring)."""
    return list(_ring_blocks(n, j, m, None if h is None else mp.mpf(h), symmetries))


@functools.lru_cache(maxsize=64)
@_dps
def _ring_blocks(n, j, m, h, symmetries):
    x, L, loops = twisted_ring(n, j, m)
    J = closure_jacobian(x, L, loops)
    out = []
    for p in range(n // 2 + 1):
        waves = [[mp.cos(2 * mp.pi * p * k / n) for k in range(n)]]
        if 0 < 2 * p < n:
            waves.append([mp.sin(2 * mp.pi * p * k / n) for k in range(n)])
        V = _orthonormal(_embed([w], range(b * n, (b + 1) * n), 3 * n)[0] for b in range(3) for w in waves)
        Vm = mp.matrix([[v[c] for v in V] for c in range(3 * n)])  # columns
        N = _null_space(J * Vm)
        W = [[mp.fsum(r[i] * V[i][c] for i in range(len(V))) for c in range(3 * n)] for r in N]
        if not symmetries:
            W = remove_symmetries(W, x)
        QA, QB = probe_parts(x, L, loops, h, W)
        out.append((p, QA, QB))
    return tuple(out)  # cached: callers must not modify the matrices


@_dps
def ring_spectrum_probe(n, j=1, m=0, c1sq=1, c2sq=1, h=None):
    """The sorted eigenvalues of the (twisted) ring's reduced Hessian from its Fourier blocks (symmetries kept)."""
    ev = []
    for _, QA, QB in ring_blocks(n, j, m, h):
        ev += eigenvalues(mp.mpf(c1sq) * QA + mp.mpf(c2sq) * QB)
    return sorted(ev)


@_dps
def ring_K(n, j, p, c1sq=1, c2sq=1, h=1):
    """The closed-form 2x2 Hermitian out-of-plane block K(p) of the untwisted ring (module docstring)."""
    d, mu = 2 * mp.pi * j / n, 2 * mp.pi * p / n
    c1sq, c2sq, h = mp.mpf(c1sq), mp.mpf(c2sq), mp.mpf(h)
    a = (2 * c1sq * (mp.cos(d) - mp.cos(mu)) + c2sq * (1 - mp.cos(d)) * (1 + mp.cos(mu))) / h
    b = c2sq * mp.sin(d) * mp.sin(mu) / h  # K = [[a, i b], [-i b, c]]
    c = c2sq * (1 + mp.cos(d)) * (1 - mp.cos(mu)) / h
    return a, b, c


@_dps
def ring_spectrum(n, j=1, c1sq=1, c2sq=1, h=1):
    """(in-plane, out-of-plane) closed-form eigenvalues (sorted, symmetry zeros included) of the untwisted ring of
    n equal bodies: in the plane 0 (rotation) and (2 c1^2/h) cos delta (1 - cos mu), p != 0, +-j; out of it
    0 (spin) and the two eigenvalues of K(p), p = 1..n-1."""
    d = 2 * mp.pi * j / n
    inp = [mp.mpf(0)] + [2 * mp.mpf(c1sq) / mp.mpf(h) * mp.cos(d) * (1 - mp.cos(2 * mp.pi * p / n)) for p in range(1, n) if p % n not in (j % n, (-j) % n)]
    outp = [mp.mpf(0)]
    for p in range(1, n):
        a, b, c = ring_K(n, j, p, c1sq, c2sq, h)
        disc = mp.sqrt((a - c) ** 2 + 4 * b**2)
        outp += [(a + c - disc) / 2, (a + c + disc) / 2]
    return sorted(inp), sorted(outp)


def ring_split_inertia_formula(n, j):
    """((planar index, nullity), (out-of-plane index, nullity)) of the untwisted equal ring from the closed forms
    (any c1, c2 > 0): in the plane n - 3 negatives iff cos delta < 0 (all zero iff cos delta = 0); out of it
    #{p in 1..n-1 : cos(2 pi p/n) > cos delta} negatives; extra zeros only at cos delta = -1 (n = 2j)."""
    with mp.workdps(DPS):
        d = 2 * mp.pi * j / n
        cd = mp.cos(d)
        if abs(cd) < mp.mpf(10) ** -30:
            planar_ = (0, n - 3)
        else:
            planar_ = (n - 3 if cd < 0 else 0, 0)
        out_index = sum(1 for p in range(1, n) if mp.cos(2 * mp.pi * p / n) > cd + mp.mpf(10) ** -30)
        return planar_, (out_index, 0)


@_dps
def critical_ratio(n, j=1, m=1, h=None, lo="1e-3", hi=None, grid=60):
    """The c2^2/c1^2 at which the twisted ring's least non-symmetry eigenvalue first crosses zero (from the
    Fourier blocks of the probe, symmetries removed; scan of [lo, hi] then bisection, ~1e-14 relative)."""
    hi = mp.mpf(3) / m if hi is None else mp.mpf(hi)
    blocks = [(QA, QB) for _, QA, QB in ring_blocks(n, j, m, h, symmetries=False)]
    return _first_crossing(blocks, lo, hi, grid)


def critical_gamma(n, j=1, m=1, h=None):
    """Michell's Gamma = m c2^2 / c1^2 at the twisted ring's loss of stability (``critical_ratio`` times m)."""
    r = critical_ratio(n, j, m, h)
    return None if r is None else m * r
