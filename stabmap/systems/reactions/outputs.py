"""The outputs of the reactions system, each declared once (``stabmap.store.variables``)."""

from __future__ import annotations

from ...store.variables import Variable
from .solver import BALANCE_RTOL, RANK_RTOL, TIE_RTOL

NODE_DIM, COMPONENT_DIM = "node", "component"
COMPONENTS = ("x", "y", "z")
_WHERE_NONE = "NaN where no reactions balance the load (compatible = incompatible)"

R = Variable(
    "R",
    "float64",
    "reaction force on the body at each node",
    units="N",
    comment="the least sum of |R_i|^2 among all reactions with sum R + F = 0, sum x_i x R_i + M = 0 and no force "
    f"along a node's released directions (equal elastic nodes; docs/reactions.md); {_WHERE_NONE}",
    dims=(NODE_DIM, COMPONENT_DIM),
)
R_NORM = Variable("R_norm", "float64", "magnitude of the reaction at each node", units="N", comment=_WHERE_NONE, dims=(NODE_DIM,))
R_MAX = Variable("R_max", "float64", "largest magnitude of a node's reaction", units="N", comment=_WHERE_NONE)
CRITICAL_NODE = Variable(
    "critical_node",
    "int16",
    "node carrying the largest reaction (0-based)",
    units="1",
    comment=f"the lowest-numbered node whose |R_i| is within {TIE_RTOL:g} (relative) of R_max, when several carry it "
    "(n_critical says how many); -1 where no reactions balance the load",
    fill=-2,
)
N_CRITICAL = Variable(
    "n_critical",
    "int16",
    "number of nodes carrying the largest reaction",
    units="1",
    comment=f"nodes whose |R_i| is within {TIE_RTOL:g} (relative) of R_max; 0 where no reactions balance the load",
)
RANK = Variable(
    "rank",
    "int16",
    "rank of the linear constraint system of the reactions",
    units="1",
    comment="the six balance equations and one row per release: 6 for a general layout without releases, 5 for "
    f"collinear nodes; singular values of the scaled system below {RANK_RTOL:g} of the largest count as zero",
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
    comment=f"incompatible: the part of the load the nodes cannot carry exceeds {BALANCE_RTOL:g} of the load scale "
    "s = sqrt(|F|^2 + |M_c|^2 / ell^2), M_c the moment about the nodes' centroid, ell their RMS distance from it",
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
VARIABLES = (R, R_NORM, R_MAX, CRITICAL_NODE, N_CRITICAL, RANK, FREE_MOTIONS, COMPATIBLE, BALANCE_RESIDUAL)
