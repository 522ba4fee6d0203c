"""Every label of a closed chain proved in space (docs/closed.md, section 5): the planar block (``proofs``) and
the out-of-plane block, or the whole spatial Hessian of a twisted ring, or the point flagged ``undecided``.

The labels depend on the exact length ratio h2/h1 and the exact gamma = c2^2/c1^2 only (h1, c1^2 and h scale
the forces, the energy and the Hessian by positive factors), so one proof serves every point of a (ratio,
gamma) pair, and the planar block one ratio.  ``gamma`` None is the planar model (the chain confined to its
plane, scene ``model = "planar"``): the planar block alone decides.

- **Out of the plane**, at a planar twist-free equilibrium: the block of ``space.out_of_plane`` on the
  loops' closures normal to the plane, with the two rotations about axes in the plane and the uniform spin
  taken out as rows of the bordered matrix, proved in balls like the planar block (``proofs.bordered_inertia``)
  from the same closed forms; at a folded end point in exact rational arithmetic (``proofs.exact_inertia``).
  Rings: the closed form theta_k = 2 pi j k/n in balls (``arb.cos_pi``).
- **Twisted rings** (twist m != 0): the configuration is not symmetric under the reflection, so the whole
  spatial Hessian (``space.spatial``, 3n components) is proved in balls, with the three closures, the three
  rotations and the spin as rows; the planar counts are those of the restriction to in-plane bending (each body
  turned about the plane's normal).
"""

from __future__ import annotations

import numpy as np
from flint import arb, fmpq

from . import proofs, space
from .proofs import (
    ABSENT_VERDICT,
    BY_BALLS,
    PRECISIONS,
    UNDECIDED,
    UNDECIDED_VERDICT,
    Verdict,
    Verdicts,
    bordered_inertia,
    exact,
    exact_inertia,
    in_space,
    out_of_plane_inertia,
    planar_only,
    precision,
    scaled_rows,
)


def gamma_of(c1sq: float, c2sq: float) -> fmpq:
    """c2^2/c1^2 exactly, from the two doubles."""
    return exact(c2sq) / exact(c1sq)


# ------------------------------------------------------------------------------------------------- planar shapes
def out_of_plane_pattern(family: str, r: fmpq, gamma: fmpq, pattern, loop_of) -> tuple[int, int] | None:
    """(index, nullity) of the out-of-plane block of a two-length family that exists at ratio r: exactly at a
    folded end, in balls elsewhere."""
    if proofs.pattern_existence(family, r) == "folded":
        c, s, rho = proofs.closed_form(family, r, proofs._exact_sqrt)
        H, closures, symmetries = space.out_of_plane(c, s, rho, proofs._pattern_lengths(pattern, r), loop_of, gamma)
        return exact_inertia(H, closures, symmetries)
    for bits in PRECISIONS:
        with precision(bits):
            rb = arb(r)
            c, s, rho = proofs.closed_form(family, rb, lambda x: x.sqrt())
            found = out_of_plane_inertia(c, s, rho, proofs._pattern_lengths(pattern, rb), loop_of, arb(gamma))
        if found is not None:
            return found
    return None


def out_of_plane_ring(lengths: list[fmpq], j: int, gamma: fmpq) -> tuple[int, int] | None:
    """(index, nullity) of the out-of-plane block of the closed ring of winding j (R = 0)."""
    n = len(lengths)
    for bits in PRECISIONS:
        with precision(bits):
            c = [arb(fmpq(2 * j * k, n)).cos_pi() for k in range(1, n + 1)]
            s = [arb(fmpq(2 * j * k, n)).sin_pi() for k in range(1, n + 1)]
            found = out_of_plane_inertia(c, s, [(arb(0), arb(0))], [arb(x) for x in lengths], [0] * n, arb(gamma))
        if found is not None:
            return found
    return None


def prove_pattern(family: str, r: fmpq, gamma: fmpq | None, pattern, loop_of, planar: Verdict | None = None) -> Verdict:
    """The verdict of a two-length family at ratio r and gamma (None: in the plane only)."""
    planar = planar or proofs.prove_pattern(family, r, pattern, loop_of)
    if gamma is None or planar.exists != 1 or planar.decided_by == UNDECIDED:
        return planar_only(planar)
    return in_space(planar, out_of_plane_pattern(family, r, gamma, pattern, loop_of))


def prove_ring(lengths: list[fmpq], j: int, m: int, gamma: fmpq | None, planar: Verdict | None = None) -> Verdict:
    """The verdict of the ring of winding j and twist m with exact lengths, at gamma (None: in the plane)."""
    if m:
        return prove_twisted_ring(len(lengths), j, m, gamma)
    planar = planar or proofs.prove_ring(lengths, j)
    if gamma is None or planar.exists != 1:
        return planar_only(planar)
    return in_space(planar, out_of_plane_ring(lengths, j, gamma))


