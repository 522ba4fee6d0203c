"""A small gyroscope atlas built by hand whose grid nodes carry every ``cell`` flag in every class, so the figure and
the page tests can check what is drawn at each node without computing an atlas."""

from __future__ import annotations

import numpy as np
import xarray as xr

from stabmap.store.dataset import BOUNDS_DIM, bounds
from stabmap.store.variables import CELL
from stabmap.systems.gyroscopes.outputs import DECIDED_BY, N_COMPLEX_PAIRS

NODE_ONLY, WHOLE, CHANGE, NOT_PROVED = (CELL.value(m) for m in ("node_only", "whole_cell", "contains_change", "not_proved"))
ATTRS = {
    "omega": {"long_name": "common spin rate", "units": "rad s-1", "scale": "linear"},
    "K_1": {"long_name": "stiffness of joint 1", "units": "N m rad-1", "scale": "linear"},
    "m_2": {"long_name": "mass of body 2 (liquid included)", "units": "kg", "scale": "linear"},
}
# (K_1, omega): an unstable window (N_c = 1) between stable columns, two pairs at high spin; its nodes carry every flag
LABELS = np.array([[1, 1, 0, 0, 2, 2],
                   [1, 1, 0, 0, 2, 2],
                   [1, 1, 1, 0, 0, 2],
                   [0, 1, 1, 0, 0, 2],
                   [0, 0, 1, 1, 0, 0]])
CELLS = np.array([[WHOLE, CHANGE, CHANGE, WHOLE, CHANGE, WHOLE],
                  [NODE_ONLY, CHANGE, CHANGE, CHANGE, CHANGE, NODE_ONLY],
                  [WHOLE, WHOLE, CHANGE, CHANGE, CHANGE, CHANGE],
                  [CHANGE, CHANGE, NODE_ONLY, CHANGE, WHOLE, CHANGE],
                  [NOT_PROVED, CHANGE, CHANGE, CHANGE, CHANGE, WHOLE]])


def flagged_atlas(m_2: list[float] | None = None, discrete: bool = False, repeat: int = 1) -> xr.Dataset:
    """The atlas of LABELS and CELLS over (K_1, omega), each node made ``repeat`` x ``repeat`` nodes; with ``m_2``
    the same map at each of its values along a third axis (``discrete``: its cells of zero width, as for listed
    values)."""
    labels, cells = (np.kron(a, np.ones((repeat, repeat), dtype=a.dtype)) for a in (LABELS, CELLS))
    axes = {"K_1": np.linspace(0.0, 40.0, labels.shape[0]), "omega": np.linspace(10.0, 60.0, labels.shape[1])}
    if m_2 is not None:
        axes = {"m_2": np.asarray(m_2, dtype=float), **axes}
        labels, cells = (np.broadcast_to(a, (len(m_2), *a.shape)) for a in (labels, cells))
    dims = tuple(axes)
    coords = {}
    for d, v in axes.items():
        coords[d] = (d, v, {**ATTRS[d], "bounds": f"{d}_bounds"})
        b = np.column_stack([v, v]) if d == "m_2" and discrete else bounds(v)
        coords[f"{d}_bounds"] = ((d, BOUNDS_DIM), b)
    data = {
        "n_complex_pairs": (dims, labels.astype(np.int16), N_COMPLEX_PAIRS.attrs()),
        "decided_by": (dims, np.zeros(labels.shape, dtype=np.int8), DECIDED_BY.attrs()),
        "cell": (dims, cells.astype(np.int8), CELL.attrs()),
    }
    return xr.Dataset(data, coords=coords, attrs={"title": "flags by hand", "stabmap_format_version": 3})
