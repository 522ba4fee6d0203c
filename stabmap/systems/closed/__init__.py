"""Closed chains of elastic joints (docs/closed.md): the planar and twisted equilibria of a closed rod of n bodies,
their forces and their stability in space (and in their plane), from Bolgrabskaya, Savchenko and Shchepin (2006), as
restated, corrected and extended in docs/closed.md.

The pipeline's part of this system is the ``System`` below; the physics is in the modules beside it:

- ``families``: the named families (ring, figure-eights, hinges) and their closed forms;
- ``equations``: the general equilibrium equations, energy, constrained Hessian, rotation index;
- ``space``: the joint energy in space, the out-of-plane block and the spatial Hessian (twisted rings);
- ``proofs``: the proof of the planar labels (exact rational and ball arithmetic, python-flint) and of the
  inertia of any bordered Hessian, or the flag undecided; ``space_proofs``: the labels in space, per point batch;
- ``decide``: a batch of configurations and their proofs -> every output (shared by atlases and ``solve``);
- ``solve`` and ``search``: the Python API (``stabmap.closed``);
- ``checks``, ``scene``: what an input must satisfy, and the scene files;
- ``outputs``: the variables written.
"""

from __future__ import annotations

import numpy as np

from ..base import System
from . import proofs, space_proofs
from . import scene as _scene
from .decide import ABSENT, DEGENERATE, STABLE, UNDECIDED, decide
from .equations import joint_angles
from .families import FAMILIES, twist_form
from .outputs import STABILITY, VARIABLES
from .scene import Scene

REFERENCES = (
    "I. A. Bolgrabskaya, A. Ya. Savchenko, N. N. Shchepin, Closed systems of coupled rigid bodies (in Russian), "
    "Mekhanika tverdogo tela 36 (2006): equations (22)-(52); corrected and extended in stabmap's docs/closed.md"
)


