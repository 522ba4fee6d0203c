"""The outputs of the closed-chain system, each declared once (``stabmap.store.variables``)."""

from __future__ import annotations

from ...store.variables import Variable
from .decide import ABSENT, DEGENERATE, NO_COUNT, NO_TURNS, STABLE, UNSTABLE

STABILITY = Variable(
    "stability",
    "int8",
    "stability of the planar equilibrium: a strict minimum of the elastic energy on closed configurations",
    comment="stable: index and nullity of the constrained Hessian both 0; unstable: index > 0 and nullity 0; "
    "degenerate: nullity > 0 (a zero eigenvalue, or a loop folded onto a line), never called stable; "
    "absent: the family has no equilibrium at these lengths. Out-of-plane stability is not decided",
    flags=((ABSENT, "absent"), (DEGENERATE, "degenerate"), (STABLE, "stable"), (UNSTABLE, "unstable")),
    fill=-3,
)
EXISTS = Variable(
    "exists",
    "int8",
    "whether the family has an equilibrium at these lengths",
    flags=((0, "absent"), (1, "exists")),
)
INDEX = Variable(
    "index",
    "int16",
    "index of the constrained Hessian: negative eigenvalues on closed configurations modulo rotation",
    units="1",
    comment=f"{NO_COUNT} where absent",
)
NULLITY = Variable(
    "nullity",
    "int16",
    "nullity of the constrained Hessian: zero eigenvalues, plus the closure rank a folded loop loses",
    units="1",
    comment=f"{NO_COUNT} where absent",
)
ROTATION_INDEX = Variable(
    "rotation_index",
    "int8",
    "rotation index (turning number) of the chain: the sum of its joint angles over 2 pi",
    units="1",
    comment=f"ring: its winding j; figure-eight: 0; hinge: -1. {NO_TURNS} where absent or where a joint is folded "
    "back (a joint angle of +-pi leaves the turning undefined)",
)
ENERGY = Variable("energy", "float64", "elastic energy U = (c1^2/h) sum (1 - cos(theta_k - theta_(k-1)))", units="J",
                  comment="NaN where absent")
RESIDUAL = Variable(
    "residual",
    "float64",
    "largest scaled residual of the equilibrium equations",
    units="1",
    comment="each torque equation (22) divided by 2 + a_k |R|, each loop's closure by its length sum; NaN where absent",
)
THETA = Variable("theta", "float64", "angle of the axis of each body, e_k = (-sin theta_k, cos theta_k)", units="rad",
                 comment="NaN where absent and beyond the chain's n bodies", dims=("body",))
JOINT_ANGLE = Variable("joint_angle", "float64", "angle of each joint, theta_k - theta_(k-1) in (-pi, pi] (joint 1 joins body n to body 1)",
                       units="rad", comment="NaN where absent and beyond the chain's n bodies", dims=("body",))
FORCE_Y = Variable("force_y", "float64", "y component R_y of the joint force of each closing loop", units="N",
                   comment="loop 1 holds body 1; the hinge's loop 2 holds bodies 2, 3, 4. NaN where absent", dims=("loop",))
FORCE_Z = Variable("force_z", "float64", "z component R_z of the joint force of each closing loop", units="N",
                   comment="as force_y", dims=("loop",))

VARIABLES = (STABILITY, EXISTS, INDEX, NULLITY, ROTATION_INDEX, ENERGY, RESIDUAL, THETA, JOINT_ANGLE, FORCE_Y, FORCE_Z)
