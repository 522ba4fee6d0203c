"""Modes followed along the spin axis (frequencies = true): checked against closed forms and against every root of
the exact rational polynomial (FLINT/Arb), on lines where the roots cross, meet and stay apart."""

from __future__ import annotations

import numpy as np
import pytest

import stabmap
from stabmap.systems.gyroscopes.outputs import MODE_TRACKING
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.rates import exact_roots
from stabmap.systems.gyroscopes.tracking import AMBIGUOUS, ASCENDING, FOLLOWED, follow_modes

TOP = """
title = "one top with one liquid mode"
frequencies = true
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.1
fluid = {{ E = [{E}], kappa = [40.0] }}
[grid]
omega = {{ start = 12.0, stop = 60.0, num = {num} }}
"""


def test_a_liquid_line_is_followed_through_its_crossing_with_the_nutation_root():
    """With E = 0 the liquid mode decouples: p = (lambda + beta) p_top with its root -beta = (2 - kappa)/kappa omega
    (a straight line), which crosses the top's nutation root between omega = 26 and 28.  Sorted by real part the two
    swap places; followed, the liquid mode stays on its line at every point, and the links where the order changed are
    flagged, not passed off as followed."""
    ds = stabmap.compute_atlas(stabmap.loads_scene(TOP.format(E=0.0, num=25)), progress=False)
    omega = ds.omega.values
    line = (2 - 40.0) / 40.0 * omega
    f, r = ds.frequency.values, ds.frequency_radius.values
    on_line = np.abs(f - line[:, None]) <= r + 1e-9 * np.abs(line[:, None])
    modes = np.flatnonzero(on_line.all(axis=0))
    assert modes.size == 1, "one mode index holds the liquid root at every spin rate"
    sorted_index = np.argmin(np.abs(np.sort(f, axis=1) - line[:, None]), axis=1)
    assert len(set(sorted_index)) == 2, "sorted by real part, the liquid root changes index at the crossing"
    swap = np.flatnonzero(np.diff(sorted_index) != 0)[0] + 1  # the first point past the crossing
    assert ds.mode_tracking.values[swap, modes[0]] == AMBIGUOUS
    assert ds.mode_tracking.values[0].tolist() == [ASCENDING] * 3
    assert ds.mode_tracking.attrs["flag_meanings"] == " ".join(MODE_TRACKING.meanings)


def test_modes_never_swap_where_the_exact_roots_stay_apart():
    """A two-body chain over spin rates where every root is real and the exact roots (Arb) are separated at every
    point of a line four times finer: no two roots cross, so each mode is the j-th root at every point, and every
    link is followed."""
    text = stabmap.example("paper-n2-fixed").to_toml()
    scene = stabmap.loads_scene(text).with_grid(())
    import dataclasses

    from stabmap.scene.grid import Axis

    scene = dataclasses.replace(scene, frequencies=True, growth_rate=False)
    omega = np.linspace(150.0, 200.0, 21)
    scene = scene.with_grid((Axis("omega", tuple(omega)),))
    ds = stabmap.compute_atlas(scene, progress=False)
    assert (ds.n_complex_pairs == 0).all(), "the line is chosen where every root is real"
    fine = np.linspace(omega[0], omega[-1], 4 * (omega.size - 1) + 1)
    points = point_arrays(scene, {"omega": fine})
    exact = np.array([np.sort(exact_roots(points, i, scene.degree)[0].real) for i in range(fine.size)])
    gaps = np.diff(exact, axis=1)  # between neighbouring roots: a crossing takes one of them through 0
    assert gaps.min() > np.abs(np.diff(gaps, axis=0)).max(), "no gap closes between two fine points: no crossing"
    f = ds.frequency.values
    np.testing.assert_allclose(f, exact[::4], rtol=1e-9, atol=1e-9)
    assert (ds.mode_tracking.values[1:] == FOLLOWED).all()


