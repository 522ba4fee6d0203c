"""Every kind of netCDF file stabmap writes passes the IOOS compliance checker's CF-1.10 suite with no errors.

The files are written as ``stabmap atlas`` and ``stabmap critical`` write them (``stabmap.jobs``), on tiny grids: a
gyroscope atlas, a refined one, its critical values, a closed chain's atlas and critical values, a viscous atlas and
a reactions atlas.  The checker runs offline: it fetches a standard-name table only when a file names one in a
``standard_name_vocabulary`` global attribute, and stabmap's files name none, so it uses the table it bundles.
"""

from __future__ import annotations

import warnings

import netCDF4
import pytest
from compliance_checker import runner as checker  # the 'test' extra
from compliance_checker.base import BaseCheck

import stabmap
from stabmap import jobs
from stabmap.scene.grid import resample

SUITE = "cf:1.10"

# (file name, example, axes resampled to a few points, what to write: "atlas", "refined" or the critical axis)
FILES = [
    ("atlas", "paper-n3-fixed", {"omega": 5, "m_2": 3}, "atlas"),
    ("refined", "paper-n3-fixed", {"omega": 5, "m_2": 3}, "refined"),
    ("critical", "paper-n3-fixed", {"omega": 5, "m_2": 3}, "omega"),
    ("closed", "closed-hinge", {"ratio": 5}, "atlas"),
    ("closed-critical", "closed-hinge", {"ratio": 5}, "ratio"),
    ("viscous", "viscous-top-sphere", {"omega": 4, "C_1": 3}, "atlas"),
    ("reactions", "reactions-square-plate", {"c_x": 3, "c_y": 3}, "atlas"),
]


def _write(tmp_path, name, example, nums, what):
    scene = resample(stabmap.example(example), **nums)
    path = tmp_path / f"{name}.nc"
    run = {"threads": 2, "progress": False}
    if what in ("atlas", "refined"):
        jobs.atlas(scene, path, refine=what == "refined", **({"coarse_stride": 2} if what == "refined" else {}), **run)
    else:
        jobs.critical(scene, path, along=what, listing=False, **run)
    return path


def _check(path):
    """The checker's results of ``SUITE`` on ``path``: (failed results by priority, exceptions raised by its checks)."""
    suite = checker.CheckSuite()
    with warnings.catch_warnings():  # loading every checker imports the IOOS SOS ones, deprecated upstream
        warnings.simplefilter("ignore", DeprecationWarning)
        suite.load_all_available_checkers()
    ds = suite.load_dataset(str(path))
    try:
        results, exceptions = suite.run_all(ds, [SUITE], skip_checks=[])[SUITE]
    finally:
        ds.close()
    failed: dict[int, list[str]] = {}
    for r in results:
        score = r.value
        ok = score[0] >= score[1] if isinstance(score, tuple) else bool(score)
        if not ok:
            failed.setdefault(r.weight, []).extend(f"{r.name}: {m}" for m in r.msgs)
    return failed, exceptions


@pytest.mark.parametrize(("name", "example", "nums", "what"), FILES, ids=[f[0] for f in FILES])
def test_every_kind_of_file_passes_the_cf_checker(tmp_path, name, example, nums, what):
    path = _write(tmp_path, name, example, nums, what)
    failed, exceptions = _check(path)
    assert failed.get(BaseCheck.HIGH, []) == [], f"{name}: CF errors"
    # The bounds (CF 7.1) and missing data (2.5.1) sections pass whole: no warnings there either.
    warned = [m for m in failed.get(BaseCheck.MEDIUM, []) + failed.get(BaseCheck.LOW, []) if m.startswith(("§7.1", "§2.5"))]
    assert warned == []
    # A check that raised did not run: the strict-monotonicity one did on a string-valued coordinate variable.
    assert exceptions == {}


def test_coordinates_and_bounds_carry_no_fill_value_and_bounds_no_own_names(tmp_path):
    """What the checker finds wrong otherwise, read from the file itself: CF 2.5.1 and 7.1."""
    path = _write(tmp_path, "atlas", *FILES[0][1:])
    with netCDF4.Dataset(path) as nc:
        assert "standard_name_vocabulary" not in nc.ncattrs()  # the checker downloads the table such a name names
        for axis in ("omega", "m_2"):
            assert "_FillValue" not in nc[axis].ncattrs()
            bounds = nc[nc[axis].bounds]
            assert not {"_FillValue", "long_name", "units"} & set(bounds.ncattrs())
            assert "midpoints between grid values" in bounds.comment
        assert "_FillValue" not in nc["g"].ncattrs()  # a fixed parameter: a scalar coordinate
        assert "_FillValue" in nc["growth_rate"].ncattrs()  # data keep theirs: NaN marks a missing rate
    back = stabmap.open_atlas(path)
    assert back["omega_bounds"].shape == (5, 2) and back["omega"].attrs["bounds"] == "omega_bounds"


def test_a_part_of_an_older_atlas_is_rewritten_compliant(tmp_path):
    """An atlas written before (NaN _FillValue on every coordinate, a long_name on each bounds variable) still opens,
    and a part of it written again by ``stabmap.write_atlas`` passes: its bounds' text is kept as a comment."""
    new = _write(tmp_path, "atlas", *FILES[0][1:])
    ds = stabmap.open_atlas(new)
    for axis in ("omega", "m_2"):
        ds[f"{axis}_bounds"].attrs = {"long_name": f"edges of the grid cells along {axis} (midpoints between grid values)"}
    old = tmp_path / "old.nc"
    ds.to_netcdf(old, encoding={name: {"_FillValue": float("nan")} for name in ds.coords if ds[name].dtype.kind == "f"})
    with netCDF4.Dataset(old) as nc:
        assert "_FillValue" in nc["omega"].ncattrs()  # made as the older writer made it
    part = tmp_path / "part.nc"
    stabmap.write_atlas(stabmap.open_atlas(old).isel(omega=slice(0, 3)), part)
    failed, _ = _check(part)
    assert [m for m in sum(failed.values(), []) if m.startswith(("§7.1", "§2.5"))] == []
    back = stabmap.open_atlas(part)
    assert back["omega_bounds"].attrs == {"comment": "edges of the grid cells along omega (midpoints between grid values)"}
    assert back.sizes["omega"] == 3 and (back["n_complex_pairs"].values == ds["n_complex_pairs"].values[:3]).all()


def test_a_string_axis_is_written_as_labels_and_read_back_as_the_axis(tmp_path):
    """CF 1.3 and 6.1: a coordinate variable is numeric, so the reactions atlas's component axis (x, y, z) is stored
    as a string-valued auxiliary coordinate; ``open_atlas`` gives the axis back, selectable by its strings."""
    path = _write(tmp_path, *FILES[-1])
    with netCDF4.Dataset(path) as nc:
        assert "component" not in nc.variables and list(nc["component_label"][:]) == ["x", "y", "z"]
        assert "component_label" in nc["R"].coordinates.split()
    ds = stabmap.open_atlas(path)
    assert list(ds.indexes["component"]) == ["x", "y", "z"] and "component_label" not in ds.variables
    assert ds["component"].attrs["long_name"] == "Cartesian component in the nodes' frame"
    centre = ds["R"].sel(c_x=0.0, c_y=0.0, component="z")
    assert centre.values == pytest.approx([98.1 / 4] * 4, rel=1e-15)  # the plate's weight, a quarter on each corner
    again = tmp_path / "again.nc"
    stabmap.write_atlas(ds.isel(c_x=[0, 1]), again)
    back = stabmap.open_atlas(again)
    assert back["R"].identical(ds["R"].isel(c_x=[0, 1]))