def prove_twisted_ring(n: int, j: int, m: int, gamma: fmpq) -> Verdict:
    """The verdict of the ring of n equal bodies, winding j and twist m, proved on the whole spatial Hessian."""
    for bits in PRECISIONS:
        with precision(bits):
            quats, rho, _ = space.twisted_ring(n, j, m, arb(gamma), lambda x: x.cos_pi(), lambda x: x.sin_pi(),
                                               lambda a, b: arb(fmpq(a, b)))
            H, g, closures, symmetries = space.spatial(quats, [arb(1)] * n, rho, arb(gamma))
            if not all(x.contains(0) for x in g):  # the symmetry argument and R_x make g = 0 exactly (docs, section 2b)
                raise ArithmeticError(f"the twisted ring n = {n}, j = {j}, m = {m} is not stationary in balls: its force is wrong")
            found = bordered_inertia(H, scaled_rows(closures + symmetries))
            planar = _in_plane_restriction(H, closures, quats) if found is not None else None
        if found is not None and planar is not None:
            return Verdict(1, found[0], found[1], BY_BALLS, planar[0], planar[1])
    return Verdict(1, -1, -1, UNDECIDED)


def _in_plane_restriction(H, closures, quats):
    """(index, nullity) of the spatial Hessian restricted to in-plane bending: body k turned about the plane's
    normal x, v_k = t_k a_k with t_k = Q_k^T x; rows: the closures in the plane and the rotation about x."""
    n = len(quats)
    t = [[space.matrix(q)[0][i] for i in range(3)] for q in quats]  # row x of Q_k = Q_k^T x
    zero = H[0][0] * 0
    Hp = [[sum((t[a][i] * H[3 * a + i][3 * b + k] * t[b][k] for i in range(3) for k in range(3)), zero) for b in range(n)]
          for a in range(n)]
    rows = [[sum((row[3 * k + i] * t[k][i] for i in range(3)), zero) for k in range(n)] for row in closures[1:]]
    return bordered_inertia(Hp, scaled_rows(rows) + [[zero + 1] * n])


# ---------------------------------------------------------------------------------------------------------- batches
def prove_ratios(fam, n: int, j: int, m: int, ratio, gamma) -> Verdicts:
    """The verdicts of family ``fam`` at the ratios h2/h1 (doubles, exact) of its pattern and the exact gammas
    (fmpq per point, or None for the planar model): one proof per (ratio, gamma), one planar proof per ratio."""
    ratio = np.asarray(ratio, dtype=float).reshape(-1)
    gammas = [None] * ratio.size if gamma is None else list(gamma)
    loop_of = [int(v) for v in fam.loop_of(n)]
    planar: dict[float, Verdict] = {}
    done: dict[tuple, Verdict] = {}
    out = []
    for r, g in zip(ratio.tolist(), gammas, strict=True):
        key = (r, g)
        if key not in done:
            q = exact(r)
            if fam.pattern is None:
                lengths = [fmpq(1) if k % 2 == 0 else q for k in range(n)]
                if r not in planar and not m:
                    planar[r] = proofs.prove_ring(lengths, j)
                done[key] = prove_ring(lengths, j, m, g, planar.get(r))
            else:
                if r not in planar:
                    planar[r] = proofs.prove_pattern(fam.name, q, fam.pattern, loop_of)
                done[key] = prove_pattern(fam.name, q, g, fam.pattern, loop_of, planar[r])
        out.append(done[key])
    return Verdicts.of(out)


def prove_lengths(fam, j: int, m: int, lengths, gamma: fmpq | None, guess=None) -> Verdict:
    """The verdict of family ``fam`` (a ``families.Family``) at explicit ``lengths`` (doubles, exact).

    ``guess()`` gives (theta, rho) of the floating-point closed form, for lengths that follow the family's pattern
    only to rounding (then no closed form holds exactly and the Krawczyk operator proves the equilibrium).
    """
    q = [exact(v) for v in lengths]
    n = len(q)
    if fam.pattern is None:
        return prove_ring(q, j, m, gamma)
    loop_of = [int(v) for v in fam.loop_of(n)]
    r = proofs.pattern_ratio(q, fam.pattern)
    if r is not None:
        return prove_pattern(fam.name, r, gamma, fam.pattern, loop_of)
    if proofs.ratio_hull_absent(fam.name, q, fam.pattern):
        return planar_only(ABSENT_VERDICT)
    theta, rho = guess() if guess is not None else (None, None)
    if theta is None or not (np.isfinite(theta).all() and np.isfinite(rho).all()):
        return UNDECIDED_VERDICT
    return proofs.prove_equilibrium(theta, rho, lengths, loop_of, gamma)


__all__ = ["gamma_of", "prove_lengths", "prove_ratios"]
