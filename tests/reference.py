"""Exact (sympy, rational) reference for the characteristic polynomial.

This module is a test oracle only. It restates ``docs/model.md`` (the physics stabmap computes)
literally, in exact rational arithmetic, so the numeric engine can be checked
against it. It deliberately imports nothing from ``stabmap`` or ``kernels``:
an oracle that shares code with the thing it checks cannot catch that code's
mistakes.

Conventions (all from docs/model.md):

* ``theta_k`` is the complex tilt of body ``k`` (body 1 at the bottom) and the
  solutions go as ``exp(i lam t)``.
* ``Phi(lam) = lam^2 M + lam G - K - diag(lam^2 (lam + omega_k) sum_l E_kl /
  (lam + omega_k - lambda_kl))`` with ``lambda_kl = 2 omega_k / kappa_kl``.
* ``p(lam) = det Phi(lam) * prod_k Q_k(lam)`` with
  ``Q_k = prod_l (lam + omega_k - lambda_kl)``.

Trees of bodies (``docs/trees.md``) get their own derivation in
:func:`tree_matrices`: bodies placed with exact trigonometry, M and K as
Hessians of the kinetic and potential energy, no lever-arm formula and no
incidence or path matrix, so it also checks the engine's use of those.
"""

from __future__ import annotations

from fractions import Fraction
from numbers import Number

import sympy
from sympy import QQ
from sympy.polys.matrices import DomainMatrix

__all__ = [
    "lam",
    "exact",
    "char_poly",
    "tree_char_poly",
    "tree_matrices",
    "system_matrices",
    "lever_arms",
    "liquid_Q",
    "paper_F",
    "count_real_roots",
    "count_complex_pairs",
    "sturm_complex_pairs",
    "arb_complex_pairs",
]

#: The spectral variable of every polynomial produced here.
lam = sympy.Symbol("lam")

_RING = QQ[lam]


def exact(x):
    """Convert a number to an exact ``sympy.Rational``.

    Parameters
    ----------
    x : int, float, Fraction or sympy number
        Floats are taken at their exact binary value (``0.1`` becomes
        ``3602879701896397/36028797018963968``); that is intended, because the
        engine receives the same binary double and must reproduce its
        polynomial, not the decimal the user had in mind.

    Returns
    -------
    sympy.Rational

    Raises
    ------
    TypeError
        For booleans, strings, irrational or symbolic input: a silent
        ``True -> 1`` or a rounded ``sqrt(2)`` would make the oracle inexact
        without anyone noticing.
    """
    if isinstance(x, bool) or not isinstance(x, (Number, Fraction, sympy.Basic)):
        raise TypeError(f"expected a number, got {type(x).__name__}: {x!r}")
    if isinstance(x, sympy.Basic) and not x.is_Rational and not x.is_Float:
        raise TypeError(f"expected a rational number, got {x!r}")
    return sympy.Rational(x)


def _body(b):
    """Validate one body dict and return its parameters as exact rationals."""
    missing = {"m", "A", "C", "c", "s", "omega"} - set(b)
    if missing:
        raise ValueError(f"body is missing keys {sorted(missing)}")
    out = {key: exact(b[key]) for key in ("m", "A", "C", "c", "s", "omega")}
    E = [exact(e) for e in b.get("E", ())]
    kappa = [exact(k) for k in b.get("kappa", ())]
    if len(E) != len(kappa):
        raise ValueError(f"E has {len(E)} modes but kappa has {len(kappa)}")
    if any(k == 0 for k in kappa):
        raise ValueError("kappa_kl = 0 gives an infinite liquid frequency")
    out["E"] = E
    # lambda_kl = 2 omega_k / kappa_kl: the liquid frequencies follow the spin.
    out["lams"] = [2 * out["omega"] / k for k in kappa]
    return out


def _normalise(bodies, support, g, joints, K0):
    """Shared argument checking for :func:`system_matrices` and friends."""
    if support not in ("fixed", "free"):
        raise ValueError(f"support must be 'fixed' or 'free', not {support!r}")
    bs = [_body(b) for b in bodies]
    n = len(bs)
    if n == 0:
        raise ValueError("need at least one body")
    joints = [exact(k) for k in joints]
    if len(joints) > n - 1:
        raise ValueError(f"{n} bodies have {n - 1} joints, got {len(joints)}")
    joints += [sympy.Integer(0)] * (n - 1 - len(joints))
    K0 = exact(K0)
    g = exact(g)
    if support == "free" and K0 != 0:
        # A free chain has no base to be elastically attached to; accepting
        # K0 here would silently model a different system.
        raise ValueError("K0 (base stiffness) only exists for a fixed support")
    return bs, joints, g, K0


