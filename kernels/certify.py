"""N_c of one point without the coefficients of p: inertia for the real roots, disks for the rest.

docs/certification.md, section 4, gives the proofs.  In short, with
Phi^(x) = diag(Q(x)) Phi(x) diag(Q(x)) (a real symmetric polynomial matrix,
det Phi^ = p prod Q, every zero of prod Q real) and nu(x) the number of
negative eigenvalues of Phi(x), which is that of Phi^(x) off the poles:

* between increasing separators a < b at which Phi is provably nonsingular,
  p has at least |nu(b) - nu(a)| - (poles in (a, b)) real roots (the analytic
  eigenvalue branches of Phi^ must cross zero for nu to change);
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
MERGE = 2.0**-40  # features closer than this share of their size get no separator between them
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
def _real_roots_at_least(z, d, m, body, E, nmodes, parent, pws, feat, Sm, Sr, suspect, with_poles):
    """Lower bound of the real roots of p from the inertia of Phi at separators.

    Neighbouring features (approximations that may be real, within NUDGE of
    the axis, and poles) get a separator midway; poles with such an
    approximation close by, and the exact zero roots, are fenced by
    separators just either side instead.  So a root that moved past a pole
    since z was found is still counted.  Where a root lies inside a pole's
    fence (a tiny E), every neighbouring pair gets its midway separator too:
    if the fences cannot be evaluated, the sign change of p between those
    still proves the root beside its pole (``_sign_of_p``).  Where nu changes
    less across an interval than the near-real roots and poles inside it, the
    approximations inside are marked in ``suspect``: polishing them is usually
    all a retry needs.  ``feat`` needs 2 degree + 4 sum L + 8 entries.

    ``with_poles`` False: separators between the approximations that may be real alone (and the fences of the
    exact zero roots).  p is a polynomial, so its sign change proves a root in an interval whatever poles of Phi
    lie there: one separator between neighbouring simple real roots is all they need, against one or two more
    for every pole.  Repeated roots (no sign change), or a pole's jump in nu cancelling theirs, then leave
    suspects, and the caller counts again with ``with_poles`` True.
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
    if nr + lsum == 0 or (nr == 0 and not with_poles):
        suspect[:d] = False
        return 0  # nothing may be real: no real root is proved (and none is expected)
    roots = np.sort(feat[:nr])
    poles = np.sort(feat[nr : nr + lsum])
    sep = feat[nr + lsum :]
    # the poles that place separators; all of them count in each interval's jump of nu below
    lsep = lsum if with_poles else 0
    lo = min(roots[0], poles[0]) if lsum and nr else (poles[0] if lsum else roots[0])
    hi = max(roots[nr - 1], poles[lsum - 1]) if lsum and nr else (poles[lsum - 1] if lsum else roots[nr - 1])
    pad = 0.25 * (hi - lo) + 1e-3 * max(abs(lo), abs(hi)) + 1e-300
    zero_eps = FENCE * max(abs(lo), abs(hi)) + 1e-300
    # a separator midway between neighbouring features (approximations that may be real, poles);
    # a pole with such an approximation within RIDE of it, and the exact zero roots, are fenced on
    # both sides instead, so that a root that moved past its pole since z was found is still counted
    sep[0] = lo - pad
    ns = 1
    # a root inside a pole's fence (a tiny E) may be too close to it for the fences to be evaluated: then every
    # neighbouring pair of features gets its midway separator, fenced or not, so that the pole and that root
    # still get an interval of their own, whose sign change of p proves the root.  Otherwise fenced features get
    # no midway separator: it would only cost an inertia evaluation.
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
        if started and (tight or not (fence or last_fenced)) and x - last > MERGE * max(abs(x), abs(last)):
            sep[ns] = 0.5 * (x + last)
            ns += 1
        if fence:
            sep[ns] = x - eps
            sep[ns + 1] = x + eps
            ns += 2
        last, last_fenced, started = x, fence, True
    sep[ns] = hi + pad
    ns += 1
    # the count below needs increasing separators (a fence may lie beyond a neighbouring root)
    sep[:ns].sort()
    suspect[:d] = False
    total, last, prev, sign_last = 0, -1, 0.0, 0
    for s in range(ns):
        x = sep[s]
        if not pencil.real_matrix(x, body, E, nmodes, parent, pws, Sm, Sr):
            continue
        nu = elimination.inertia(Sm, Sr, n)
        if nu < 0:
            continue
        sign = _sign_of_p(x, nu, beta, nmodes, n)
        if last >= 0:
            # roots of p in (prev, x) >= |jump| - poles inside (and >= m around the zero roots)
            inside = 0
            for t in range(lsum):
                inside += prev < poles[t] < x
            here = max(abs(nu - last) - inside, 0)
            if sign * sign_last < 0:
                # p changes sign: at least one root, though a pole's jump may cancel the root's in nu (a tiny E
                # puts a root within a few hundred ulps of its pole, too close for a separator between them)
                here = max(here, 1)
            expected = 0
            for i in range(d):
                if prev < z[i].real < x and abs(z[i].imag) <= NEAR_REAL * abs(z[i]):
                    expected += 1
            if m > 0 and prev < 0.0 < x:
                here = max(here, m)
                expected += m
            total += here
            if here < expected:
                for i in range(d):
                    if prev < z[i].real < x:
                        suspect[i] = True
        last, prev, sign_last = nu, x, sign
    return total


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
    # approximations from the eigenvalue problem (no sweeps) are accurate: separators between them alone
    # usually prove every real root; a neighbour's, extrapolated, often leave suspects, so those count at once
    # with the poles fenced
    real = _real_roots_at_least(z, d, m, body, E, nmodes, parent, pws, feat, Sm, Sr, done, sweeps > 0)
    if sweeps == 0 and done[:d].any():  # an interval short of its expected roots: count again, poles fenced
        real = _real_roots_at_least(z, d, m, body, E, nmodes, parent, pws, feat, Sm, Sr, done, True)
    real = max(m, real)
    near, upper = 0, 0
    for i in range(d):
        near += abs(z[i].imag) <= NUDGE * abs(z[i])
        upper += z[i].imag > approximations.UPPER * abs(z[i])
    cost = SEPARATOR_COST * (near + 2 * nmodes.sum() + 2)
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
    ok, lead_m, lead_e = disks.lead_bound(pws, n, Sm, Sr)
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
