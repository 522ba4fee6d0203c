"""N_c of one point without the coefficients of p: inertia for the real roots, disks for the rest.

docs/certification.md, section 4, gives the proofs.  In short, with H(x)
the pole-free symmetric form of Phi bordered by one row per liquid mode
(a polynomial matrix, det H = prod c_kl p) and nu_H(x) = nu(Phi(x)) +
#{kl : c_kl (x + beta_kl) < 0} its number of negative eigenvalues:

* between increasing separators a < b at which Phi is provably nonsingular,
  p has at least |nu_H(b) - nu_H(a)| real roots (the analytic eigenvalue
  branches of H must cross zero for nu_H to change; each real root moves it
  by its Krein type, a pole not at all), so one interval counts a whole
  cluster of roots of one type;
* a Newton disk around z (radius d / |p~'/p~(z)|, the ratio enclosed by
  elimination of [Phi(z) | Phi'(z)] in balls) holds a root of p~ = p / z^m;
  disjoint ones clear of the axis hold distinct non-real roots.  Where those
  do not suffice, the Gerschgorin disks of Braess & Hadeler around all
  approximations: a connected group of k disks missing the axis holds k
  non-real roots.

When the lower bound of real roots plus the non-real roots proved make deg p,
N_c is proved.  The approximations only place separators and disks: a grid
neighbour's roots, extrapolated, first (no eigenvalue problem at all), else
the eigenvalues of the first-order linearisation, polished by Aberth sweeps
on det Phi.  Repeated roots (identical bodies) need no special case: k
branches cross zero together and nu jumps by k.
"""

from __future__ import annotations

import math

import numpy as np

from . import allatonce, approximations, ball, disks, elimination, layout, pencil
from .approximations import RIDE
from .options import kernel
from .status import DECIDED_ALLATONCE, DECIDED_DISKS, DECIDED_INERTIA, UNDECIDED

COLD_SWEEPS = 24  # Aberth sweeps from the linearisation's eigenvalues (CERTIFY.md: enough to degree 48)
WARM_STEPS = 8  # Aberth sweeps (at most) on a neighbour's non-real roots before their disks
# What the warm-or-cold choice counts, in n x n complex solves (one Aberth or Newton step); measured on
# the kernels for n = 2..32 (inertia at a separator 0.43-0.62 solves, a Newton disk 3.9-10)
SEPARATOR_COST, DISK_COST = 0.55, 7.0
WARM_SWEEPS = 4  # Aberth sweeps on a neighbour's roots that the inertia found out of place (at most)
PAUSE = 16  # points done cold when warm starts do not pay, before the next try
SMOOTH = 0.1  # weight of the newest point in those running means
LOOSE_TOL = 2.0**-26  # enough for separators; the disks polish their own roots further
MERGE = 2.0**-40  # features closer than this share of their size get no separator between them (FINE)
# ... and in the first, COARSE, placement: a cluster of roots of one Krein type needs no separator inside it (the
# low-spin liquid roots of a chain lie 1e-6 apart, relative); a float study of paper-n3-fixed grouped at 1e-3
GROUP = 2.0**-10
COARSE, FINE, POLES = 0, 1, 2  # placements of ``_real_roots_at_least``
UNTRIED = -2  # a candidate separator not evaluated (-1: evaluated, Phi not proved nonsingular there)
FENCE = 2.0**-30  # separators this close (relative) either side of each pole
NEAR_REAL = 2.0**-20  # approximations this close to the axis (relative) are expected to be real roots
NUDGE = 2.0**-10  # relative imaginary offset given to suspect real approximations before polishing
# The all-at-once certificate goes first from this many bodies, where n^4 >= ALLATONCE_PRICE D^3: the Newton disks
# cost about n^4 a point, it about D^3 (measured: BENCHMARKS.md, "All eigenvalues at once")
ALLATONCE_BODIES = 10
ALLATONCE_PRICE = 0.1
# ... and from ALLATONCE_FEW bodies where D <= ALLATONCE_WIDTH n (at most 3 modes a body on average) and p has no
# exact zero root (free chains, kappa = 2: its discs then refine warm less often): on grid lines its warm points
# cost less than the disks' there (BENCHMARKS.md, "Issue 32, third session")
ALLATONCE_FEW = 4
ALLATONCE_WIDTH = 5
COLD_RUN = 3  # this many cold starts in a row: no neighbour helps (scattered points), the disks' cold start is cheaper
MANY, FEW = 2, 1  # which price rule put the all-at-once certificate first (``_allatonce_first``)
PAUSE_MAX = 256  # the all-at-once pauses double up to this many points while its cold starts keep failing to pay
MAGNITUDE_LOW, MAGNITUDE_HIGH = 2.0**-150, 2.0**150  # parameters outside are left to exact arithmetic


