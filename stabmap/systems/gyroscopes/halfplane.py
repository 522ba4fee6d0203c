"""Roots of a polynomial with complex coefficients in the growing half-plane, counted exactly (python-flint).

A future model of a liquid at large but finite Reynolds number (docs/viscous.md, last section) gives
characteristic polynomials p(lambda) = re(lambda) + i im(lambda) with complex coefficients.  Solutions go like
exp(i lambda t), so a root with Im lambda < 0 grows.  This module counts, with multiplicity and exactly, the roots
in each part of the plane; it is the exact fallback such a model's interval kernel would use.  No atlas uses it yet.

**Method** (Cauchy index by a Sturm chain; Frank 1946, Bull. AMS 52, 144-157; Eisermann 2008, arXiv 0808.0097;
Gantmacher, *Theory of Matrices* vol. 2, ch. XV):

1. *Normalise.*  With c = a + ib the leading coefficient of p (degree n), the polynomial conj(c) p has a real
   positive leading coefficient |c|^2 and the same roots.  Its real and imaginary parts on the real axis are

       P = a re + b im,   Q = a im - b re,    deg Q < deg P = n,

   computed exactly in rationals (a division by a complex c mixes re and im; multiplying by conj(c) does the
   same exactly, and the positive factor |c|^2 is left out, since it moves no root and no sign).
2. *Index.*  Along the real axis, Delta arg p = pi (n_+ - n_-), n_+ the decaying roots (Im > 0), n_- the growing
   ones, for a p without real roots; and Delta arg p = -pi I(Q/P), with I the Cauchy index over the whole axis.
   Sturm's theorem for the Cauchy index gives I = V(-inf) - V(+inf), V the sign changes of the Euclid chain
   f_0 = P, f_1 = Q, f_{k+1} = -rem(f_{k-1}, f_k); at +-inf only degrees and leading coefficients matter.
3. *Common factor.*  The chain's last term g = gcd(P, Q) is real: it carries exactly the roots p shares with its
   conjugate polynomial, the real roots (a structural lambda = 0 among them) and pairs a, conj(a).  Dividing the
   chain by g changes no sign change (the index is that of p/g, which has no real root), and each pair in g has
   one growing member, so

       n_- = (n - deg g + I)/2 + (deg g - r_g)/2,     r_g = real roots of g with multiplicity,

   r_g counted by FLINT/Arb as ``exact.count_real_roots`` does (certified isolation of the exact polynomial).
4. *Ideal limit.*  For a real p, Q = 0 and g = P: n_- = (n - r)/2 = N_c, today's label (``exact.complex_pairs``).
5. *Threshold.*  The roots growing faster than sigma_0 (-Im lambda > sigma_0, strictly) are the growing roots of
   p(x - i sigma_0), whose coefficients are computed exactly by Horner's rule in Gaussian rationals; a root growing
   at exactly sigma_0 lands on the real axis of the shifted polynomial and is not counted.
"""

from __future__ import annotations

from fractions import Fraction
from math import isfinite
from typing import TypeAlias

import flint

from ...errors import StabmapError
from .exact import count_real_roots

Rational: TypeAlias = "flint.fmpq | int | Fraction | float"  # exact; a float at its binary value


def _poly(f, name: str) -> flint.fmpq_poly:
    """``f`` as an fmpq_poly (an fmpq_poly, an fmpz_poly, or a list of ascending rational coefficients)."""
    if isinstance(f, flint.fmpq_poly):
        return f
    try:
        return flint.fmpq_poly(f)
    except (TypeError, ValueError) as err:
        raise StabmapError(f"{name} must be a polynomial with rational coefficients (flint.fmpq_poly), got {f!r}") from err


def _rational(x: Rational, name: str) -> flint.fmpq:
    """``x`` as an exact rational; a float is taken at its exact binary value."""
    if isinstance(x, flint.fmpq):
        return x
    if isinstance(x, bool):
        raise StabmapError(f"{name} must be a rational number, got {x!r}")
    if isinstance(x, int):
        return flint.fmpq(x)
    if isinstance(x, Fraction):
        return flint.fmpq(x.numerator, x.denominator)
    if isinstance(x, float):
        if not isfinite(x):
            raise StabmapError(f"{name} must be finite, got {x!r}")
        num, den = x.as_integer_ratio()
        return flint.fmpq(num, den)
    raise StabmapError(f"{name} must be a rational number (flint.fmpq, int, Fraction or float), got {x!r}")


