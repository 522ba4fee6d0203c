"""Box proofs: a label proved at every point of a box of parameters (kernels/boxcount.py, docs/certification.md).

Every claim is checked in exact rational arithmetic (python-flint) at points inside the box, and the critical
values of the case that motivated them (../shared/REGIONS.md) against the exact roots of the discriminant.
"""

from __future__ import annotations

import numpy as np
import pytest

import stabmap
from stabmap.run.critical import critical
from stabmap.systems.gyroscopes import exact
from stabmap.systems.gyroscopes.decide import prove_boxes
from stabmap.systems.gyroscopes.boxes import BoxArrays, box_arrays, box_axes, boxes
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.scene import from_dict

# Two-body fixed chain with small liquid modes: a stable window 0.108 rad/s wide near omega = 12, between two
# scan values 1 rad/s apart.  Exact boundaries (roots of the discriminant in omega): 11.909452, 12.017778, 13.838770.
WINDOW = {
    "support": "fixed", "g": 9.81, "joints": [10.0],
    "bodies": [
        {"m": 1.0, "A": 0.02, "C": 0.06, "c": 0.1, "s": 0.2, "fluid": {"E": [5e-4], "kappa": [-2.5]}},
        {"m": 1.0, "A": 0.05, "C": 0.06, "c": 0.05, "fluid": {"E": [5e-4], "kappa": [4.5]}},
    ],
    "grid": {"omega": {"start": 0.5, "stop": 99.5, "num": 100}},
}
EXACT_BOUNDARIES = (11.909452, 12.017778, 13.838770)


def _exact(scene, values: dict[str, np.ndarray]) -> np.ndarray:
    pts = point_arrays(scene, values)
    return exact.decide_points(*pts.kernel_args(), np.arange(pts.body.shape[0]))


def test_the_window_between_two_scan_values_is_found_and_located():
    ds = critical(from_dict(WINDOW), "omega", rtol=1e-10, progress=False, threads=1)
    lo, hi = ds["boundary_lower"].values, ds["boundary_upper"].values
    keep = np.isfinite(lo)
    lo, hi = lo[keep], hi[keep]
    assert lo.size == 3
    for a, b, x in zip(lo, hi, EXACT_BOUNDARIES):
        assert b - a <= 1e-10 * b and abs(0.5 * (a + b) - x) < 1e-6
    assert ds["n_complex_pairs_below"].values[keep].tolist() == [1, 0, 1]
    assert ds["n_complex_pairs_above"].values[keep].tolist() == [0, 1, 0]
    assert int(ds["n_stable_intervals"]) == 2
    assert ds["omega_stable_lower"].values[0] == pytest.approx(EXACT_BOUNDARIES[0], abs=1e-6)
    assert ds["omega_stable_upper"].values[0] == pytest.approx(EXACT_BOUNDARIES[1], abs=1e-6)
    assert "features narrower" not in ds.attrs["comment"]
    # the spin-scaled box proofs leave nothing undecided: both intervals are stable at every value
    assert int(ds["n_undecided"]) == 0
    assert ds["omega_stable_whole"].values.tolist() == [1, 1]


def _scenes():
    rng = np.random.default_rng(7)
    for support in ("fixed", "free"):
        for _ in range(3):
            n = int(rng.integers(1, 4))
            bodies = []
            for k in range(n):
                body = {"m": float(rng.uniform(0.5, 2)), "A": float(rng.uniform(0.01, 0.05)), "C": float(rng.uniform(0.01, 0.08)),
                        "c": float(rng.uniform(-0.05, 0.15)), "s": float(rng.uniform(0.1, 0.3))}
                if rng.random() < 0.7:
                    L = int(rng.integers(1, 3))
                    body["fluid"] = {"E": [float(x) for x in rng.uniform(1e-4, 2e-3, L)],
                                     "kappa": [float(x) for x in rng.choice([-2.5, 1.3, 2.7, 4.5], L, replace=False)]}
                bodies.append(body)
            scene = {"support": support, "bodies": bodies, "joints": [float(x) for x in rng.uniform(0, 20, n - 1)]}
            if support == "fixed":
                scene["g"] = 9.81
            yield scene, rng


KINDS = ("spin-scaled", "one axis", "plain")  # box i is of kind i % 3 (boxes.boxes)


def _random_boxes(system: dict, rng, nbox: int = 45):
    """A scene of ``system`` with axes omega, m_1, c_1 (and K_1), and boxes of the three kinds, 1e-5 to 1e-1 wide."""
    n = len(system["bodies"])
    axes = {"omega": (1.0, 120.0), "m_1": (0.3, 3.0), "c_1": (-0.1, 0.2)}
    if n > 1:
        axes["K_1"] = (0.0, 30.0)
    scene = from_dict(dict(system, grid={name: {"values": [lo]} for name, (lo, _) in axes.items()}))
    lower, upper = {}, {}
    for name, (lo, hi) in axes.items():
        a = rng.uniform(lo, hi, nbox)
        lower[name], upper[name] = a, a + (hi - lo) * 10.0 ** rng.uniform(-5, -1, nbox)
    one = [k for k in axes if k != "omega" and not (scene.free and k == "m_1")]
    for i in range(nbox):
        if i % 3 == 0:
            continue
        upper["omega"][i] = lower["omega"][i]  # one spin rate: not spin-scaled
        if i % 3 == 1:  # one mechanical axis moves
            keep = one[rng.integers(len(one))]
            for k in axes:
                if k not in ("omega", keep):
                    upper[k][i] = lower[k][i]
    return scene, axes, lower, upper


