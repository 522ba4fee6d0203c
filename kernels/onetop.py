"""One heavy top (one body, no liquid modes) decided in plain floats with a proved error bound.

For a single body p(lambda) = a lambda^2 + b lambda - k with a = A + m c^2,
b = C omega and k = K_0 - g m c on a fixed support (docs/model.md; the
one-body case of ``charpoly``), and a = A, k = 0 on a free one (the lever arm
about the centre of mass is 0).  The sign of the discriminant
Delta = b^2 + 4 a k is the whole count: two real roots if Delta > 0, one
complex pair if Delta < 0.

Why floats suffice where they are used: with every input zero or of moderate
magnitude (``certify.moderate``: 2^-150 < |x| < 2^150), no product of up to
five inputs under- or overflows, so each operation has relative error at most
u = 2^-53.  Writing alpha = |A| + |m| c^2 and kappa = |K_0| + |g m c|, the
computed a and k are within 3u alpha and 3u kappa, b^2 within 3u b^2, 4 a k
within 28u alpha kappa, and the final sum adds u (b^2 + 4 alpha kappa): the
computed Delta is within 8u (b^2 + 4 alpha kappa) of the true one (to first
order; the bound used, 16u times that sum as computed, covers the rest).  A
Delta inside its bound (a double root within rounding) goes on to the
double-double path, then to exact arithmetic.  This filter costs a few
flops; the general enclosure of p costs the float peer's whole eigenvalue
problem at this degree (BENCHMARKS.md, "Degree 2").
"""

from __future__ import annotations

from . import layout
from .certify import moderate
from .options import kernel
from .status import DECIDED_FLOAT, UNDECIDED

BOUND = 16.0 * 2.0**-53  # twice the first-order error of the discriminant (module docstring)


@kernel
def one_top(body, joint, at, g, E, kappa, nmodes, free):
    """(N_c, status) of a one-body point without modes; UNDECIDED where the float filter cannot tell."""
    if not moderate(body, joint, at, g, E, kappa, nmodes):
        return -1, UNDECIDED
    m, A, C, c, omega = body[0, layout.M], body[0, layout.A], body[0, layout.C], body[0, layout.CM], body[0, layout.OMEGA]
    if free:
        # p = lambda (A lambda + C omega): both roots real once the degree is proved by A != 0
        return (0, DECIDED_FLOAT) if A != 0.0 else (-1, UNDECIDED)
    a = A + m * c * c
    alpha = abs(A) + abs(m) * c * c
    if abs(a) <= 4.0 * 2.0**-53 * alpha:  # a = 0 may hide in rounding: the degree is unproved here
        return -1, UNDECIDED
    gmc = g * m * c
    k = joint[0] - gmc
    kap = abs(joint[0]) + abs(gmc)
    b2 = C * omega * (C * omega)
    disc = b2 + 4.0 * (a * k)
    if abs(disc) <= BOUND * (b2 + 4.0 * alpha * kap):
        return -1, UNDECIDED
    return (0 if disc > 0.0 else 1), DECIDED_FLOAT
