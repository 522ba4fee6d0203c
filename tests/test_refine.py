"""Adaptive atlases (stabmap.run.refine): equal to the dense atlas cell for cell, far fewer evaluations.

Also pins down the documented assumption (docs/refine.md): a feature that hides
inside a cell whose corners agree, more than ``margin`` cells from any
disagreeing cell, is not seen, and the points it covers are flagged inferred.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import stabmap
from stabmap import systems
from stabmap.cli import main
from stabmap.systems.gyroscopes.outputs import BY_INFERRED
from stabmap.scene.grid import Axis, resample
from scenes import top_toml

# Every bundled example of a system that can be refined (reactions, say, cannot: its label is no stability class).
# refinement infers points from the corners of cells of a map: examples of two axes or more
ALL_EXAMPLES = [n for n in stabmap.example_names() if systems.of(stabmap.example(n)).inferred(np.zeros(0, dtype=np.int16)) is not None
                and len(stabmap.example(n).grid) >= 2]


def regrid(scene, *nums: int):
    """The scene with its grid axes resampled to ``nums`` points over the same ranges."""
    return resample(scene, **{a.name: num for a, num in zip(scene.grid, nums)})


def dense(scene):
    """Every node computed on its own, as the nodes refinement computes (their decided_by compared)."""
    return stabmap.compute_atlas(scene, threads=2, progress=False, prove_cells=False)


def refined(scene, **kwargs):
    return stabmap.compute_refined(scene, threads=2, progress=False, **kwargs)


def check_against_dense(ref, den) -> np.ndarray:
    """Refined equals dense cell for cell; computed points carry dense's proof, the rest flag 3. Returns mismatches."""
    by_r, by_d = ref["decided_by"].values, den["decided_by"].values
    computed = by_r != BY_INFERRED
    assert (by_r[computed] == by_d[computed]).all()
    assert int(ref.attrs["n_evaluated_points"]) == int(computed.sum())
    label = systems.of_atlas(den.attrs).label  # n_complex_pairs, or a viscous scene's asymptotic_stability
    assert ref[label].dims == den[label].dims
    for name in ref.coords:
        np.testing.assert_array_equal(ref[name].values, den[name].values)
    mismatch = ref[label].values != den[label].values
    assert not (mismatch & computed).any()  # only inferred points can differ
    return mismatch


# Liquid-mode resonances cut unstable bands one grid row wide through this map; a band
# thinner than the coarse spacing can fall between coarse rows (docs/refine.md).
THIN_BANDS = {"top-cylinder-cavity": 0.005}
# Seven boundary curves cross the whole 129 x 129 grid of this scene (three overlapping unstable bands), so
# refinement cannot save half of the evaluations there; it must still equal the dense atlas.
BOUNDARY_DENSE = {"paper-n3-free-identical"}


@pytest.mark.parametrize("name", ALL_EXAMPLES)
def test_equals_dense_on_every_example(name):
    scene = regrid(stabmap.example(name), 129, 129)
    den = dense(scene)
    for stride in (None, 8):
        ref = refined(scene, coarse_stride=stride)
        mismatch = check_against_dense(ref, den)  # mismatches only at points flagged inferred
        assert mismatch.mean() <= THIN_BANDS.get(name, 0.0)
        if name not in THIN_BANDS:
            label = "stability" if "stability" in den else systems.of_atlas(den.attrs).label
            assert (ref[label].values == den[label].values).all()
        assert list(ref.attrs["refine_coarse_stride"]) == [stride or 2] * 2
    if name not in BOUNDARY_DENSE:
        assert int(ref.attrs["n_evaluated_points"]) < den["decided_by"].size / 2


def test_much_fewer_evaluations_at_1024():
    scene = regrid(stabmap.example("paper-n2-fixed"), 1024, 1024)
    den, ref = dense(scene), refined(scene)
    assert not check_against_dense(ref, den).any()
    assert 20 * int(ref.attrs["n_evaluated_points"]) < den["n_complex_pairs"].size
    assert set(np.unique(den["n_complex_pairs"])) == {0, 1, 2}  # three regions, two boundaries


def test_cusp_missed_without_margin_found_with_it():
    # paper-n1-fixed has a stable tongue that narrows to a cusp; at 300 x 300 and stride 4 its tip
    # is thinner than a coarse cell, so corners that agree hide it unless the margin opens its cells.
    scene = regrid(stabmap.example("paper-n1-fixed"), 300, 300)
    den = dense(scene)
    missed = check_against_dense(refined(scene, margin=0), den)
    assert missed.sum() > 0
    assert not check_against_dense(refined(scene, margin=1), den).any()


def striped_scene():
    """33 sorted cavity heights of the liquid-filled top at 150 rad/s, where unstable bands of the cavity's modes
    (Greenhill's bands) alternate with stable gaps: the points 4, 20 and 28..32 lie in bands, the rest in gaps."""
    heights = [0.0110, 0.0115, 0.0120, 0.0125, 0.01315, *np.linspace(0.0185, 0.0265, 15), 0.0273,
               *np.linspace(0.030, 0.050, 7), *np.linspace(0.055, 0.058, 5)]
    grid = (Axis("half_height_1", tuple(heights), "values"),)
    return dataclasses.replace(stabmap.example("top-cylinder-cavity"), omega=150.0, grid=grid)


