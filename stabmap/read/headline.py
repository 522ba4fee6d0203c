"""The one sentence that sums up an atlas, in the order people read a map: first its grid points (the stable share,
and whether every label there is proved), then its cells (the share of the region over which the label is proved,
and the share proved to hold a change; docs/cells.md).

Written here once for ``stabmap info``, the line ``stabmap atlas`` prints, figure titles, interactive pages and
``ds.stabmap.summary()["headline"]``, so that no two of them can disagree with each other or with the map.
"""

from __future__ import annotations

from dataclasses import dataclass


def region_word(axes: int) -> str:
    """What the cells of ``axes`` scanned axes tile: a range (one axis), an area (two) or a volume (more)."""
    return "range" if axes <= 1 else "area" if axes == 2 else "volume"


@dataclass(frozen=True)
class Headline:
    """What the headline says. ``stable``: grid points of the stable class (None: a system without stability);
    ``inferred``: labels inferred from cell corners (``cell = not_proved``); ``undecided``: points of the system's
    undecided class; ``whole`` and ``change``: the shares of the region whose cells are ``whole_cell`` and
    ``contains_change`` (cells weighted by their size; ``whole`` None: the atlas has no ``cell`` variable);
    ``axes``: how many axes the region spans; ``shown``: a figure of part of the atlas (a slice, panels)."""

    points: int
    stable: int | None
    inferred: int = 0
    undecided: int = 0
    whole: float | None = None
    change: float = 0.0
    axes: int = 2
    shown: bool = False

    def points_text(self, stable_word: str = "stable", proved: str = "proved") -> str:
        """'63.5 % of 38,400 grid points stable (every point proved)'."""
        grid = f"the {self.points:,} grid points shown" if self.shown else f"{self.points:,} grid points"
        head = grid  # a system without stability: the points and what is proved of them
        if self.stable is not None:
            head = f"{100 * self.stable / self.points if self.points else 0.0:.1f} % of {grid} {stable_word}"
        if not (self.inferred or self.undecided):
            return f"{head} (every point {proved})"
        counts = [(self.inferred, "inferred"), (self.undecided, "undecided")]
        said = [f"{n:,} {word}" for n, word in counts if n]
        first = counts[0][0] or counts[1][0]
        said[0] = said[0].replace(" ", f" point{'' if first == 1 else 's'} ", 1)  # '12 points inferred and 3 undecided'
        return f"{head} ({' and '.join(said)}, not {proved})"

    def cells_text(self, proved: str = "proved") -> str:
        """'label proved over 34.6 % of the scanned area, a change proved in 1.6 %', or that cells add nothing."""
        if self.whole is None:
            return ""
        if self.whole == 0 and self.change == 0:  # node-by-node atlases, closed chains, reactions: no 0.0 % to read
            return f"cells: nothing {proved} between grid points"
        where = f"the {region_word(self.axes)} shown" if self.shown else f"the scanned {region_word(self.axes)}"
        text = f"label {proved} over {100 * self.whole:.1f} % of {where}"
        return text + (f", a change {proved} in {100 * self.change:.1f} %" if self.change > 0 else "")

    def text(self, system) -> str:
        """The headline in the words of ``system`` (its ``stable_word``; "decided" for a system whose labels are
        not proofs)."""
        proved = "proved" if system.proves_labels else "decided"
        parts = [self.points_text(system.stable_word, proved), self.cells_text(proved)]
        return "; ".join(p for p in parts if p)