def test_tracking_is_the_same_whatever_the_chunks_and_in_a_file(tmp_path):
    """Lines are followed once every point is in: chunks that cut the spin axis, and the streamed write of a file,
    give the very same modes as one block in memory."""
    scene = stabmap.loads_scene(TOP.format(E=1e-5, num=49))
    whole = stabmap.compute_atlas(scene, progress=False)
    cut = stabmap.compute_atlas(scene, progress=False, chunk_points=7, prove_cells=False)
    path = tmp_path / "top.nc"
    stabmap.compute_to_file(scene, path, progress=False, chunk_points=5)
    stored = stabmap.open_atlas(path)
    for other in (cut, stored):
        for name in ("frequency", "frequency_radius", "root_kind", "mode_tracking"):
            np.testing.assert_array_equal(whole[name].values, other[name].values, err_msg=name)
    assert stored.frequency.dims == ("omega", "mode") and stored.mode.attrs["followed_along"] == "omega"
    from stabmap.read.info import describe

    followed = int((stored.mode_tracking == FOLLOWED).sum())
    assert f"modes: 3, followed along omega; links followed {followed:,}" in describe(stored)


def test_each_line_of_a_map_is_followed_on_its_own():
    scene = stabmap.loads_scene(TOP.format(E=1e-5, num=25).replace("[grid]", "[grid]\nc_1 = { values = [0.08, 0.1] }"))
    ds = stabmap.compute_atlas(scene, progress=False)
    for c in ds.c_1.values:
        one = stabmap.compute_atlas(stabmap.loads_scene(TOP.format(E=1e-5, num=25).replace("c = 0.1", f"c = {c}")), progress=False)
        np.testing.assert_array_equal(ds.frequency.sel(c_1=c).transpose("omega", "mode").values, one.frequency.values)


def test_an_avoided_crossing_finer_than_the_grid_is_flagged():
    """y = +-sqrt(x^2 + eps^2) sampled at a step far wider than eps: continuity cannot tell a crossing from a veering,
    so the links around x = 0 are ambiguous, whichever way they are continued."""
    x = np.linspace(-1, 1, 21)
    eps = 1e-4
    y = np.stack([-np.sqrt(x**2 + eps**2), np.sqrt(x**2 + eps**2)], axis=-1)
    r = np.full(y.shape, 1e-12)
    kind = np.zeros(y.shape, np.int8)
    f, _, _, flag = follow_modes(x, y, r, kind)
    near = np.abs(x) <= 0.11
    assert (flag[near & (x > 0)] == AMBIGUOUS).all()
    assert (flag[1:][np.abs(x[1:]) > 0.3] == FOLLOWED).all()


def test_straight_lines_that_cross_are_followed_and_flagged():
    x = np.linspace(0, 1, 11)
    a, b = 2 * x - 1.05, -x + 0.3  # cross at x = 0.45, between grid points
    y = np.sort(np.stack([a, b], -1), axis=-1)
    f, _, _, flag = follow_modes(x, y, np.full(y.shape, 1e-12), np.zeros(y.shape, np.int8))
    np.testing.assert_allclose(f[:, 0], b) if np.isclose(f[0, 0], b[0]) else np.testing.assert_allclose(f[:, 0], a)
    np.testing.assert_allclose(np.sort(f, axis=1), y)
    assert (flag[5] == AMBIGUOUS).all() and (flag[[2, 3, 8, 9]] == FOLLOWED).all()


@pytest.mark.parametrize("missing", [True, False])
def test_a_point_not_computed_restarts_the_line(missing):
    x = np.linspace(0, 1, 6)
    y = np.stack([x - 2, 2 - x], -1)
    if missing:
        y[2] = np.nan
    kind = np.where(np.isnan(y), -1, 0).astype(np.int8)
    _, _, _, flag = follow_modes(x, y, np.full(y.shape, 1e-9), kind)
    assert flag[3].tolist() == ([ASCENDING] * 2 if missing else [FOLLOWED] * 2)
    assert flag[2].tolist() == ([-1, -1] if missing else [FOLLOWED] * 2)
