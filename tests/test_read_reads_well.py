"""What a user reads and sees (issue 22): ``info`` text for 1 to 32 bodies, a short stable-fraction repr, and
figures that carry the fixed parameters, label log axes between decades, keep one-cell bands in their class
colour and put the scanned parameter on x in critical plots as on atlas maps."""

from __future__ import annotations

import re

import io

import numpy as np
import pytest
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb

import stabmap
from stabmap import systems
from stabmap.read.info import WIDTH, describe
from stabmap.read.plot import atlas_figure, colour, critical_figure
from stabmap.run.critical import critical
from stabmap.systems.gyroscopes.outputs import DECIDED_BY, N_COMPLEX_PAIRS
from stabmap.systems.gyroscopes.scene import from_dict


def chain_scene(n: int) -> dict:
    bodies = [{"m": 1.0 + 0.01 * k, "A": 0.02, "C": 0.03, "c": 0.1, "s": 0.25} for k in range(n)]
    bodies[0]["fluid"] = {"E": [2.0e-3, 1.0e-4], "kappa": [2.7, 3.1]}
    return {"title": f"a chain of {n}", "support": "fixed", "g": 9.81, "joints": [10.0 + k for k in range(n - 1)],
            "bodies": bodies, "grid": {"omega": {"start": 1.0, "stop": 100.0, "num": 5}}}


def hand_atlas(n: int, nc: np.ndarray | None = None, log_y: bool = False) -> xr.Dataset:
    """An atlas of an n-body chain over (K_0 or nothing, omega), made by hand: its label is ``nc`` (no computing)."""
    table = chain_scene(n)
    scene = from_dict(table)
    nc = np.zeros((1, 5), dtype=np.int16) if nc is None else nc
    ny, nx = nc.shape
    omega = np.linspace(1.0, 100.0, nx)
    y = np.geomspace(0.1, 100.0, ny) if log_y else np.linspace(0.0, 1.0, ny)
    coords = {"K_0": ("K_0", y, {"long_name": "stiffness of the support", "units": "N m rad-1", "scale": "log" if log_y else "linear"}),
              "omega": ("omega", omega, {"long_name": "common spin rate", "units": "rad s-1", "scale": "linear"})}
    fixed = systems.get("gyroscopes").fixed_values(scene)
    for k, v in fixed.items():
        if k not in ("omega", "K_0"):
            coords[k] = ((), v, {"units": "kg" if k.startswith("m_") else ""})
    dims = ("K_0", "omega")
    data = {"n_complex_pairs": (dims, nc, N_COMPLEX_PAIRS.attrs()), "decided_by": (dims, np.zeros(nc.shape, np.int8), DECIDED_BY.attrs())}
    attrs = {"title": table["title"], "stabmap_format_version": 3, "n_bodies": n, "support": "fixed", "polynomial_degree_bound": 3 * n,
             "scene": scene.to_toml(), "source": "stabmap test", "history": "2026-01-01T00:00:00+00:00 computed by stabmap test"}
    return xr.Dataset(data, coords=coords, attrs=attrs)


@pytest.mark.parametrize("n", [1, 4, 32])
def test_info_lines_are_short_grouped_per_body_and_show_the_liquid(n):
    text = describe(hand_atlas(n), "atlas.nc")
    lines = text.splitlines()
    assert max(map(len, lines)) <= WIDTH, max(lines, key=len)
    assert sum(line.lstrip().startswith("body ") for line in lines) == n  # one group a body
    assert "E = 0.002, 0.0001 kg m2" in text and "\u03ba = 2.7, 3.1" in text and "2 modes given" in text
    assert f"{n} bod{'y' if n == 1 else 'ies'}," in text and "1 bodies" not in text
    assert text.count("stabmap test") == 1  # provenance once: source named by the history line
    assert "1 points" not in text


def test_stable_fraction_has_a_short_repr():
    ds = hand_atlas(2, np.zeros((3, 5000), dtype=np.int16))
    ds.attrs.pop("scene")
    frac = ds.stabmap.stable_fraction()
    text = repr(frac)
    assert len(text) < 300 and "5000 grid values" in text and "15000 points" in text
    assert len(frac.axes["omega"].values) == 5000  # the numbers are still there


def test_caption_holds_the_fixed_values_per_body():
    fig = atlas_figure(hand_atlas(4, np.zeros((4, 5), dtype=np.int16)))
    (caption,) = [t for t in fig.texts if t.get_gid() == "fixed-caption"]
    text = caption.get_text().replace("\u00a0", " ")
    assert "body 4: $m$ = 1.03 kg" in text and "$g$ = 9.81" in text and "$K_{3}$ = 12" in text
    assert "E = 0.002, 0.0001 kg m$^{2}$, \u03ba = 2.7, 3.1" in text  # each body's liquid modes, one list unbroken
    assert "$s$" in text.split("body 3:")[1].split("body 4:")[0] and "$s$" not in text.split("body 4:")[1]  # no joint above the top
    shown = [re.sub(r"[${}^_]", "", re.sub(r"\\[A-Za-z]+", "x", line)) for line in text.splitlines()]
    assert max(map(len, shown)) <= 15.5 * fig.get_figwidth() + 1


