"""The exact path's fast count: root inclusion disks from ball values of det A(z), no exact polynomial.

A(x) = sum_t coefs[t] x^t is diag(Q) Phi with its rows cleared of denominators (``exact.int_matrix``), so
p = det A / den.  Approximations z_1 .. z_d of the roots of det A come from the eigenvalues of a block
companion matrix of A in floats (numpy); they only place the disks.  The proof is section 3's theorem
(docs/certification.md): with a the exact leading coefficient of det A (an integer determinant) and

    W_i = det A(z_i) / (a prod_{j != i} (z_i - z_j)),

every disk |lambda - z_i| <= d |W_i| that meets no other disk holds exactly one root; such a disk centred on the
real axis holds a real root, one that misses the axis a non-real root (a disk that meets the axis is first
moved onto it, grown to still hold itself).  det A(z_i) and the products are Arb balls (python-flint) at
``PREC`` bits from the exact integer coefficients, so each W_i encloses the true value.  Whenever the disks
are not pairwise apart (close or repeated roots, poor approximations), even after a few Weierstrass steps,
``count`` returns None and the caller takes the exact polynomial (``exact.complex_pairs``).
"""

from __future__ import annotations

import math

import flint
import numpy as np

PREC = 128  # bits of the balls: det A(z_i) at a simple root's float approximation needs ~60 above the noise
REFINE = 4  # at most this many Weierstrass steps in balls when the float disks do not separate
SAFE = 1.0 + 2.0**-40  # float distances and radii are rounded outward by far more than their few-ulp errors
TINY = 2.0**-1000


def count(coefs: list, degrees: list) -> int | None:
    """Real roots of det(sum_t coefs[t] x^t) with multiplicity, or None where the disks do not prove it.

    ``coefs``: integer n x n matrices (``flint.fmpz_mat``); ``degrees[k]``: the degree bound of row k.  The
    count is proved only when the x^sum(degrees) coefficient a of the determinant is nonzero, so the degree
    is exactly d = sum(degrees) and all d roots sit in the d disks (after the rows' factors x, ``_deflate``).
    """
    n = coefs[0].nrows()
    for k, m in enumerate(degrees):
        if any(coefs[t][k, j] != 0 for t in range(m + 1, len(coefs)) for j in range(n)):
            raise ValueError(f"exact_disks.count: row {k} has terms above its degree bound degrees[{k}] = {m}; "
                             "pass each row's true degree bound (the proof needs the x^sum(degrees) coefficient)")
    coefs, degrees, zeros = _deflate(coefs, degrees)
    d = sum(degrees)
    if d == 0:
        return zeros
    lead = _lead(coefs, degrees)
    a = lead.det()
    if a == 0:
        return None
    z = _approximations(coefs, degrees)
    if z is None:
        return None
    old = flint.ctx.prec
    flint.ctx.prec = PREC
    try:
        mats = ([flint.arb_mat(c) for c in coefs], [flint.acb_mat(c) for c in coefs])
        centres = [flint.acb(float(x.real), float(x.imag)) for x in z]
        largest = math.inf
        for step in range(REFINE + 1):
            W = _corrections(mats, a, centres)
            if W is None:
                return None
            real = _real_if_separated(centres, W, d)
            if real is not None:
                return zeros + real
            # Steps that do not shrink the largest correction 4x are in a cluster's or a repeated root's slow
            # (linear) regime: the exact polynomial is cheaper than more of them.
            now = max(float(abs(w).mid()) for w in W)
            if now > largest / 4:
                return None
            largest = now
            # A Weierstrass (Durand-Kerner) step on the midpoints.  The first one also tilts every centre off the
            # axis by 2^-30 of itself: real approximations of a cluster that holds a complex pair stay real
            # under the real iteration, and a real root's centre comes back to the axis in a step or two.
            tilt = [flint.acb(0, 2.0**-30 * (-1) ** i) if step == 0 else 0 for i in range(d)]
            centres = [(c - w + c * t).mid() for c, w, t in zip(centres, W, tilt, strict=True)]
    finally:
        flint.ctx.prec = old
    return None


def _corrections(mats: tuple, a, centres: list) -> list | None:
    """W_i = det A(z_i) / (a prod_{j != i} (z_i - z_j)) as Arb balls; None where one is not finite.

    ``mats``: the coefficients as arb_mat and as acb_mat; a real centre takes the real ones (2-3x cheaper).
    """
    prods = flint.acb_poly.from_roots(centres).derivative().evaluate(centres, algorithm="iter")
    out = []
    for x, q in zip(centres, prods, strict=True):
        real = x.imag.is_zero()
        coefs = mats[0] if real else mats[1]
        x = x.real if real else x
        val = coefs[-1]
        for c in coefs[-2::-1]:
            val = val * x + c
        w = val.det() / (q * a)
        if not w.is_finite():
            return None
        out.append(w)
    return out


