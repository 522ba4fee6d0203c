"""First-order growth rates of the simple real roots of p(lambda) under a viscous liquid (docs/viscous.md).

p = det Phi is the characteristic polynomial of the chain with its liquid frozen.  The viscous liquid of body k
adds -i eps_k lambda^2 (lambda + omega_k) at (k, k) of Phi, eps_k = rho_k P_k / nu_k, and a simple real root
lambda_0 of p moves by i eps q(lambda_0) / p'(lambda_0) to first order.  The perturbation of Phi is diagonal, so
d det / d eps_k is its entry times the cofactor, and lambda^2 cof_kk = dp/dA_k (A_k enters Phi only as lambda^2 A_k
at (k, k)); p is affine in A_k, hence dp/dA_k = (p(A_k + h) - p(A_k)) / h exactly, for any h.  The growth rate of
the mode (solutions ~ exp(i lambda t)) is then

    sigma = -Im lambda = -q(lambda_0) / p'(lambda_0),     q = sum_k eps_k (lambda + omega_k) dp/dA_k.

Everything is ball arithmetic (``ball``): the coefficient enclosures of ``charpoly``, the root enclosures of
``roots.roots_block`` and eps_k as balls; an enclosure of sigma that excludes 0 proves its sign.
"""

from __future__ import annotations

import numpy as np

from . import layout
from .ball import ETA, INFL, U, excludes_zero, radd, rdiv, rmul
from .charpoly import allocate, charpoly_point
from .options import kernel
from .roots import REAL

RATE_OK = 1  # sigma's enclosure computed (p' excludes 0 on the root's enclosure)


@kernel
def _balls(c, m, r):
    """dd intervals (hi, lo, rad) -> balls (m, r)."""
    for i in range(c.shape[0]):
        m[i] = c[i, 0] + c[i, 1]
        r[i] = (c[i, 2] + 2.0 * U * abs(m[i]) + ETA) * INFL


@kernel
def _horner(m, r, xm, xr):
    """The ball polynomial (m, r), ascending, at the ball (xm, xr)."""
    d = m.shape[0] - 1
    hm, hr = m[d], r[d]
    for i in range(d - 1, -1, -1):
        hm, hr = rmul(hm, hr, xm, xr)
        hm, hr = radd(hm, hr, m[i], r[i])
    return hm, hr


@kernel
def _derivative(m, r, dm, dr):
    for i in range(1, m.shape[0]):
        dm[i - 1], dr[i - 1] = rmul(float(i), 0.0, m[i], r[i])


@kernel
def first_order_block(body, joint, g, E, kappa, nmodes, free, parent, at, liquid, eps, eps_r, root_z, root_r, root_kind,
                      out_mid, out_rad, out_ok):
    """sigma of every real root of p enclosed by ``roots_block``, for a block of points.

    Inputs as for ``block.charpoly_block``, and: ``liquid`` int64[nl], the bodies (kernel numbering) whose liquid is
    viscous; ``eps``, ``eps_r`` float64[npts, nl], the balls of eps_k [kg m^2 s]; ``root_z``, ``root_r``,
    ``root_kind`` the outputs of ``roots_block`` for these points.  Writes ``out_mid``, ``out_rad`` float64[npts, D]
    (sigma's ball [1/s] for each root; NaN where not computed) and ``out_ok`` int8[npts, D] (``RATE_OK`` or 0).
    Roots that are exact zeros (radius 0 at 0), unseparated or non-real are not computed here.
    """
    npts, n = body.shape[0], body.shape[1]
    rowdeg = nmodes + 2
    D = int(rowdeg.sum())
    nl = liquid.shape[0]
    ws = allocate(n, max(1, nmodes.max()), D, parent)
    c = np.empty((D + 1, 3))
    cm, cr = np.empty(D + 1), np.empty(D + 1)
    pm, pr = np.empty(D), np.empty(D)
    am, ar = np.empty(D + 1), np.empty(D + 1)
    dm = np.empty((nl, D + 1))
    dr = np.empty((nl, D + 1))
    bk = np.empty((n, 6))
    for p in range(npts):
        out_ok[p, :] = 0
        out_mid[p, :] = np.nan
        out_rad[p, :] = np.nan
        charpoly_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, False)
        _balls(c, cm, cr)
        _derivative(cm, cr, pm, pr)
        for j in range(nl):
            k = liquid[j]
            bk[:, :] = body[p]
            # doubling A_k is exact in binary floating point (h = A_k); a massless shell takes h = 1
            h = bk[k, layout.A] if bk[k, layout.A] != 0.0 else 1.0
            bk[k, layout.A] = bk[k, layout.A] + h
            charpoly_point(bk, joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, False)
            _balls(c, am, ar)
            for i in range(D + 1):
                sm, sr = radd(am[i], ar[i], -cm[i], cr[i])
                dm[j, i], dr[j, i] = rdiv(sm, sr, h, 0.0)
        for i in range(D):
            if root_kind[p, i] != REAL or root_r[p, i] != root_r[p, i]:
                continue
            xm, xr = root_z[p, i].real, root_r[p, i]
            if xm == 0.0 and xr == 0.0:
                continue
            fm, fr = _horner(pm, pr, xm, xr)
            if not excludes_zero(fm, fr):
                continue
            qm, qr = 0.0, 0.0
            for j in range(nl):
                vm, vr = _horner(dm[j], dr[j], xm, xr)
                wm, wr = radd(xm, xr, body[p, liquid[j], layout.OMEGA], 0.0)
                vm, vr = rmul(vm, vr, wm, wr)
                vm, vr = rmul(vm, vr, eps[p, j], eps_r[p, j])
                qm, qr = radd(qm, qr, vm, vr)
            sm, sr = rdiv(qm, qr, fm, fr)
            out_mid[p, i], out_rad[p, i] = -sm, sr
            out_ok[p, i] = RATE_OK