def lever_arms(bodies, support):
    """Lever-arm matrix ``J`` with ``y_k = sum_i J_ki theta_i``.

    Parameters
    ----------
    bodies : list of dict
        Body parameters (see :func:`char_poly`).
    support : {"fixed", "free"}

    Returns
    -------
    sympy.Matrix
        ``n x n``. Fixed: ``J_ki = s_i`` (i < k), ``J_kk = c_k``. Free: the same
        minus the mass-weighted mean of every column, so that the centre of
        mass of the whole chain does not move.
    """
    bs = [_body(b) for b in bodies]
    n = len(bs)
    J = sympy.zeros(n, n)
    for k in range(n):
        for i in range(k):
            J[k, i] = bs[i]["s"]
        J[k, k] = bs[k]["c"]
    if support == "free":
        mtot = sum(b["m"] for b in bs)
        for i in range(n):
            mean = sum(bs[j]["m"] * J[j, i] for j in range(n)) / mtot
            for k in range(n):
                J[k, i] -= mean
    elif support != "fixed":
        raise ValueError(f"support must be 'fixed' or 'free', not {support!r}")
    return J


def system_matrices(bodies, support, g=0, joints=(), K0=0):
    """Inertia, gyroscopic and stiffness matrices ``(M, G, K)``.

    Parameters
    ----------
    bodies, support, g, joints, K0
        As in :func:`char_poly`.

    Returns
    -------
    M, G, K : sympy.Matrix
        Exact rational ``n x n`` matrices of docs/model.md.
    """
    bs, joints, g, K0 = _normalise(bodies, support, g, joints, K0)
    n = len(bs)
    J = lever_arms(bodies, support)
    m = [b["m"] for b in bs]
    M = sympy.diag(*[b["A"] for b in bs]) + J.T * sympy.diag(*m) * J
    G = sympy.diag(*[b["C"] * b["omega"] for b in bs])
    K = sympy.zeros(n, n)
    for k, Kk in enumerate(joints):
        K[k, k] += Kk
        K[k + 1, k + 1] += Kk
        K[k, k + 1] -= Kk
        K[k + 1, k] -= Kk
    if support == "fixed":
        K[0, 0] += K0
        for k, b in enumerate(bs):
            # a_k: first moment about O_k of body k plus everything above it
            # (the upper bodies' mass acts at O_{k+1}, a distance s_k away).
            a_k = b["m"] * b["c"] + b["s"] * sum(m[k + 1:], sympy.Integer(0))
            K[k, k] -= g * a_k
    # Free support: uniform gravity exerts no torque about the centre of mass
    # of a free system, so g drops out and is ignored rather than rejected.
    return M, G, K


def liquid_Q(omega, kappa):
    """Liquid denominator ``Q(lam) = prod_l (lam + omega - 2 omega / kappa_l)``.

    Parameters
    ----------
    omega : number
        Spin rate of the body.
    kappa : sequence of numbers
        Liquid eigenvalues of its cavity.

    Returns
    -------
    sympy.Expr
        A polynomial in :data:`lam` (``1`` when there is no liquid).
    """
    w = exact(omega)
    out = sympy.Integer(1)
    for k in kappa:
        out *= lam + w - 2 * w / exact(k)
    return out


