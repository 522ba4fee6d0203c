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