@kernel
def allocate(n, nmodes, parent):
    """Scratch for ``certify_point`` (one block)."""
    lmax = max(1, nmodes.max())
    degree = int((nmodes + 2).sum())
    nfeat = 2 * degree + 4 * int(nmodes.sum()) + 8  # roots, poles, then the separators
    pws = pencil.allocate(n, lmax, parent)
    C = np.empty((degree, degree))
    Mo = np.empty((n, n))
    wr = np.empty(degree)
    wi = np.empty(degree)
    vdummy = np.empty(1)
    z = np.empty(degree, np.complex128)
    F = np.empty((n, n), np.complex128)
    dF = np.empty((n, n), np.complex128)
    Sm = np.empty((n, n))
    Sr = np.empty((n, n))
    feat = np.empty(nfeat)
    R = np.empty(degree)
    group = np.empty(degree, np.int64)
    state = np.zeros(layout.CERTIFY_STATE, np.int64)  # slots named in layout (PREV_DECIDED, ...)
    # running means (layout.WARM_COST, WARM_HITS, COLD_COST): the hit rate is hoped 1 until tried
    costs = np.zeros(layout.CERTIFY_COSTS)
    costs[layout.WARM_HITS] = 1.0
    zold = np.empty(degree, np.complex128)
    bold = np.zeros((n, lmax))  # beta of the previous point
    dm = np.empty((n, n), np.complex128)
    dr = np.empty((n, n))
    centre = np.empty(degree, np.complex128)
    done = np.empty(degree, np.bool_)
    aw = allatonce.allocate(n, nmodes)  # the all-at-once certificate's scratch and its decomposition
    return layout.CertifyWork(pws, C, Mo, wr, wi, vdummy, z, F, dF, Sm, Sr, feat, R, group, state, dm, dr, centre, done, zold, bold,
                              costs, aw)