def test_a_proved_box_has_its_label_at_random_interior_points_in_exact_arithmetic():
    proved_by_kind = dict.fromkeys(KINDS, 0)
    for system, rng in _scenes():
        scene, axes, lower, upper = _random_boxes(system, rng)
        assert set(axes) <= box_axes(scene)
        nc, proved = prove_boxes(scene, lower, upper)
        for i in np.flatnonzero(proved):
            t = rng.random((4, len(axes)))
            t[0], t[1] = 0.0, 1.0  # two corners, then random interior points
            values = {name: lower[name][i] + t[:, d] * (upper[name][i] - lower[name][i]) for d, name in enumerate(axes)}
            assert np.all(_exact(scene, values) == nc[i]), (system, i)
            proved_by_kind[KINDS[i % 3]] += 1
    assert min(proved_by_kind.values()) >= 20, proved_by_kind


def test_each_box_goes_to_its_narrowest_enclosure_and_holds_its_points():
    for system, rng in _scenes():
        scene, axes, lower, upper = _random_boxes(system, rng, nbox=12)
        parts = boxes(scene, lower, upper)
        seen = np.concatenate([rows for rows, _ in parts])
        assert np.array_equal(np.sort(seen), np.arange(12))  # every box once
        for rows, part in parts:
            kinds = {KINDS[i % 3] for i in rows}
            if isinstance(part, BoxArrays):
                assert kinds <= {"plain", "one axis"}  # a free system's mass is not a node axis
                inside = point_arrays(scene, {k: lower[k][rows] + 0.37 * (upper[k][rows] - lower[k][rows]) for k in axes})
                for got, mid, rad in ((inside.body, part.mid.body, part.rbody), (inside.joint, part.mid.joint, part.rjoint),
                                      (inside.at, part.mid.at, part.rat), (inside.g, part.mid.g, part.rg)):
                    assert np.all(np.abs(got - mid) <= rad)
                continue
            assert kinds in ({"spin-scaled"}, {"one axis"})
            assert np.all(np.diff(part.t, axis=1) < 0) and np.all((part.t_lo[:, None] <= part.t) & (part.t <= part.t_hi[:, None]))
            if kinds == {"spin-scaled"}:
                # u = 1 / omega^2 of every point of the box lies in [t_lo, t_hi]; the spin column is 1
                w = np.stack([lower["omega"][rows], upper["omega"][rows]])
                assert np.all((part.t_lo <= 1.0 / w**2) & (1.0 / w**2 <= part.t_hi))
                assert np.all(part.body[..., 5] == 1.0) and np.all(part.rbody[..., 5] == 0.0)
            else:
                # the inputs at each node are the model's at that node, exactly (radius 0)
                i = int(rows[0])
                axis = next(k for k in axes if lower[k][i] != upper[k][i])
                at_nodes = point_arrays(scene, {**{k: np.repeat(lower[k][i], part.t.shape[1]) for k in axes}, axis: part.t[0]})
                assert np.array_equal(part.body[0], at_nodes.body) and np.array_equal(part.joint[0], at_nodes.joint)
                assert not part.rbody.any() and not part.rjoint.any()


def test_cavity_sizes_are_not_enclosed_so_their_boxes_are_not_proved():
    scene = stabmap.example("top-cylinder-cavity")
    assert not {"half_height_1", "radius_1"} & box_axes(scene)
    name = next(a.name for a in scene.grid if a.name not in box_axes(scene))
    value = scene.grid[[a.name for a in scene.grid].index(name)].array[:1]
    nc, proved = prove_boxes(scene, {name: value}, {name: value * 1.01})
    assert not proved.any()
    with pytest.raises(ValueError, match=name):
        box_arrays(scene, {name: value}, {name: value * 1.01})


def _label_from_file(ds, x: np.ndarray) -> np.ndarray:
    """N_c at scan values x from a critical file of one point: the start label, then each boundary's label above."""
    keep = np.isfinite(ds["boundary_lower"].values)
    upper, above = ds["boundary_upper"].values[keep], ds["n_complex_pairs_above"].values[keep]
    out = np.full(x.shape, int(ds["n_complex_pairs_at_scan_start"]))
    for hi, label in zip(upper, above):
        out[x >= hi] = label
    return out


@pytest.mark.parametrize("E", [1e-4, 1e-5, 1e-6, 1e-7])
def test_narrow_liquid_bands_never_hide_in_a_proved_stretch(E):
    # Smaller E narrows the liquid resonances to bands far below the scan step (1 rad/s).  At random values outside
    # the brackets and the listed gaps, the label the file gives must be the exact count.
    system = dict(WINDOW, bodies=[dict(b, fluid=dict(b["fluid"], E=[E])) for b in WINDOW["bodies"]])
    scene = from_dict(system)
    ds = critical(scene, "omega", rtol=1e-10, progress=False, threads=1)
    rng = np.random.default_rng(int(-np.log10(E)))
    x = rng.uniform(0.5, 99.5, 400)
    keep = np.isfinite(ds["boundary_lower"].values)
    n = int(ds["n_undecided"])
    holes = [(a, b) for a, b in zip(ds["boundary_lower"].values[keep], ds["boundary_upper"].values[keep])]
    holes += list(zip(ds["undecided_lower"].values[:n], ds["undecided_upper"].values[:n]))
    outside = np.ones(x.size, dtype=bool)
    for a, b in holes:
        outside &= ~((x >= a) & (x <= b))
    # and just beside every boundary, where a hidden band would sit
    near = np.concatenate([ds["boundary_lower"].values[keep] - 1e-7, ds["boundary_upper"].values[keep] + 1e-7])
    x = np.concatenate([x[outside], near])
    assert np.array_equal(_label_from_file(ds, x), _exact(scene, {"omega": x}))
