"""The reactions in floating point with a proved bound on their error, vectorised (docs/reactions.md).

The exact problem is the one of ``exact``: C R = d with C the balance rows (about the origin of the node
positions x_i) and the independent release rows, d = (-F, -M, 0), and R* = C^+ d its least-norm solution. Any
invertible row operation S leaves the solution alone. Here S takes moments about a float point p (the rounded
centroid) and divides them by a power of two ell (near the nodes' RMS distance from p), so C' = S C has entries of
order one. Neither step needs to be exact in floating point, because each rounding is bounded.

**The solve.** R = C''^T y with G y = d'': the least-norm solution through the Gram matrix G = C'' C''^T of
the rounded C'' (an eigendecomposition per distinct layout), followed by one step of iterative refinement on the
residual. R lies in the row space of C'' up to the rounding of that product (z below). G squares the condition
number, but a layout for which that matters fails the bound below, and its points are solved exactly.

**The bound.** For float multipliers y and R = fl(C''^T y), let z = R - C'^T y (only rounding). Then

    R* - R = C'^+ r - P z,        r = d' - C' R,  P the projector onto the null space of C',

and the two terms are orthogonal, so |R* - R| <= delta = sqrt(a^2 + |z|^2) for any a >= |C'^+ r|. With a float
w ~ G^-1 r (the correction one more step of refinement would make), C'^+ r = C'^T w + C'^+ (r - C' C'^T w), so

    a = |C'^T w| + |r - C' C'^T w| / sigma + |r - r''| / sigma,      sigma <= sigma_min(C'),

r'' the computed residual. Bounding |C'^+ r| by |r| / sigma alone would make delta grow like kappa^2 u; this
way it grows like kappa u. Each quantity is bounded from above (the norms) or from below (sigma):

- C'' is C' rounded (x_i - p rounds; the rest is exact), and each entry's error is at most 2u |C''| [u = 2^-53];
- every sum of products of floats has the classical a priori error gamma_k sum |terms| (Higham, *Accuracy and
  Stability of Numerical Algorithms*, 2002, section 3.1), gamma_k = k u / (1 - k u). This holds for any summation
  order and with or without fused multiply-add, and so for any BLAS. Rounding to nearest is assumed (numpy
  does not change it);
- sigma_min(C') >= sigma_min(C'') - |C' - C''|_F. sigma_min(C'')^2 = lambda_min(C'' C''^T), and G differs from
  C'' C''^T by at most gamma |C''| |C''|^T entrywise (Weyl). A lower bound of lambda_min(G) comes from the
  approximate eigenbasis V of G: Gershgorin's discs of V^T G V (its computed entries widened by their rounding
  bounds) bound lambda_min(V^T G V) from below. By Ostrowski's theorem, lambda_min(G) >= lambda_min(V^T G V) /
  lambda_max(V^T V), and lambda_max(V^T V) <= 1 + |V^T V - I|_F.

A bound computed in floats is itself rounded. ``hi`` and ``lo`` widen each such result by a relative 2^-30 (far
more than the gamma_k of the few thousand operations behind it) and an absolute 2^-960 (far more than every
underflow together). A non-finite bound decides nothing. sigma > 0 proves that C' has full row rank: rank =
6 + releases, every load compatible. The critical node is proved when its |R_i| minus the bound exceeds every
other node's |R_i| plus the bound, each widened by the rounding of the norm, a few u (``separated``).
"""

from __future__ import annotations

import numpy as np

U = 2.0**-53  # unit roundoff of binary64, rounding to nearest
SLACK = 2.0**-30  # relative widening of every computed bound
TINY = 2.0**-960  # absolute widening: covers underflow (each costs at most 2^-1074, or 2^-1022 flushed to zero)


def hi(x):
    """An upper bound of the exact value of x >= 0, computed by a few float operations on bounds."""
    return x + np.abs(x) * SLACK + TINY


def lo(x):
    """A lower bound of the exact value of x, the result of one float operation on bounds."""
    return x - np.abs(x) * SLACK - TINY


def gamma(k: int) -> float:
    """An upper bound of Higham's gamma_k, the relative error of a sum of k rounded products (k u < 0.01)."""
    return 1.01 * (k + 1) * U


def _fro(a, axes=(-2, -1)):
    return np.sqrt(np.sum(a * a, axis=axes))


def _stacked(v: np.ndarray, B: np.ndarray) -> np.ndarray:
    """v B over stacks: v of shape S + (k,), B of shape L + (k, m), L broadcasting against S.

    The axes where L has size one (trailing ones, as when a grid's last axes scan the load only) become rows of
    one matrix product per layout, instead of one small product per point.
    """
    if B.ndim == 2:
        return v @ B
    L = B.shape[:-2]
    t = len(L) - len(np.trim_zeros(np.array(L) != 1, "b"))  # trailing axes of size one in L
    t = min(t, v.ndim - 1)
    if not t:
        return (v[..., None, :] @ B)[..., 0, :]
    tail = v.shape[v.ndim - 1 - t : -1]
    rows = v.reshape(v.shape[: v.ndim - 1 - t] + (-1, v.shape[-1]))
    out = rows @ B.reshape(L[: len(L) - t] + B.shape[-2:])
    return out.reshape(out.shape[:-2] + tail + out.shape[-1:])


