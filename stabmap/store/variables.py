"""The output registry's one type: a Dataset variable declared once, with its dtype and CF attributes.

Each system declares its outputs as ``Variable`` objects (``System.variables``);
the writer, ``info``, ``query`` and ``plot`` read names, flag values and flag
meanings from those declarations and from nowhere else.  A categorical variable
is a CF flag variable: ``flag_values`` with ``flag_meanings``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# The flag meaning of a point that an adaptive atlas (stabmap atlas --refine) filled from its grid cell's
# agreeing corners instead of computing it; a system that supports refinement has it in its provenance flags.
INFERRED = "inferred_from_cell_corners"


@dataclass(frozen=True)
class Variable:
    """One output variable of a system.

    ``flags`` makes it a CF flag variable: (value, meaning) pairs, meanings one word each.
    ``dims`` are its dimensions beyond the grid axes (their sizes come from ``System.dims``).
    ``fill`` is the value that stands for "no value" where a variable is padded (e.g. a count below the first
    grid value); None: the variable is never padded.
    """

    name: str
    dtype: str
    long_name: str
    units: str | None = None
    comment: str = ""
    flags: tuple[tuple[int, str], ...] = ()
    dims: tuple[str, ...] = ()
    fill: int | float | None = None

    @property
    def meanings(self) -> tuple[str, ...]:
        return tuple(m for _, m in self.flags)

    def value(self, meaning: str) -> int:
        """The flag value of ``meaning``."""
        for v, m in self.flags:
            if m == meaning:
                return v
        raise KeyError(f"{self.name} has no flag meaning {meaning!r}; its meanings are {', '.join(self.meanings)}")

    def meaning(self, value: int) -> str:
        """The flag meaning of ``value``."""
        for v, m in self.flags:
            if v == value:
                return m
        raise KeyError(f"{self.name} has no flag value {value!r}")

    def attrs(self) -> dict:
        """CF attributes (netCDF-safe: strings, numbers and arrays of them)."""
        out = {"long_name": self.long_name}
        if self.units is not None:
            out["units"] = self.units
        if self.flags:
            out["flag_values"] = np.array([v for v, _ in self.flags], dtype=self.dtype)
            out["flag_meanings"] = " ".join(self.meanings)
        if self.comment:
            out["comment"] = self.comment
        return out


# Every atlas's one variable beyond its system's own: what is proved about the cell around each node
# (stabmap.run.cells; docs/cells.md).  Declared here, once, for every system.
CELL = Variable(
    "cell",
    "int8",
    "what is proved about the grid cell around this node",
    comment="A node's cell reaches halfway to its neighbours along every grid axis (the scan's first and last values "
    "close the outermost cells; the bounds variables give its edges). "
    "whole_cell: the node's label is proved at every point of its cell; "
    "contains_change: the cell is proved to hold two labels, so a boundary lies in it; "
    "node_only: the label is proved at the node only, the rest of the cell is not decided; "
    f"not_proved: not even the node is proved (the label was {INFERRED}, an opt-in --refine atlas)",
    flags=((0, "node_only"), (1, "whole_cell"), (2, "contains_change"), (3, "not_proved")),
)
