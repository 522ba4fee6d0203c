"""Rigorous interval arithmetic with double-double midpoints.

An interval is three float64 numbers ``(h, l, r)``: every real x with
|x - (h + l)| <= r.  Plain float64 midpoints lose too much in a Sturm sequence
of degree 12 and more (measured: most such points undecided), double-double
midpoints keep about 32 digits and decide nearly all points away from a
stability boundary.

Error bounds (u = 2**-53, relative to the result; Joldes, Muller & Popescu,
"Tight and rigorous error bounds for basic building blocks of double-word
arithmetic", ACM TOMS 2017, with margin):
  add  3u^2 / (1 - 4u)  -> we use 4u^2
  mul  below 10u^2 for this variant (products xh*yl, xl*yh in float64, xl*yl
       dropped)          -> we use 16u^2
  div  bounded a posteriori from the residual a - q b, computed rigorously.
Radii are float64 sums of nonnegative terms, inflated by (1 + 16u) to cover
their own rounding; ``ETA`` covers underflow of the low parts.  Operations on
exact zeros (0, 0, 0) give exact zeros, so the zeros the physics puts into the
characteristic polynomial survive and are factored out exactly.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from .options import kernel

U = 2.0**-53
INFL = 1.0 + 16.0 * U
ABS = 1.0 + 4.0 * U  # |h + l| <= |h| * ABS for a normalised double-double
ADD_REL = 4.0 * 2.0**-106
MUL_REL = 16.0 * 2.0**-106
ETA = 2.0**-1000
LARGE = 2.0**600  # magnitudes beyond which we refuse to decide (overflow/underflow margins)


@kernel
def two_sum(a, b):
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@kernel
def fast_two_sum(a, b):
    s = a + b
    return s, b - (s - a)


@intrinsic
def _fused_multiply_add(typingctx, a, b, c):
    """a * b + c rounded once (llvm.fma: one instruction on CPUs with FMA, an exact libm call elsewhere)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]), "llvm.fma.f64")
        return builder.call(fn, args)

    return sig, codegen


@kernel
def two_prod(a, b):
    """p + e = a * b exactly (barring underflow): e is the rounding error of p = fl(a * b)."""
    p = a * b
    return p, _fused_multiply_add(a, b, -p)


@kernel
def is_zero(h, l, r):
    """True if the interval is the exact zero."""
    return h == 0.0 and r == 0.0


@kernel
def certain_nonzero(h, l, r):
    """True if the interval excludes zero and is safely inside the float range (False for NaN)."""
    a = abs(h)
    return a * (1.0 - 4.0 * U) > r and a < LARGE and a > 1.0 / LARGE


@kernel
def add(ah, al, ar, bh, bl, br):
    """Enclosure of a + b."""
    sh, sl = two_sum(ah, bh)
    th, tl = two_sum(al, bl)
    sl += th
    sh, sl = fast_two_sum(sh, sl)
    sl += tl
    sh, sl = fast_two_sum(sh, sl)
    if sh == 0.0 and ar == 0.0 and br == 0.0:
        return 0.0, 0.0, 0.0
    return sh, sl, (ar + br + ADD_REL * abs(sh) * ABS) * INFL


@kernel
def neg(ah, al, ar):
    return -ah, -al, ar


@kernel
def mul(ah, al, ar, bh, bl, br):
    """Enclosure of a * b."""
    if (ah == 0.0 and ar == 0.0) or (bh == 0.0 and br == 0.0):
        return 0.0, 0.0, 0.0
    p, e = two_prod(ah, bh)
    e += ah * bl + al * bh
    h, l = fast_two_sum(p, e)
    aa = abs(ah) * ABS
    ab = abs(bh) * ABS
    r = aa * br + ar * ab + ar * br + MUL_REL * abs(h) * ABS + ETA
    return h, l, r * INFL


@kernel
def fma(ch, cl, cr, ah, al, ar, bh, bl, br):
    """Enclosure of c + a * b."""
    ph, pl, pr = mul(ah, al, ar, bh, bl, br)
    return add(ch, cl, cr, ph, pl, pr)


@kernel
def div(ah, al, ar, bh, bl, br):
    """Enclosure of a / b; the caller guarantees that b excludes zero."""
    if ah == 0.0 and ar == 0.0:
        return 0.0, 0.0, 0.0
    q1 = ah / bh
    rh, rl, rr = fma(ah, al, 0.0, -q1, 0.0, 0.0, bh, bl, 0.0)
    q2 = (rh + rl) / bh
    qh, ql = fast_two_sum(q1, q2)
    # |a/b - q| <= |a - q b| / |b| for the midpoint, plus the propagated radii.
    sh, sl, sr = fma(ah, al, 0.0, -qh, -ql, 0.0, bh, bl, 0.0)
    blow = abs(bh) * (1.0 - 4.0 * U) - br
    resid = (abs(sh) * ABS + sr) / blow
    prop = (ar + (abs(qh) * ABS + resid) * br) / blow
    return qh, ql, (resid + prop) * (1.0 + 64.0 * U) + ETA
