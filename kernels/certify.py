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

from . import approximations, disks, elimination, pencil
from .options import kernel
from .status import DECIDED_DISKS, DECIDED_INERTIA, UNDECIDED

COLD_SWEEPS = 24  # Aberth sweeps from the linearisation's eigenvalues (CERTIFY.md: enough to degree 48)
WARM_STEPS = 8  # Newton steps on a neighbour's non-real roots before their disks
WARM_SWEEPS = 4  # Aberth sweeps on a neighbour's roots that the inertia found out of place (at most)
MISSES, PAUSE = 4, 16  # warm starts that failed in a row, and the points then done cold
LOOSE_TOL = 2.0**-26  # enough for separators; the disks polish their own roots further
MERGE = 2.0**-40  # features closer than this share of their size get no separator between them
FENCE = 2.0**-30  # separators this close (relative) either side of each pole
NEAR_REAL = 2.0**-20  # approximations this close to the axis (relative) are expected to be real roots
NUDGE = 2.0**-10  # relative imaginary offset given to suspect real approximations before polishing
MAGNITUDE_LOW, MAGNITUDE_HIGH = 2.0**-150, 2.0**150  # parameters outside are left to exact arithmetic


@kernel
def allocate(n, nmodes, parent):
    """Scratch for ``certify_point`` (one block)."""
    lmax = max(1, nmodes.max())
    degree = int((nmodes + 2).sum())
    nfeat = 2 * degree + 3 * int(nmodes.sum()) + 6  # roots, poles, then the separators
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
    # state: [0] the previous point was decided, [1] its degree d, [2] its N_c, [3] points left to do
    # cold, [4] warm misses in a row, [5] zold holds the roots of the point before the previous one,
    # [6] the workspace holds the structure (M T, K T) of the last point given
    state = np.zeros(7, np.int64)
    zold = np.empty(degree, np.complex128)
    bold = np.zeros((n, lmax))  # beta of the previous point
    dm = np.empty((n, n), np.complex128)
    dr = np.empty((n, n))
    centre = np.empty(degree, np.complex128)
    done = np.empty(degree, np.bool_)
    return pws, C, Mo, wr, wi, vdummy, z, F, dF, Sm, Sr, feat, R, group, state, dm, dr, centre, done, zold, bold


@kernel
def _real_roots_at_least(z, d, m, body, E, nmodes, parent, pws, feat, Sm, Sr, suspect):
    """Lower bound of the real roots of p from the inertia of Phi at separators.

    Every pole (and the exact zero roots) is fenced by separators just either
    side of it, and two neighbouring approximations (real parts of z) that no
    fence separates get a separator midway.  So a root that moved past a pole
    since z was found is still counted; where nu changes
    less across an interval than the near-real roots and poles inside it, the
    approximations inside are marked in ``suspect``: polishing them is usually
    all a retry needs.  ``feat`` needs 2 degree + 3 sum L + 6 entries.
    """
    n = body.shape[0]
    beta = pws[5]
    nr = 0
    for i in range(d):
        feat[nr] = z[i].real
        nr += 1
    if m > 0:
        feat[nr] = 0.0
        nr += 1
    lsum = 0
    for k in range(n):
        for l in range(nmodes[k]):
            feat[nr + lsum] = -beta[0, k, l]
            lsum += 1
    roots = np.sort(feat[:nr])
    poles = np.sort(feat[nr : nr + lsum])
    sep = feat[nr + lsum :]
    lo = min(roots[0], poles[0]) if lsum else roots[0]
    hi = max(roots[nr - 1], poles[lsum - 1]) if lsum else roots[nr - 1]
    pad = 0.25 * (hi - lo) + 1e-3 * max(abs(lo), abs(hi)) + 1e-300
    zero_eps = FENCE * max(abs(lo), abs(hi)) + 1e-300
    # every pole (and the exact zero roots) fenced on both sides, and a separator midway between
    # two approximations that no fence already separates
    sep[0] = lo - pad
    ns = 1
    for j in range(lsum):
        eps = FENCE * abs(poles[j]) + 1e-300
        sep[ns] = poles[j] - eps
        sep[ns + 1] = poles[j] + eps
        ns += 2
    if m > 0:
        sep[ns] = -zero_eps
        sep[ns + 1] = zero_eps
        ns += 2
    j = 0
    for i in range(1, nr):
        a, b = roots[i - 1], roots[i]
        while j < lsum and poles[j] <= a:
            j += 1
        fenced = (j < lsum and poles[j] < b) or (m > 0 and a <= 0.0 <= b)
        if not fenced and b - a > MERGE * max(abs(a), abs(b)):
            sep[ns] = 0.5 * (a + b)
            ns += 1
    sep[ns] = hi + pad
    ns += 1
    # the count below needs increasing separators (a fence may lie beyond a neighbouring root)
    sep[:ns].sort()
    suspect[:d] = False
    total, last, prev = 0, -1, 0.0
    for s in range(ns):
        x = sep[s]
        if not pencil.real_matrix(x, body, E, nmodes, parent, pws, Sm, Sr):
            continue
        nu = elimination.inertia(Sm, Sr, n)
        if nu < 0:
            continue
        if last >= 0:
            # roots of p in (prev, x) >= |jump| - poles inside (and >= m around the zero roots)
            inside = 0
            for t in range(lsum):
                inside += prev < poles[t] < x
            here = max(abs(nu - last) - inside, 0)
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
        last, prev = nu, x
    return total