def _mv(A: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A v over stacks: A of shape L + (m, k), v of shape S + (k,), L and S broadcasting."""
    return _stacked(v, np.swapaxes(A, -1, -2))


def _mtv(A: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A^T v over stacks."""
    return _stacked(v, A)


def _join(parts: list[np.ndarray]) -> np.ndarray:
    """Concatenate along the last axis, the leading axes broadcast."""
    lead = np.broadcast_shapes(*(a.shape[:-1] for a in parts))
    return np.concatenate([np.broadcast_to(a, lead + a.shape[-1:]) for a in parts], axis=-1)


def norm(v: np.ndarray) -> np.ndarray:
    """The 2-norm along the last axis."""
    return np.sqrt(np.sum(v * v, axis=-1))


def _cross_abs(a, b):
    """|a| (x) |b|: the sum of |terms| of each component of a x b."""
    a, b = np.abs(a), np.abs(b)
    return np.stack([a[..., 1] * b[..., 2] + a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] + a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] + a[..., 1] * b[..., 0]], axis=-1)


def _moment_rows(l: np.ndarray) -> np.ndarray:
    """The three rows of sum_i l_i x R_i as a matrix of shape (..., 3, 3n), R ordered (R_0x, R_0y, R_0z, R_1x, ...)."""
    z = np.zeros(l.shape[:-1])
    x, y, w = l[..., 0], l[..., 1], l[..., 2]
    rows = [np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)]  # (..., n, 3) each
    return np.stack([r.reshape(r.shape[:-2] + (-1,)) for r in rows], axis=-2)


