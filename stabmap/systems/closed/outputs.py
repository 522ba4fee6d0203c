"""The outputs of the closed-chain system, each declared once (``stabmap.store.variables``)."""

from __future__ import annotations

from ...store.variables import Variable
from .decide import ABSENT, DEGENERATE, NO_COUNT, NO_TURNS, STABLE, UNDECIDED, UNSTABLE
from .proofs import BY_BALLS, BY_EXACT, BY_INTERVAL_NEWTON, BY_STRUCTURE
from .proofs import UNDECIDED as BY_NONE

_CLASSES = ((UNDECIDED, "undecided"), (ABSENT, "absent"), (DEGENERATE, "degenerate"), (STABLE, "stable"), (UNSTABLE, "unstable"))
STABILITY = Variable(
    "stability",
    "int8",
    "stability of the equilibrium in space: a strict minimum of the elastic energy on closed configurations, "
    "against every motion (out of the plane and twist included)",
    comment="stable: index and nullity of the constrained Hessian in space both 0 (the in-plane and the "
    "out-of-plane blocks both positive definite, modulo the rotations and the bodies' common spin); unstable: "
    "index > 0 and nullity 0; degenerate: nullity > 0 (a zero eigenvalue, or a loop folded onto a line), never "
    "called stable; absent: the family has no equilibrium at these lengths; undecided: no class, the proof did not "
    "decide the point (decided_by = undecided). Every other value is proved (decided_by, docs/closed.md). "
    "With the scene's model = planar (attribute closed_model) the chain is confined to its plane and this is "
    "planar_stability",
    flags=_CLASSES,
    fill=-4,
)
PLANAR_STABILITY = Variable(
    "planar_stability",
    "int8",
    "stability of the equilibrium against motions in its plane only (the paper's planar model)",
    comment="as stability, for the in-plane block of the Hessian alone (planar_index, planar_nullity); a twisted "
    "ring: its restriction to bending in the plane. Stable here and unstable in space means the equilibrium "
    "escapes out of its plane or by twisting",
    flags=_CLASSES,
    fill=-4,
)
EXISTS = Variable(
    "exists",
    "int8",
    "whether the family has an equilibrium at these lengths",
    comment="proved, in exact rational arithmetic or by the Krawczyk operator (decided_by); undecided: not proved",
    flags=((-1, "undecided"), (0, "absent"), (1, "exists")),
)
DECIDED_BY = Variable(
    "decided_by",
    "int8",
    "how the stability class of this point was proved",
    comment="ball_arithmetic: existence in exact rational arithmetic, index and nullity from the bordered Hessian "
    "in ball arithmetic (python-flint arb) on the family's closed form; "
    "exact_rational_arithmetic: the family is absent, or folded onto a line, decided exactly; "
    "exact_structure: a ring, closed by an exact cyclotomic test, its Hessian cos(2 pi j/n) times a Laplacian; "
    "interval_newton: no exact closed form (lengths off the pattern by rounding), the equilibrium proved by the "
    "Krawczyk operator and its inertia in ball arithmetic. These four are proofs; docs/closed.md. "
    "undecided: not proved, the point has the class undecided",
    flags=((BY_BALLS, "ball_arithmetic"), (BY_EXACT, "exact_rational_arithmetic"), (BY_STRUCTURE, "exact_structure"),
           (BY_INTERVAL_NEWTON, "interval_newton"), (BY_NONE, "undecided")),
)
INDEX = Variable(
    "index",
    "int16",
    "index of the constrained Hessian in space: negative eigenvalues on closed configurations modulo the rotations "
    "and the common spin",
    units="1",
    comment=f"proved as the class is; {NO_COUNT} where absent or undecided",
)
NULLITY = Variable(
    "nullity",
    "int16",
    "nullity of the constrained Hessian in space: zero eigenvalues, plus the closure rank a folded loop loses",
    units="1",
    comment=f"proved as the class is; {NO_COUNT} where absent or undecided",
)
PLANAR_INDEX = Variable("planar_index", "int16", "index of the in-plane block of the constrained Hessian (modulo the rotation in the plane)",
                        units="1", comment=f"proved; index - planar_index is the out-of-plane block's; {NO_COUNT} where absent or undecided")
PLANAR_NULLITY = Variable("planar_nullity", "int16", "nullity of the in-plane block, plus the closure rank a folded loop loses",
                          units="1", comment=f"proved; {NO_COUNT} where absent or undecided")
ROTATION_INDEX = Variable(
    "rotation_index",
    "int8",
    "rotation index (turning number) of the chain: the sum of its joint angles over 2 pi",
    units="1",
    comment=f"ring: its winding j; figure-eight: 0; hinge: -1. {NO_TURNS} where absent or where a joint is folded "
    "back (a joint angle within 1e-9 rad of +-pi leaves the turning undefined); from the floating-point angles",
)
ENERGY = Variable("energy", "float64", "elastic energy U = (c1^2/h) sum (1 - cos(theta_k - theta_(k-1)))", units="J",
                  comment="floating point; NaN where absent")
RESIDUAL = Variable(
    "residual",
    "float64",
    "largest scaled residual of the equilibrium equations",
    units="1",
    comment="each torque equation (22) divided by 2 + a_k |R|, each loop's closure by its length sum, at the "
    "floating-point angles and forces; a twisted ring also every component of the spatial torque balance, divided "
    "by 2 + a_k |R|; NaN where absent",
)
THETA = Variable("theta", "float64", "angle of the axis of each body, e_k = (-sin theta_k, cos theta_k)", units="rad",
                 comment="floating point; NaN where absent and beyond the chain's n bodies", dims=("body",))
JOINT_ANGLE = Variable("joint_angle", "float64", "angle of each joint, theta_k - theta_(k-1) in (-pi, pi] (joint 1 joins body n to body 1)",
                       units="rad", comment="floating point; NaN where absent and beyond the chain's n bodies", dims=("body",))
FORCE_Y = Variable("force_y", "float64", "y component R_y of the joint force of each closing loop", units="N",
                   comment="floating point; loop 1 holds body 1; the hinge's loop 2 holds bodies 2, 3, 4. NaN where absent", dims=("loop",))
FORCE_Z = Variable("force_z", "float64", "z component R_z of the joint force of each closing loop", units="N",
                   comment="as force_y", dims=("loop",))
FORCE_X = Variable("force_x", "float64", "component R_x of the joint force normal to the plane", units="N",
                   comment="floating point; 0 but for twisted rings, R_x = (c2^2/(h h_1)) sin(2 pi j/n) sin(2 pi m/n); NaN where absent",
                   dims=("loop",))
TWIST_ANGLE = Variable("twist_angle", "float64", "turn phi_k of each body about its own axis, the body's frame Rx(theta_k) Rz(phi_k)",
                       units="rad", comment="floating point; 0 but for twisted rings, phi_k = 2 pi m k/n; NaN where absent", dims=("body",))

VARIABLES = (STABILITY, DECIDED_BY, EXISTS, INDEX, NULLITY, PLANAR_STABILITY, PLANAR_INDEX, PLANAR_NULLITY, ROTATION_INDEX, ENERGY,
             RESIDUAL, THETA, TWIST_ANGLE, JOINT_ANGLE, FORCE_X, FORCE_Y, FORCE_Z)