@kernel
def _real_roots_at_least(z, d, m, lead_nu, body, E, nmodes, parent, pws, feat, Sm, Sr, suspect, placement):
    """Lower bound of the real roots of p from the inertia of the pole-free form H at separators.

    nu_H(x) = nu(Phi(x)) + #{modes kl : c_kl (x + beta_kl) < 0} changes only at real roots of p, by the
    roots' Krein types, and not at the poles (``_between``; docs/certification.md, section 4).  So an
    interval needs separators at its ends only, wherever its roots all have one type.  ``placement``:

    * COARSE: the approximations that may be real (within NUDGE of the axis) and the exact zero roots, grouped
      where neighbours lie within GROUP (relative); separators only between groups, and only where needed:
      from the ends (+-inf, whose nu_H the leading matrix gives, ``lead_nu``) an interval is cut at the middle
      gap between its groups while it proves fewer roots than the features in it.  A run of roots of one type
      costs no separator inside it; a point costs about one evaluation per change of type.
    * FINE: a separator between every two such features more than MERGE apart.
    * POLES: FINE, with the poles as features too, fenced either side where an approximation is near.  The
      pole-free count does not need them; they stay as the last placement, which the earlier count, with
      |nu(b) - nu(a)| - (poles inside), needed.

    The exact zero roots are fenced either side (2^-30 of the features' size).  Where the count across an
    interval falls short of the near-real approximations inside it, those are marked in ``suspect``: a finer
    placement, or polishing them, is what a retry needs.  ``feat`` needs 2 degree + 4 sum L + 8 entries.
    ``lead_nu`` < 0 (the leading matrix's inertia unproved): the ends are evaluated beyond the features instead.
    Returns (the bound, the separators evaluated).
    """
    n = body.shape[0]
    beta = pws.beta
    nr = 0
    for i in range(d):
        # only approximations that may be real need separating: the others' disks prove them
        if abs(z[i].imag) <= NUDGE * abs(z[i]):
            feat[nr] = z[i].real
            nr += 1
    if m > 0:
        feat[nr] = 0.0
        nr += 1
    lsum = 0
    for k in range(n):
        for l in range(nmodes[k]):
            if beta[0, k, l] == 0.0 and beta[1, k, l] == 0.0:
                continue  # kappa = 2: no pole (pencil._liquid_real); its zero of prod Q is among the m exact zero roots
            feat[nr + lsum] = -beta[0, k, l]
            lsum += 1
    with_poles = placement == POLES
    if nr + lsum == 0 or (nr == 0 and not with_poles):
        suspect[:d] = False
        return 0, 0  # nothing may be real: no real root is proved (and none is expected)
    roots = feat[:nr]
    poles = feat[nr : nr + lsum]
    _sort(roots)
    _sort(poles)
    sep = feat[nr + lsum :]
    lsep = lsum if with_poles else 0  # the poles that place separators
    merge = GROUP if placement == COARSE else MERGE
    if lsep and nr:
        lo, hi = min(roots[0], poles[0]), max(roots[nr - 1], poles[lsep - 1])
    elif lsep:
        lo, hi = poles[0], poles[lsep - 1]
    else:
        lo, hi = roots[0], roots[nr - 1]
    pad = 0.25 * (hi - lo) + 1e-3 * max(abs(lo), abs(hi)) + 1e-300
    zero_eps = FENCE * max(abs(lo), abs(hi)) + 1e-300
    sep[0] = -np.inf if lead_nu >= 0 else lo - pad
    ns = 1
    # POLES: a root inside a pole's fence (a tiny E) may be too close to it for the fences to be evaluated: then
    # every neighbouring pair of features gets its midway separator, fenced or not
    tight = False
    for t in range(lsep):
        tight = tight or _gap_to_root(roots, nr, poles[t]) < 2.0 * (FENCE * abs(poles[t]) + 1e-300)
    i, j = 0, 0
    last, last_fenced, started = 0.0, False, False
    while i < nr or j < lsep:
        pole = j < lsep and (i >= nr or poles[j] < roots[i])
        x = poles[j] if pole else roots[i]
        fence = False
        eps = 0.0
        if pole:
            near = _gap_to_root(roots, nr, x)
            fence = near < RIDE * abs(x)
            eps = FENCE * abs(x) + 1e-300
            if near < 2.0 * eps:  # a root inside the fence (a tiny E): the fence between them, if floats can tell
                eps = max(0.5 * near, 64.0 * 2.0**-52 * abs(x)) + 1e-300
            j += 1
        else:
            fence = m > 0 and x == 0.0
            eps = zero_eps
            i += 1
        if started and (tight or not (fence or last_fenced)) and x - last > merge * max(abs(x), abs(last)):
            sep[ns] = 0.5 * (x + last)
            ns += 1
        if fence:
            sep[ns] = x - eps
            sep[ns + 1] = x + eps
            ns += 2
        last, last_fenced, started = x, fence, True
    sep[ns] = np.inf if lead_nu >= 0 else hi + pad
    ns += 1
    # the count below needs increasing separators (a fence may lie beyond a neighbouring root)
    _sort(sep[:ns])
    if placement == COARSE:
        return _cut_where_short(z, d, m, lead_nu, body, E, nmodes, parent, pws, sep, ns, zero_eps, Sm, Sr, suspect)
    return _krein_count(z, d, m, lead_nu, body, E, nmodes, parent, pws, sep, ns, Sm, Sr, suspect)


@kernel
def _sort(a):
    """Sort a few floats in place (insertion sort: numba's np.sort costs about 1 us on a dozen)."""
    for i in range(1, a.size):
        x = a[i]
        j = i - 1
        while j >= 0 and a[j] > x:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = x


@kernel
def _fixed(s, ns, x, zero_eps):
    """Whether sep[s] of sep[:ns] is one every count evaluates: an end, or a fence of the exact zero roots."""
    return s == 0 or s == ns - 1 or abs(x) == zero_eps