def test_feature_smaller_than_a_cell_is_the_documented_blind_spot():
    # Stride 8: cells [0,8] [8,16] [16,24] [24,32].  A real boundary in the last cell (28..32 unstable);
    # one-point features at 4 (inside a cell of agreeing corners, far from it) and 20 (next to it).
    scene = striped_scene()
    den = dense(scene)
    assert list(np.flatnonzero(den["n_complex_pairs"].values)) == [4, 20, 28, 29, 30, 31, 32]

    ref = refined(scene, coarse_stride=8, margin=1)
    missed = check_against_dense(ref, den)
    assert list(np.flatnonzero(missed)) == [4]  # the margin opened the cell holding 20, nothing opened 4's
    assert ref["decided_by"].values[4] == BY_INFERRED  # and the missed point does not claim a proof

    assert list(np.flatnonzero(check_against_dense(refined(scene, coarse_stride=8, margin=0), den))) == [4, 20]
    assert not check_against_dense(refined(scene, coarse_stride=4, margin=0), den).any()  # 4 and 20 are nodes


@pytest.mark.parametrize("shape", [(), (1001,), (65, 33, 17), (129, 1, 2)])
def test_any_number_of_axes(shape):
    names = ("omega", "K_1", "m_2")
    axes = tuple(
        Axis(name, tuple(float(v) for v in np.linspace(lo, hi, num)))
        for name, (lo, hi), num in zip(names, ((1.0, 150.0), (0.0, 40.0), (0.1, 5.0)), shape)
    )
    scene = dataclasses.replace(stabmap.example("paper-n2-fixed"), grid=axes)
    den = dense(scene)
    for stride in (None, 4):
        ref = refined(scene, coarse_stride=stride)
        assert ref["n_complex_pairs"].shape == shape
        assert not check_against_dense(ref, den).any()


def test_threads_and_chunks_do_not_change_the_result():
    scene = regrid(stabmap.example("paper-n1-free"), 257, 257)
    a = refined(scene, coarse_stride=16)
    b = stabmap.compute_refined(scene, coarse_stride=16, threads=1, chunk_points=100, progress=False)
    assert (a["n_complex_pairs"].values == b["n_complex_pairs"].values).all()
    assert (a["decided_by"].values == b["decided_by"].values).all()


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"coarse_stride": 12}, "coarse_stride=12: must be a power of two"),
        ({"coarse_stride": 0}, "coarse_stride=0: must be a power of two"),
        ({"coarse_stride": 8.0}, "coarse_stride=8.0: must be a whole power of two"),
        ({"margin": -1}, "margin=-1: must be a whole number of cells >= 0"),
        ({"threads": -2}, "threads=-2: must be a whole number >= 1"),
    ],
)
def test_bad_arguments(kwargs, message):
    with pytest.raises(stabmap.StabmapError, match=message):
        stabmap.compute_refined(stabmap.example("paper-n1-fixed"), **kwargs)


def test_refining_a_grid_too_coarse_to_refine_says_so(tmp_path, capsys):
    scene = tmp_path / "small.toml"
    scene.write_text(top_toml("omega = { start = 1.0, stop = 100.0, num = 40 }\n"))
    assert main(["atlas", str(scene), "-o", str(tmp_path / "a.nc"), "--refine", "-q"]) == 0
    err = capsys.readouterr().err
    assert "nothing to infer, every point computed" in err and "--coarse-stride" in err and "x fewer" not in err


def test_cli_refine_file_info_query(tmp_path, capsys):
    out = tmp_path / "a.nc"
    assert main(["atlas", "--example", "paper-n2-fixed", "-o", str(out), "--refine", "--coarse-stride", "8", "-q"]) == 0
    err = capsys.readouterr().err
    assert "polynomials evaluated instead of 60,000" in err and "x fewer" in err
    ds = stabmap.open_atlas(out)
    assert list(ds.attrs["refine_coarse_stride"]) == [8, 8] and int(ds.attrs["refine_margin"]) == 2
    inferred = int((ds["decided_by"].values == BY_INFERRED).sum())
    assert inferred + int(ds.attrs["n_evaluated_points"]) == 60000
    assert "inferred_from_cell_corners" in ds["decided_by"].attrs["flag_meanings"].split()
    assert stabmap.summary(ds)["decided_by"]["inferred_from_cell_corners"] == inferred
    assert main(["info", str(out)]) == 0
    assert f"inferred from cell corners {inferred}" in capsys.readouterr().out
    assert main(["query", str(out), "omega=100", "K_1=20"]) == 0
    assert "not computed: inferred from the agreeing corners" in capsys.readouterr().out


@pytest.mark.parametrize(
    "args,message",
    [
        (["--refine", "--coarse-stride", "12"], "--coarse-stride 12: must be a power of two"),
        (["--coarse-stride", "8"], "--coarse-stride applies to adaptive atlases only; add --refine"),
        (["--margin", "2"], "--margin applies to adaptive atlases only; add --refine"),
        (["--refine", "--margin", "-1"], "--margin -1: must be a whole number of cells >= 0"),
    ],
)
def test_cli_bad_refine_options(tmp_path, capsys, args, message):
    out = tmp_path / "a.nc"
    assert main(["atlas", "--example", "paper-n1-fixed", "-o", str(out), *args]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()
