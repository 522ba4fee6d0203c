"""The figure never hides a grid node's proved class: whatever its cell's flag (whole cell, a change inside,
node only, not proved), the pixels at the node show the colour of its label, and the marks over it (hatch, dots)
are explained in the legend, naming the axes a change may lie along in a slice of a larger atlas."""

from __future__ import annotations

import numpy as np
import pytest
from flagged import CELLS, LABELS, flagged_atlas
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba

import stabmap
from stabmap.read.plot import atlas_figure
from stabmap.read.plot.palette import system_colour


def pixels(fig) -> np.ndarray:
    """The figure drawn by Agg, as (rows from the top, columns, RGB)."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3]


def dominant(image: np.ndarray, ax, x: float, y: float, half: int = 6) -> tuple[int, ...]:
    """The most frequent colour in a square of 2 half + 1 pixels around the data point (x, y) of ``ax``: the fill
    under a hatch or dots, which cover only some of its pixels. A node on the scan's end (the map's border) is
    sampled just inside, in its own cell (half a cell wide, some fifty pixels)."""
    (left, bottom), (right, top) = ax.transAxes.transform([(0, 0), (1, 1)])
    px, py = ax.transData.transform((x, y))
    px, py = np.clip(px, left + half + 3, right - half - 3), np.clip(py, bottom + half + 3, top - half - 3)
    row, col = int(round(image.shape[0] - py)), int(round(px))
    patch = image[row - half : row + half + 1, col - half : col + half + 1].reshape(-1, 3)
    colours, counts = np.unique(patch, axis=0, return_counts=True)
    return tuple(int(c) for c in colours[np.argmax(counts)])


def rgb(colour: str) -> tuple[int, ...]:
    return tuple(int(round(255 * c)) for c in to_rgba(colour)[:3])


def node_colours(fig, ds, ax) -> list[tuple[str, tuple, tuple]]:
    """(flag, colour seen, colour of the label) at every grid node of the first map."""
    system = stabmap.systems.of_atlas(ds.attrs)
    image = pixels(fig)
    meanings = ds.cell.attrs["flag_meanings"].split()
    out = []
    for j, k1 in enumerate(ds.K_1.values):
        for i, w in enumerate(ds.omega.values):
            out.append((meanings[CELLS[j, i]], dominant(image, ax, w, k1), rgb(system_colour(int(LABELS[j, i]), system))))
    return out


def test_every_node_shows_the_colour_of_its_label_whatever_its_cell():
    """Each node is about a hundred pixels wide: the colour around its centre is its label's class colour, in cells
    proved whole, proved to hold a change, proved at the node only and inferred alike."""
    ds = flagged_atlas()
    fig = atlas_figure(ds, x="omega", y="K_1")
    seen = node_colours(fig, ds, fig.axes[0])
    assert {flag for flag, _, _ in seen} == {"whole_cell", "contains_change", "node_only", "not_proved"}
    wrong = [(flag, got, want) for flag, got, want in seen if np.abs(np.subtract(got, want)).max() > 3]
    assert not wrong, f"nodes not in their class colour (flag, seen, label's colour): {wrong}"


def test_cells_holding_a_change_are_hatched_not_filled():
    """The change is a hatch over the class colour (a patch with no face), never a filled collection."""
    fig = atlas_figure(flagged_atlas(), x="omega", y="K_1")
    ax = fig.axes[0]
    (hatch,) = [a for a in ax.get_children() if a.get_gid() == "change-cells"]
    assert hatch.get_hatch() and hatch.get_facecolor()[3] == 0
    assert not [a for a in ax.get_children() if a.get_gid() == "stability-change-cells"]


def legend_texts(fig) -> list[str]:
    legend = (fig.legends or fig.subfigs[1].legends)[0]
    return [t.get_text().replace("\n", " ") for t in legend.get_texts()]


@pytest.mark.parametrize("m_2, discrete, axis", [(None, False, None), ([1.0, 2.0], False, "$m_{2}$"), ([1.0, 2.0], True, None)])
def test_the_legend_says_what_the_hatch_proves_and_along_which_axes(m_2, discrete, axis):
    """In plain words: a change is proved inside the cell, the colour is the grid point's label; in a facet of an
    atlas whose cells span a further axis the change may lie along that axis alone (not for a discrete axis)."""
    fig = atlas_figure(flagged_atlas(m_2, discrete), x="omega", y="K_1")
    (text,) = [t for t in legend_texts(fig) if t.startswith("hatched")]
    assert "a change of label is proved inside the cell" in text and "colour: the label at its grid point" in text
    if axis is None:
        assert "may lie along" not in text
    else:
        assert f"may lie along {axis} alone" in text


def test_a_facet_shows_the_class_colour_of_every_node():
    """Small multiples of a 3-D atlas: in each panel the nodes keep their class colours under the marks."""
    ds = flagged_atlas([1.0, 2.0])
    fig = atlas_figure(ds, x="omega", y="K_1", facet="m_2")
    for ax in fig.subfigs[0].axes:
        seen = node_colours(fig, ds, ax)
        assert all(np.abs(np.subtract(got, want)).max() <= 3 for _, got, want in seen), seen


def test_the_axes_a_change_may_lie_along_are_those_the_cells_span():
    """What a cell spans comes from the bounds variables: an axis off the map whose cells have width, not one of
    zero width or without bounds among axes with them (discrete, listed values); no bounds at all: the cells reach
    halfway to the neighbours, as drawn."""
    from stabmap.read.plot.marks import hidden_cell_axes

    def hidden(ds):
        return hidden_cell_axes(ds, "n_complex_pairs", ("omega", "K_1"))

    three = flagged_atlas([1.0, 2.0])
    assert hidden(flagged_atlas()) == []
    assert hidden(three) == ["m_2"]
    assert hidden(flagged_atlas([1.0, 2.0], discrete=True)) == []
    assert hidden(three.drop_vars("m_2_bounds")) == []
    assert hidden(three.drop_vars(["m_2_bounds", "K_1_bounds", "omega_bounds"])) == ["m_2"]
    assert hidden(flagged_atlas([1.0])) == []  # one value: nothing to span
