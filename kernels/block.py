"""Block kernels: loop over the points of one grid chunk, no per-point allocation."""

from __future__ import annotations

import numpy as np

from . import certify, dd, layout, pencil
from .boxcount import middle
from .charpoly import allocate, block_det, charpoly_point, diagonal_blocks, matrix_box, matrix_point, same_structure
from .count import allocate_count, count_box, count_nodes, count_point, fails_at_nodes
from .onetop import one_top
from .options import kernel
from .status import DECIDED_FLOAT, DECIDED_INCLUSION, UNDECIDED, ZERO_POLYNOMIAL

LAPLACE_MAX = 12  # bodies: the coefficient path's 2^n minors cost 47 ms a point at n = 12
STURM_FIRST = 12  # degree up to which the Sturm sequence is the cheapest proof (scripts/bench_kernel.py)


@kernel
def charpoly_block(body, joint, g, E, kappa, nmodes, free, parent, at, out):
    """Rigorous enclosures of p(lambda) for a block of points.

    Parameters
    ----------
    body : float64[npts, n, 6]
        (m [kg], A [kg m^2], C [kg m^2], c [m], s [m], omega [rad/s]) per body; s is not read
        (joint positions come in ``at``).
    joint : float64[npts, n]
        Stiffness of the joint of body k with its parent [N m/rad]; joint[:, 0] is the base
        joint (fixed support only).  A chain: K_0 (base) and K_1..K_{n-1}.
    g : float64[npts]
        Gravity [m/s^2] (ignored for a free system).
    E, kappa : float64[npts, n, Lmax]
        Liquid modes E [kg m^2] and kappa [1]; only the first nmodes[k] of body k are read.
    nmodes : int64[n]
    free : bool
    parent : int64[n]
        The tree in a regular numbering: parent[0] = -1, 0 <= parent[k] < k (a chain: k - 1).
        ValueError otherwise.
    at : float64[npts, n]
        Position [m] of the joint of body k on the axis of parent[k], from the parent's own
        joint, up positive; at[:, 0] is not read.  A chain: at[:, k] = s of body k - 1.
    out : float64[npts, sum(nmodes + 2) + 1, 3]
        Written: coefficients as (hi, lo, rad) with p_i in [hi + lo - rad, hi + lo + rad],
        ascending powers of lambda.
    """
    npts, n = body.shape[0], body.shape[1]
    rowdeg = nmodes + 2
    degree = int(rowdeg.sum())
    ws = allocate(n, max(1, nmodes.max()), degree, parent)
    for p in range(npts):
        reuse = same_structure(body, joint, at, g, p)
        charpoly_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, out[p], reuse)


@kernel
def count_block(body, joint, g, E, kappa, nmodes, free, parent, at, out_nc, out_status):
    """Number of complex-conjugate root pairs N_c of p(lambda) for a block of points.

    Inputs as for ``charpoly_block``.  Writes ``out_nc`` (int16[npts], -1 where
    undecided or degenerate) and ``out_status`` (int8[npts], codes of kernels.status).

    Where the characteristic matrix is block triangular (``diagonal_blocks``),
    p is the product of the blocks' determinants and N_c the sum of theirs:
    lower degrees, and no repeated roots shared between identical factors.
    """
    npts, n = body.shape[0], body.shape[1]
    rowdeg = nmodes + 2
    degree = int(rowdeg.sum())
    ws = allocate(n, max(1, nmodes.max()), degree, parent)
    c = np.empty((degree + 1, 3))
    cs = allocate_count(degree)
    starts = np.empty(n + 1, np.int64)
    for p in range(npts):
        reuse = same_structure(body, joint, at, g, p)
        out_nc[p], out_status[p] = _count_coefficients(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, cs,
                                                       starts, reuse)


@kernel
def _count_coefficients(body, joint, at, g, E, kappa, nmodes, parent, rowdeg, free, ws, c, cs, starts, reuse, inclusion=True):
    """(N_c, status) of one point from the enclosed coefficients of p, factor by factor (``count_point``)."""
    matrix_point(body, joint, at, g, E, kappa, nmodes, parent, free, ws, reuse)
    return _count_matrix(ws, rowdeg, c, cs, starts, inclusion, False)