class Closed(System[Scene]):
    name = "closed"
    title = "planar and twisted equilibria of a closed chain of elastic joints, with their forces and stability in space"
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
    symbols = {"ratio": "h_2/h_1", "n": "n", "j": "j", "twist": "m", "h": "h", "h1": "h_1", "c1sq": "c_1^2", "c2sq": "c_2^2"}
    scene_type = Scene
    default_axis = "ratio"  # h2/h1: where the families' equilibria change stability (docs/closed.md)
    paper = "stabmap.paper.closed"

    def attrs(self, scene: Scene) -> dict:
        fam = scene.fam
        out = {"closed_family": fam.name, "closed_family_title": fam.title, "closed_exists_where": fam.ratio_range,
               "closed_model": scene.model}
        if scene.lengths:
            out["closed_lengths"] = np.array(scene.lengths)
        if fam.loops:
            out["closed_loops"] = "; ".join(" ".join(f"S{k}" for k in loop) for loop in fam.loops)
        out["closed_h"] = "min of the lengths at each point" if scene.h is None else f"{scene.h:g} m"
        out["closed_c2sq"] = "c1sq at each point" if scene.c2sq is None else f"{scene.c2sq:g} N m2"
        return out

    def describe(self, attrs: dict) -> list[str]:
        lines = [f"family {attrs.get('closed_family')}: {attrs.get('closed_family_title')}; exists where {attrs.get('closed_exists_where')}"]
        if "closed_loops" in attrs:
            lines.append(f"two loops, each with its own force: {attrs['closed_loops']}")
        if "closed_lengths" in attrs:
            lines.append(f"lengths {[float(v) for v in np.atleast_1d(attrs['closed_lengths'])]} m")
        lines.append(f"h: {attrs.get('closed_h')}; c2sq: {attrs.get('closed_c2sq', 'c1sq at each point')}")
        model = attrs.get("closed_model", "planar (written before stabmap decided stability in space)")
        lines.append(f"model: {model}" + (" (stability against every motion, out of the plane and twist included)" if model == "spatial"
                                          else " (the chain confined to its plane)"))
        return lines

    def dims(self, scene: Scene) -> dict[str, int]:
        return {"body": scene.n_max, "loop": len(scene.fam.loops) or 1}

    def input_bytes(self, scene: Scene) -> int:
        return 8 * (10 + 4 * scene.n_max)  # the point's scalars and its lengths, angles and forces along the chain

    def evaluate(self, scene: Scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        shape = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
        p = _scene.point_values(scene, values)
        size = int(np.prod(shape, dtype=np.int64))
        dims = self.dims(scene)
        out = {v.name: np.empty((size,) + tuple(dims[d] for d in v.dims), dtype=v.dtype) for v in VARIABLES}
        for name in ("theta", "twist_angle", "joint_angle", "force_x", "force_y", "force_z"):
            out[name][:] = np.nan
        fam = scene.fam
        n_of = p["n"].astype(np.int64) if "n" in p else np.full(size, scene.n_max)
        j_of = p["j"].astype(np.int64) if "j" in p else np.ones(size, dtype=np.int64)
        m_of = p["twist"].astype(np.int64) if "twist" in p else np.zeros(size, dtype=np.int64)
        gamma = _gammas(p["c1sq"], p["c2sq"]) if scene.spatial else None
        for (n, j, m), pts in _scene.combinations(n_of, j_of, m_of):
            n, j, m = int(n), int(j), int(m)
            if scene.lengths:
                lengths = np.broadcast_to(np.asarray(scene.lengths), (pts.size, n))
            else:
                lengths = fam.lengths(p["h1"][pts], p["ratio"][pts], n)
            c1sq, c2sq = p["c1sq"][pts], p["c2sq"][pts]
            h = p["h"][pts] if "h" in p else lengths.min(-1)
            loop_of = fam.loop_of(n)
            g = None if gamma is None else [gamma[i] for i in pts]
            if scene.lengths:  # the scene's lengths: one proof per gamma (c1^2 and h leave the labels alone)
                guess = _guess(fam, lengths[:1], c1sq[:1], h[:1], j)
                done: dict = {}  # gamma -> its proof
                verdicts = proofs.Verdicts.of([
                    done[x] if x in done else done.setdefault(x, space_proofs.prove_lengths(fam, j, m, scene.lengths, x, guess))
                    for x in (g or [None] * pts.size)])
            else:  # the labels depend on the exact ratio h2/h1 and gamma only: one proof per pair
                verdicts = space_proofs.prove_ratios(fam, n, j, m, p["ratio"][pts], g)
            theta, forces, _ = fam.closed_form(lengths, c1sq, h, j, exists=verdicts.exists != 0)
            phi, force_x = twist_form(lengths, c1sq, c2sq, h, j, m)
            d = decide(theta, forces, verdicts, lengths, loop_of, c1sq, h, c2sq=c2sq, phi=phi, force_x=force_x)
            for name in ("stability", "decided_by", "exists", "index", "nullity", "planar_stability", "planar_index",
                         "planar_nullity", "rotation_index", "energy", "residual"):
                out[name][pts] = getattr(d, name)
            out["theta"][pts, :n] = d.theta
            out["twist_angle"][pts, :n] = d.phi
            out["joint_angle"][pts, :n] = joint_angles(d.theta)
            out["force_x"][pts] = d.force_x
            out["force_y"][pts] = d.forces[..., 0]
            out["force_z"][pts] = d.forces[..., 1]
        return {k: v.reshape(shape + v.shape[1:]) for k, v in out.items()}

    def class_name(self, value: int) -> str:
        names = {ABSENT: "absent (no equilibrium)", DEGENERATE: "degenerate (nullity > 0)", UNDECIDED: "undecided (not proved)"}
        return names.get(value) or STABILITY.meaning(value)


def _gammas(c1sq: np.ndarray, c2sq: np.ndarray) -> list:
    """gamma = c2^2/c1^2 exactly at every point (one fmpq per distinct pair of doubles)."""
    pairs: dict = {}
    return [pairs.setdefault((a, b), space_proofs.gamma_of(a, b)) for a, b in zip(c1sq.tolist(), c2sq.tolist(), strict=True)]


def _guess(fam, lengths, c1sq, h, j):
    """(theta, rho = R h / c1^2) of the floating-point closed form at one length vector, for ``proofs``."""

    def guess():
        theta, forces, _ = fam.closed_form(lengths, c1sq, h, j, exists=[True])
        return theta[0], forces[0] * (h[0] / c1sq[0])

    return guess


SYSTEM = Closed()

__all__ = ["FAMILIES", "SYSTEM", "Scene"]
