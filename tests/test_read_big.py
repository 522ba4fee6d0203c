"""Reading atlases of any size (stabmap.read.blocks, lazy stabmap.open_atlas): the chunk-by-chunk passes give
exactly the answers of the in-memory ones, big maps are drawn in pixel blocks that keep every stability boundary,
and memory is bounded by the chunks read, not by the atlas.

The reductions are compared with brute-force numpy on random maps cut into odd chunks; the queries of a lazily
opened atlas (netCDF and Zarr) with those of the same atlas loaded into memory; the drawn figure pixel by pixel.
"""

from __future__ import annotations

import runpy
import tracemalloc
from pathlib import Path

import dask.array as da
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import stabmap
from stabmap.read import blocks
from stabmap.read.plot import atlas_figure
from stabmap.store import files

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"
make_atlas = runpy.run_path(str(SCRIPTS / "bench_read.py"))["make_atlas"]
maps = arrays(np.int16, st.tuples(st.integers(1, 17), st.integers(1, 19)), elements=st.integers(-1, 3))


def chunked(a: np.ndarray, rows: int, cols: int) -> da.Array:
    return da.from_array(a, chunks=(rows, cols))


# ------------------------------------------------------------------------------------------- the reductions
@settings(max_examples=30, deadline=None)
@given(maps, st.integers(2, 6), st.integers(2, 6), st.integers(1, 4), st.integers(1, 4), st.integers(0, 2**31))
def test_blocks_against_brute_force(values, rows, cols, fy, fx, seed):
    flags = np.random.default_rng(seed).random(values.shape) < 0.2
    got = blocks.reduce_blocks(chunked(values, rows, cols), chunked(flags, cols, rows), 0, (fy, fx))
    ny, nx = -(-values.shape[0] // fy), -(-values.shape[1] // fx)
    assert got.low.shape == (ny, nx)
    for j in range(ny):
        for i in range(nx):
            cell = values[j * fy : (j + 1) * fy, i * fx : (i + 1) * fx]
            assert got.low[j, i] == cell.min() and got.high[j, i] == cell.max()
            assert got.mixed_stability[j, i] == ((cell == 0).any() and (cell != 0).any())
            assert got.any_flag[j, i] == flags[j * fy : (j + 1) * fy, i * fx : (i + 1) * fx].any()
    u, n = np.unique(values, return_counts=True)
    assert got.counts == dict(zip(u.tolist(), n.tolist()))


@settings(max_examples=30, deadline=None)
@given(maps, st.integers(2, 6), st.integers(2, 6), st.integers(0, 2**31))
def test_changes_and_first_true_against_brute_force(values, rows, cols, seed):
    flags = np.random.default_rng(seed).random(values.shape) < 0.3
    lazy, lazy_flags = chunked(values, rows, cols), chunked(flags, cols, rows)
    (line, k), below, above, flag_below, flag_above = blocks.changes(lazy, lazy_flags)
    want_line, want_k = np.nonzero(values[:, 1:] != values[:, :-1])  # C order
    np.testing.assert_array_equal(line, want_line)
    np.testing.assert_array_equal(k, want_k)
    np.testing.assert_array_equal(below, values[want_line, want_k])
    np.testing.assert_array_equal(above, values[want_line, want_k + 1])
    np.testing.assert_array_equal(flag_below, flags[want_line, want_k])
    np.testing.assert_array_equal(flag_above, flags[want_line, want_k + 1])

    found = blocks.first_true(lazy == 0, lazy, lazy_flags, -2)
    for j, row in enumerate(values):
        hits = np.flatnonzero(row == 0)
        assert found.has[j] == bool(hits.size)
        if not hits.size:
            assert not found.true_to_end[j] and found.value_before[j] == -2 and not found.flag_at[j]
            continue
        f = hits[0]
        assert found.first[j] == f and found.true_to_end[j] == bool((row[f:] == 0).all())
        assert found.value_before[j] == (row[f - 1] if f else -2)
        assert found.flag_at[j] == flags[j, f] and found.flag_before[j] == (f > 0 and flags[j, f - 1])


# --------------------------------------------------------------------------------- lazy atlases answer the same
@pytest.fixture(scope="module", params=["nc", "zarr"])
def lazy_and_loaded(request, tmp_path_factory):
    """A 600 x 500 synthetic atlas in small chunks (many of them), opened lazily and loaded."""
    path = make_atlas(tmp_path_factory.mktemp("big") / f"atlas.{request.param}", (600, 500), chunk_points=1 << 14)
    return path, stabmap.open_atlas(path)


def test_read_chunks_are_whole_file_chunks_grown_to_the_target(lazy_and_loaded, monkeypatch):
    path, _ = lazy_and_loaded
    with stabmap.open_atlas(path, lazy=True) as lazy:  # the file's chunks: 32 x 500 points (2**14, trailing axis whole)
        assert lazy["n_complex_pairs"].data.chunksize == (600, 500)  # 2**20 points would be 2097 rows: all 600
        assert files.read_chunks(lazy, points=1 << 15) == {"omega": 64, "K_1": 500}
        assert files.read_chunks(lazy, points=1) == {"omega": 32, "K_1": 500}  # never less than a chunk of the file
    monkeypatch.setattr(files, "READ_CHUNK_POINTS", 1 << 15)
    with stabmap.open_atlas(path, lazy=True) as lazy:
        assert lazy["n_complex_pairs"].data.chunks[0] == (64,) * 9 + (24,)
        assert lazy["decided_by"].data.chunks == lazy["n_complex_pairs"].data.chunks


@pytest.mark.parametrize(
    "question",
    [
        lambda ds: stabmap.stable_fraction(ds),
        lambda ds: stabmap.stable_fraction(ds, K_1=3, omega=(20, 90)),
        lambda ds: stabmap.boundaries(ds, "omega"),
        lambda ds: stabmap.boundaries(ds, "K_1", omega=(100, 130)),
        lambda ds: stabmap.smallest_stable(ds, "omega", over="K_1"),
        lambda ds: stabmap.smallest_stable(ds, "K_1", omega=(50, None)),
        lambda ds: stabmap.label_at(ds, omega=120, K_1=5),
    ],
)
def test_lazy_atlas_answers_as_the_loaded_one(lazy_and_loaded, question, monkeypatch):
    path, loaded = lazy_and_loaded
    want = question(loaded)
    for points in (files.READ_CHUNK_POINTS, 1 << 15):  # one dask chunk, and ten of 64 rows
        monkeypatch.setattr(files, "READ_CHUNK_POINTS", points)
        with stabmap.open_atlas(path, lazy=True) as lazy:
            got = question(lazy)
        if hasattr(want, "identical"):
            assert got.identical(want)
        else:
            assert got == want


# ---------------------------------------------------------------------------------------- pixel blocks in figures
@pytest.fixture(scope="module")
def big_map(tmp_path_factory):
    """A 3000 x 1200 atlas (3.6 M points): far more points than the figure has pixels."""
    path = make_atlas(tmp_path_factory.mktemp("map") / "atlas.nc", (3000, 1200))
    ds = stabmap.open_atlas(path, lazy=True)
    yield ds
    ds.close()


def test_blocks_keep_every_stability_boundary(big_map):
    """Every pair of neighbouring points of different stability lies in a block drawn black, or on the edge of
    two blocks whose stability differs (a thick line)."""
    from stabmap.read.plot import block_classes

    nc = big_map["n_complex_pairs"].transpose("K_1", "omega").values
    factors = (7, 9)
    b = blocks.reduce_blocks(nc, None, 0, factors)
    _, state = block_classes(b, 0)
    stable = nc == 0
    for axis in (0, 1):
        lo = [slice(None)] * 2
        hi = [slice(None)] * 2
        lo[axis], hi[axis] = slice(None, -1), slice(1, None)
        j, i = np.nonzero(stable[tuple(lo)] != stable[tuple(hi)])
        j2, i2 = (j + 1, i) if axis == 0 else (j, i + 1)
        a, c = (j // factors[0], i // factors[1]), (j2 // factors[0], i2 // factors[1])
        shown = b.mixed_stability[a] | b.mixed_stability[c] | (state[a] != state[c])
        assert j.size and shown.all()


def test_big_map_is_drawn_in_blocks_no_smaller_than_pixels_and_says_so(big_map):
    fig = atlas_figure(big_map)
    ax = fig.axes[0]
    title = ax.get_title().replace("\n", " ")
    assert "3,000 × 1,200 grid points drawn in blocks of" in title
    assert "black if it holds stable and unstable points" in title
    fig.set_dpi(150)
    fig.draw_without_rendering()
    box = ax.get_window_extent()
    mesh = next(a for a in ax.get_children() if a.get_gid() == "mixed-stability-blocks")
    rows, cols = mesh.get_array().shape
    assert cols <= box.width and rows <= box.height  # no block is smaller than a pixel
    assert cols > box.width / 2 and rows > box.height / 2  # ... and not much larger


def test_facet_panels_are_drawn_in_blocks_no_smaller_than_pixels(big_map):
    import xarray as xr

    part = big_map.isel(K_1=slice(0, 900))
    three = xr.concat([part.assign_coords(m_2=m) for m in (0.5, 1.0, 2.0, 4.0)], dim="m_2").transpose("omega", "K_1", "m_2", ...)
    three["m_2"].attrs.update(units="kg", long_name="mass of body 2")
    fig = atlas_figure(three)
    fig.set_dpi(150)
    fig.draw_without_rendering()
    panels = fig.subfigs[0].axes
    assert len(panels) == 4 and "3,000 × 900 grid points drawn in blocks of" in fig.subfigs[0]._suptitle.get_text().replace("\n", " ")
    for ax in panels:
        box = ax.get_window_extent()
        rows, cols = next(a for a in ax.get_children() if a.get_gid() == "mixed-stability-blocks").get_array().shape
        assert cols <= box.width and rows <= box.height


def test_thin_unstable_line_is_black_in_the_picture(big_map):
    """The synthetic atlas has one omega grid value of N_c = 1 across its stable region: a line one grid value
    thin, 1/2.5 of a pixel. Drawn in blocks, it must still cross the whole map in black."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = atlas_figure(big_map)
    fig.set_dpi(150)  # as saved to PNG
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    image = np.asarray(canvas.buffer_rgba())[..., :3]
    ax = fig.axes[0]
    omega = float(big_map["omega"][int(0.8 * (big_map.sizes["omega"] - 1))])
    x, _ = ax.transData.transform((omega, 0))
    box = ax.get_window_extent()
    top, bottom = image.shape[0] - int(box.y1) + 2, image.shape[0] - int(box.y0) - 2
    band = image[top:bottom, int(x) - 2 : int(x) + 3]
    black_rows = (band.max(axis=2) < 40).any(axis=1)
    assert black_rows.all()


def test_small_maps_are_drawn_point_by_point(big_map):
    small = big_map.isel(omega=slice(0, 300), K_1=slice(0, 200))
    fig = atlas_figure(small)
    assert "blocks" not in fig.axes[0].get_title()
    assert not [a for a in fig.axes[0].get_children() if a.get_gid() in ("mixed-stability-blocks", "mixed-class-blocks")]


# ----------------------------------------------------------------------------------------------- bounded memory
def _traced_peak(fn) -> float:
    """Peak of the memory numpy and Python allocate while ``fn`` runs [MiB] (netCDF's own buffers not counted:
    scripts/bench_read.py measures the resident memory of whole processes)."""
    fn()  # imports, caches, the first figure
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


@pytest.fixture(scope="module")
def atlases(tmp_path_factory):
    """The same synthetic atlas at about 1.1 M and 4.5 M points (labels 2.1 and 8.6 MiB as int16), in chunks of
    2**16 points, shaped so that both are drawn in the same number of blocks (2 x 2 and 4 x 4 points each)."""
    from stabmap.read.plot import panel_pixels

    py, px = panel_pixels(7.5, 1, 1, facets=False, strip=False)
    d = tmp_path_factory.mktemp("sizes")
    return [make_atlas(d / f"atlas-{k}.zarr", (k * px, k * py), chunk_points=1 << 16) for k in (2, 4)]


@pytest.mark.parametrize(
    "command",
    [
        ["info"],
        ["query", "omega=42.5", "K_1=3"],
        ["query", "--fraction"],
        ["query", "--boundaries", "omega", "--limit", "2"],
        ["query", "--boundaries", "K_1", "--limit", "2"],
        ["query", "--smallest-stable", "omega", "--over", "K_1", "--limit", "2"],
        ["plot", "-o", "{png}"],
        ["plot", "-o", "{png}", "--var", "growth_rate"],
    ],
)
def test_memory_does_not_grow_with_the_atlas(atlases, command, monkeypatch, tmp_path, capsys):
    """Four times the points, about the same peak: what is in memory at once is a few chunks (and the figure), not the
    atlas. (Traced by tracemalloc: numpy's and Python's memory; scripts/bench_read.py measures whole processes.)"""
    from stabmap.cli import main

    monkeypatch.setattr(files, "READ_CHUNK_POINTS", 1 << 16)  # 128 KiB of labels a chunk
    argv = [a.replace("{png}", str(tmp_path / "map.png")) for a in command[1:]]
    small, big = (_traced_peak(lambda path=path: main([command[0], str(path), *argv])) for path in atlases)
    with stabmap.open_atlas(atlases[1], lazy=True) as ds:
        labels = ds["n_complex_pairs"].nbytes / 2**20
    assert big < small + 3, f"{command}: {small:.1f} MiB traced at 1 M points, {big:.1f} MiB at 4 M"
    if command[0] != "plot":  # a figure of 1125 x 780 pixels costs more than these labels, whatever the atlas
        assert big < labels, f"{command}: {big:.1f} MiB traced; the labels alone are {labels:.1f} MiB"
