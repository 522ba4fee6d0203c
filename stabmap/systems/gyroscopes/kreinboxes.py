"""Krein boxes (``kernels.kreinbox``): N_c on a whole box of (omega, t) from definite compressions at its corners.

A box qualifies when every body spins at the one rate omega of one grid axis, which the box moves, not through 0,
and at most one other axis moves: a mechanical axis (``boxes.is_mechanical``) that is not a length (lengths enter M
quadratically), whose kernel inputs are copies of its value at both corners (``nodes.copies``), so that M, C and K
are affine in it.  The kernel gets the inputs at the axis's two ends with every spin 1 and the stiffness at u = 1
(it multiplies by u in balls), and the interval of u = 1 / omega^2 rounded outward.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ...kernels import layout
from ...kernels.kreinbox import NINFO, krein_box_block
from ...kernels.status import UNDECIDED
from .boxes import box_corners, is_mechanical, is_spin, spin_rows, unenclosed
from .nodes import LENGTHS, copies, u_interval
from .parameters import parse_name
from .points import point_arrays
from .scene import Scene

__all__ = ["KreinBoxes", "cheap_box_cost", "krein_arrays", "krein_box", "prove_boxes_cheaply", "prove_krein_boxes", "qualifies"]


@dataclass
class KreinBoxes:
    """Arguments of ``kernels.kreinbox.krein_box_block``: inputs at the two ends (axis 1) of the box's t interval."""

    body: np.ndarray  # (npts, 2, n, 6), every spin 1
    joint: np.ndarray  # (npts, 2, n), at u = 1
    g: np.ndarray  # (npts, 2), at u = 1
    at: np.ndarray  # (npts, 2, n)
    E: np.ndarray
    kappa: np.ndarray
    nmodes: np.ndarray
    free: bool
    parent: np.ndarray
    u_lo: np.ndarray
    u_hi: np.ndarray

    def take(self, rows: np.ndarray) -> KreinBoxes:
        """The boxes ``rows`` (the per-box fields; the chain's structure is shared)."""
        per_box = ("body", "joint", "g", "at", "E", "kappa", "u_lo", "u_hi")
        return dataclasses.replace(self, **{f: getattr(self, f)[rows] for f in per_box})

    def kernel_args(self):
        args = (self.body, self.joint, self.g, self.at, self.E, self.kappa, self.nmodes, self.free, self.parent, self.u_lo, self.u_hi)
        return tuple(np.require(a, requirements=("C", "W")) if isinstance(a, np.ndarray) else a for a in args)


def _affine_axis(scene: Scene, key: str) -> bool:
    """A mechanical axis whose every entry of Phi is affine in it: not a length, not a free system's mass."""
    return is_mechanical(scene, key) and parse_name(key, scene.n, scene.support).symbol not in LENGTHS


def krein_arrays(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> tuple[np.ndarray, KreinBoxes | None]:
    """(rows, boxes): the boxes with corners ``lower``, ``upper`` that qualify (module docstring), as kernel inputs."""
    lo, hi = box_corners(scene, lower, upper)
    npts = lo.body.shape[0]
    lower = {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (npts,)) for k, v in lower.items()}
    upper = {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (npts,)) for k, v in upper.items()}
    moves = {k: lower[k] != upper[k] for k in lower}
    spin = spin_rows(scene, lo, hi, moves)
    others = [k for k in lower if not is_spin(scene, k)]
    n = scene.n
    body = np.empty((npts, 2, n, layout.NBODY))
    joint = np.empty((npts, 2, n))
    g = np.empty((npts, 2))
    at = np.empty((npts, 2, n))
    ok = np.zeros(npts, dtype=bool)
    count = sum((moves[k].astype(int) for k in others), np.zeros(npts, dtype=int))
    # boxes along the spin alone: both ends are the corner inputs
    sel = spin[count[spin] == 0]
    if sel.size:
        for j in range(2):
            body[sel, j], joint[sel, j], g[sel, j], at[sel, j] = lo.body[sel], lo.joint[sel], lo.g[sel], lo.at[sel]
        ok[sel] = True
    for axis in others:
        if not _affine_axis(scene, axis):
            continue
        sel = spin[(count[spin] == 1) & moves[axis][spin]]
        if sel.size == 0:
            continue
        t_lo, t_hi = np.minimum(lower[axis][sel], upper[axis][sel]), np.maximum(lower[axis][sel], upper[axis][sel])
        values = {k: np.repeat(lower[k][sel], 2) for k in lower}
        values[axis] = np.stack([t_lo, t_hi], axis=1).ravel()
        pts = point_arrays(scene, values)
        keep = copies(pts, lo, hi, sel, {axis: np.stack([t_lo, t_hi], axis=1)}, {axis: (t_lo, t_hi)}, True)
        sel = sel[keep]
        body[sel], joint[sel], g[sel], at[sel] = (x.reshape((keep.size, 2) + x.shape[1:])[keep] for x in (pts.body, pts.joint, pts.g, pts.at))
        ok[sel] = True
    rows = np.flatnonzero(ok)
    if rows.size == 0:
        return rows, None
    u_lo, u_hi = u_interval(lo.body[rows, 0, layout.OMEGA], hi.body[rows, 0, layout.OMEGA])
    b = body[rows]
    b[..., layout.OMEGA] = 1.0
    return rows, KreinBoxes(b, joint[rows], g[rows], at[rows], lo.E[rows], lo.kappa[rows], lo.nmodes, lo.free, lo.parent, u_lo, u_hi)


