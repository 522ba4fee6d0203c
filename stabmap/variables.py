"""Every Dataset variable stabmap writes, named once with its dtype and CF attributes."""

from __future__ import annotations

import numpy as np

N_COMPLEX_PAIRS = "n_complex_pairs"
STABILITY = "stability"
DECIDED_BY = "decided_by"

UNSTABLE, STABLE, DEGENERATE = 0, 1, 2

ATTRS = {
    N_COMPLEX_PAIRS: {
        "long_name": "number of complex-conjugate root pairs of the characteristic polynomial",
        "units": "1",
        "comment": "N_c = (deg p - real roots counted with multiplicity) / 2; 0 means all roots real "
        "(stable in Kononov's necessary sense); -1 where p is identically zero",
    },
    STABILITY: {
        "long_name": "stability of the uniform rotation (necessary condition: all characteristic roots real)",
        "flag_values": np.array([UNSTABLE, STABLE, DEGENERATE], dtype=np.int8),
        "flag_meanings": "unstable stable degenerate",
        "comment": "degenerate: the characteristic polynomial vanishes identically",
    },
    DECIDED_BY: {
        "long_name": "arithmetic that decided n_complex_pairs at this point",
        "flag_values": np.array([0, 1, 2, 3], dtype=np.int8),
        "flag_meanings": "interval_sturm_sequence exact_rational_arithmetic interval_root_inclusion "
        "inferred_from_cell_corners",
        "comment": "interval_sturm_sequence: proved by the double-double interval Sturm sequence; "
        "interval_root_inclusion: proved by disjoint Gerschgorin inclusion disks around the roots; "
        "exact_rational_arithmetic: neither could decide and the point was recomputed exactly. "
        "These three are proofs; docs/certification.md. "
        "inferred_from_cell_corners: not computed and not proved; an adaptive atlas (stabmap atlas --refine) "
        "gave the point the value on which all corners of its grid cell agree; docs/refine.md",
    },
}

DTYPES = {N_COMPLEX_PAIRS: np.int16, STABILITY: np.int8, DECIDED_BY: np.int8}


def stability_from_pairs(nc: np.ndarray) -> np.ndarray:
    """The stability flag from N_c."""
    return np.where(nc < 0, DEGENERATE, np.where(nc == 0, STABLE, UNSTABLE)).astype(np.int8)


def flag_meaning(name: str, value: int) -> str:
    """The meaning of one value of a flag variable."""
    meanings = ATTRS[name]["flag_meanings"].split()
    values = list(ATTRS[name]["flag_values"])
    return meanings[values.index(value)]
