"""Titles and captions: the atlas title with its headline, the fixed axes, the panels and the notes; the
caption of fixed parameters under every figure; and the filling of long lines that hold mathtext."""

from __future__ import annotations

import math
import re
import textwrap

import xarray as xr

from ... import systems
from ..info import fixed_parameters, scene_notes
from .labels import axis_label, symbol, units_text, value_text
from .layout import FigurePlan


def atlas_title(
    ds: xr.Dataset, plan: FigurePlan, headline: str, chars: int, factors: tuple[int, int] = (1, 1), shape: tuple[int, int] = (1, 1),
    *, filled: bool = False,
) -> str:
    """The atlas title, its ``headline`` (:mod:`stabmap.read.headline`: the grid points and cells drawn; ``filled``:
    already in lines), the fixed axes, the panels, the notes and the rule that reduced a large grid."""
    title = [fill_title(ds.attrs.get("title", "") or "stabmap atlas", chars)]
    # narrower: clear of the legend beside it; the cells' part on a line of its own, after the grid points'
    title.append(headline if filled else ";\n".join(textwrap.fill(part, min(chars, 72 if plan.facet else 60)) for part in headline.split("; ")))
    if plan.fixed:
        fixed = []
        for k, (i, asked) in plan.fixed.items():
            text = value_text(ds, k, float(ds[k][i]))
            if asked is not None and not math.isclose(asked, float(ds[k][i]), rel_tol=1e-9, abs_tol=1e-300):
                text += f" (nearest to {asked:g})"
            fixed.append(text)
        title.append(textwrap.fill("fixed: " + ", ".join(t.replace(" ", "\u00a0") for t in fixed), chars))
    if plan.facet is not None:
        title.append(textwrap.fill("panels: " + " × ".join(axis_label(ds, d, width=500) for d in (plan.facet, plan.row) if d), chars))
    title.extend(textwrap.fill(note, chars) for note in plan.notes)
    if factors != (1, 1):
        title.append(textwrap.fill(reduction_note(ds, plan, factors, shape), chars))
    return "\n".join(title)


def reduction_note(ds: xr.Dataset, plan: FigurePlan, factors: tuple[int, int], shape: tuple[int, int]) -> str:
    """The caption line of a reduced map: how many grid points a block holds and how a block is coloured."""
    fy, fx = factors
    size = f"{fx} × {fy}" if plan.y else f"{fx}"
    grid = f"{shape[1]:,} × {shape[0]:,}" if plan.y else f"{shape[1]:,}"
    stable = systems.of_atlas(ds.attrs).stable_label is not None
    mixed = "black if it holds stable and unstable points, dark grey if several other classes" if stable else "dark grey if it holds several classes"
    return f"{grid} grid points drawn in blocks of {size}: a block shows its class where all its points agree, {mixed}"


def captioned_figure(ds: xr.Dataset, size: tuple[float, float]):
    """A constrained-layout Figure of ``size`` [in] for the plot, taller by the caption of the fixed parameters,
    which sits below everything else: the layout keeps the bottom strip free for it."""
    from matplotlib.figure import Figure

    caption = fixed_caption(ds, int(15.5 * size[0]))
    caption_height = 0.13 * (caption.count("\n") + 1) + 0.1 if caption else 0.0
    size = (size[0], size[1] + caption_height)
    fig = Figure(figsize=size, layout="constrained")
    if caption:
        fig.get_layout_engine().set(rect=(0, caption_height / size[1], 1, 1 - caption_height / size[1]))
        fig.text(0.01, 0.02 / size[1], caption, fontsize=7, va="bottom", ha="left", color="#333333", gid="fixed-caption")
    return fig


def fill_title(text: str, chars: int) -> str:
    """The atlas title in lines of ``chars``, never broken between "eq." and its number."""
    text = re.sub(r"\b(eqs?\.|No\.) (?=\S)", "\\1\u00a0", text)
    return textwrap.fill(text, chars, break_on_hyphens=False, break_long_words=False)


def fixed_caption(ds: xr.Dataset, chars: int) -> str:
    """The atlas's fixed parameters (its scalar coordinates), grouped as ``stabmap info`` groups them (per body for
    gyroscopes) with each group's liquid modes, symbols and units as in the titles, in lines of at most ``chars``
    characters (mathtext markup not counted); ``""`` if there are none.

    Axes fixed by ``sel`` are in the title, not here.
    """

    def item(name: str, value: float, units: str) -> str:
        return f"{symbol(ds, name)} = {value:.6g}" + (f" {units_text(units)}" if units_text(units) else "")

    system = systems.of_atlas(ds.attrs)
    groups = fixed_parameters(ds, system, item)
    caveats = [fill_mathtext(c, chars) for c in system.caveats(ds)]  # e.g. where the model's assumptions fail
    if not groups:
        return "\n".join(caveats)
    notes = scene_notes(ds.attrs)
    parts = []
    for head, items in groups:
        said = [system.figure_text(t, units_text) for t in notes.get(head, [])]  # e.g. a body's liquid, units in mathtext
        parts.append((f"{head}: " if head else "") + ", ".join(items + said))
    return "\n".join([fill_mathtext("fixed: " + "; ".join(parts), chars), *caveats])


def fill_mathtext(text: str, chars: int) -> str:
    """Wrap ``text`` at spaces into lines of at most ``chars`` shown characters: ``$...$`` markup counts as the
    characters it shows, and spaces inside an entry (``m = 1 kg``) do not break."""
    def shown(word: str) -> int:  # '$\\kappa_{2}$' shows as two characters
        return len(re.sub(r"[${}^_]", "", re.sub(r"\\[A-Za-z]+", "x", word)))

    lines: list[str] = []
    line: list[str] = []
    width = 0
    for word in re.split(r"(?<=[,;:]) (?![\d-])", text):  # a list of values (E = 1e-4, 2e-5) stays on one line
        word = word.replace(" ", "\u00a0")
        w = shown(word)
        if line and width + 1 + w > chars:
            lines.append(" ".join(line))
            line, width = [], 0
        line.append(word)
        width += w + (1 if width else 0)
    return "\n".join(lines + [" ".join(line)])