@kernel
def _attempt(z, d, m, degree, body, E, nmodes, parent, ws, newton_steps):
    """(real roots at least, N_c, status) from the approximations z: inertia, then Newton disks.

    ``newton_steps``: first polish the approximations of non-real roots (a
    neighbour's roots are good enough for separators, not for disks).
    """
    pws, C, Mo, wr, wi, vdummy, _z, F, dF, Sm, Sr, feat, R, group, state, dm, dr, centre, done, zold, bold = ws
    real = max(m, _real_roots_at_least(z, d, m, body, E, nmodes, parent, pws, feat, Sm, Sr, done))
    if real > degree:  # impossible for a proved bound: never label from it
        return real, -1, UNDECIDED
    if real == degree:
        return real, 0, DECIDED_INERTIA
    if (degree - real) % 2 == 0:
        if newton_steps > 0:
            approximations.newton_upper(z, d, m, newton_steps, body, E, nmodes, pws, F, dF)
        nonreal = disks.nonreal_newton(z, d, m, body, E, nmodes, pws, dm, dr, R, centre)
        if real + nonreal == degree:
            return real, nonreal // 2, DECIDED_DISKS
    return real, -1, UNDECIDED


@kernel
def _fits(x):
    a = abs(x)
    return a == 0.0 or (MAGNITUDE_LOW < a < MAGNITUDE_HIGH)


@kernel
def _moderate(body, joint, at, g, E, kappa, nmodes):
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
    pws, C, Mo, wr, wi, vdummy, z, F, dF, Sm, Sr, feat, R, group, state, dm, dr, centre, done, zold, bold = ws
    n = body.shape[0]
    degree = C.shape[0]
    # M T and K T in the workspace are the previous point's only if it got as far as prepare
    reuse = reuse and state[6] == 1
    state[6] = 0
    if not _moderate(body, joint, at, g, E, kappa, nmodes):
        state[0] = 0
        return -1, UNDECIDED
    m = pencil.prepare(body, joint, at, g, E, kappa, nmodes, parent, free, pws, reuse)
    state[6] = 1
    d = degree - m
    ok, lead_m, lead_e = disks.lead_bound(pws, n, Sm, Sr)
    if not ok:  # deg p unproved: nothing below counts
        state[0] = 0
        return -1, UNDECIDED
    nc, status = -1, UNDECIDED
    # 1. a grid neighbour's roots, extrapolated, usually separate this point's: no eigenvalue problem
    neighbour = state[0] == 1 and state[1] == d
    if neighbour:
        approximations.predict(z, zold, d, state[5] == 1, nmodes, pws[5], bold)
    state[5] = 1 if neighbour else 0
    bold[:] = pws[5][0]
    if neighbour and state[3] <= 0:
        real, nc, status = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, WARM_STEPS)
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
            approximations.aberth(z, d, m, WARM_SWEEPS, body, E, nmodes, pws, F, dF, done, LOOSE_TOL)
            real, nc, status = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, WARM_STEPS)
        # after a run of misses (scattered points, not a grid) stop trying for a while
        state[4] = 0 if status != UNDECIDED else state[4] + 1
        if state[4] >= MISSES:
            state[3], state[4] = PAUSE, 0
    elif state[3] > 0:
        state[3] -= 1
    # 2. approximations from the linearisation, 3. polished by Aberth sweeps, 4. every disk
    if status == UNDECIDED:
        state[5] = 0  # the eigenvalues come in their own order: no history to extrapolate from
        if pencil.linearisation(body, E, nmodes, parent, pws, C, Mo) and approximations.eigenvalues(C, wr, wi, vdummy, z, degree, m):
            real, nc, status = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, 0)
            if status == UNDECIDED:
                done[:d] = False
                approximations.aberth(z, d, m, COLD_SWEEPS, body, E, nmodes, pws, F, dF, done, approximations.STEP_TOL)
                real, nc, status = _attempt(z, d, m, degree, body, E, nmodes, parent, ws, 0)
            if status == UNDECIDED:
                nonreal = disks.nonreal_in_disks(z, d, m, body, E, nmodes, pws, R, group, lead_m, lead_e)
                if real + nonreal == degree and nonreal % 2 == 0:
                    nc, status = nonreal // 2, DECIDED_DISKS
    state[0] = 1 if status != UNDECIDED else 0
    state[1] = d
    state[2] = nc
    return nc, status