def paper_F(A_prime, C, omega, E=(), kappa=(), restoring=0):
    """The paper's diagonal function ``F_k(lam)`` (eqs. 22-24, 29-30).

    ``F = A' + C omega / lam + restoring / lam^2
          - (lam + omega) sum_l E_l / (lam + omega - lambda_l)``

    Parameters
    ----------
    A_prime : number
        The paper's ``A'_k`` (for a fixed support the *about-joint* inertia
        plus the upper masses' contribution; for a free one the reduced
        inertia). The caller supplies it from the paper's printed formula, so
        the oracle's own ``M`` is not used to build the thing it is compared
        with.
    C, omega : number
        Axial inertia and spin rate.
    E, kappa : sequence of numbers
        Liquid modes.
    restoring : number or sympy.Expr
        Numerator of the ``1/lam^2`` term: ``a_k g - kappa_{k-1}^2 -
        kappa_k^2`` in the paper's notation (fixed) or ``-(kappa_{k-1}^2 +
        kappa_k^2)`` (free).

    Returns
    -------
    sympy.Expr
        Rational function of :data:`lam`.
    """
    if len(E) != len(kappa):
        raise ValueError("E and kappa must have the same length")
    w = exact(omega)
    liquid = sum(
        (exact(e) / (lam + w - 2 * w / exact(k)) for e, k in zip(E, kappa)),
        sympy.Integer(0),
    )
    restoring = sympy.sympify(restoring)
    return (exact(A_prime) + exact(C) * w / lam + restoring / lam**2
            - (lam + w) * liquid)


def char_poly(bodies, support, g=0, joints=(), K0=0):
    """Exact characteristic polynomial ``p(lam)`` of docs/model.md.

    Parameters
    ----------
    bodies : list of dict
        Bottom to top. Keys ``m, A, C, c, s, omega`` (``A`` about the body's
        own centre of mass, ``c`` from the lower joint to the centre of mass,
        ``s`` from the lower to the upper joint) and optional equal-length
        lists ``E`` and ``kappa`` (retained liquid modes).
    support : {"fixed", "free"}
    g : number, optional
        Gravity (fixed support only; ignored for a free chain, where it
        exerts no torque about the centre of mass).
    joints : sequence of numbers, optional
        ``K_1 .. K_{n-1}``; a shorter sequence is padded with zeros.
    K0 : number, optional
        Base stiffness at ``O_1`` (fixed support only).

    Returns
    -------
    sympy.Poly
        ``det Phi(lam) * prod_k Q_k(lam)`` over ``QQ`` in :data:`lam`, of
        degree at most ``sum_k (2 + L_k)``.

    Notes
    -----
    Row ``k`` of ``Phi`` is multiplied by ``Q_k`` before the determinant: that
    clears every denominator (only the diagonal has one) and multiplies the
    determinant by exactly ``prod_k Q_k``, so the result is ``p`` with no
    rational-function cancellation at all. The determinant is then taken over
    the polynomial ring ``QQ[lam]`` with sympy's fraction-free ``DomainMatrix``
    routine, which stays fast for ``n = 5`` with two modes per body.
    """
    bs, joints, g, K0 = _normalise(bodies, support, g, joints, K0)
    M, G, K = system_matrices(bodies, support, g, joints, K0)
    return _det_poly(bs, M, G, K)


def _det_poly(bs, M, G, K):
    """``det Phi(lam) * prod_k Q_k(lam)`` for validated bodies ``bs`` and exact matrices (see :func:`char_poly`)."""
    n = len(bs)
    rows = []
    for k, b in enumerate(bs):
        w = b["omega"]
        factors = [lam + w - lk for lk in b["lams"]]
        Qk = sympy.Mul(*factors)
        # Q_k * sum_l E_kl / (lam + w - lambda_kl), written without division.
        liquid = sum(
            (e * sympy.Mul(*(factors[:l] + factors[l + 1:]))
             for l, e in enumerate(b["E"])),
            sympy.Integer(0),
        )
        row = []
        for j in range(n):
            entry = Qk * (lam**2 * M[k, j] - K[k, j])
            if j == k:
                entry += Qk * lam * G[k, k] - lam**2 * (lam + w) * liquid
            row.append(_RING.from_sympy(sympy.expand(entry)))
        rows.append(row)
    det = DomainMatrix(rows, (n, n), _RING).det()
    return sympy.Poly(_RING.to_sympy(det), lam, domain=QQ)