@kernel
def _cut_where_short(z, d, m, lead_nu, body, E, nmodes, parent, pws, sep, ns, zero_eps, Sm, Sr, suspect):
    """``_krein_count`` on the fixed separators and those of sep[:ns] it needs: from the left, an interval whose
    count falls short of the features that may be real inside it is cut at its middle candidate, until it is not
    short or no candidate is left in it.  Returns (the bound, the separators evaluated)."""
    nus = np.full(ns, UNTRIED, np.int64)
    signs = np.zeros(ns, np.int64)
    evaluated = 0
    for s in range(ns):
        if _fixed(s, ns, sep[s], zero_eps):
            nus[s], signs[s] = _value(sep[s], lead_nu, d + m, body, E, nmodes, parent, pws, Sm, Sr)
            evaluated += not math.isinf(sep[s])
    suspect[:d] = False
    total = 0
    a = 0
    while a < ns and nus[a] < 0:
        a += 1
    while a < ns:
        b = a + 1  # the next proved separator: the candidates before it are untried (or failed)
        while b < ns and nus[b] < 0:
            b += 1
        if b >= ns:
            break
        here, expected, maybe = _between(sep[a], sep[b], nus[a], nus[b], signs[a], signs[b], z, d, m, body, E, nmodes, pws)
        if here < maybe:
            k = _middle_untried(nus, a, b)
            if k >= 0:
                nus[k], signs[k] = _value(sep[k], lead_nu, d + m, body, E, nmodes, parent, pws, Sm, Sr)
                evaluated += 1
                continue  # (a, k) next, if k was proved; else (a, b) again with k out
        total += here
        if here < expected:
            _mark(z, d, sep[a], sep[b], suspect)
        a = b
    return total, evaluated


@kernel
def _middle_untried(nus, a, b):
    """The index in (a, b) of the untried separator nearest the middle, or -1."""
    best, gap = -1, b - a
    mid = 0.5 * (a + b)
    for k in range(a + 1, b):
        if nus[k] == UNTRIED and abs(k - mid) < gap:
            best, gap = k, abs(k - mid)
    return best


@kernel
def _krein_count(z, d, m, lead_nu, body, E, nmodes, parent, pws, sep, ns, Sm, Sr, suspect):
    """Real roots of p proved between the increasing separators sep[:ns] (those where Phi is proved
    nonsingular; +-inf from the leading matrix).  Returns (the bound, the separators evaluated)."""
    suspect[:d] = False
    total, last, prev, sign_last, evaluated = 0, -1, 0.0, 0, 0
    for s in range(ns):
        x = sep[s]
        nu, sign = _value(x, lead_nu, d + m, body, E, nmodes, parent, pws, Sm, Sr)
        evaluated += not math.isinf(x)
        if nu < 0:
            continue
        if last >= 0:
            here, expected, _ = _between(prev, x, last, nu, sign_last, sign, z, d, m, body, E, nmodes, pws)
            total += here
            if here < expected:
                _mark(z, d, prev, x, suspect)
        last, prev, sign_last = nu, x, sign
    return total, evaluated


@kernel
def _mark(z, d, a, b, suspect):
    for i in range(d):
        if a < z[i].real < b:
            suspect[i] = True


@kernel
def _value(x, lead_nu, degree, body, E, nmodes, parent, pws, Sm, Sr):
    """(nu_H(x), the sign of p(x)) at a separator (``nu_h``); at x = +-inf from the leading matrix M' = M -
    diag(sum E), nonsingular with ``lead_nu`` negative eigenvalues: nu_H(+-inf) = nu(M') + #{kl : +-c_kl < 0}
    (Phi(x) ~ x^2 M'), and p(+-inf) has the sign of lc p = det M' times (+-1)^degree."""
    if not math.isinf(x):
        return nu_h(x, body, E, nmodes, parent, pws, Sm, Sr)
    side = 1 if x > 0.0 else -1
    nu = lead_nu
    for k in range(body.shape[0]):
        for l in range(nmodes[k]):
            nu += side * pws.krein[k, l] < 0
    sign = -1 if lead_nu % 2 else 1
    if side < 0 and degree % 2:
        sign = -sign
    return nu, sign