@kernel
def _count_matrix(ws, rowdeg, c, cs, starts, inclusion, box):
    """(N_c, status) from the interval matrix P in ws.P, factor by factor: the same N_c for every P it holds.

    ``box``: P encloses a box of parameter points, and each factor is counted by ``count_box``.
    """
    nblocks = diagonal_blocks(ws.P, starts)
    total, status = 0, DECIDED_FLOAT
    for b in range(nblocks):
        d = block_det(ws, rowdeg, starts[b], starts[b + 1], c)
        nc, st = count_box(c[: d + 1], cs) if box else count_point(c[: d + 1], cs, inclusion)
        if st == ZERO_POLYNOMIAL or st == UNDECIDED:
            total, status = -1, st
            if st == ZERO_POLYNOMIAL:
                break
        elif status != UNDECIDED:
            total += nc
            if st == DECIDED_INCLUSION:
                status = DECIDED_INCLUSION
    return total, status


@kernel
def decide_block(body, joint, g, E, kappa, nmodes, free, parent, at, out_nc, out_status):
    """N_c of a block of points by whichever certificate proves it fastest.

    Inputs and outputs as for ``count_block``.  One body without modes goes
    first through a float filter with a proved error bound (``onetop``).  Up to degree ``STURM_FIRST``
    the interval Sturm sequence on the coefficients is the cheapest proof
    (scripts/bench_kernel.py), so it goes first; then the certificates of
    ``certify``; then root inclusion on the coefficients, up to ``LAPLACE_MAX``
    bodies (the coefficients cost 2^n minors).  Points none decides stay
    UNDECIDED: the caller takes them to exact arithmetic.
    """
    npts, n = body.shape[0], body.shape[1]
    rowdeg = nmodes + 2
    degree = int(rowdeg.sum())
    cws = certify.allocate(n, nmodes, parent)
    laplace = n <= LAPLACE_MAX
    sturm_first = degree <= STURM_FIRST
    ws = allocate(n if laplace else 1, max(1, nmodes.max()), degree if laplace else 1, parent if laplace else parent[:1])
    c = np.empty((degree + 1, 3))
    cs = allocate_count(degree)
    starts = np.empty(n + 1, np.int64)
    coefficients_last = -1  # the last point whose M and K the coefficient path built
    certified_last = -1  # and the certificate
    top = n == 1 and nmodes[0] == 0
    for p in range(npts):
        if top:  # a float filter with a proved error bound decides almost every one-top point (onetop.py)
            out_nc[p], out_status[p] = one_top(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, free)
            if out_status[p] != UNDECIDED:
                continue
        reuse = same_structure(body, joint, at, g, p)
        nc, st = -1, UNDECIDED
        if sturm_first:
            again = reuse and coefficients_last == p - 1
            nc, st = _count_coefficients(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, cs, starts, again,
                                         False)
            coefficients_last = p
        if st == UNDECIDED:
            # M and K in the certificate's workspace are those of the last point it saw
            again = reuse and certified_last == p - 1
            nc, st = certify.certify_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, cws, again)
            certified_last = p
        if st == UNDECIDED and laplace:
            again = (reuse and coefficients_last == p - 1) or coefficients_last == p
            nc, st = _count_coefficients(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, cs, starts, again)
            coefficients_last = p
        out_nc[p] = nc
        out_status[p] = st


@kernel
def allatonce_block(body, joint, g, E, kappa, nmodes, free, parent, at, out_nc, out_status):
    """N_c of a block of points by the all-at-once certificate alone (docs/certification.md, section 4b).

    Inputs and outputs as for ``count_block``; out_status is DECIDED_ALLATONCE or UNDECIDED.  For tests and
    benchmarks: ``decide_block`` puts this certificate in its proof chain where it pays.  Returns the number of
    cold starts (eigenvector computations); the other decided points were refined from their neighbour's.
    """
    npts, n = body.shape[0], body.shape[1]
    cws = certify.allocate(n, nmodes, parent)
    for p in range(npts):
        reuse = same_structure(body, joint, at, g, p)
        out_nc[p], out_status[p] = certify.allatonce_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, cws, reuse)
    return cws.aw.state[layout.AAO_COLD]


@kernel
def linearise_block(body, joint, g, E, kappa, nmodes, free, parent, at, out):
    """The D x D first-order linearisation of every point into out (npts, D, D); returns a bool mask of success.

    Its eigenvalues are the roots of p (``pencil.linearisation``): what a float
    method takes as its input.  False where M - diag(sum E) is singular.
    """
    npts, n = body.shape[0], body.shape[1]
    ws = pencil.allocate(n, max(1, nmodes.max()), parent)
    Mo = np.empty((n, n))
    ok = np.zeros(npts, np.bool_)
    for p in range(npts):
        pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws, same_structure(body, joint, at, g, p))
        ok[p] = pencil.linearisation(body[p], E[p], nmodes, parent, ws, out[p], Mo)
    return ok


