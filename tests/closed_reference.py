"""Independent references for the closed-chain tests, written from the model of docs/closed.md (section 1, from seed 000) and nothing of stabmap.

- ``closed_form``: each family's angles and loop forces at 40 digits (mpmath), typed from docs/closed.md (section 2);
- ``residual``: the general equations (22), (24) per body and loop, at any precision;
- ``project``, ``tangent_basis``, ``probe``: the energy U restricted to the closed configurations, probed by
  second differences along curves that stay closed (Gauss-Newton back onto the closures).  The probe never
  uses the forces or a Hessian formula: its inertia is the index and nullity of U on the constraint manifold.
- ``newton``: Newton's method on the general equations (mpmath), from any start.
- ``hessian``, ``hessian_inertia``: docs/closed.md's Hessian formula on the same tangent basis, at any precision (the
  probe's second differences cannot resolve eigenvalues much below its step; this can, at enough digits).
"""

from __future__ import annotations

import mpmath as mp

mp.mp.dps = 40

# Each family: (pattern of h1/h2 per body, loops as 0-based bodies); plain chains have one loop of every body.
PATTERNS = {
    "figure-eight-4": ((1, 2, 1, 2), None),
    "figure-eight-6": ((1, 2, 1, 1, 2, 1), None),
    "hinge": ((1, 1, 2, 1, 1, 2), ((0, 4, 5), (1, 2, 3))),
    "hinge-straight": ((1, 1, 2, 1, 1, 2), None),
}


def lengths_of(family: str, ratio, n: int | None = None, h1=1):
    """The lengths of a family's pattern (the ring alternates h1, h2)."""
    h1 = mp.mpf(h1)
    h2 = h1 * mp.mpf(ratio)
    if family == "ring":
        return [h1 if k % 2 == 0 else h2 for k in range(n)]
    return [h1 if p == 1 else h2 for p in PATTERNS[family][0]]


def loops_of(family: str, n: int):
    loops = PATTERNS.get(family, (None, None))[1]
    return [list(l) for l in loops] if loops else [list(range(n))]


def closed_form(family: str, lengths, c1sq=1, h=None, j=1):
    """(theta, forces) of docs/closed.md's closed form; forces: one (R_y, R_z) per loop.  None where it does not exist."""
    L = [mp.mpf(x) for x in lengths]
    c1sq = mp.mpf(c1sq)
    h = min(L) if h is None else mp.mpf(h)
    n = len(L)
    a1 = L[0] * h / c1sq
    pi = mp.pi
    if family == "ring":
        return [2 * pi * j * k / n for k in range(1, n + 1)], [(mp.mpf(0), mp.mpf(0))]
    if family == "figure-eight-4":
        h1, h2 = L[0], L[1]
        if not h2 < h1:
            return None
        t = mp.asin(h2 / h1)
        return [-t, pi / 2, pi + t, pi / 2], [(2 / a1, mp.mpf(0))]
    if family == "figure-eight-6":
        a = L[0] / L[1]
        if not a < (mp.sqrt(2) - 1) / 2:
            return None
        p = 1 - 2 * a + mp.sqrt(1 - 4 * a)
        t = mp.asin(mp.sqrt((p**2 - 1) / (p**2 - 4 * a**2)))
        s = mp.asin(2 * a * mp.sin(t))
        assert abs(mp.cos(s) - p * mp.cos(t)) < mp.mpf(10) ** (-30)  # docs/closed.md: cos s = p cos t, s acute
        return [t, -s, t, pi - t, pi + s, pi - t], [((2 - p - 2 * a) * mp.sin(t) / a1, mp.mpf(0))]
    t_ok = L[2] < 2 * L[0]
    if not t_ok:
        return None
    t = mp.asin(L[2] / (2 * L[0]))
    if family == "hinge":
        R = (2 * mp.sin(t) + 1) / a1
        return [-t, t, -pi / 2, pi - t, pi + t, pi / 2], [(R, mp.mpf(0)), (-R, mp.mpf(0))]
    if family == "hinge-straight":
        return [-t, -t, pi / 2, pi + t, pi + t, pi / 2], [(1 / a1, mp.mpf(0))]
    raise KeyError(family)


