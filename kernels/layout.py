"""Named layouts of the kernels' arrays: the columns of the parameter arrays, the slots of the state arrays and the
fields of the block workspaces, in one place that the kernels and the labelled layer both import.

The constants are plain module-level ints: numba freezes a global int into the compiled code as a constant, so
``body[k, OMEGA]`` compiles to exactly what ``body[k, 5]`` did.  The workspaces are ``namedtuple``s (numba
compiles heterogeneous ones as it does plain tuples, fields read by name at no cost); each kernel module's
``allocate`` builds its own and the kernels read ``ws.state``, ``ws.C``, ... instead of unpacking by position.
"""

from __future__ import annotations

from collections import namedtuple

# body[..., k, :] of one body (``charpoly_block``); joint[..., k], at[..., k] and g have no columns
M = 0  # mass m [kg], liquid included
A = 1  # equatorial moment of inertia about the body's own centre of mass [kg m^2]
C = 2  # axial moment of inertia [kg m^2]
CM = 3  # c: centre of mass on the axis, from the body's own joint [m]
S = 4  # s: the next joint on the axis (a chain's ``at`` of the body above; the kernels read ``at`` instead) [m]
OMEGA = 5  # spin rate [rad/s]
BODY_COLUMNS = ("m", "A", "C", "c", "s", "omega")  # the names the scenes give those columns, in column order
NBODY = len(BODY_COLUMNS)
STRUCTURE = (M, A, C, CM, S)  # every column but omega: equal columns between neighbours reuse M T and K T

# A ball's midpoint and radius along a leading axis of length 2 (``pencil``'s beta, ``allatonce``'s An, Mp, yb)
MID, RAD = 0, 1

# pencil.allocate().mat: planes of n x n float balls (midpoints, radii), the pencil's matrices at one point
MT_MID, MT_RAD = 0, 1  # M T
KT_MID, KT_RAD = 2, 3  # K T
M_MID, M_RAD = 6, 7  # M (planes 4 and 5 are not used)
K_MID, K_RAD = 8, 9  # K
PENCIL_MAT = 10
# pencil.allocate().vec: rows of n float balls
G_MID, G_RAD = 0, 1  # C_k omega_k, the gyroscopic diagonal
ESUM_MID, ESUM_RAD = 2, 3  # sum over l of E_kl, body k's liquid
PENCIL_VEC = 4

# certify.allocate().state: int64 slots carried from one point of a block to the next
PREV_DECIDED = 0  # 1 if the previous point was decided, so its roots in z may start this one
PREV_DEGREE = 1  # deg p of the previous point less its exact zero roots (a neighbour only if this one's matches)
COLD_LEFT = 2  # points left to start cold: warm starts paused because they did not pay
HISTORY = 3  # 1 if zold holds the roots of the point before the previous one (extrapolate from both)
KEPT = 4  # 1 if the workspace holds M T and K T of the last point given (``reuse`` may take them)
AAO_COLD_RUN = 5  # the all-at-once certificate's cold starts in a row
AAO_PAUSE = 6  # its last pause [points]
LEAD_NU = 7  # negative eigenvalues of M - diag(sum E) (the leading matrix), -1 if unproved
CERTIFY_STATE = 8

# certify.allocate().costs: running means of what each way costs, in n x n complex solves
WARM_COST = 0  # a warm start
WARM_HITS = 1  # a warm start's rate of decided points (1 until tried)
COLD_COST = 2  # a cold start
CERTIFY_COSTS = 3

# allatonce.allocate().state: int64 slots of the all-at-once certificate
AAO_HELD = 0  # 1 if X, Y hold a decomposition to refine
AAO_COLD = 1  # cold starts (eigenvectors computed), counted over the block
AAO_WARM = 2  # points decided warm, counted over the block
AAO_SKIP = 3  # points left to skip in a pause (``certify._allatonce``)
AAO_CONTINUES = 4  # 1 if the X, Y one point back continue this one (extrapolate from both)
AAO_MOVED = 5  # 1 if the blocks changed at this point (a pair split or joined: no extrapolation next)
ALLATONCE_STATE = 6

# Workspaces: each module's ``allocate`` returns one, allocated once per block and reused for every point.
# charpoly: J, M T, K T (n, n, 3) intervals; q, w the liquid factors; P = diag(Q) Phi T (n, n, lmax + 3, 3);
# D the Laplace expansion's minors; T the path matrix; sub (n, 3) scratch; zero, zero1 a point's radii (0)
CharpolyWork = namedtuple("CharpolyWork", "J M K q w P D T sub zero zero1")
# pencil: T the path matrix; jmk (3, n, n, 3) J, M T, K T in double-double intervals; sub scratch; mat (10, n, n)
# and vec (4, n) balls (``pencil.allocate``); beta (2, n, lmax) mid, rad; cm, cr Phi(z) mid, rad
PencilWork = namedtuple("PencilWork", "T jmk sub mat vec beta krein cm cr")
# count: the Sturm sequence W, the polynomial X, its float coefficients a and roots z, disk radii R, group, flags
CountWork = namedtuple("CountWork", "W X a z R group flags")
# allatonce: ``allatonce.allocate`` says what each holds; state has the AAO_* slots above
AllatonceWork = namedtuple("AllatonceWork", "mats An Mp yk yb lam size vec disc rad group state")
# certify: pws a PencilWork; C, Mo the linearisation; wr, wi, vdummy, z its eigenvalues; F, dF, Sm, Sr, dm, dr
# matrices at one z or x; feat the inertia's features; R, group, centre, done the disks'; state (CERTIFY_STATE
# slots) and costs (CERTIFY_COSTS) carried between points; zold, bold the previous point's roots and beta;
# aw an AllatonceWork
CertifyWork = namedtuple("CertifyWork", "pws C Mo wr wi vdummy z F dF Sm Sr feat R group state dm dr centre done zold bold costs aw")
