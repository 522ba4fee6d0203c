"""Chains and trees of Lagrange gyroscopes whose cavities hold a highly viscous liquid (docs/viscous.md).

The scenes are the gyroscopes' own (``stabmap.systems.gyroscopes.scene``): a cavity with a ``viscosity`` makes a
scene viscous, and its ``system`` then names this one.  The label is asymptotic stability to first order in the
inverse viscosity (Chernousko's expansion, seed 003 after (18)); ``decide`` proves it.
"""

from __future__ import annotations

import numpy as np

from ...errors import StabmapError
from ..gyroscopes import Gyroscopes
from .outputs import ALL_VARIABLES, ASYMPTOTIC_STABILITY, BY, GROWTH_VARIABLES, UNDECIDED, VARIABLES

REFERENCES = (
    "Yu. N. Kononov, On the motion of a system of coupled rigid bodies with cavities containing liquid (in Russian), "
    "equations (1)-(18); F. L. Chernousko, Motion of a rigid body with cavities containing a viscous fluid, Moscow, "
    "1968 (NASA TT F-13 227, 1972)"
)


class Viscous(Gyroscopes):
    name = "viscous"
    title = "chains and trees of Lagrange gyroscopes with cavities full of a highly viscous liquid"
    references = REFERENCES
    variables = ALL_VARIABLES
    label = ASYMPTOTIC_STABILITY.name
    label_symbol = "class"
    label_title = "asymptotic stability"
    stable_label = ASYMPTOTIC_STABILITY.value("asymptotically_stable")
    undecided_label = UNDECIDED
    stable_word = "asymptotically stable"
    provenance = "decided_by"
    symbols = {**Gyroscopes.symbols, "viscosity": r"\nu"}
    paper = "stabmap.paper.viscous"

    def scene_from_dict(self, table, base_dir=None):
        # the gyroscopes' scenes, refusing one without a viscous liquid under system = "viscous"
        scene = super().scene_from_dict(table, base_dir)
        if not scene.viscous:
            raise StabmapError('system = "viscous" needs a viscous liquid: give a body\'s cavity a viscosity [m2 s-1] '
                               '(docs/viscous.md), or remove system = "viscous" for the ideal liquid')
        return scene

    def outputs(self, scene) -> tuple:
        return VARIABLES + (GROWTH_VARIABLES if scene.growth_rate else ())

    def labels_only(self, scene):
        import dataclasses

        return dataclasses.replace(scene, growth_rate=False)

    def dims(self, scene) -> dict[str, int]:
        return {}

    def dim_coords(self, scene) -> dict:
        return {}

    def evaluate(self, scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        from .decide import evaluate

        shape = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
        out = evaluate(scene, values)
        keep = {v.name for v in self.outputs(scene)}
        return {k: v.reshape(shape) for k, v in out.items() if k in keep}

    def box_axes(self, scene) -> set[str]:
        return set()  # labels are proved at the nodes; the cells of an atlas say so (docs/cells.md)

    def at_proved_nodes(self, scene, values, label):
        return None

    def roots(self, scene, values):
        return None

    def inferred(self, label: np.ndarray) -> dict[str, np.ndarray]:
        label = np.asarray(label)
        nan = np.full(label.shape, np.nan, dtype=np.float32)
        return {"decided_by": np.full(label.shape, BY["inferred_from_cell_corners"], dtype=np.int8), "reynolds": nan,
                **{v.name: nan.copy() for v in GROWTH_VARIABLES}}

    def caveats(self, ds) -> list[str]:
        out = []
        if "reynolds" in ds:
            re_ = ds["reynolds"]
            outside, total, top = (float(x) for x in ((re_ >= 1).sum(), re_.notnull().sum(), re_.max()))
            if total:
                out.append(f"first order in 1/Re (Chernousko): Re = \u03c9a\u00b2/\u03bd >= 1 at {100 * outside / total:.3g} % of the "
                           f"points (largest Re {top:.3g}), where the model does not hold")
        if ds.attrs.get("support") == "free":
            out.append("free support: the \u03bb = 0 roots (tilts of the whole) are neutral; asymptotically stable means up to them")
        return out

    def class_name(self, value: int) -> str:
        names = {-3: "undecided (not proved)", -1: "degenerate (p \u2261 0)", 0: "asymptotically stable", 1: "unstable"}
        return names.get(int(value), f"{self.label} = {value}")


SYSTEM = Viscous()

__all__ = ["SYSTEM"]
