"""The reactions paper's worked example checked (``stabmap paper reactions``).

The square plate on four corner supports (Ovchinnikov & Sadchikov 1987; docs/reactions.md): with the centre of
mass at the centre, each corner carries a quarter of the weight, G/4, and the four are an exact tie for the most
loaded. With the centre of mass at (c_x, c_y) on a plate with corners (±a, ±a) the vertical reactions are the
linear distribution R_z,i = G/4 (1 + c_x x_i / a² + c_y y_i / a²) and the horizontal ones are 0. The bundled
``reactions-square-plate`` atlas is checked against this at every grid point, and against the paper's closed form
(6)-(9) (``stabmap.reactions.closed_form``) on every tenth point.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

NAME = "reactions-square-plate"
RTOL = 1e-12  # relative to G; the solver's proved error bound is far below this


def run(*, out: Path | None = None) -> dict:
    """Compute the plate's atlas and compare it with the closed forms; its figure into ``out`` (None: none)."""
    from ..examples import example
    from ..run import atlas
    from ..systems.reactions.scene import Scene
    from ..systems.reactions.solver import closed_form

    t0 = time.perf_counter()
    scene = example(NAME)
    assert isinstance(scene, Scene) and scene.body is not None  # the example: a plate whose load is its weight
    ds = atlas.compute(scene, progress=False)
    nodes = np.array(scene.nodes, dtype=float)
    a = float(np.abs(nodes[:, 0]).max())
    G = float(scene.body.mass) * -float(scene.body.gravity[2])
    cx, cy = np.meshgrid(ds["c_x"].values, ds["c_y"].values, indexing="ij")
    Rz = G / 4 * (1 + cx[..., None] * nodes[:, 0] / a**2 + cy[..., None] * nodes[:, 1] / a**2)
    R = ds["R"].transpose("c_x", "c_y", "node", "component").values
    problems = []
    err_z = float(np.max(np.abs(R[..., 2] - Rz))) / G
    err_xy = float(np.max(np.abs(R[..., :2]))) / G
    if err_z > RTOL or err_xy > RTOL:
        problems.append(f"{NAME}: linear distribution off by {err_z:.1e} G (vertical), {err_xy:.1e} G (horizontal)")
    centre = ds.sel(c_x=0.0, c_y=0.0)
    if not (np.all(centre["R"].sel(component="z").values == G / 4) and int(centre["n_critical"]) == 4):
        problems.append(f"{NAME}: at the centre R_z = {centre['R'].sel(component='z').values}, n_critical = "
                        f"{int(centre['n_critical'])}; the paper gives G/4 = {G / 4} at each of the 4 corners, a tie of 4")
    worst_cf = 0.0
    for i in range(0, cx.shape[0], 10):
        for j in range(0, cx.shape[1], 10):
            c = np.array([cx[i, j], cy[i, j], 0.0])
            F = np.array([0.0, 0.0, -G])
            expected = closed_form(nodes, F, np.cross(c, F))
            worst_cf = max(worst_cf, float(np.max(np.abs(R[i, j] - expected))) / G)
    if worst_cf > RTOL:
        problems.append(f"{NAME}: the paper's closed form (6)-(9) differs by {worst_cf:.1e} G")
    if out is not None:
        from ..read.plot import plot_atlas

        out.mkdir(parents=True, exist_ok=True)
        plot_atlas(ds, out / f"{NAME}.png")
    lines = [
        "# reactions: the square plate's atlas against G/4 at the centre, the linear distribution at every point and",
        f"# the paper's closed form (6)-(9) on every tenth point; all must agree to {RTOL:g} G",
        "",
        "| case | points | centre: R_z, ties | linear distribution, max diff / G | closed form (6)-(9), max diff / G | disagreements |",
        "|---|---|---|---|---|---|",
        f"| {NAME} | {cx.size} | {G / 4:g} = G/4, {int(centre['n_critical'])} | {max(err_z, err_xy):.1e} | {worst_cf:.1e} | {len(problems)} |",
    ]
    lines += [f"DISAGREES: {m}" for m in problems]
    lines.append(f"# total {time.perf_counter() - t0:.0f} s")
    return {"results": [], "problems": problems, "text": "\n".join(lines)}