def residual(theta, lengths, forces, loops, c1sq=1, h=None):
    """The largest absolute residual of (22) (each body with its loop's force) and of every loop's closure."""
    n = len(theta)
    L = [mp.mpf(x) for x in lengths]
    h = min(L) if h is None else mp.mpf(h)
    loop_of = {k: i for i, loop in enumerate(loops) for k in loop}
    worst = mp.mpf(0)
    for k in range(n):
        Ry, Rz = forces[loop_of[k]]
        a = L[k] * h / mp.mpf(c1sq)
        r = mp.sin(theta[(k + 1) % n] - theta[k]) - mp.sin(theta[k] - theta[k - 1]) - a * (Rz * mp.sin(theta[k]) + Ry * mp.cos(theta[k]))
        worst = max(worst, abs(r))
    for loop in loops:
        worst = max(worst, abs(mp.fsum(L[k] * mp.sin(theta[k]) for k in loop)), abs(mp.fsum(L[k] * mp.cos(theta[k]) for k in loop)))
    return worst


def energy(theta, c1sq=1, h=1):
    n = len(theta)
    return mp.mpf(c1sq) / mp.mpf(h) * mp.fsum(1 - mp.cos(theta[k] - theta[k - 1]) for k in range(n))


def _closure(theta, L, loops):
    g, A = [], []
    n = len(theta)
    for loop in loops:
        g += [mp.fsum(L[k] * mp.sin(theta[k]) for k in loop), mp.fsum(L[k] * mp.cos(theta[k]) for k in loop)]
        A += [[L[k] * mp.cos(theta[k]) if k in loop else 0 for k in range(n)], [-L[k] * mp.sin(theta[k]) if k in loop else 0 for k in range(n)]]
    return mp.matrix(g), mp.matrix(A)


def project(theta, lengths, loops, steps: int = 60):
    """theta moved back onto the closed configurations by minimum-norm Gauss-Newton steps (rotation untouched)."""
    L = [mp.mpf(x) for x in lengths]
    theta = list(theta)
    tol = mp.mpf(10) ** (-(mp.mp.dps - 4))
    for _ in range(steps):
        g, A = _closure(theta, L, loops)
        if mp.norm(g) < tol:
            return theta
        y = mp.lu_solve(A * A.T, g)
        step = A.T * y
        theta = [theta[k] - step[k] for k in range(len(theta))]
    raise ArithmeticError("projection onto the closures did not converge")


def tangent_basis(theta, lengths, loops):
    """An orthonormal basis of the closures' tangent space with the rotation (all ones) taken out (Gram-Schmidt)."""
    n = len(theta)
    L = [mp.mpf(x) for x in lengths]
    _, A = _closure(theta, L, loops)
    rows = [[A[i, k] for k in range(n)] for i in range(A.rows)] + [[mp.mpf(1)] * n]
    ortho = []
    for v in rows + [[mp.mpf(int(i == k)) for k in range(n)] for i in range(n)]:
        for u in ortho:
            dot = mp.fsum(a * b for a, b in zip(v, u))
            v = [a - dot * b for a, b in zip(v, u)]
        norm = mp.sqrt(mp.fsum(a * a for a in v))
        if norm > mp.mpf(10) ** (-20):
            ortho.append([a / norm for a in v])
    return ortho[len(rows):]


def probe(theta, lengths, loops, eps=None):
    """The matrix of second derivatives of U along closed curves through theta in the tangent basis (polarised
    second differences of U at projected points): its inertia is the index and nullity on the closed shapes."""
    eps = mp.mpf(10) ** (-12) if eps is None else mp.mpf(eps)
    basis = tangent_basis(theta, lengths, loops)
    d = len(basis)

    def U(*terms):
        point = list(theta)
        for c, v in terms:
            point = [p + c * eps * x for p, x in zip(point, v)]
        return energy(project(point, lengths, loops))

    Q = mp.matrix(d, d)
    for i in range(d):
        for j in range(i, d):
            vi, vj = basis[i], basis[j]
            q = (U((1, vi), (1, vj)) - U((1, vi), (-1, vj)) - U((-1, vi), (1, vj)) + U((-1, vi), (-1, vj))) / (4 * eps**2)
            Q[i, j] = Q[j, i] = q
    return Q