def _parts(re, im) -> tuple[flint.fmpq_poly, flint.fmpq_poly]:
    """(P, Q): the real and imaginary parts of conj(c) p, c the leading coefficient of p = re + i im (step 1)."""
    re, im = _poly(re, "re"), _poly(im, "im")
    if re.is_zero() and im.is_zero():
        raise StabmapError("the polynomial p = re + i*im is identically zero: it has no roots to count")
    n = max(re.degree(), im.degree())
    a, b = re[n], im[n]  # coefficients past the degree read as 0
    return a * re + b * im, a * im - b * re


def _sign_at(f: flint.fmpq_poly, end: int) -> int:
    """The sign of the nonzero f at +inf (end = 1) or -inf (end = -1)."""
    s = 1 if f.leading_coefficient() > 0 else -1
    return s if end > 0 or f.degree() % 2 == 0 else -s


def _changes(chain: list, end: int) -> int:
    signs = [_sign_at(f, end) for f in chain]
    return sum(1 for s, t in zip(signs, signs[1:], strict=False) if s != t)


def _index_and_gcd(P: flint.fmpq_poly, Q: flint.fmpq_poly) -> tuple[int, flint.fmpq_poly]:
    """(I, g): the Cauchy index of Q/P over the real axis and g = gcd(P, Q), the chain's last term (step 2)."""
    if Q.is_zero():
        return 0, P
    chain = [P, Q]
    while True:
        r = -(chain[-2] % chain[-1])
        if r.is_zero():
            break
        chain.append(r / abs(r.leading_coefficient()))  # a positive factor: the signs, and so V, stay
    return _changes(chain, -1) - _changes(chain, 1), chain[-1]


def counts(re, im) -> tuple[int, int, int]:
    """(growing, on the axis, decaying): the roots of p = re + i*im with Im lambda < 0, = 0 and > 0.

    ``re`` and ``im`` are the real and imaginary parts of p's coefficients (flint.fmpq_poly, exact rationals); p
    must not be identically zero.  Roots are counted with multiplicity, so the three sum to deg p.
    """
    P, Q = _parts(re, im)
    n = P.degree()
    I, g = _index_and_gcd(P, Q)
    dg = g.degree()
    r_g = count_real_roots(g) if dg > 0 else 0
    if (n - dg + I) % 2 or (dg - r_g) % 2:  # the theorem says both are even: anything else is a bug here
        raise AssertionError(f"half-plane count: odd parity (n={n}, deg g={dg}, I={I}, r_g={r_g})")
    growing = (n - dg + I) // 2 + (dg - r_g) // 2
    return growing, r_g, n - growing - r_g


def growing_roots(re, im) -> int:
    """Roots of p = re + i*im with Im lambda < 0 (growing, for exp(i lambda t)), with multiplicity, exactly."""
    return counts(re, im)[0]


def real_roots(re, im) -> int:
    """Roots of p = re + i*im on the real axis (neither growing nor decaying), with multiplicity, exactly."""
    return counts(re, im)[1]


def decaying_roots(re, im) -> int:
    """Roots of p = re + i*im with Im lambda > 0 (decaying), with multiplicity, exactly."""
    return counts(re, im)[2]


def shifted(re, im, sigma0: Rational) -> tuple[flint.fmpq_poly, flint.fmpq_poly]:
    """The real and imaginary parts of p(x - i sigma0), exactly (Horner's rule in Gaussian rationals).

    A root lambda of p becomes lambda + i sigma0: growth rate -Im lambda > sigma0 exactly when it is growing.
    """
    re, im = _poly(re, "re"), _poly(im, "im")
    s = _rational(sigma0, "sigma0")
    n = max(re.degree(), im.degree())
    x = flint.fmpq_poly([0, 1])
    R, J = flint.fmpq_poly([]), flint.fmpq_poly([])
    for k in range(n, -1, -1):
        # (R + iJ)(x - i s) + c_k = (R x + s J + Re c_k) + i (J x - s R + Im c_k)
        R, J = R * x + s * J + re[k], J * x - s * R + im[k]
    return R, J


def faster_than(re, im, sigma0: Rational) -> int:
    """Roots of p = re + i*im growing strictly faster than sigma0 (-Im lambda > sigma0), with multiplicity.

    The growing roots of p(x - i sigma0) (``shifted``).  Strict: a root growing at exactly sigma0 is not counted;
    ``counts(*shifted(re, im, sigma0))`` gives (faster, exactly sigma0, slower).  sigma0 = 0 is ``growing_roots``;
    a negative sigma0 counts the roots decaying more slowly than |sigma0|, and the growing ones.
    """
    return growing_roots(*shifted(re, im, sigma0))


__all__ = ["counts", "decaying_roots", "faster_than", "growing_roots", "real_roots", "shifted"]
