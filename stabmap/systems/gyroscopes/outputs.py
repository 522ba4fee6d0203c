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
    "all_eigenvalues_at_once: every root at once, by Gerschgorin discs of the first-order linearisation after an "
    "approximate eigen-decomposition, in rigorous float matrix products (docs/certification.md, section 4b); "
    "exact_rational_arithmetic: none of these could decide and the point was recomputed exactly; "
    "box_proof: not computed on its own: N_c was proved at every point of a box of parameters that holds this "
    "node (docs/certification.md, section 6; docs/cells.md). "
    "These seven are proofs; docs/certification.md. "
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
        (7, "all_eigenvalues_at_once"),
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
BY_ALLATONCE = DECIDED_BY.value("all_eigenvalues_at_once")


def stability_from_pairs(nc: np.ndarray) -> np.ndarray:
    """The stability flag from N_c."""
    stable, unstable, degenerate = (STABILITY.value(m) for m in ("stable", "unstable", "degenerate"))
    return np.where(nc < 0, degenerate, np.where(nc == 0, stable, unstable)).astype(np.int8)


# ------------------------------------------------------------------ growth rates and frequencies (docs/rates.md)
_NOT_COMPUTED = ("NaN where growth_rate_method is not_computed or degenerate: a point inferred (--refine) is not "
                 "evaluated, and its rate is not made up")
GROWTH_RATE = Variable(
    "growth_rate",
    "float32",
    "largest growth rate of a perturbation: the largest |Im lambda| over the characteristic roots",
    units="s-1",
    comment="solutions ~ exp(i lambda t) grow like exp(|Im lambda| t); exactly 0 where every root is proved real "
    "(n_complex_pairs = 0 proved). Elsewhere the approximation of the root, inside the proved enclosure "
    f"[growth_rate_lower, growth_rate_upper]. {_NOT_COMPUTED}",
    fill=float("nan"),
)
GROWTH_RATE_LOWER = Variable(
    "growth_rate_lower", "float32", "proved lower bound of growth_rate", units="s-1",
    comment=f"rounded down to float32; inclusion disks or exact roots (growth_rate_method). {_NOT_COMPUTED}", fill=float("nan"))
GROWTH_RATE_UPPER = Variable(
    "growth_rate_upper", "float32", "proved upper bound of growth_rate", units="s-1",
    comment=f"rounded up to float32; inclusion disks or exact roots (growth_rate_method). {_NOT_COMPUTED}", fill=float("nan"))
EFOLDING_TIME = Variable(
    "efolding_time",
    "float32",
    "e-folding time of the fastest growing perturbation, 1 / growth_rate",
    units="s",
    comment="+inf where growth_rate is 0 (every root real: no perturbation grows); the proved enclosure is "
    f"[1 / growth_rate_upper, 1 / growth_rate_lower]. {_NOT_COMPUTED}",
    fill=float("nan"),
)
GROWTH_RATE_METHOD = Variable(
    "growth_rate_method",
    "int8",
    "how growth_rate and its bounds were obtained",
    comment="all_roots_real: n_complex_pairs = 0 is proved, so the rate is exactly 0; "
    "inclusion_disks: Braess-Hadeler inclusion disks around every root in double-double interval arithmetic; "
    "exact_arb_roots: the exact rational polynomial's roots isolated by FLINT/Arb (where the disks were too wide); "
    "not_computed: the point was inferred (--refine), not computed; a point proved over a box has its rate computed "
    "at the node from its proved label; "
    "degenerate: p is identically zero; "
    "newton_pairs: disjoint Newton disks around the n_complex_pairs roots in the upper half plane, which the proved "
    "label says are all the non-real roots (the real roots contribute exactly 0)",
    flags=((0, "all_roots_real"), (1, "inclusion_disks"), (2, "exact_arb_roots"), (3, "not_computed"), (4, "degenerate"),
           (5, "newton_pairs")),
)
FREQUENCY = Variable(
    "frequency",
    "float64",
    "real part of each characteristic root: the frequency of its mode in the non-spinning frame",
    units="rad s-1",
    comment="every root of p(lambda) with multiplicity, one a mode: along the spin axis each mode is followed from point "
    "to point by continuity (mode_tracking says how surely), elsewhere ascending; a real root is a mode's frequency "
    "(lambda < 0: prograde), a complex pair's two roots share their real part. For one top without liquid the two "
    "roots are the nutation (larger |lambda|) and precession frequencies. NaN beyond the degree of p and where not "
    "computed (inferred or degenerate points). Opt-in: the scene key frequencies = true",
    dims=("mode",),
    fill=float("nan"),
)
FREQUENCY_RADIUS = Variable(
    "frequency_radius",
    "float64",
    "proved radius around frequency",
    units="rad s-1",
    comment="the root lies within this distance of frequency + i Im(lambda) in the complex plane, so its real part "
    "lies in [frequency - frequency_radius, frequency + frequency_radius]; where disks overlap, every root of the "
    "group lies in each member's disk. Opt-in with frequency",
    dims=("mode",),
    fill=float("nan"),
)
ROOT_KIND = Variable(
    "root_kind",
    "int8",
    "what is proved about each characteristic root",
    comment="real: proved real; complex: proved non-real (one of a conjugate pair); not_separated: its inclusion disks "
    "meet the real axis without proving it real; none: padding beyond the degree of p, or not computed. Opt-in with frequency",
    dims=("mode",),
    flags=((-1, "none"), (0, "real"), (1, "complex"), (2, "not_separated")),
)
MODE_TRACKING = Variable(
    "mode_tracking",
    "int8",
    "how each mode's root was matched to the mode's root at the previous point along the spin axis",
    comment="ascending: the first point of a line along the spin axis (or after a point not computed, or an atlas "
    "without spin axis): modes numbered by ascending real part; followed: the order that keeps the real parts' "
    "order and the order of the values extrapolated from the mode's last two points agree on this root, and its "
    "proved enclosure here and at the previous point meets no other mode's (a conjugate excepted); ambiguous: "
    "continued by the better of the two orders, through a crossing or past enclosures that meet, identity not "
    "proved; none: padding or not computed. Opt-in with frequency",
    dims=("mode",),
    flags=((-1, "none"), (0, "ascending"), (1, "followed"), (2, "ambiguous")),
)
GROWTH_VARIABLES = (GROWTH_RATE, GROWTH_RATE_LOWER, GROWTH_RATE_UPPER, EFOLDING_TIME, GROWTH_RATE_METHOD)
FREQUENCY_VARIABLES = (FREQUENCY, FREQUENCY_RADIUS, ROOT_KIND, MODE_TRACKING)
ALL_VARIABLES = VARIABLES + GROWTH_VARIABLES + FREQUENCY_VARIABLES
