"""The outputs of the reactions system, each declared once (``stabmap.store.variables``)."""

from __future__ import annotations

from ...store.variables import Variable
from .solver import DECIDED_BY as _MEANINGS
from .solver import ERROR_RTOL

NODE_DIM, COMPONENT_DIM = "node", "component"
COMPONENTS = ("x", "y", "z")
_WHERE_NONE = "NaN where no reactions balance the load (compatible = incompatible)"

R = Variable(
    "R",
    "float64",
    "reaction force on the body at each node",
    units="N",
    comment="the least sum of |R_i|^2 among all reactions with sum R + F = 0, sum x_i x R_i + M = 0 and no force "
    "along a node's released directions (equal elastic nodes; docs/reactions.md): where decided_by is "
    f"exact_rational, the exact reactions rounded; where float_with_bound, within {ERROR_RTOL:g} R_max of them "
    f"(2-norm over all nodes, proved); {_WHERE_NONE}",
    dims=(NODE_DIM, COMPONENT_DIM),
)
R_NORM = Variable("R_norm", "float64", "magnitude of the reaction at each node", units="N", comment=_WHERE_NONE, dims=(NODE_DIM,))
R_MAX = Variable("R_max", "float64", "largest magnitude of a node's reaction", units="N", comment=_WHERE_NONE)
CRITICAL_NODE = Variable(
    "critical_node",
    "int16",
    "node carrying the largest reaction (0-based)",
    units="1",
    comment="proved (decided_by says how); the lowest-numbered node when several carry exactly R_max "
    "(n_critical says how many); -1 where no reactions balance the load",
    fill=-2,
)
N_CRITICAL = Variable(
    "n_critical",
    "int16",
    "number of nodes carrying the largest reaction",
    units="1",
    comment="nodes whose exact |R_i| equals the exact R_max (exact ties, as on symmetric layouts); 0 where no "
    "reactions balance the load",
)
RANK = Variable(
    "rank",
    "int16",
    "rank of the linear constraint system of the reactions",
    units="1",
    comment="the six balance equations and one row per release: 6 for a general layout without releases, 5 for "
    "collinear nodes; exact (decided_by says how)",
)
FREE_MOTIONS = Variable(
    "free_motions",
    "int16",
    "rigid motions of the body that the nodes do not stop",
    units="1",
    comment="6 minus the rank of the balance equations on the forces the nodes can carry: 0 for a body held "
    "fully, 1 for collinear nodes (rotation about their line); a load with a component along a free motion "
    "is incompatible",
)
COMPATIBLE = Variable(
    "compatible",
    "int8",
    "whether reactions of the nodes can balance the load",
    comment="incompatible: no reactions balance the load exactly (the load has a part the nodes cannot carry); "
    "exact (decided_by says how)",
    flags=((0, "incompatible"), (1, "compatible")),
)
BALANCE_RESIDUAL = Variable(
    "balance_residual",
    "float64",
    "balance of the computed reactions, relative to the load",
    units="1",
    comment="(|sum R + F| + |sum l_i x R_i + M_c| / ell) / s, with l_i the nodes about their centroid and s, M_c, "
    "ell as for compatible; " + _WHERE_NONE,
)
DECIDED_BY = Variable(
    "decided_by",
    "int8",
    "arithmetic that decided the labels at this point",
    comment="float_with_bound: the float reactions and a proved bound on their error: the exact constraint "
    "system has full row rank (rank and compatibility follow), and the largest |R_i| exceeds every other by more "
    "than the bound; exact_rational: rank, compatibility, R and the critical node in exact rational arithmetic "
    "(rank-deficient layouts, ties, near-ties). Both are proofs about the binary64 node positions, F and M that "
    "the solver receives; docs/reactions.md",
    flags=tuple(enumerate(_MEANINGS)),
)
VARIABLES = (R, R_NORM, R_MAX, CRITICAL_NODE, N_CRITICAL, RANK, FREE_MOTIONS, COMPATIBLE, BALANCE_RESIDUAL, DECIDED_BY)