@kernel
def _between(a, b, nu_a, nu_b, sign_a, sign_b, z, d, m, body, E, nmodes, pws):
    """(real roots of p proved in (a, b), near-real approximations there, approximations that may be real there)
    from nu_H and the sign of p at its ends.

    With c_kl = E_kl beta_kl^2 (omega_k - beta_kl) over the modes with a pole term (sign in ``pws.krein``), the
    symmetric matrix H(x) of size n + L, [[x^2 M + x G - K - diag_k sum_l E_kl q_kl(x), C], [C^t, diag c_kl (x +
    beta_kl)]], is a polynomial in x, its Schur complement is Phi(x) and det H = prod c_kl * p(x) / (the factors of
    p it leaves out), so by Haynsworth's inertia additivity nu_H(x) = nu(Phi(x)) + #{kl : c_kl (x + beta_kl) < 0}
    (Gohberg, Lancaster & Rodman 1982, the sign characteristic; Kollar & Miller 2014).  Rellich's theorem: across
    (a, b) nu_H changes only where an analytic eigenvalue branch of H vanishes, at a root of p, by at most the
    root's multiplicity, so

        real roots of p in (a, b) >= |nu_H(b) - nu_H(a)| + (modes with E = 0 whose root -beta lies inside),

    and >= m around the exact zero roots, and >= 1 where p changes sign.  A mode whose c has no proved sign (none
    from the model's inputs; kept for safety) stays a pole of the bordered form: its jump is subtracted, as in the
    bound |nu(b) - nu(a)| - (poles inside) this count replaces.
    """
    beta, krein = pws.beta, pws.krein
    inside, exact_roots = 0, 0
    for k in range(body.shape[0]):
        for l in range(nmodes[k]):
            if (beta[0, k, l] == 0.0 and beta[1, k, l] == 0.0) or krein[k, l] != 0:
                continue
            # the balls a + beta_kl and b + beta_kl exclude 0 (real_matrix succeeded at both, or an end is
            # infinite), so -beta_kl lies inside (a, b) exactly when their midpoints differ in sign
            crossed = a + beta[0, k, l] < 0.0 < b + beta[0, k, l]
            if E[k, l] == 0.0:
                exact_roots += crossed  # p's exact factor x + beta_kl
            else:
                inside += crossed  # a pole of unknown type
    here = max(abs(nu_b - nu_a) - inside, 0) + exact_roots
    if sign_a * sign_b < 0:
        # p changes sign: at least one root, whatever the count of the eigenvalue branches
        here = max(here, 1)
    expected, maybe = 0, 0
    for i in range(d):
        if a < z[i].real < b:
            r = abs(z[i].imag)
            expected += r <= NEAR_REAL * abs(z[i])
            maybe += r <= NUDGE * abs(z[i])
    if m > 0 and a < 0.0 < b:
        here = max(here, m)
        expected += m
        maybe += m
    return here, expected, maybe


@kernel
def nu_h(x, body, E, nmodes, parent, pws, Sm, Sr):
    """(nu_H(x), the sign of p(x)) at the real float x, or (-1, 0) where Phi(x) is not proved nonsingular.

    nu_H = nu(Phi(x)) + #{kl : c_kl (x + beta_kl) < 0} (``_krein_count``).  real_matrix succeeded, so each
    ball x + beta_kl (beta_kl != 0) excludes 0 and its midpoint has its sign."""
    n = body.shape[0]
    if not pencil.real_matrix(x, body, E, nmodes, parent, pws, Sm, Sr):
        return -1, 0
    nu = elimination.inertia(Sm, Sr, n)
    if nu < 0:
        return -1, 0
    sign = _sign_of_p(x, nu, pws.beta, nmodes, n)
    for k in range(n):
        for l in range(nmodes[k]):
            if pws.krein[k, l] != 0 and pws.krein[k, l] * (x + pws.beta[0, k, l]) < 0.0:
                nu += 1
    return nu, sign


@kernel
def _gap_to_root(roots, nr, x):
    """Distance from x to the nearest of the sorted roots[:nr] (inf if there are none)."""
    k = np.searchsorted(roots[:nr], x)
    near = np.inf
    if k < nr:
        near = roots[k] - x
    if k > 0:
        near = min(near, x - roots[k - 1])
    return near


@kernel
def _sign_of_p(x, nu, beta, nmodes, n):
    """Sign of p(x) = det Phi(x) prod (x + beta_kl) at a separator where Phi(x) has nu negative eigenvalues, else 0.

    Phi(x) is proved nonsingular there, so det Phi(x) has the sign (-1)^nu; ``real_matrix`` succeeded, so every
    ball x + beta_kl with beta_kl != 0 excludes 0 and its midpoint has its sign (the same balls are formed here).
    A mode with beta exactly 0 contributes the factor x (0 at x = 0: sign unknown).
    """
    sign = -1 if nu % 2 else 1
    for k in range(n):
        for l in range(nmodes[k]):
            tm, tr = ball.radd(x, 0.0, beta[0, k, l], beta[1, k, l])
            if not ball.excludes_zero(tm, tr):
                return 0
            if tm < 0.0:
                sign = -sign
    return sign