@kernel
def box_block(body, rbody, joint, rjoint, g, rg, E, kappa, nmodes, free, parent, at, rat, out_nc, out_status):
    """N_c proved for every parameter point of each of a block of boxes, or UNDECIDED.

    Box p is the set of parameter points within the radii (``rbody``, ``rjoint``, ``rg``, ``rat``,
    shaped as ``body``, ``joint``, ``g`` and ``at``, all >= 0) of the midpoint given in ``body``,
    ``joint``, ``g`` and ``at`` (layout as for ``charpoly_block``); E and kappa are exact.  The
    coefficients of p are enclosed over the whole box, and ``count_box`` (the Sturm sequence, then
    sign changes and Newton disks) proves one N_c for every polynomial in that enclosure: every sign
    a count needs is proved on the whole box, so the number of real roots, the degree and hence N_c
    cannot change inside it (docs/certification.md, section 6).  Writes ``out_nc`` (int16[npts], -1
    unless decided) and ``out_status`` (int8[npts]: DECIDED_FLOAT (Sturm), DECIDED_INCLUSION (signs
    and disks), ZERO_POLYNOMIAL or UNDECIDED).  A box of more than ``LAPLACE_MAX`` bodies is
    UNDECIDED.
    """
    npts, n = body.shape[0], body.shape[1]
    rowdeg = nmodes + 2
    degree = int(rowdeg.sum())
    laplace = n <= LAPLACE_MAX
    ws = allocate(n if laplace else 1, max(1, nmodes.max()), degree if laplace else 1, parent if laplace else parent[:1])
    c = np.empty((degree + 1, 3))
    cs = allocate_count(degree)
    starts = np.empty(n + 1, np.int64)
    for p in range(npts):
        out_nc[p], out_status[p] = -1, UNDECIDED
        if not laplace or not _box_ok(body[p], rbody[p]):
            continue
        matrix_box(body[p], rbody[p], joint[p], rjoint[p], at[p], rat[p], g[p], rg[p], E[p], kappa[p], nmodes, parent, free, ws)
        out_nc[p], out_status[p] = _count_matrix(ws, rowdeg, c, cs, starts, True, True)


@kernel
def _box_ok(body, rb):
    """False for a box the enclosures cannot take: a radius not finite and >= 0, or a magnitude beyond dd.LARGE."""
    for k in range(body.shape[0]):
        for col in range(layout.NBODY):
            r = rb[k, col]
            if not (r >= 0.0 and r < dd.LARGE and abs(body[k, col]) < dd.LARGE):
                return False
    return True


