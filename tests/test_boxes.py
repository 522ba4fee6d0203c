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
from stabmap.systems.gyroscopes.points import box_arrays, box_axes, point_arrays
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


def test_a_proved_box_has_its_label_at_random_interior_points_in_exact_arithmetic():
    checked = 0
    spin_scaled = [0, 0]  # proved boxes that move omega (the spin-scaled model), and that do not
    for system, rng in _scenes():
        n = len(system["bodies"])
        axes = {"omega": (1.0, 120.0), "m_1": (0.3, 3.0)}
        if n > 1:
            axes["K_1"] = (0.0, 30.0)
        system = dict(system, grid={name: {"values": [lo]} for name, (lo, _) in axes.items()})
        scene = from_dict(system)
        assert set(axes) <= box_axes(scene)
        nbox = 40
        lower, upper = {}, {}
        for name, (lo, hi) in axes.items():
            a = rng.uniform(lo, hi, nbox)
            w = (hi - lo) * 10.0 ** rng.uniform(-5, -1, nbox)
            lower[name], upper[name] = a, a + w
        upper["omega"][::2] = lower["omega"][::2]  # every other box at one spin rate: not spin-scaled
        nc, proved = prove_boxes(scene, lower, upper)
        spin_scaled[0] += int(proved[1::2].sum())
        spin_scaled[1] += int(proved[::2].sum())
        for i in np.flatnonzero(proved):
            t = rng.random((4, len(axes)))
            t[0], t[1] = 0.0, 1.0  # two corners, then random interior points
            values = {name: lower[name][i] + t[:, d] * (upper[name][i] - lower[name][i]) for d, name in enumerate(axes)}
            assert np.all(_exact(scene, values) == nc[i]), (system, i)
            checked += 1
    assert checked >= 60 and min(spin_scaled) >= 20, spin_scaled


def test_box_arrays_hold_the_kernel_inputs_of_every_interior_point():
    system, rng = next(_scenes())
    system = dict(system, grid={"omega": {"values": [1.0]}, "c": {"values": [0.1]}, "m_1": {"values": [1.0]}})
    scene = from_dict(system)
    lower = {"omega": np.array([3.0]), "c": np.array([-0.02]), "m_1": np.array([0.7])}
    upper = {"omega": np.array([3.5]), "c": np.array([0.2]), "m_1": np.array([0.9])}
    box = box_arrays(scene, lower, upper)
    t = rng.random((50, 3))
    inside = point_arrays(scene, {k: lower[k] + t[:, d] * (upper[k] - lower[k]) for d, k in enumerate(lower)})
    # omega moves and every body follows it: the box is spin-scaled, its spin column 1 and u = 1/omega^2 in range
    assert np.all(box.mid.body[..., 5] == 1.0) and np.all(box.rbody[..., 5] == 0.0)
    assert np.all((box.u_lo <= 1.0 / inside.body[:, 0, 5] ** 2) & (1.0 / inside.body[:, 0, 5] ** 2 <= box.u_hi))
    for got, mid, rad in ((inside.body[..., :5], box.mid.body[..., :5], box.rbody[..., :5]), (inside.joint, box.mid.joint, box.rjoint),
                          (inside.at, box.mid.at, box.rat), (inside.g, box.mid.g, box.rg)):
        assert np.all(np.abs(got - mid) <= rad)
    # with omega fixed, the box is not scaled and holds the spin column as it is
    fixed = box_arrays(scene, dict(lower, omega=lower["omega"]), dict(upper, omega=lower["omega"]))
    assert np.isnan(fixed.u_lo).all() and np.all(fixed.mid.body[..., 5] == lower["omega"][0])


def test_cavity_sizes_are_not_enclosed_so_their_boxes_are_not_proved():
    scene = stabmap.example("top-cylinder-cavity")
    assert not {"half_height_1", "radius_1"} & box_axes(scene)
    name = next(a.name for a in scene.grid if a.name not in box_axes(scene))
    value = scene.grid[[a.name for a in scene.grid].index(name)].array[:1]
    nc, proved = prove_boxes(scene, {name: value}, {name: value * 1.01})
    assert not proved.any()
    with pytest.raises(ValueError, match=name):
        box_arrays(scene, {name: value}, {name: value * 1.01})