@kernel
def _attempt(z, d, m, degree, body, E, nmodes, parent, ws, sweeps):
    """(real roots at least, N_c, status, cost in n x n solves) from the approximations z.

    The inertia, then Newton disks.  ``sweeps``: first polish the
    approximations of non-real roots by at most as many Aberth sweeps (a
    neighbour's roots are good enough for separators, not for disks).
    """
    pws, F, dF, Sm, Sr, R, group, done = ws.pws, ws.F, ws.dF, ws.Sm, ws.Sr, ws.R, ws.group, ws.done
    feat, dm, dr, centre = ws.feat, ws.dm, ws.dr, ws.centre
    # separators between groups of near-real approximations first: a group of roots of one Krein type is
    # counted whole; where an interval is short of its expected roots (a group holds both types), a separator
    # between every two, then the poles fenced too.  Every count is a lower bound: the largest holds.
    lead_nu = ws.state[layout.LEAD_NU]
    real, evaluated = _real_roots_at_least(z, d, m, lead_nu, body, E, nmodes, parent, pws, feat, Sm, Sr, done, COARSE)
    for placement in (FINE, POLES):
        if not done[:d].any():
            break
        more, count = _real_roots_at_least(z, d, m, lead_nu, body, E, nmodes, parent, pws, feat, Sm, Sr, done, placement)
        real = max(real, more)
        evaluated += count
    real = max(m, real)
    upper = 0
    for i in range(d):
        upper += z[i].imag > approximations.UPPER * abs(z[i])
    cost = SEPARATOR_COST * evaluated
    if real > degree:  # impossible for a proved bound: never label from it
        return real, -1, UNDECIDED, cost
    if real == degree:
        return real, 0, DECIDED_INERTIA, cost
    if (degree - real) % 2 == 0:
        if sweeps > 0:
            cost += approximations.aberth_nonreal(z, d, m, sweeps, body, E, nmodes, pws, F, dF, group)
        cost += DISK_COST * upper
        nonreal = disks.nonreal_newton(z, d, m, body, E, nmodes, pws, dm, dr, R, centre)
        if real + nonreal == degree:
            return real, nonreal // 2, DECIDED_DISKS, cost
    return real, -1, UNDECIDED, cost


@kernel
def _eigenvalue_price(n, degree):
    """The D x D eigenvalue problem in n x n solves: fits of their measured times (us, D = 6..64, n = 2..32)."""
    eig = 3.0 + 0.5 * degree + 0.04 * degree**2 + 1.1e-3 * degree**3
    solve = 0.15 + 8e-3 * n**2 + 1e-3 * n**3
    return eig / solve


@kernel
def _fits(x):
    a = abs(x)
    return a == 0.0 or (MAGNITUDE_LOW < a < MAGNITUDE_HIGH)


@kernel
def moderate(body, joint, at, g, E, kappa, nmodes):
    """True if every parameter is zero or of moderate magnitude: the balls then neither overflow nor underflow."""
    if not _fits(g):
        return False
    for k in range(body.shape[0]):
        if not (_fits(joint[k]) and _fits(at[k])):
            return False
        for c in range(body.shape[1]):
            if not _fits(body[k, c]):
                return False
        for l in range(nmodes[k]):
            if not (_fits(E[k, l]) and _fits(kappa[k, l])):
                return False
    return True


