"""Closed chains of elastic joints (docs/closed.md): the planar equilibria of a closed rod of n bodies, their
forces and their stability, from Bolgrabskaya, Savchenko and Shchepin (2006), as restated and corrected in docs/closed.md.

The pipeline's part of this system is the ``System`` below; the physics is in the modules beside it:

- ``families``: the named families (ring, figure-eights, hinges) and their closed forms;
- ``equations``: the general equilibrium equations, energy, constrained Hessian, rotation index;
- ``proofs``: the proof of every label (exact rational and ball arithmetic, python-flint), or the flag undecided;
- ``decide``: a batch of configurations and their proofs -> every output (shared by atlases and ``solve``);
- ``solve`` and ``search``: the Python API (``stabmap.closed``);
- ``checks``, ``scene``: what an input must satisfy, and the scene files;
- ``outputs``: the variables written.
"""

from __future__ import annotations

import numpy as np

from ..base import Cost, System
from . import proofs
from . import scene as _scene
from .decide import ABSENT, DEGENERATE, STABLE, UNDECIDED, decide
from .equations import joint_angles
from .families import FAMILIES
from .outputs import STABILITY, VARIABLES
from .scene import Scene

REFERENCES = (
    "I. A. Bolgrabskaya, A. Ya. Savchenko, N. N. Shchepin, Closed systems of coupled rigid bodies (in Russian), "
    "Mekhanika tverdogo tela 36 (2006): equations (22)-(52); corrected and extended in stabmap's docs/closed.md"
)


class Closed(System):
    name = "closed"
    title = "planar equilibria of a closed chain of elastic joints, with their forces and stability"
    references = REFERENCES
    variables = VARIABLES
    label = STABILITY.name
    label_symbol = "class"
    label_title = "equilibrium"
    stable_label = STABLE
    absent_label = ABSENT
    undecided_label = UNDECIDED
    proves_labels = True  # every class is proved or flagged undecided (proofs.py, docs/closed.md)
    provenance = "decided_by"
    symbols = {"ratio": "h_2/h_1", "n": "n", "j": "j", "h": "h", "h1": "h_1", "c1sq": "c_1^2"}
    scene_module = _scene

    def attrs(self, scene: Scene) -> dict:
        fam = scene.fam
        out = {"closed_family": fam.name, "closed_family_title": fam.title, "closed_exists_where": fam.ratio_range}
        if scene.lengths:
            out["closed_lengths"] = np.array(scene.lengths)
        if fam.loops:
            out["closed_loops"] = "; ".join(" ".join(f"S{k}" for k in loop) for loop in fam.loops)
        out["closed_h"] = "min of the lengths at each point" if scene.h is None else f"{scene.h:g} m"
        return out

    def describe(self, attrs: dict) -> list[str]:
        lines = [f"family {attrs.get('closed_family')}: {attrs.get('closed_family_title')}; exists where {attrs.get('closed_exists_where')}"]
        if "closed_loops" in attrs:
            lines.append(f"two loops, each with its own force: {attrs['closed_loops']}")
        if "closed_lengths" in attrs:
            lines.append(f"lengths {[float(v) for v in np.atleast_1d(attrs['closed_lengths'])]} m")
        lines.append(f"h: {attrs.get('closed_h')}")
        return lines

    def dims(self, scene: Scene) -> dict[str, int]:
        return {"body": scene.n_max, "loop": len(scene.fam.loops) or 1}

    def cost(self, scene: Scene) -> Cost:
        # Measured on one core (scripts/bench_closed.py): a two-length family costs 0.1-0.15 ms a ratio, almost
        # all of it the proof in ball arithmetic (proofs.py; points of one ratio share it); a ring 9 us a point
        # for six bodies, 25 us for fifty (numpy on batches, an exact cyclotomic test per ratio).
        n = scene.n_max
        seconds = 6e-6 + 4e-7 * n if scene.ring else 1.6e-4
        return Cost(seconds=seconds, bytes=8 * (6 + 2 * n))

    def evaluate(self, scene: Scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        shape = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
        p = _scene.point_values(scene, values)
        size = int(np.prod(shape, dtype=np.int64))
        dims = self.dims(scene)
        out = {v.name: np.empty((size,) + tuple(dims[d] for d in v.dims), dtype=v.dtype) for v in VARIABLES}
        for name in ("theta", "joint_angle", "force_y", "force_z"):
            out[name][:] = np.nan
        fam = scene.fam
        n_of = p["n"].astype(np.int64) if "n" in p else np.full(size, scene.n_max)
        j_of = p["j"].astype(np.int64) if "j" in p else np.ones(size, dtype=np.int64)
        for (n, j), pts in _scene.combinations(n_of, j_of):
            if scene.lengths:
                lengths = np.broadcast_to(np.asarray(scene.lengths), (pts.size, n))
            else:
                lengths = fam.lengths(p["h1"][pts], p["ratio"][pts], n)
            c1sq = p["c1sq"][pts]
            h = p["h"][pts] if "h" in p else lengths.min(-1)
            loop_of = fam.loop_of(n)
            if scene.lengths:  # one proof for the scene's lengths (c1^2 and h leave the labels alone)
                guess = _guess(fam, lengths[:1], c1sq[:1], h[:1], j)
                verdicts = proofs.Verdicts.of([proofs.prove_lengths(fam, j, scene.lengths, guess)] * pts.size)
            else:  # the labels depend on the exact ratio h2/h1 only: one proof per ratio
                verdicts = proofs.prove_ratios(fam, n, j, p["ratio"][pts])
            theta, forces, _ = fam.closed_form(lengths, c1sq, h, j, exists=verdicts.exists != 0)
            d = decide(theta, forces, verdicts, lengths, loop_of, c1sq, h)
            out["stability"][pts] = d.stability
            out["decided_by"][pts] = d.decided_by
            out["exists"][pts] = d.exists
            out["index"][pts] = d.index
            out["nullity"][pts] = d.nullity
            out["rotation_index"][pts] = d.rotation_index
            out["energy"][pts] = d.energy
            out["residual"][pts] = d.residual
            out["theta"][pts, :n] = d.theta
            out["joint_angle"][pts, :n] = joint_angles(d.theta)
            out["force_y"][pts] = d.forces[..., 0]
            out["force_z"][pts] = d.forces[..., 1]
        return {k: v.reshape(shape + v.shape[1:]) for k, v in out.items()}

    def class_name(self, value: int) -> str:
        names = {ABSENT: "absent (no equilibrium)", DEGENERATE: "degenerate (nullity > 0)", UNDECIDED: "undecided (not proved)"}
        return names.get(value) or STABILITY.meaning(value)


def _guess(fam, lengths, c1sq, h, j):
    """(theta, rho = R h / c1^2) of the floating-point closed form at one length vector, for ``proofs``."""

    def guess():
        theta, forces, _ = fam.closed_form(lengths, c1sq, h, j, exists=[True])
        return theta[0], forces[0] * (h[0] / c1sq[0])

    return guess


SYSTEM = Closed()

__all__ = ["FAMILIES", "SYSTEM", "Scene"]
