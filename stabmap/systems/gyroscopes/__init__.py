"""Chains and trees of Lagrange gyroscopes with liquid-filled cavities (docs/model.md): the first system.

The pipeline's part of this system is the ``System`` below; the physics is in
the modules beside it:

- ``scene``, ``parameters``, ``topology``, ``liquid``, ``cavity``: what a scene holds and how it is checked;
- ``points``: a scene and a block of its grid -> the kernels' per-point arrays;
- ``decide`` (with ``stabmap.kernels``) and ``exact``: N_c of each point, proved;
- ``outputs``: the variables written;
- ``paper``: the source paper's printed equations, restated exactly, to compare with.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...store.variables import Variable
from ..base import System
from ..stages import stage
from .outputs import ALL_VARIABLES, BY_BOX, BY_INFERRED, FREQUENCY_VARIABLES, GROWTH_VARIABLES, N_COMPLEX_PAIRS, VARIABLES, stability_from_pairs
from .scene import Body, Scene

REFERENCES = (
    "Yu. N. Kononov, On the motion of a system of coupled rigid bodies with cavities containing "
    "liquid (in Russian), Donetsk State University, received 22.11.1999: equations (22)-(34)"
)


class Gyroscopes(System[Scene]):
    name = "gyroscopes"
    title = "chains and trees of Lagrange gyroscopes with liquid-filled cavities"
    references = REFERENCES
    variables: tuple[Variable, ...] = ALL_VARIABLES
    label = N_COMPLEX_PAIRS.name
    label_symbol = "N_c"
    label_title = "complex root pairs N$_c$"
    stable_label = 0
    provenance = "decided_by"
    symbols = {"omega": r"\omega", "g": "g", "m": "m", "A": "A", "C": "C", "c": "c", "s": "s", "K": "K", "density": r"\rho",
               "M_alpha": r"M_\alpha", "S_g": "S_g", "C_over_A": "C/A", "aspect": "h/a"}
    scene_type = Scene
    default_axis = "omega"  # "how fast must it spin?"
    paper = "stabmap.paper.gyroscopes"
    stages = ("rates",)  # the growth rates and frequencies: optional, and at times the dearer part (docs/rates.md)

    def derived_coords(self, scene: Scene) -> dict[str, tuple]:
        from .ratios import coordinates

        return coordinates(scene, scene.parameter)

    def attrs(self, scene: Scene) -> dict:
        attrs = {"support": scene.support, "n_bodies": scene.n, "polynomial_degree_bound": scene.degree}
        if scene.topology is not None:
            attrs["topology_parent"] = np.array(scene.topology.parent, dtype=np.int32)
        return attrs

    def describe(self, attrs: dict) -> list[str]:
        n = attrs.get("n_bodies")
        lines = [
            f"support {attrs.get('support')}, {n} bod{'y' if n == 1 else 'ies'}, characteristic polynomial of degree "
            f"<= {attrs.get('polynomial_degree_bound')}"
        ]
        if "topology_parent" in attrs:
            lines.append(f"a tree: parent = {[int(p) for p in np.atleast_1d(attrs['topology_parent'])]} (0: the base; docs/trees.md)")
        return lines

    def fixed_groups(self, names: list[str]) -> list[tuple[str, list[str]]]:
        # The whole scene (g, omega), the joints K_0.. (K_0 the support's, K_k between bodies k and k+1),
        # then one group a body: m_k, A_k, C_k, c_k, s_k, omega_k, at_k and its cavity's parameters.
        scene: list[str] = []
        joints: list[str] = []
        bodies: dict[int, list[str]] = {}
        for name in names:
            head, _, index = name.rpartition("_")
            if not index.isdigit() or not head:
                scene.append(name)
            elif head == "K":
                joints.append(name)
            else:
                bodies.setdefault(int(index), []).append(name)
        groups = [("", scene)] if scene else []
        groups += [("joints", joints)] if joints else []
        return groups + [(f"body {k}", bodies[k]) for k in sorted(bodies)]

    def outputs(self, scene: Scene) -> tuple:
        # the growth rate is on unless the scene turns it off, the frequencies (D values a point) only if it asks
        return VARIABLES + (GROWTH_VARIABLES if scene.growth_rate else ()) + (FREQUENCY_VARIABLES if scene.frequencies else ())

    def labels_only(self, scene: Scene) -> Scene:
        import dataclasses

        return dataclasses.replace(scene, growth_rate=False, frequencies=False)

    def dims(self, scene: Scene) -> dict[str, int]:
        return {"mode": scene.degree}

    def dim_coords(self, scene: Scene) -> dict:
        if not scene.frequencies:
            return {}
        along = tracking_axis(scene)
        how = (f"followed along {along} by continuity (mode_tracking)" if along else
               "numbered by ascending real part (the grid has no spin axis to follow the modes along)")
        attrs = {"long_name": f"mode: one characteristic root (multiplicity counted), {how}", "units": "1"}
        return {"mode": (np.arange(scene.degree, dtype=np.int32), {**attrs, **({"followed_along": along} if along else {})})}

    def finish(self, scene: Scene, ds):
        along = tracking_axis(scene) if scene.frequencies else None
        if along is None:
            return ds
        from .tracking import follow_atlas

        return follow_atlas(ds, along)

    def fastest_axes(self, scene: Scene) -> tuple[int, ...]:
        # The kernels rebuild the inertia and stiffness matrices only when a point's masses, lengths or
        # stiffnesses differ from the previous point's: runs of points that differ only in spin skip that work.
        spins = {"omega", "S_g"} if scene.hold.S_g == "M_alpha" else {"omega"}  # S_g moves the spin by default
        return tuple(d for d, a in enumerate(scene.grid) if a.name in spins or a.name.startswith("omega_"))

    def input_bytes(self, scene: Scene) -> int:
        from .points import point_arrays

        one = point_arrays(scene, {})
        assert one.at is not None  # PointArrays.__post_init__ fills it
        return sum(a.nbytes for a in (one.body, one.joint, one.g, one.E, one.kappa, one.at)) + 8

    def evaluate(self, scene: Scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        from .decide import decide
        from .points import point_arrays

        shape = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
        points = point_arrays(scene, values)
        nc, by = decide(points)
        out = {"n_complex_pairs": nc, "stability": stability_from_pairs(nc), "decided_by": by}
        if scene.growth_rate or scene.frequencies:
            from .rates import rates

            with stage("rates"):
                out.update(rates(points, nc, scene.growth_rate, scene.frequencies))
        return {k: v.reshape(shape + v.shape[1:]) for k, v in out.items()}

    def box_axes(self, scene: Scene) -> set[str]:
        from .boxes import box_axes

        return box_axes(scene)

    def box_cost(self, scene: Scene) -> float:
        from .boxes import box_cost

        return box_cost(scene)

    def prove_boxes_cheaply(self, scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray],
                            batch: np.ndarray | None = None):
        from .kreinboxes import prove_boxes_cheaply

        return prove_boxes_cheaply(scene, lower, upper, batch)

    def cheap_box_cost(self, scene: Scene) -> float:
        from .kreinboxes import cheap_box_cost

        return cheap_box_cost(scene)

    def prove_boxes(self, scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]):
        from .decide import prove_boxes

        return prove_boxes(scene, lower, upper)

    def prove_and_cut_boxes(self, scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]):
        from .decide import prove_boxes

        return prove_boxes(scene, lower, upper, cut=True)

    def proved_box(self, label: np.ndarray) -> dict[str, np.ndarray]:
        from .rates import not_computed

        return {"stability": stability_from_pairs(label), "decided_by": np.full(np.shape(label), BY_BOX, dtype=np.int8),
                **not_computed(label, proved=True)}

    def at_proved_nodes(self, scene: Scene, values: dict[str, np.ndarray], label: np.ndarray) -> dict[str, np.ndarray] | None:
        # the box proved N_c at the node; the roots there are cheaper than a decision (docs/rates.md)
        if not (scene.growth_rate or scene.frequencies):
            return None
        from .points import point_arrays
        from .rates import rates

        with stage("rates"):
            return rates(point_arrays(scene, values), label, scene.growth_rate, scene.frequencies)

    def skip_stage(self, scene: Scene, stage: str) -> tuple[str, str] | None:
        keys = [k for k in ("growth_rate", "frequencies") if stage == "rates" and getattr(scene, k)]
        if not keys:
            return None
        what = " and ".join({"growth_rate": "growth rates", "frequencies": "frequencies"}[k] for k in keys)
        return what, f"set {' and '.join(f'{k} = false' for k in keys)} in the scene to skip them"

    def class_name(self, value: int) -> str:
        if value < 0:
            return "degenerate (p \u2261 0)"
        if value == 0:
            return "stable (all roots real)"
        # every class but N_c = 0 is unstable: the legend says so, not only how many pairs (issue 30)
        return f"unstable: {value} complex pair{'s' if value > 1 else ''}"

    def roots(self, scene: Scene, values: dict[str, float]) -> tuple[list, str]:
        from .modes import RULE, roots_at

        return roots_at(scene, values), RULE

    def inferred(self, label: np.ndarray) -> dict[str, np.ndarray]:
        from .rates import not_computed

        return {"stability": stability_from_pairs(label), "decided_by": np.full(np.shape(label), BY_INFERRED, dtype=np.int8),
                **not_computed(label, proved=False)}

    # figures
    def figure_text(self, text: str, units: Callable[[str], str]) -> str:
        # Each body's A is "about its centre of mass" (parameters.py); an axis label has no room to say it again.
        text = text.replace(" about its centre of mass", "")
        for unit in ("kg m2", "m7"):  # what notes() writes after numbers: a liquid's E, a viscous liquid's tensor
            text = text.replace(f" {unit}", f" {units(unit)}")
        return text


def tracking_axis(scene: Scene) -> str | None:
    """The grid axis the modes are followed along: ``omega``, else the first body's own spin rate; None without."""
    names = [a.name for a in scene.grid if a.continuous]  # listed cases are not a line to follow a mode along
    spins = [n for n in names if n == "omega"] + [n for n in names if n.startswith("omega_")]
    return spins[0] if spins else None


SYSTEM = Gyroscopes()

__all__ = ["SYSTEM", "Body", "Scene"]