@kernel
def certify_point(body, joint, at, g, E, kappa, nmodes, parent, free, ws, reuse):
    """(N_c, status) of one point; status UNDECIDED leaves it to the coefficient path.

    The previous point given to the same workspace is taken as a grid
    neighbour: its roots are tried first.
    """
    pws, z, F, dF, Sm, Sr, R, group, done = ws.pws, ws.z, ws.F, ws.dF, ws.Sm, ws.Sr, ws.R, ws.group, ws.done
    state, costs, zold, bold, aw = ws.state, ws.costs, ws.zold, ws.bold, ws.aw
    n = body.shape[0]
    degree = ws.C.shape[0]
    # M T and K T in the workspace are the previous point's only if it got as far as prepare
    reuse = reuse and state[layout.KEPT] == 1
    state[layout.KEPT] = 0
    if not moderate(body, joint, at, g, E, kappa, nmodes):
        state[layout.PREV_DECIDED] = 0
        return -1, UNDECIDED
    m = pencil.prepare(body, joint, at, g, E, kappa, nmodes, parent, free, pws, reuse)
    state[layout.KEPT] = 1
    d = degree - m
    ok, lead_m, lead_e, lead_nu = disks.lead_bound(pws, n, Sm, Sr)
    state[layout.LEAD_NU] = lead_nu
    if not ok:  # deg p unproved: nothing below counts
        state[layout.PREV_DECIDED] = 0
        return -1, UNDECIDED
    first = _allatonce_first(n, degree, m)
    skipped = False
    if first > 0:
        nc, skipped = _allatonce(body, E, nmodes, parent, m, ws, first == FEW)
        if nc >= 0:
            state[layout.PREV_DECIDED] = 0  # the roots in z are not this point's
            return nc, DECIDED_ALLATONCE
    nc, status = -1, UNDECIDED
    # 1. a grid neighbour's roots, extrapolated, usually separate this point's: no eigenvalue problem
    neighbour = state[layout.PREV_DECIDED] == 1 and state[layout.PREV_DEGREE] == d
    if neighbour:
        approximations.predict(z, zold, d, state[layout.HISTORY] == 1, nmodes, pws.beta, bold)
    state[layout.HISTORY] = 1 if neighbour else 0
    bold[:] = pws.beta[layout.MID]
    if neighbour and state[layout.COLD_LEFT] <= 0:
        real, nc, status, warm = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, WARM_STEPS)
        suspects = done[:d].sum()
        if status == UNDECIDED and 0 < suspects <= d // 4:
            # polish the few approximations the inertia found out of place (done holds them);
            # separators need a few digits, not all.  Real ones are nudged off the axis first:
            # on a real polynomial Aberth keeps real iterates real, so a pair of real roots
            # that met and left the axis would never be found.  More suspects than that: the
            # neighbour is too far, and the eigenvalues are cheaper than polishing them all.
            sign = 1.0
            for i in range(d):
                if done[i] and abs(z[i].imag) <= NEAR_REAL * abs(z[i]):
                    z[i] += complex(0.0, sign * NUDGE * (abs(z[i]) + 1e-300))
                    sign = -sign
                done[i] = not done[i]
            warm += approximations.aberth(z, d, m, WARM_SWEEPS, body, E, nmodes, pws, F, dF, done, LOOSE_TOL)
            real, nc, status, more = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, WARM_STEPS)
            warm += more
        # try warm starts while they pay: their mean cost below the cold start's times their hit rate
        # (scattered points, or grid neighbours too far apart, make them fail or cost too much)
        costs[layout.WARM_COST] = (1 - SMOOTH) * costs[layout.WARM_COST] + SMOOTH * warm if costs[layout.WARM_COST] > 0 else warm
        costs[layout.WARM_HITS] = (1 - SMOOTH) * costs[layout.WARM_HITS] + SMOOTH * (status != UNDECIDED)
        if costs[layout.COLD_COST] > 0 and costs[layout.WARM_COST] > costs[layout.WARM_HITS] * costs[layout.COLD_COST]:
            state[layout.COLD_LEFT] = PAUSE
    elif state[layout.COLD_LEFT] > 0:
        state[layout.COLD_LEFT] -= 1
    # 2. approximations from the linearisation, 3. polished by Aberth sweeps, 4. every disk
    if status == UNDECIDED:
        state[layout.HISTORY] = 0  # the eigenvalues come in their own order: no history to extrapolate from
        C = ws.C
        if pencil.linearisation(body, E, nmodes, parent, pws, C, ws.Mo) and approximations.eigenvalues(C, ws.wr, ws.wi, ws.vdummy, z, degree, m):
            cold = _eigenvalue_price(n, degree)
            real, nc, status, more = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, 0)
            cold += more
            if status == UNDECIDED:
                done[:d] = False
                cold += approximations.aberth(z, d, m, COLD_SWEEPS, body, E, nmodes, pws, F, dF, done, approximations.STEP_TOL)
                real, nc, status, more = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, 0)
                cold += more
            costs[layout.COLD_COST] = (1 - SMOOTH) * costs[layout.COLD_COST] + SMOOTH * cold if costs[layout.COLD_COST] > 0 else cold
            if status == UNDECIDED:
                nonreal = disks.nonreal_in_disks(z, d, m, body, E, nmodes, pws, R, group, lead_m, lead_e)
                if real + nonreal == degree and nonreal % 2 == 0:
                    nc, status = nonreal // 2, DECIDED_DISKS
    if status == UNDECIDED and skipped:
        # the disks did not decide a point the all-at-once certificate skipped in a pause: it tries, cold, before
        # the point goes to exact arithmetic (ill-conditioned identical chains, say, which only it decides)
        nc, _ = allatonce.certify(body, E, nmodes, parent, m, pws, ws.C, ws.Mo, aw, False)
        if nc >= 0:
            state[layout.PREV_DECIDED] = 0
            return nc, DECIDED_ALLATONCE
    state[layout.PREV_DECIDED] = 1 if status != UNDECIDED else 0
    state[layout.PREV_DEGREE] = d
    return nc, status


