"""``stabmap paper``: the source papers' results recomputed by the installed engine and checked.

One module per system (``stabmap/paper/<system>.py``), each with a ``run`` that computes, compares
with the paper's printed determinants or closed forms, and draws its figures:

- ``gyroscopes``: the cases n = 1, 2, 3 (seed 003; docs/paper-cases.md), against the printed determinants
  (22), (28)-(32) in exact arithmetic and the closed forms (23), (24), (33), (34) and the split;
- ``closed``: the hinge and six-body figure-eight families' boundaries along h2/h1, against docs/closed.md
  (docs/closed.md);
- ``reactions``: the square plate's atlas against G/4 and the paper's closed form (docs/reactions.md);
- ``viscous``: the gyroscopes' cases n = 1, 2, 3 with a viscous liquid, against the Kelvin-Tait-Chetaev criterion
  in exact arithmetic (docs/viscous.md).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import StabmapError

SYSTEMS = ("gyroscopes", "closed", "reactions", "viscous")


def check(systems=None, *, out: str | Path | None = None, quick: bool = False, cases=None, rows: int | None = None) -> dict:
    """Run the papers' checks of ``systems`` (default all); figures into ``out`` (None: none).

    ``quick``, ``cases`` and ``rows`` apply to the gyroscopes (coarse grids and 3 checked rows; some cases; rows
    per case). Returns ``{"problems": [...], "text": str}``; ``problems`` is empty when everything agrees.
    """
    systems = list(systems or (["gyroscopes"] if cases else SYSTEMS))
    unknown = [s for s in systems if s not in SYSTEMS]
    if unknown:
        raise StabmapError(f"no paper check for system {unknown[0]!r}; choose from: {', '.join(SYSTEMS)}")
    if cases and "gyroscopes" not in systems:
        raise StabmapError("--case names a gyroscope paper case; add 'gyroscopes' to the systems, or drop --case")
    if rows is not None and rows < 1:
        raise StabmapError(f"--rows must be >= 1, got {rows}")
    out = None if out is None else Path(out)
    texts, problems = [], []
    for name in systems:
        where = None if out is None else out / name
        if name == "gyroscopes":
            from . import gyroscopes as paper_cases

            known = [c.name for c in paper_cases.CASES]
            bad = [c for c in cases or () if c not in known]
            if bad:
                raise StabmapError(f"unknown paper case {bad[0]!r}; choose one of: {', '.join(known)}")
            done = paper_cases.run(cases, quick=quick, rows=rows, out=where)
        elif name == "closed":
            from . import closed as paper_cases

            done = paper_cases.run(out=where)
        elif name == "viscous":
            from . import viscous as paper_cases

            done = paper_cases.run(out=where, quick=quick)
        else:
            from . import reactions as paper_cases

            done = paper_cases.run(out=where)
        texts.append(f"## {name}\n{done['text']}" + ("" if where is None else f"\nfigures in {where}/"))
        problems += done["problems"]
    texts.append("all agree with the papers" if not problems else f"{len(problems)} disagreements with the papers")
    return {"problems": problems, "text": "\n\n".join(texts)}