def inertia(Q, tol=1e-8):
    """(index, nullity) of a symmetric matrix."""
    tol = mp.mpf(tol)
    if Q.rows == 0:
        return 0, 0
    ev = mp.eigsy(Q, eigvals_only=True)
    return sum(1 for e in ev if e < -tol), sum(1 for e in ev if abs(e) <= tol)


def newton(theta, forces, lengths, loops, c1sq=1, h=None, steps: int = 40):
    """Newton (mp.findroot) on the general equations with theta_1 fixed, from a start; returns (theta, forces)."""
    n = len(theta)
    L = [mp.mpf(x) for x in lengths]
    h = min(L) if h is None else mp.mpf(h)
    loop_of = {k: i for i, loop in enumerate(loops) for k in loop}
    nl = len(loops)
    t1 = theta[0]

    def F(*x):
        th = [t1] + list(x[: n - 1])
        R = [(x[n - 1 + 2 * i], x[n + 2 * i]) for i in range(nl)]
        out = []
        for k in range(n):
            # The sum of all torque equations vanishes on closed shapes (the sines telescope, the forces meet
            # their loops' closures): body 1's equation follows from the others.
            if k == 0:
                continue
            Ry, Rz = R[loop_of[k]]
            a = L[k] * h / mp.mpf(c1sq)
            out.append(mp.sin(th[(k + 1) % n] - th[k]) - mp.sin(th[k] - th[k - 1]) - a * (Rz * mp.sin(th[k]) + Ry * mp.cos(th[k])))
        for loop in loops:
            out += [mp.fsum(L[k] * mp.sin(th[k]) for k in loop), mp.fsum(L[k] * mp.cos(th[k]) for k in loop)]
        return out

    x0 = list(theta[1:]) + [c for f in forces for c in f]
    x = mp.findroot(F, x0, tol=mp.mpf(10) ** (-30), maxsteps=steps)
    x = [x[i] for i in range(len(x0))]
    return [t1] + x[: n - 1], [(x[n - 1 + 2 * i], x[n + 2 * i]) for i in range(nl)]


def hessian(theta, lengths, forces, loops, c1sq=1, h=None):
    """docs/closed.md's Hessian of U - sum R . closure: (c1^2/h) (cyclic Laplacian with weights cos(theta_k -
    theta_(k-1))) + diag(h_k (R_z cos theta_k - R_y sin theta_k)), each body with its loop's force."""
    n = len(theta)
    L = [mp.mpf(x) for x in lengths]
    h = min(L) if h is None else mp.mpf(h)
    scale = mp.mpf(c1sq) / h
    loop_of = {k: i for i, loop in enumerate(loops) for k in loop}
    H = mp.matrix(n, n)
    for k in range(n):
        i = (k - 1) % n
        w = mp.cos(theta[k] - theta[i])  # joint k: bodies k - 1 and k
        H[k, k] += scale * w
        H[i, i] += scale * w
        H[k, i] -= scale * w
        H[i, k] -= scale * w
        Ry, Rz = forces[loop_of[k]]
        H[k, k] += L[k] * (Rz * mp.cos(theta[k]) - Ry * mp.sin(theta[k]))
    return H


def hessian_inertia(theta, lengths, forces, loops, tol):
    """(index, nullity, the eigenvalues) of the Hessian on the closures' tangent space modulo rotation
    (``tangent_basis``); an eigenvalue counts as zero when |ev| <= tol.  Use far more digits than tol needs."""
    basis = tangent_basis(theta, lengths, loops)
    d = len(basis)
    if d == 0:
        return 0, 0, []
    H = hessian(theta, lengths, forces, loops)
    B = mp.matrix([[basis[i][k] for i in range(d)] for k in range(len(theta))])
    ev = mp.eigsy(B.T * H * B, eigvals_only=True)
    ev = [ev[i] for i in range(d)]
    tol = mp.mpf(tol)
    return sum(1 for e in ev if e < -tol), sum(1 for e in ev if abs(e) <= tol), ev
