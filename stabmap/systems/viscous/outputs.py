"""The outputs of the viscous-liquid system, each declared once (``stabmap.store.variables``; docs/viscous.md)."""

from __future__ import annotations

from ...store.variables import INFERRED, Variable

ASYMPTOTICALLY_STABLE, UNSTABLE, DEGENERATE, UNDECIDED = 0, 1, -1, -3
_FREE = ("a free system's lambda = 0 roots (the tilts of the whole, or of parts joined by ideal joints, as one rigid "
         "body) are neutral: they are exact roots for every viscosity and the motion settles into a uniform rotation about "
         "a slightly tilted axis, so asymptotically_stable means 'asymptotically stable up to those tilts' there")

ASYMPTOTIC_STABILITY = Variable(
    "asymptotic_stability",
    "int8",
    "asymptotic stability of the uniform rotation with a highly viscous liquid, to first order in 1/Re",
    comment="asymptotically_stable: every characteristic root of the chain with its liquid frozen is real and simple, "
    "and the first-order viscous growth rate of each is proved negative; unstable: the frozen chain has a complex root "
    "pair (proved), or one first-order growth rate is proved positive; undecided: not proved either way (a multiple "
    "root, an enclosure that holds 0, or a lambda = 0 root beyond the structural ones; decided_by says which); "
    "degenerate: the characteristic polynomial vanishes identically. First order in Chernousko's expansion: valid "
    f"where the Reynolds number (variable reynolds) is small; {_FREE}",
    flags=((UNDECIDED, "undecided"), (DEGENERATE, "degenerate"), (ASYMPTOTICALLY_STABLE, "asymptotically_stable"), (UNSTABLE, "unstable")),
    fill=-4,
)
DECIDED_BY = Variable(
    "decided_by",
    "int8",
    "what decided asymptotic_stability at this point",
    comment="frozen_chain_unstable: the chain with its liquid frozen has n_complex_pairs > 0, proved by the certified "
    "kernels (docs/certification.md): a root grows at order 1 and a small dissipation cannot stop it; "
    "first_order_balls: every simple real root's first-order growth rate enclosed in ball arithmetic from the "
    "kernels' root enclosures; first_order_arb: the same from the exact rational polynomial, its roots isolated by "
    "FLINT/Arb; split_multiple_root: unstable, because a multiple real root of the frozen chain that the liquid feels "
    "splits as eps^(1/m) and one branch grows (Puiseux; its growth_rate is that branch's leading term); "
    "multiple_root, zero_rate, zero_root: undecided, because a multiple root is not felt by the liquid at first order, a "
    "growth rate's exact enclosure holds 0, or lambda = 0 is a root beyond the structural ones; degenerate: p is identically "
    f"zero; {INFERRED}: not computed (stabmap atlas --refine), the value on which its cell's corners agree",
    # INFERRED takes the gyroscopes' value, so that one number means "inferred" in both systems' atlases
    flags=((0, "frozen_chain_unstable"), (1, "first_order_balls"), (2, "first_order_arb"), (3, INFERRED),
           (4, "multiple_root"), (5, "zero_rate"), (6, "zero_root"), (7, "degenerate"), (8, "split_multiple_root")),
)
GROWTH_RATE = Variable(
    "growth_rate",
    "float32",
    "largest growth rate of a perturbation, negative when every mode decays",
    units="s-1",
    comment="solutions ~ exp(i lambda t); the largest -Im lambda over the roots, to first order in 1/nu where the "
    "frozen chain's roots are real (lambda = 0 roots of a free system excluded: neutral), and the frozen chain's "
    "largest |Im lambda| where it is unstable (the O(1/nu) correction of a complex root is not added). Inside "
    "[growth_rate_lower, growth_rate_upper]. NaN where not computed (inferred, degenerate, a multiple root)",
    fill=float("nan"),
)
GROWTH_RATE_LOWER = Variable("growth_rate_lower", "float32", "proved lower bound of growth_rate", units="s-1",
                             comment="rounded outward to float32", fill=float("nan"))
GROWTH_RATE_UPPER = Variable("growth_rate_upper", "float32", "proved upper bound of growth_rate", units="s-1",
                             comment="rounded outward to float32", fill=float("nan"))
TIME_CONSTANT = Variable(
    "time_constant",
    "float32",
    "time constant of the mode of growth_rate: 1 / |growth_rate|",
    units="s",
    comment="the nutation time constant where that mode decays (amplitude falls by e in this time), its e-folding "
    "time where it grows; inf where growth_rate is 0",
    fill=float("nan"),
)
FREQUENCY = Variable(
    "frequency",
    "float32",
    "frequency of the mode of growth_rate in the non-spinning frame: Re lambda",
    units="rad s-1",
    comment="lambda < 0: prograde (as docs/model.md); the approximation of the frozen chain's root. NaN where the frozen "
    "chain is unstable (its growing root is complex) and where growth_rate is NaN",
    fill=float("nan"),
)
REYNOLDS = Variable(
    "reynolds",
    "float32",
    "largest Reynolds number |omega_k| a_k^2 / nu_k over the viscous cavities",
    units="1",
    comment="a_k the cavity's radius (a tensor table's stated radius); the first-order model assumes it small: "
    "stabmap info and figure captions give the share of the map where it is 1 or more",
    fill=float("nan"),
)
VARIABLES = (ASYMPTOTIC_STABILITY, DECIDED_BY, REYNOLDS)
GROWTH_VARIABLES = (GROWTH_RATE, GROWTH_RATE_LOWER, GROWTH_RATE_UPPER, TIME_CONSTANT, FREQUENCY)
ALL_VARIABLES = VARIABLES + GROWTH_VARIABLES
BY = {m: DECIDED_BY.value(m) for m in DECIDED_BY.meanings}
