"""Every root of p(lambda) at one point, enclosed exactly, with its kind and its origin (docs/rates.md).

The enclosures and the kinds are proofs: the exact rational polynomial's roots isolated by FLINT/Arb, real ones
returned with an imaginary part that is exactly zero, the others with one that excludes zero.  Whether a root is a
*liquid mode* or *structural* is not a proof but a rule: the share of its eigenvector, in the first-order
linearisation (``kernels.linearise_block``: state theta, v = lambda theta, y_kl = lambda v_k / (lambda + beta_kl)),
that the liquid coordinates y carry among the velocity-level ones, |y|^2 / (|v|^2 + |y|^2).  A root with a share
above ``LIQUID_SHARE`` is a liquid mode.  As every E_kl -> 0 a liquid root tends to -beta_kl, where v = 0 and the
share is 1, and a structural one keeps a bounded y, so the rule names the branches that continuation from E = 0
would; near a crossing of two branches it may not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...kernels import linearise_block
from .decide import kernel_args
from .points import point_arrays

LIQUID_SHARE = 0.5
RULE = ("liquid mode: its eigenvector's liquid coordinates carry more than half of |v|^2 + |y|^2 in the linearisation "
        "(a rule, not a proof; docs/rates.md)")


@dataclass(frozen=True)
class Root:
    """One root lambda [rad/s] of p (solutions ~ exp(i lambda t)), proved to lie within ``radius`` of ``value``.

    ``kind``: "real" or "complex pair" (proved); ``origin``: "liquid", "structural" (the rule of ``RULE``) or
    "unknown" (no linearisation); ``liquid_share`` in [0, 1] (NaN if unknown).
    """

    value: complex
    radius: float
    multiplicity: int
    kind: str
    origin: str
    liquid_share: float

    @property
    def growth_rate(self) -> float:
        """|Im lambda| [1/s]: the growth rate of its solution (one of a conjugate pair)."""
        return abs(self.value.imag)


def roots_at(scene, values: dict[str, float]) -> list[Root]:
    """Every distinct root at the point ``values`` (grid-axis names -> numbers; other axes: the scene's values),
    ascending by real part then imaginary part."""
    from .rates import exact_roots

    points = point_arrays(scene, {k: np.array([float(v)]) for k, v in values.items()})
    D = scene.degree
    poly_roots = _distinct(*exact_roots(points, 0, D)[:3])
    shares = _shares(points, scene, [z for z, *_ in poly_roots])
    out = [Root(z, r, m, "real" if kind == 0 else "complex pair", _origin(s), s) for (z, r, m, kind), s in zip(poly_roots, shares, strict=True)]
    return sorted(out, key=lambda root: (root.value.real, root.value.imag))


def _distinct(z, r, kind):
    """(value, radius, multiplicity, kind) per distinct root: ``exact_roots`` repeats a multiple root."""
    out: list[list] = []  # [value, radius, multiplicity, kind], the multiplicity counted up
    for i in range(len(z)):
        if kind[i] < 0:
            continue
        if out and out[-1][0] == z[i] and out[-1][1] == r[i]:
            out[-1][2] += 1
        else:
            out.append([complex(z[i]), float(r[i]), 1, int(kind[i])])
    return [tuple(x) for x in out]


def _origin(share: float) -> str:
    return "unknown" if not np.isfinite(share) else ("liquid" if share > LIQUID_SHARE else "structural")


def _shares(points, scene, values: list[complex]) -> list[float]:
    """The liquid share of the eigenvector of the linearisation's eigenvalue nearest each root (each used once)."""
    n, D = scene.n, scene.degree
    if not scene.nmodes.sum():
        return [0.0] * len(values)
    C = np.zeros((1, D, D))
    if not linearise_block(*kernel_args(points), C)[0]:
        return [np.nan] * len(values)
    w, V = np.linalg.eig(C[0])
    free = list(range(D))
    out = []
    for z in values:
        j = min(free, key=lambda i: abs(w[i] - z))
        free.remove(j)
        v, y = V[n : 2 * n, j], V[2 * n :, j]
        velocity = float(np.vdot(v, v).real + np.vdot(y, y).real)
        out.append(float(np.vdot(y, y).real) / velocity if velocity > 0 else np.nan)
    return out