def _real_if_separated(centres: list, W: list, d: int) -> int | None:
    """The number of real roots if the disks |lambda - z_i| <= d |W_i| are pairwise apart, else None.

    A disk that meets the real axis is moved onto it (centre Re z_i, radius grown by |Im z_i|: it still
    holds the first) and then, isolated, holds one real root; a disk off the axis, isolated, holds one
    non-real root.  Checked in floats: each centre rounded to a float grows its radius by the rounding, and
    the float distances and sums are rounded outward by SAFE.
    """
    z = np.empty(len(centres), dtype=complex)
    radius = np.empty(len(centres))
    for i, (c, w) in enumerate(zip(centres, W, strict=True)):
        z[i] = complex(float(c.real.mid()), float(c.imag.mid()))
        moved = abs(c - flint.acb(z[i].real, z[i].imag)).upper()
        radius[i] = math.nextafter(float((w.abs_upper() * d + moved).upper()), math.inf)
    if not np.all(np.isfinite(radius)):
        return None
    real = np.abs(z.imag) / SAFE <= radius * SAFE + TINY
    radius[real] = (radius[real] + np.abs(z.imag[real])) * SAFE
    z[real] = z[real].real
    # TINY: a difference or hypot that lands below the normal range has an absolute, not a relative, error.
    gap = np.abs(z[:, None] - z[None, :]) / SAFE - TINY
    np.fill_diagonal(gap, np.inf)
    if np.any(gap <= (radius[:, None] + radius[None, :]) * SAFE + TINY):
        return None
    return int(np.count_nonzero(real))


def _deflate(coefs: list, degrees: list):
    """(coefs, degrees, zeros): every row whose entries all vanish at x = 0 divided by x, as often as it goes.

    det A = x^zeros det A'; a liquid mode with beta = 0 (kappa = 2, or omega = 0) puts the factor x in its
    body's whole row, and a root exactly at 0 would otherwise sit under a disk it cannot be told apart from.
    """
    coefs = list(coefs)
    degrees = list(degrees)
    n, zeros = coefs[0].nrows(), 0
    for k in range(n):
        while degrees[k] > 0 and all(coefs[0][k, j] == 0 for j in range(n)):
            coefs = [flint.fmpz_mat(c) for c in coefs]  # copies: the caller's matrices stay as they were
            for t in range(len(coefs) - 1):
                for j in range(n):
                    coefs[t][k, j] = coefs[t + 1][k, j]
            for j in range(n):
                coefs[-1][k, j] = 0
            degrees[k] -= 1
            zeros += 1
    return coefs, degrees, zeros


def _lead(coefs: list, degrees: list) -> flint.fmpz_mat:
    """Row k's coefficient of x^degrees[k]: det of it is the x^d coefficient of det A."""
    n = coefs[0].nrows()
    out = flint.fmpz_mat(n, n)
    for k, m in enumerate(degrees):
        if m < len(coefs):
            for j in range(n):
                out[k, j] = coefs[m][k, j]
    return out


def _approximations(coefs: list, degrees: list) -> np.ndarray | None:
    """d float approximations: eigenvalues of the block companion of A with row k shifted by x^(m - degrees[k]).

    The shifts add sum(m - degrees[k]) roots at 0 to the padded determinant; that many eigenvalues of
    smallest modulus are dropped.  Rows are scaled by powers of two (roots unchanged) so the floats stay in range.
    """
    n, m = coefs[0].nrows(), max(degrees)
    shift = [m - dk for dk in degrees]
    F = np.zeros((m + 1, n, n))
    for k in range(n):
        row = [[int(coefs[t][k, j]) if 0 <= t < len(coefs) else 0 for j in range(n)] for t in range(-shift[k], m + 1 - shift[k])]
        bits = max((abs(v).bit_length() for r in row for v in r), default=0)
        if bits == 0:
            return None
        scale = 1 << max(bits - 60, 0)
        for t, r in enumerate(row):
            F[t, k] = [v / scale for v in r]
    try:
        X = np.linalg.solve(F[m], np.concatenate(F[:m], axis=1))
    except np.linalg.LinAlgError:
        return None
    C = np.zeros((n * m, n * m))
    C[: n * (m - 1), n:] = np.eye(n * (m - 1))
    C[n * (m - 1):] = -X
    with np.errstate(all="ignore"):
        z = np.linalg.eigvals(C)
    if not np.all(np.isfinite(z)):
        return None
    drop = sum(shift)
    z = z[np.argsort(np.abs(z), kind="stable")][drop:] if drop else z
    return z.astype(complex)