class Layouts:
    """The layouts' share of the solve and the bound, for a stack of layouts x of shape L + (n, 3).

    ``releases`` are ``exact.release_rows``. Attributes: ``p`` (L, 3), ``ell`` (L), ``l`` = fl(x - p)
    (L, n, 3), the rounded matrix ``C`` (L, m, 3n) and its entrywise error bound ``EC``, the eigendecomposition
    ``lam``, ``V`` of the Gram matrix G and its float inverse ``Ginv``, and ``sigma`` (L): a proved lower bound
    of sigma_min(C'), NaN where none (then C' may not have full row rank, and the layout is for ``exact``).
    """

    def __init__(self, x: np.ndarray, releases) -> None:
        n = x.shape[-2]
        L = x.shape[:-2]
        self.releases = releases
        with np.errstate(all="ignore"):
            self.p = x.mean(axis=-2)
            self.l = x - self.p[..., None, :]
            rms = np.sqrt(np.mean(np.sum(self.l * self.l, axis=-1), axis=-1))
            ok = np.isfinite(rms) & (rms > 0)
            self.ell = np.where(ok, np.ldexp(1.0, np.frexp(np.where(ok, rms, 1.0))[1]), 1.0)  # a power of two
            force = np.broadcast_to(np.tile(np.eye(3), (1, n)), L + (3, 3 * n))
            moment = _moment_rows(self.l / self.ell[..., None, None])
            rel = np.zeros(L + (len(releases), 3 * n))
            for j, (k, e) in enumerate(releases):
                rel[..., j, 3 * k : 3 * k + 3] = e
            self.C = np.concatenate([force, moment, rel], axis=-2)
            m = self.C.shape[-2]
            self.EC = np.concatenate([np.zeros(L + (3, 3 * n)), 2 * U * np.abs(moment) + TINY, np.full(rel.shape, TINY)], axis=-2)
            self.aC = np.abs(self.C)
            eC = hi(_fro(self.EC))
            self.ER = self.EC + gamma(3 * n + 1) * self.aC  # |r error| <= ... + ER |R|
            self.EZ = self.EC + gamma(m) * self.aC  # |z| <= EZ^T |y|

            # The Gram matrix, exactly symmetric (its lower triangle copied), each entry a float dot product:
            # |G - C'' C''^T| <= gamma |C''| |C''|^T, whose Frobenius norm is at most gamma |C''|_F^2.
            G = self.C @ np.swapaxes(self.C, -1, -2)
            G = np.tril(G) + np.swapaxes(np.tril(G, -1), -1, -2)
            c2 = hi(np.sum(self.aC * self.aC, axis=(-2, -1)))
            eG = hi(gamma(3 * n) * c2)
            finite = np.all(np.isfinite(G), axis=(-2, -1))
            G = np.where(finite[..., None, None], G, np.eye(m))
            self.lam, self.V = np.linalg.eigh(G)

            # lambda_min(G) from below: Gershgorin on V^T G V, Ostrowski back to G. The products' rounding in
            # Frobenius norms, |fl(A B) - A B|_F <= gamma_m |A|_F |B|_F, so every entry of V^T G V is within
            # eH of the computed one.
            V = self.V
            Vt = np.swapaxes(V, -1, -2)
            Y = G @ V
            H = Vt @ Y
            v2 = hi(np.sum(V * V, axis=(-2, -1)))  # |V|_F^2
            g = hi(_fro(G))
            eH = hi(gamma(m) * (hi(np.sqrt(v2) * _fro(Y)) + hi(v2 * g)))
            off = hi(np.sum(np.abs(H) * (1.0 - np.eye(m)), axis=-1))
            discs = lo(np.diagonal(H, axis1=-2, axis2=-1) - hi(off + m * eH[..., None]))  # lower ends of Gershgorin's discs
            h = discs.min(axis=-1)
            D = Vt @ V - np.eye(m)
            vmax = hi(1.0 + hi(_fro(D) + gamma(m) * v2))  # >= lambda_max(V^T V)
            w = lo(lo(h / vmax) - eG)  # <= lambda_min(C'' C''^T)
            sigma = lo(lo(np.sqrt(np.where(w > 0, w, 0.0))) - eC)
            self.sigma = np.where(finite & (h > 0) & (w > 0) & (sigma > 0), sigma, np.nan)
            inv_lam = np.where(self.lam > 0, 1.0 / self.lam, 0.0)  # zero along non-positive eigenvalues
            self.Ginv = (V * inv_lam[..., None, :]) @ Vt  # G^-1 in floats (for the solve; no rigour needed)
            self.EA = self.aC + self.EC  # >= |C'|

    def _load(self, F: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """d'' = fl(d') at every point (forces, moments about p over ell, releases) and a bound of |d'' - d'|."""
        dM = -(M - np.cross(self.p, F)) / self.ell[..., None]
        eM = gamma(3) * (np.abs(M) + _cross_abs(self.p, F)) / self.ell[..., None]
        zero = np.zeros(len(self.releases))
        return _join([-F, dM, zero]), _join([np.zeros(F.shape), eM, zero])

    def _solve_gram(self, v):
        """G^-1 v (those layouts whose G is not positive definite are not used)."""
        return _mv(self.Ginv, v)

    def solve(self, F: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The float reactions R (shape S + (n, 3)) and delta >= |R* - R| (shape S; 2-norm over all nodes and
        components; NaN where nothing is proved). F, M of shape S' + (3,) broadcast against the layouts' L."""
        n = self.l.shape[-2]
        with np.errstate(all="ignore"):
            d, ed = self._load(F, M)
            y = self._solve_gram(d)
            R = _mtv(self.C, y)
            y = y + self._solve_gram(d - _mv(self.C, R))  # one step of iterative refinement
            R = _mtv(self.C, y)
            # r = d' - C' R, as computed: the load's rounding, C'' - C', and the sum's rounding bounded by er.
            r = d - _mv(self.C, R)
            er = ed + gamma(3 * n + 1) * np.abs(d) + _mv(self.ER, np.abs(R))
            # C'^+ r = C'^T w + C'^+ (r - C' C'^T w) for the float w = G^-1 r: the correction a further step of
            # refinement would make, and what that step would leave, over sigma. q = fl(C''^T w) is within
            # EZ^T |w| of C'^T w; s = fl(r - C'' q) within es of r - C' C'^T w.
            w = self._solve_gram(r)
            q = _mtv(self.C, w)
            eq = _mtv(self.EZ, np.abs(w))
            s = r - _mv(self.C, q)
            es = _mv(self.ER, np.abs(q)) + gamma(3 * n + 1) * np.abs(r) + _mv(self.EA, eq)
            a = hi(hi(norm(q) + norm(eq)) + hi(hi(norm(s) + norm(es) + norm(er)) / self.sigma))
            # z = fl(C''^T y) - C'^T y: the product's rounding and C'' - C'; P z is the part of R off the row space.
            z = hi(norm(_mtv(self.EZ, np.abs(y))))
            delta = hi(np.sqrt(hi(a * a + z * z)))
            R = R.reshape(R.shape[:-1] + (n, 3))
            return R, np.where(np.isfinite(delta) & (self.sigma > 0), delta, np.nan)


def separated(norms: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """True where the node with the largest float |R_i| (norms, shape S + (n,)) provably carries the most: its
    |R_i| - delta exceeds every other node's |R_i| + delta.

    A float norm nu of a 3-vector is within 3u of its exact value (3 products, 2 sums, a square root), and each
    of the two operations below rounds by at most u more: (nu + delta)(1 + 8u) >= |R_i| + delta, and
    nu (1 - 8u) - delta, rounded, is <= |R_i| - delta (TINY covers underflow).
    """
    n = norms.shape[-1]
    with np.errstate(all="ignore"):
        if n == 1:
            return np.isfinite(delta)
        top = np.argmax(norms, axis=-1)
        upper = (norms + delta[..., None]) * (1 + 8 * U) + TINY
        low_top = (np.take_along_axis(norms, top[..., None], -1)[..., 0] * (1 - 8 * U) - delta) - TINY
        others = np.where(np.arange(n) == top[..., None], -np.inf, upper).max(axis=-1)
        return np.isfinite(delta) & (low_top > others)