def tree_matrices(bodies, parent, at, support, g=0, stiffness=None):
    """``(M, G, K)`` of bodies joined as a tree, from the Lagrangian of the geometry.

    Deliberately not docs/model.md's lever-arm formula: every body is placed in a
    vertical plane with exact trigonometry, the kinetic and potential energies are
    written out literally, and ``M`` and ``K`` are their Hessians at the upright
    state (for a free system after eliminating the translation of the whole system
    by Routh's procedure: its momentum is zero).  Motion out of the plane has the
    same ``M`` and ``K``; the spin only adds ``G = diag(C_k omega_k)``.

    Parameters
    ----------
    bodies : list of dict
        Keys ``m, A, C, c, omega`` (and optional ``E``, ``kappa``) as in
        :func:`char_poly`; ``c`` is measured from the body's own joint O_k.
    parent : sequence of int
        ``parent[k - 1]`` is the body that body k is mounted on; 0 the base
        (fixed support) or nothing (free support).  Exactly one body has 0; any
        numbering.
    at : sequence of numbers
        ``at[k - 1]``: the height of O_k above O_parent along the parent's axis
        (ignored for the body on the base).
    support : {"fixed", "free"}
    g : number
        Gravity (fixed support; dropped for a free system).
    stiffness : sequence of numbers, optional
        ``stiffness[k - 1]``: the spring between the tilts of body k and of its
        parent (for the body on the base: of the base, fixed support only).

    Returns
    -------
    M, G, K : sympy.Matrix
    """
    if support not in ("fixed", "free"):
        raise ValueError(f"support must be 'fixed' or 'free', not {support!r}")
    bs = [_body(dict(b, s=b.get("s", 0))) for b in bodies]
    n = len(bs)
    parent = [int(p) for p in parent]
    at = [exact(a) for a in at]
    stiffness = [exact(x) for x in (stiffness if stiffness is not None else [0] * n)]
    if len(parent) != n or len(at) != n or len(stiffness) != n:
        raise ValueError("parent, at and stiffness need one entry per body")
    if parent.count(0) != 1:
        raise ValueError("exactly one body must hang on the base")
    root = parent.index(0)
    if support == "free" and stiffness[root] != 0:
        raise ValueError("a free system has no base joint to be stiff")
    th = sympy.symbols(f"th1:{n + 1}")
    x0, z0 = sympy.symbols("x0 z0")
    # Place every joint O_k and centre C_k; a parent is placed before its children.
    O = {}
    Cm = {}
    pending = list(range(n))
    while pending:
        for k in list(pending):
            p = parent[k] - 1
            if p == -1:
                O[k] = sympy.Matrix([x0, z0]) if support == "free" else sympy.Matrix([0, 0])
            elif p in O:
                O[k] = O[p] + at[k] * sympy.Matrix([sympy.sin(th[p]), sympy.cos(th[p])])
            else:
                continue
            Cm[k] = O[k] + bs[k]["c"] * sympy.Matrix([sympy.sin(th[k]), sympy.cos(th[k])])
            pending.remove(k)
    coords = list(th) + ([x0, z0] if support == "free" else [])
    rates = sympy.symbols(f"v1:{len(coords) + 1}")
    T = 0
    for k, b in enumerate(bs):
        v = Cm[k].jacobian(coords) * sympy.Matrix(rates)
        T += b["m"] * (v.T * v)[0] / 2 + b["A"] * rates[k] ** 2 / 2
    V = sum((stiffness[k] * (th[k] - (th[parent[k] - 1] if parent[k] else 0)) ** 2 / 2 for k in range(n)),
            sympy.Integer(0))
    if support == "fixed":
        V += exact(g) * sum((b["m"] * Cm[k][1] for k, b in enumerate(bs)), sympy.Integer(0))
    upright = {q: 0 for q in coords}
    Mfull = sympy.hessian(T, rates).subs(upright)
    K = sympy.hessian(V, th).subs(upright)
    M = Mfull[:n, :n]
    if support == "free":
        # Routh: the translation is cyclic with zero momentum; eliminate it (Schur complement).
        Mtx, Mxx = Mfull[:n, n:], Mfull[n:, n:]
        M = M - Mtx * Mxx.inv() * Mtx.T
    G = sympy.diag(*[b["C"] * b["omega"] for b in bs])
    return sympy.Matrix(M), G, sympy.Matrix(K)


def tree_char_poly(bodies, parent, at, support, g=0, stiffness=None):
    """Exact ``p(lam)`` of a tree of bodies from :func:`tree_matrices` (same conventions as :func:`char_poly`)."""
    M, G, K = tree_matrices(bodies, parent, at, support, g, stiffness)
    bs = [_body(dict(b, s=b.get("s", 0))) for b in bodies]
    return _det_poly(bs, M, G, K)