@kernel
def nodes_box_block(body, rbody, joint, rjoint, g, rg, E, kappa, nmodes, free, parent, at, rat, t, t_lo, t_hi, t2, t2_lo, t2_hi, spin,
                    out_nc, out_status, out_split):
    """N_c proved for every point of each of a block of boxes along whose one or two main parameters p is a polynomial.

    Box p moves t over [t_lo[p], t_hi[p]] and t2 over [t2_lo[p], t2_hi[p]] (its other parameters within their
    radii), and every coefficient of p is a polynomial of degree < N1 in t and < N2 in t2.  ``t[p]`` holds N1
    distinct nodes in the interval of t, ``t2[p]`` N2 in that of t2; N2 = 1 (t2 = t2_lo = t2_hi = 0) is a box along
    t alone.  ``body[p, k]``, ``joint[p, k]``, ``g[p, k]``, ``at[p, k]`` (with their radii ``rbody`` ... in the same
    layout) are the kernel inputs at node k = i N2 + j, (t[p, i], t2[p, j]), layouts as for ``box_block`` with a
    node axis after the box axis.  ``spin``: t is u = 1 / omega^2 of the spin-scaled model (every t[p, i] > 0), and
    the joints and g given are those of u = 1; node k takes them times t[p, i], a product exact in double-double
    (``charpoly.matrix_box``), so its inputs are the model's at u_i with no rounding radius.  A float product
    formed outside would carry a radius of one rounding at every node, which the near-repeated roots of identical
    bodies do not survive (docs/certification.md, section 6).  The coefficients are enclosed at each node as
    narrowly as at a point, and ``count_nodes`` counts over the whole box (docs/certification.md, section 6).
    Outputs as for ``box_block``, and ``out_split`` (int8[npts]): for a box left UNDECIDED, 1 or 2 if it is best
    cut across t1 or t2 alone (``count.fails_at_nodes``), else 0.  More than ``LAPLACE_MAX`` bodies: UNDECIDED.
    ValueError unless the node axis has N1 N2 entries.
    """
    npts, N, n = body.shape[0], body.shape[1], body.shape[2]
    N1, N2 = t.shape[1], t2.shape[1]
    if N != N1 * N2:
        raise ValueError("nodes_box_block: the node axis must hold t.shape[1] * t2.shape[1] nodes")
    rowdeg = nmodes + 2
    degree = int(rowdeg.sum())
    laplace = n <= LAPLACE_MAX
    ws = allocate(n if laplace else 1, max(1, nmodes.max()), degree if laplace else 1, parent if laplace else parent[:1])
    cs = allocate_count(degree)
    C = np.empty((N, degree + 1, 3))
    Xn = np.empty((N, degree + 1, 3))
    F = np.empty((4, N, 3))
    G = np.empty((N1, 3))
    probe = np.empty(5, np.int64)
    done = np.empty(N, np.bool_)
    for p in range(npts):
        out_nc[p], out_status[p], out_split[p] = -1, UNDECIDED, 0
        ok = laplace and _nodes_ok(t[p], t_lo[p], t_hi[p]) and _nodes_ok(t2[p], t2_lo[p], t2_hi[p])
        ok = ok and (not spin or t_lo[p] > 0.0)  # the nodes lie in [t_lo, t_hi]
        for k in range(N):
            ok = ok and _box_ok(body[p, k], rbody[p, k])
        if not ok:
            continue
        grid = (N1, t[p], *_ball(t_lo[p], t_hi[p]), N2, t2[p], *_ball(t2_lo[p], t2_hi[p]))
        # The middle and the corner nodes first: a box whose roots cross a separator, or move too far to be
        # enclosed, is left unproved there, at a fifth of the cost of all its nodes (``fails_at_nodes``).
        probe[0], probe[1:] = middle(grid), corners(N1, N2)
        done[:] = False
        for k in probe:
            if not done[k]:
                _node(p, k, N2, spin, t, body, rbody, joint, rjoint, at, rat, g, rg, E, kappa, nmodes, parent, free, ws, rowdeg, n, C)
                done[k] = True
        low, top = -1, -1
        if not np.all(done):
            fails, low, top, out_split[p] = fails_at_nodes(C, probe, grid, cs, Xn)
            if fails:
                continue
        for k in range(N):
            if not done[k]:
                _node(p, k, N2, spin, t, body, rbody, joint, rjoint, at, rat, g, rg, E, kappa, nmodes, parent, free, ws, rowdeg, n, C)
        out_nc[p], out_status[p] = count_nodes(C, grid, cs, Xn, F, G, low, top)


@kernel
def corners(N1, N2):
    """The nodes nearest the box's corners: the first and last along each axis (node i N2 + j)."""
    return np.array([0, N2 - 1, (N1 - 1) * N2, N1 * N2 - 1], dtype=np.int64)


@kernel
def _node(p, k, N2, spin, t, body, rbody, joint, rjoint, at, rat, g, rg, E, kappa, nmodes, parent, free, ws, rowdeg, n, C):
    """C[k]: p enclosed at node k of box p (``nodes_box_block``)."""
    u = t[p, k // N2] if spin else 1.0
    matrix_box(body[p, k], rbody[p, k], joint[p, k], rjoint[p, k], at[p, k], rat[p, k], g[p, k], rg[p, k], E[p], kappa[p], nmodes, parent,
               free, ws, u)
    block_det(ws, rowdeg, 0, n, C[k])


@kernel
def _nodes_ok(t, lo, hi):
    """Distinct nodes in decreasing order inside a finite [lo, hi]: the divided differences divide by their gaps."""
    ok = lo <= hi and abs(lo) < dd.LARGE and abs(hi) < dd.LARGE
    for k in range(t.shape[0]):
        ok = ok and lo <= t[k] <= hi and (k == 0 or t[k] < t[k - 1])
    return ok


@kernel
def _ball(lo, hi):
    """Midpoint and radius of a float ball holding [lo, hi]."""
    m = 0.5 * lo + 0.5 * hi
    return m, np.nextafter(max(hi - m, m - lo), np.inf)