@kernel
def _allatonce_first(n, degree, m):
    """Whether the all-at-once certificate goes first for n bodies, deg p = degree and m exact zero roots (the
    price rules above): MANY (the disks cost n^4 a point), FEW (few modes a body), or 0 (not first)."""
    if n >= ALLATONCE_BODIES and float(n) ** 4 >= ALLATONCE_PRICE * float(degree) ** 3:
        return MANY
    if n >= ALLATONCE_FEW and degree <= ALLATONCE_WIDTH * n and m == 0:
        return FEW
    return 0


@kernel
def _allatonce(body, E, nmodes, parent, m, ws, few):
    """(N_c by the all-at-once certificate (docs/certification.md, section 4b) or -1, skipped in a pause).

    It pauses after a cold start that did not decide (a free chain's defective zero roots, say): it would only
    add its cost to the certificates behind it.  With few modes a body (``few``) its cold start (eigenvectors)
    also costs more than the disks' (eigenvalues only) and pays only through the warm points after it, so it
    pauses after COLD_RUN cold starts in a row too (scattered points).  PAUSE points first, twice as many after
    each pause that did not end the run, up to PAUSE_MAX; a point decided warm ends it.
    """
    pws, C, Mo, state, aw = ws.pws, ws.C, ws.Mo, ws.state, ws.aw
    flags = aw.state  # the all-at-once certificate's own slots
    if flags[layout.AAO_SKIP] > 0:
        flags[layout.AAO_SKIP] -= 1
        flags[layout.AAO_HELD] = 0  # the decomposition kept is too old to refine
        return -1, True
    nc, warm = allatonce.certify(body, E, nmodes, parent, m, pws, C, Mo, aw, True)
    if warm:
        state[layout.AAO_COLD_RUN], state[layout.AAO_PAUSE] = 0, 0
    else:
        state[layout.AAO_COLD_RUN] += 1
        if nc < 0 or (few and state[layout.AAO_COLD_RUN] >= COLD_RUN):
            state[layout.AAO_PAUSE] = min(2 * state[layout.AAO_PAUSE], PAUSE_MAX) if state[layout.AAO_PAUSE] > 0 else PAUSE
            flags[layout.AAO_SKIP] = state[layout.AAO_PAUSE]
            state[layout.AAO_COLD_RUN] = 0
    return nc, False


@kernel
def allatonce_point(body, joint, at, g, E, kappa, nmodes, parent, free, ws, reuse):
    """(N_c, status) of one point by the all-at-once certificate alone (section 4b): DECIDED_ALLATONCE or
    UNDECIDED, never another proof (for tests and benchmarks).  The previous point's decomposition is refined
    first; ``reuse`` as for ``certify_point``."""
    pws, C, Mo, state, aw = ws.pws, ws.C, ws.Mo, ws.state, ws.aw
    reuse = reuse and state[layout.KEPT] == 1
    state[layout.KEPT] = 0
    if not moderate(body, joint, at, g, E, kappa, nmodes):
        return -1, UNDECIDED
    m = pencil.prepare(body, joint, at, g, E, kappa, nmodes, parent, free, pws, reuse)
    state[layout.KEPT] = 1
    nc, warm = allatonce.certify(body, E, nmodes, parent, m, pws, C, Mo, aw, True)
    return (nc, DECIDED_ALLATONCE) if nc >= 0 else (-1, UNDECIDED)
