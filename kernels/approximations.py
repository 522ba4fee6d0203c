"""Approximations of the roots of p for the certificates: they place separators and disks, they prove nothing.

From the eigenvalues of the first-order linearisation (LAPACK dgeev), from a
grid neighbour's roots (``predict``), polished by Aberth-Ehrlich sweeps or
Newton steps on det Phi (the trace formula, ``elimination.trace_solve``).
A poor approximation only makes a separator or a disk useless.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

from . import ball, elimination, pencil
from .options import kernel

# LAPACK dgeev (eigenvalues only) as numba's own np.linalg binds it: numba's
# np.linalg.eigvals refuses real input with complex eigenvalues, and binding
# scipy's pointer through ctypes would stop the kernels being cached.
_RGEEV = _LAPACK().numba_ez_rgeev(types.float64)
_KIND = ord("d")
_NO_VECTORS = ord("N")

STEP_TOL = 2.0**-46  # an Aberth step below this share of the root: converged
RIDE = 0.05  # a root this close to a pole (relative) is predicted to move with it
UPPER = 2.0**-30  # approximations this far above the axis (relative) are taken for non-real roots


@kernel
def eigenvalues(C, wr, wi, vdummy, z, degree, m):
    """Eigenvalues of C into z, without the m of smallest modulus (the exact zero roots); False on failure."""
    info = _RGEEV(_KIND, _NO_VECTORS, _NO_VECTORS, degree, C.ctypes, degree, wr.ctypes, wi.ctypes, vdummy.ctypes, 1, vdummy.ctypes, 1)
    if info != 0:
        return False
    for _ in range(m):
        k, best = 0, np.inf
        for i in range(degree):
            a = abs(complex(wr[i], wi[i]))
            if a < best:
                k, best = i, a
        wr[k], wi[k] = np.nan, np.inf  # removed
    pos = 0
    for i in range(degree):
        if wi[i] != np.inf:
            z[pos] = complex(wr[i], wi[i])
            pos += 1
    for i in range(pos):
        if not (math.isfinite(z[i].real) and math.isfinite(z[i].imag)):
            return False
    return True


@kernel
def newton_ratio(z, m, body, E, nmodes, pws, F, dF):
    """p~(z) / p~'(z) in floats (the trace formula); NaN where it is not finite."""
    logq = pencil.float_matrices(z, body, E, nmodes, pws, F, dF)
    t = elimination.trace_solve(F, dF, body.shape[0]) + logq - m * ball.recip(z)
    if not (math.isfinite(t.real) and math.isfinite(t.imag)) or t == 0.0:
        return complex(np.nan, np.nan)
    return ball.recip(t)


@kernel
def aberth(z, d, m, sweeps, body, E, nmodes, pws, F, dF, done, tol):
    """Aberth-Ehrlich sweeps on p~ = det Phi prod (z + beta) / z^m; returns the n x n solves it took.

    Only the roots with ``done`` False move; one whose step fell below
    ``tol`` of itself is left alone after.
    """
    solves = 0
    for _ in range(sweeps):
        moved = False
        for i in range(d):
            if done[i]:
                continue
            zi = z[i]
            solves += 1
            ratio = newton_ratio(zi, m, body, E, nmodes, pws, F, dF)
            if not (math.isfinite(ratio.real) and math.isfinite(ratio.imag)):
                done[i] = True
                continue
            s = 0.0j
            for j in range(d):
                if j != i:
                    s += ball.recip(zi - z[j])
            step = ratio * ball.recip(1.0 - ratio * s)
            if math.isfinite(step.real) and math.isfinite(step.imag):
                z[i] = zi - step
                if abs(step) > tol * abs(z[i]):
                    moved = True
                else:
                    done[i] = True
        if not moved:
            break
    return solves


@kernel
def predict(z, zold, d, two, nmodes, beta, bold):
    """This point's roots from the previous points' (z, and zold before it), in place; zold <- z.

    A root close to a pole (a liquid mode: the root rides on its pole) keeps its
    offset from that pole, scaled as the pole moved; the others are extrapolated
    linearly from the two previous points (Aberth keeps each root's index).
    Measured: quadratic extrapolation from three points separates fewer roots
    (roots passing poles make the motion anything but smooth).
    """
    for i in range(d):
        t = z[i]
        best, bk, bl = np.inf, -1, -1
        for k in range(nmodes.shape[0]):
            for l in range(nmodes[k]):
                dist = abs(t + bold[k, l])
                if dist < best:
                    best, bk, bl = dist, k, l
        if bk >= 0 and best < RIDE * abs(bold[bk, bl]) and bold[bk, bl] != 0.0:
            old, new = -bold[bk, bl], -beta[0, bk, bl]
            z[i] = new + (t - old) * (new / old)
        elif two:
            z[i] = 2.0 * t - zold[i]
        zold[i] = t



@kernel
def aberth_nonreal(z, d, m, sweeps, body, E, nmodes, pws, F, dF, idx):
    """Aberth-Ehrlich sweeps on the non-real approximations only; returns the n x n solves it took.

    The real ones stay.  If the upper half plane holds as many as the lower,
    only the upper ones move and the lower ones count as their conjugates
    (rewritten so at the end): half the work.  Unlike Newton steps from a
    neighbour's roots, two approximations cannot settle on one root (measured
    on grid lines at degree 36-48: warm starts then decided 85-94 % of points
    instead of 43-51 %).  ``idx`` is int64 scratch of d entries.
    """
    nu, nl = 0, 0
    for i in range(d):
        if z[i].imag > UPPER * abs(z[i]):
            nu += 1
        elif z[i].imag < -UPPER * abs(z[i]):
            nl += 1
    paired = nu == nl
    k = 0
    for i in range(d):
        if z[i].imag > UPPER * abs(z[i]) or (not paired and z[i].imag < -UPPER * abs(z[i])):
            idx[k] = i
            k += 1
    solves = 0
    for _ in range(sweeps):
        moved = False
        for a in range(k):
            i = idx[a]
            if i < 0:  # converged, or no step possible
                continue
            zi = z[i]
            solves += 1
            ratio = newton_ratio(zi, m, body, E, nmodes, pws, F, dF)
            if not (math.isfinite(ratio.real) and math.isfinite(ratio.imag)):
                idx[a] = -1 - i
                continue
            s = 0.0j
            for j in range(d):
                if j == i or (paired and z[j].imag < -UPPER * abs(z[j])):
                    continue  # a lower one stands for the conjugate of an upper one, added with it
                s += ball.recip(zi - z[j])
                if paired and z[j].imag > UPPER * abs(z[j]):
                    s += ball.recip(zi - z[j].conjugate())
            if paired:
                s += ball.recip(zi - zi.conjugate())
            step = ratio * ball.recip(1.0 - ratio * s)
            if not (math.isfinite(step.real) and math.isfinite(step.imag)):
                idx[a] = -1 - i
                continue
            z[i] = zi - step
            if abs(step) > STEP_TOL * abs(z[i]):
                moved = True
            else:
                idx[a] = -1 - i
        if not moved:
            break
    if paired:
        # the lower half plane: the conjugates of the upper, in the slots the lower ones held
        a = 0
        for j in range(d):
            if z[j].imag < -UPPER * abs(z[j]) and a < k:
                i = idx[a] if idx[a] >= 0 else -1 - idx[a]
                z[j] = z[i].conjugate()
                a += 1
    return solves