def test_log_axis_labels_more_than_decades():
    fig = atlas_figure(hand_atlas(1, np.zeros((30, 5), dtype=np.int16), log_y=True))
    fig.canvas.draw()
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"  # K_0, the first axis of the atlas, is x
    lo, hi = ax.get_xlim()
    labels = [t.get_text() for t in ax.xaxis.get_majorticklabels() + ax.xaxis.get_minorticklabels()
              if t.get_text() and lo <= t.get_position()[0] <= hi]
    assert len(labels) >= 9, labels  # 0.1 .. 100: 4 decades and 2, 5 of each of three
    assert "0.2" in labels and "50" in labels


def test_a_log_axis_over_many_decades_writes_every_label_one_way():
    from matplotlib.figure import Figure

    from stabmap.read.plot import log_ticks

    ax = Figure().subplots()
    ax.set_xscale("log")
    ax.set_xlim(10.0, 1e5)
    log_ticks(ax.xaxis, 10.0, 1e5)
    ax.figure.canvas.draw()
    labels = [t.get_text() for t in ax.xaxis.get_majorticklabels() if t.get_text()]
    assert labels and all(t.startswith("$") for t in labels), labels  # 10¹ .. 10⁵, not "10, 100, 1000, 10⁴"


def test_one_cell_band_keeps_its_class_colour():
    nc = np.zeros((40, 300), dtype=np.int16)
    nc[:, 150] = 2  # one column of 2 pairs between stable cells: two stability boundaries one cell apart
    fig = atlas_figure(hand_atlas(1, nc))
    FigureCanvasAgg(fig)
    fig.set_dpi(150)
    fig.canvas.draw()
    img = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255.0
    ax = fig.axes[0]  # x: K_0 (the atlas's first axis), y: omega, so the band is a row of cells
    y = img.shape[0] - float(ax.transData.transform((0.5, float(np.linspace(1.0, 100.0, 300)[150])))[1])  # its centre [px]
    x0, x1 = ax.get_window_extent().x0, ax.get_window_extent().x1
    band = img[int(y) - 3 : int(y) + 4, int(x0) + 3 : int(x1) - 3].transpose(1, 0, 2)
    want = np.array(to_rgb(colour(2)))
    hits = (np.abs(band - want).max(axis=-1) < 0.06).sum(axis=1)
    assert (hits >= 1).mean() > 0.95  # the class colour shows along (nearly) all the band: no black bar


def test_boundary_between_wide_regions_stays_thick():
    # 300 cells along omega are thinner than the thick line: only the lines around the one-cell band may thin
    # down, or the stability boundary would look like a change of N_c (thin) everywhere on fine grids
    nc = np.zeros((40, 300), dtype=np.int16)
    nc[:, 200:] = 1
    nc[:, 100] = 2
    fig = atlas_figure(hand_atlas(1, nc))
    (stab,) = [c for c in fig.axes[0].collections if c.get_gid() == "stability-boundary"]
    widths = np.broadcast_to(stab.get_linewidth(), (len(stab.get_segments()),))
    y = np.array([seg[0][1] for seg in stab.get_segments()])
    omega = np.linspace(1.0, 100.0, 300)
    wide, band = np.abs(y - (omega[199] + omega[200]) / 2) < 1e-9, np.abs(y - omega[100]) < omega[1] - omega[0]
    assert wide.any() and band.sum() >= 2
    assert widths[wide].min() == 1.5 and widths[band].max() < 0.6


def test_critical_plot_puts_the_scanned_parameter_on_x():
    scene = from_dict({"support": "fixed", "g": 9.81, "bodies": [{"m": 1.0, "A": 0.02, "C": 0.03, "c": 0.1}],
                       "grid": {"omega": {"start": 1.0, "stop": 60.0, "num": 21}, "c_1": {"values": [0.05, 0.1, 0.2]}}})
    ds = critical(scene, "omega", rtol=1e-8)
    fig = critical_figure(ds)
    ax = fig.axes[0]
    assert "\\omega" in ax.get_xlabel() and "c" in ax.get_ylabel()
    assert ax.get_xlim() == (1.0, 60.0)
    (caption,) = [t for t in fig.texts if t.get_gid() == "fixed-caption"]  # the fixed values, as under a map
    assert "$m$ = 1 kg" in caption.get_text().replace("\u00a0", " ") and "$c$" not in caption.get_text()  # c_1 is an axis
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