def prove_krein_boxes(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], warm: bool = True,
                      batch: np.ndarray | None = None):
    """(N_c int16 with -1 where not proved, proved bool, info (npts, NINFO) int64) of each box.  ``warm``: each box
    first tries what proved the one before it (``kernels.kreinbox.krein_box_block``).  ``batch`` (an integer a box):
    one kernel call per batch, its boxes in their order, so that no box is steered by another batch's (the kernel's
    scratch, warm start included, carries from box to box within a call)."""
    npts = int(np.prod(np.broadcast_shapes(*(np.shape(v) for v in (*lower.values(), *upper.values())))))
    nc = np.full(npts, -1, dtype=np.int16)
    info = np.full((npts, NINFO), -1, dtype=np.int64)
    rows, part = krein_arrays(scene, lower, upper)
    if part is not None:
        count = np.empty(rows.size, dtype=np.int16)
        status = np.empty(rows.size, dtype=np.int8)
        out_info: np.ndarray = np.zeros((rows.size, NINFO), dtype=np.int64)
        if batch is None:
            krein_box_block(*part.kernel_args(), warm, count, status, out_info)
        else:
            owner = np.asarray(batch)[rows]
            order = np.argsort(owner, kind="stable")  # each batch's boxes together, in their order
            cuts = np.flatnonzero(np.diff(owner[order])) + 1
            for run in np.split(order, cuts):
                c, st, inf = count[run], status[run], out_info[run]
                krein_box_block(*part.take(run).kernel_args(), warm, c, st, inf)
                count[run], status[run], out_info[run] = c, st, inf
        good = status != UNDECIDED
        nc[rows[good]] = count[good]
        info[rows] = out_info
    return nc, nc >= 0, info


def prove_boxes_cheaply(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], batch: np.ndarray | None = None):
    """(N_c, proved) of each box by the Krein test alone (``System.prove_boxes_cheaply``): boxes that span an axis
    outside ``box_axes``, or that do not qualify (module docstring), are left unproved."""
    npts = int(np.prod(np.broadcast_shapes(*(np.shape(v) for v in (*lower.values(), *upper.values())))))
    nc = np.full(npts, -1, dtype=np.int16)
    spans = np.zeros(npts, dtype=bool)
    for outside in unenclosed(scene, lower, upper).values():
        spans |= np.broadcast_to(outside, (npts,))
    todo = np.flatnonzero(~spans)
    if todo.size:
        sub = {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (npts,))[todo] for k, v in lower.items()}
        got = prove_krein_boxes(scene, sub, {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (npts,))[todo]
                                             for k, v in upper.items()}, batch=None if batch is None else np.asarray(batch)[todo])[0]
        nc[todo] = got
    return nc, nc >= 0


def qualifies(scene: Scene) -> bool:
    """Whether an atlas of ``scene`` has boxes the Krein test can take: its continuous grid axes are one spin axis
    and at most one affine mechanical axis (module docstring), so that its tiles and their parts move no more."""
    names = [a.name for a in scene.grid if a.continuous]
    spins = [k for k in names if is_spin(scene, k)]
    return len(spins) == 1 and len(names) <= 2 and all(is_spin(scene, k) or _affine_axis(scene, k) for k in names)


# A Krein box in point proofs: 40-110 us on 2-3 bodies (scripts/bench_kreinbox.py) over a point's 10-25 us, growing
# with the D x D eigenvalue problem of its cold start.  paper-n3-fixed at 240 x 160 (scripts/bench_kreinbox.py
# --atlas): whole cells 60.5 % at 2 + D/2 = 8, 62.5 % at 4 and 66.3 % at 2, in the same time
def cheap_box_cost(scene: Scene) -> float:
    """What one Krein box costs, in point proofs (0 where the scene has none to take: ``qualifies``)."""
    if not qualifies(scene):
        return 0.0
    return 1.0 + 0.25 * scene.degree


def krein_box(scene: Scene, intervals: dict[str, tuple[float, float]]) -> int:
    """N_c proved on the box ``{axis: (lo, hi)}`` (the spin axis and at most one more), or -1."""
    lower = {k: np.array([float(v[0])]) for k, v in intervals.items()}
    upper = {k: np.array([float(v[1])]) for k, v in intervals.items()}
    return int(prove_krein_boxes(scene, lower, upper)[0][0])
