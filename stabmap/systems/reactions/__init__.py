"""Reactions of statically indeterminate joints (seed 004; docs/reactions.md): the second system.

Two rigid bodies joined by n ideal point nodes; which reactions do the nodes carry, and which node carries the
most, for which load and layout? The pipeline's part is the ``System`` below; the physics is beside it:

- ``solver``: the least-norm reactions, every label proved, public as ``stabmap.reactions``: ``floats`` (vectorised
  floating point with a proved error bound) decides most points, ``exact`` (rational arithmetic) the others;
- ``scene``, ``parameters``: what a scene holds, how it is checked, what a grid can scan;
- ``load``: a scene and a block of its grid -> node positions, F and M;
- ``outputs``: the variables written.
"""

from __future__ import annotations

import numpy as np

from ..base import System
from .outputs import (
    COMPONENT_DIM,
    COMPONENTS,
    CRITICAL_NODE,
    DECIDED_BY,
    NODE_DIM,
    VARIABLES,
)
from .scene import Body, Load, Release, Scene

REFERENCES = (
    "V. V. Ovchinnikov, V. I. Sadchikov, A method of eliminating static indeterminacy in problems of the mechanics "
    "of a constrained rigid body (in Russian), Uchenye Zapiski TsAGI 18(6), 1987: equations (1)-(17); the "
    "collinear case corrected (docs/reactions.md)"
)


class Reactions(System[Scene]):
    name = "reactions"
    title = "reactions of n point nodes holding a rigid body, by the least sum of squares"
    references = REFERENCES
    variables = VARIABLES
    label = CRITICAL_NODE.name
    label_symbol = "critical node"
    label_title = "node carrying the\nlargest reaction"
    stable_label = None
    provenance = DECIDED_BY.name
    symbols = {"F": "F", "M": "M", "c": "c", "g": "g", "a": "a", "omega": r"\omega", "alpha": r"\alpha", "x": "x", "y": "y", "z": "z"}
    scene_type = Scene
    default_axis = "c_x"  # where the centre of mass lies decides which node carries the most
    paper = "stabmap.paper.reactions"

    def attrs(self, scene: Scene) -> dict:
        attrs = {"n_nodes": scene.n, "load_given_as": scene.kind}
        if scene.releases:
            attrs["release_nodes"] = np.array([r.node for r in scene.releases], dtype=np.int32)
        return attrs

    def describe(self, attrs: dict) -> list[str]:
        released = np.atleast_1d(attrs.get("release_nodes", np.zeros(0, dtype=np.int32)))
        how = "F and M" if attrs.get("load_given_as") == "load" else "a body's weight and motion"
        line = f"{attrs.get('n_nodes')} nodes, load given as {how}"
        if released.size:
            nodes = sorted({int(k) for k in released})
            line += f", {released.size} release{'s' if released.size > 1 else ''} at node{'s' if len(nodes) > 1 else ''} {', '.join(map(str, nodes))}"
        return [line, "reactions by the least sum of |R_i|^2 (equal elastic nodes; docs/reactions.md)"]

    def dims(self, scene: Scene) -> dict[str, int]:
        return {NODE_DIM: scene.n, COMPONENT_DIM: 3}

    def dim_coords(self, scene: Scene) -> dict:
        # Components as variable-length strings: Zarr (the checkpoint) has no stable spec for fixed-length ones.
        return {
            NODE_DIM: (np.arange(scene.n, dtype=np.int32), {"long_name": "node index (0-based, as in the scene's nodes and releases)", "units": "1"}),
            COMPONENT_DIM: (np.array(COMPONENTS, dtype=object), {"long_name": "Cartesian component in the nodes' frame"}),
        }

    def input_bytes(self, scene: Scene) -> int:
        return 8 * (3 * scene.n + 6)  # the nodes' positions, F and M

    def evaluate(self, scene: Scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        from .load import load, node_positions
        from .solver import least_norm, prepare_releases

        shape = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
        F, M = load(scene, values)
        releases = prepare_releases(scene.n, [(r.node, r.direction) for r in scene.releases])
        out = least_norm(node_positions(scene, values), F, M, releases)

        def full(a, extra=()):
            return np.ascontiguousarray(np.broadcast_to(a, shape + extra))

        return {
            "R": full(out.R, (scene.n, 3)),
            "R_norm": full(out.norms, (scene.n,)),
            "R_max": full(out.max_norm),
            "critical_node": full(out.critical_node),
            "n_critical": full(out.n_critical),
            "rank": full(out.rank),
            "free_motions": full(out.free_motions),
            "compatible": full(out.compatible.astype(np.int8)),
            "balance_residual": full(out.residual),
            "decided_by": full(out.decided_by),
        }

    def class_name(self, value: int) -> str:
        if value < 0:
            return "no reactions balance the load"
        return f"node {value}"


SYSTEM = Reactions()

__all__ = ["SYSTEM", "Body", "Load", "Release", "Scene"]
