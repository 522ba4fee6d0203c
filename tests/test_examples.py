"""Every bundled example teaches something: its map has structure, or its title says why not."""

from __future__ import annotations

import numpy as np
import pytest

import stabmap
from stabmap.examples import example_names
from stabmap.run import atlas
from stabmap.scene.grid import resample
from stabmap.systems import of

POINTS = 40  # per axis: coarse, but every example's regions are wider than a fortieth of its grid


def _coarse(name: str):
    scene = stabmap.example(name)
    return resample(scene, **{a.name: POINTS for a in scene.grid if len(a.array) > POINTS})


@pytest.mark.parametrize("name", example_names())
def test_every_example_map_has_structure_or_says_why_not(name):
    scene = _coarse(name)
    ds = atlas.compute(scene, progress=False)
    system = of(scene)
    if "stability" in ds:
        classes = {system.variable("stability").meaning(int(v)) for v in np.unique(ds["stability"].values)}
        if scene.title.startswith("all stable:"):
            assert classes == {"stable"}, f"{name} is titled 'all stable' but has {sorted(classes)}"
        else:
            assert {"stable", "unstable"} <= classes, (
                f"{name}: only {sorted(classes)} on its grid; choose ranges that show both, or title it 'all stable: <why>'")
    else:
        label = ds[system.label].values
        assert np.unique(label[label >= 0]).size >= 2, f"{name}: one value of {system.label} on the whole map"


def test_all_stable_examples_point_to_one_that_is_not():
    for name in example_names():
        title = stabmap.example(name).title
        if title.startswith("all stable:"):
            other = next(w for w in title.replace("(", " ").split() if w.startswith("paper-") and w != name)
            assert other in example_names()
