"""The outputs of the gyroscope system, each declared once (``stabmap.store.variables``)."""

from __future__ import annotations

import numpy as np

from ...store.variables import INFERRED, Variable

N_COMPLEX_PAIRS = Variable(
    "n_complex_pairs",
    "int16",
    "number of complex-conjugate root pairs of the characteristic polynomial",
    units="1",
    comment="N_c = (deg p - real roots counted with multiplicity) / 2; 0 means all roots real "
    "(stable in Kononov's necessary sense); -1 where p is identically zero",
    fill=-2,
)
STABILITY = Variable(
    "stability",
    "int8",
    "stability of the uniform rotation (necessary condition: all characteristic roots real)",
    comment="degenerate: the characteristic polynomial vanishes identically",
    flags=((0, "unstable"), (1, "stable"), (2, "degenerate")),
)
DECIDED_BY = Variable(
    "decided_by",
    "int8",
    "arithmetic that decided n_complex_pairs at this point",
    comment="interval_sturm_sequence: proved by the double-double interval Sturm sequence; "
    "interval_root_inclusion: proved by disjoint Gerschgorin inclusion disks around the roots; "
    "interval_inertia: every root real, proved by the inertia of the characteristic matrix "
    "between the roots (no coefficients formed); "
    "inertia_and_disks: the real roots counted by that inertia, the non-real ones by inclusion "
    "disks from the determinant of the characteristic matrix in interval arithmetic; "
    "exact_rational_arithmetic: none of these could decide and the point was recomputed exactly; "
    "box_proof: not computed on its own: N_c was proved at every point of a box of parameters that holds this "
    "node (docs/certification.md, section 6; docs/cells.md). "
    "These six are proofs; docs/certification.md. "
    f"{INFERRED}: not computed and not proved; an adaptive atlas (stabmap atlas --refine) "
    "gave the point the value on which all corners of its grid cell agree; docs/refine.md",
    flags=(
        (0, "interval_sturm_sequence"),
        (1, "exact_rational_arithmetic"),
        (2, "interval_root_inclusion"),
        (3, INFERRED),
        (4, "interval_inertia"),
        (5, "inertia_and_disks"),
        (6, "box_proof"),
    ),
)
VARIABLES = (N_COMPLEX_PAIRS, STABILITY, DECIDED_BY)

BY_STURM = DECIDED_BY.value("interval_sturm_sequence")
BY_EXACT = DECIDED_BY.value("exact_rational_arithmetic")
BY_INCLUSION = DECIDED_BY.value("interval_root_inclusion")
BY_INFERRED = DECIDED_BY.value(INFERRED)
BY_INERTIA = DECIDED_BY.value("interval_inertia")
BY_DISKS = DECIDED_BY.value("inertia_and_disks")
BY_BOX = DECIDED_BY.value("box_proof")


def stability_from_pairs(nc: np.ndarray) -> np.ndarray:
    """The stability flag from N_c."""
    stable, unstable, degenerate = (STABILITY.value(m) for m in ("stable", "unstable", "degenerate"))
    return np.where(nc < 0, degenerate, np.where(nc == 0, stable, unstable)).astype(np.int8)