def _as_poly(poly):
    """Coerce to a univariate exact ``Poly`` in :data:`lam` (or its own gen)."""
    if not isinstance(poly, sympy.Poly):
        poly = sympy.Poly(poly, lam)
    if len(poly.gens) != 1:
        raise ValueError(f"expected a univariate polynomial, got gens {poly.gens}")
    if not (poly.domain.is_ZZ or poly.domain.is_QQ):
        # Sturm counting on floating coefficients is not exact; refuse rather
        # than return an answer that only looks exact.
        raise ValueError(f"coefficients must be rational, domain is {poly.domain}")
    return poly


def count_real_roots(poly):
    """Number of real roots counted with multiplicity.

    Parameters
    ----------
    poly : sympy.Poly or sympy.Expr
        Nonzero univariate polynomial with rational coefficients.

    Returns
    -------
    int
    """
    poly = _as_poly(poly)
    if poly.is_zero:
        raise ValueError("the zero polynomial has no finite root count")
    # count_roots counts *distinct* real roots, so go through the square-free
    # decomposition and weight each factor by its multiplicity; a double root
    # on a stability boundary must count twice (it is real, hence stable).
    _, factors = poly.sqf_list()
    return sum(int(f.count_roots()) * mult for f, mult in factors)


def count_complex_pairs(poly):
    """Number ``N_c`` of complex-conjugate root pairs.

    Parameters
    ----------
    poly : sympy.Poly or sympy.Expr
        Nonzero univariate polynomial with rational coefficients.

    Returns
    -------
    int
        ``(deg p - #real roots with multiplicity) / 2``; the degree is the
        actual one (a ``Poly`` never carries a zero leading coefficient).
        ``N_c == 0`` is the necessary stability condition.

    Raises
    ------
    ValueError
        For the zero polynomial or non-rational coefficients.
    """
    poly = _as_poly(poly)
    if poly.is_zero:
        raise ValueError("the zero polynomial has no finite root count")
    missing = poly.degree() - count_real_roots(poly)
    # Real coefficients: non-real roots come in conjugate pairs.
    assert missing % 2 == 0, missing
    return missing // 2


def _sturm_distinct_real(f):
    """Distinct real roots of the nonzero ``flint.fmpq_poly`` f by an exact Sturm sequence."""
    seq = [f, f.derivative()]
    while seq[-1].degree() > 0:
        r = seq[-2] % seq[-1]
        if r == 0:
            break
        seq.append(-r)
    seq = [q for q in seq if q != 0]

    def changes(signs):
        signs = [x for x in signs if x != 0]
        return sum(1 for a, b in zip(signs, signs[1:]) if a != b)

    lead = [(1 if q.coeffs()[-1] > 0 else -1) for q in seq]
    at_minus = [lc if q.degree() % 2 == 0 else -lc for q, lc in zip(seq, lead)]
    return changes(at_minus) - changes(lead)


def _to_flint(poly):
    import flint

    poly = _as_poly(poly)
    if poly.is_zero:
        raise ValueError("the zero polynomial has no finite root count")
    return flint.fmpq_poly([flint.fmpq(int(c.p), int(c.q)) for c in reversed(poly.all_coeffs())])


def arb_complex_pairs(poly):
    """``N_c`` from FLINT/Arb's certified isolation of every complex root (any degree, fast).

    For the high-degree stress tests, where both sympy's root counting and
    rational Sturm sequences take minutes: the polynomial still comes from
    this module, only the root isolation is FLINT's.
    """
    g = _to_flint(poly)
    real = sum(mult for root, mult in g.numer().complex_roots() if root.imag.is_zero())
    missing = g.degree() - real
    assert missing % 2 == 0, missing
    return missing // 2


def sturm_complex_pairs(poly):
    """``N_c`` by exact Sturm sequences in python-flint rationals (about 1000x faster than sympy).

    Same contract as :func:`count_complex_pairs`; rational remainders grow
    fast, so use it up to degree ~16 (:func:`arb_complex_pairs` beyond).  Multiplicities come from the chain
    g_0 = p, g_{j+1} = gcd(g_j, g_j'): p has sum_j (distinct real roots of g_j)
    real roots counted with multiplicity.  Deliberately a different algorithm
    from the engine's exact path, which isolates complex roots with Arb.
    """
    g = _to_flint(poly)
    degree = g.degree()
    real = 0
    while g.degree() > 0:
        real += _sturm_distinct_real(g)
        g = g.gcd(g.derivative())
    missing = degree - real
    assert missing % 2 == 0, missing
    return missing // 2
