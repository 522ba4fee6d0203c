"""The closed chain in space (docs/closed.md, section 1b): the joint energy for c1 != c2, and the Hessians whose
inertia decides stability against every motion, out of the plane and twist included.

Body k has a frame Q_k (columns e1, e2, e3; e3 its axis).  Joint k joins bodies k-1 and k; p_k is the unit
quaternion of their relative rotation Q_(k-1)^T Q_k, of angle alpha and axis u.  The joint energy is

    U_k = (2/h) [c1^2 (p1^2 + p2^2) + c2^2 p3^2] = (1/h) (1 - cos alpha) [c1^2 (1 - u3^2) + c2^2 u3^2],

which is the paper's law (11) integrated where (11) has an energy (c1 = c2: U_k = (c^2/h)(1 - cos alpha), whose
torque is (c^2/h) sin alpha u = the paper's L_k), gives exactly the paper's twisting moment (19) for every c1, c2,
and in the plane without twist is the planar U.  A perturbation turns body k by the small rotation vector v_k
(components on body k's own axes): Q_k -> Q_k exp([v_k]x).  Everything here is written in the arithmetic of its
inputs (doubles, python-flint balls or exact rationals), in units of c1^2/h, with gamma = c2^2/c1^2.

- ``out_of_plane``: at a planar twist-free equilibrium, the block of the motions that leave the plane: v_k =
  (0, b_k, c_k), b_k tilting the axis out of the plane, c_k the twist.  Reflection through the plane maps
  (a, b, c) to (a, -b, -c), so the Hessian has no (a, b) or (a, c) entries and the in-plane block is the planar
  Hessian of ``proofs.hessian_and_rows``.
- ``spatial``: the Hessian over all 3n components at any configuration given by quaternions (the twisted rings).

Both return the symmetry rows too: the rotations of the whole chain and the uniform spin of every body about
its own axis (the bodies are axisymmetric), which are null directions of the reduced Hessian at every
equilibrium and are taken out as extra rows of the bordered matrix (``proofs.bordered_inertia``).
"""

from __future__ import annotations


def out_of_plane(c, s, rho, lengths, loop_of, gamma):
    """(H, closure rows, symmetry rows) of the out-of-plane block at a planar twist-free configuration.

    ``c``, ``s``: cos and sin of theta_k; ``rho``: each loop's (rho_y, rho_z) = R h / c1^2; variables ordered
    (b_1..b_n, c_1..c_n).  Per joint, with C^2 = (1 + cos D)/2, S^2 = (1 - cos D)/2, CS = sin D / 2 (D = theta_k
    - theta_(k-1); w = body k-1, v = body k), the quadratic form x^T H x has

        C^2 [(b_v - b_w)^2 + (c_v - c_w)^2] - 2 CS (c_w b_v - b_w c_v) + (gamma - 1) [C (c_v - c_w) + S (b_v + b_w)]^2

    and per body h_k (sigma_k b_k^2 - r_k b_k c_k), sigma_k = rho . e3_k, r_k = rho . e2_k (the closure's second
    order).  The closure of each loop out of the plane is sum h_k b_k = 0.
    """
    n = len(c)
    zero = c[0] * 0
    g1 = gamma - 1
    H = [[zero] * (2 * n) for _ in range(2 * n)]

    def add(i, j, x):
        H[i][j] = H[i][j] + x

    for k in range(n):
        w, v = (k - 1) % n, k
        cd = c[k] * c[w] + s[k] * s[w]  # cos D
        sd = s[k] * c[w] - c[k] * s[w]  # sin D
        cc, ss, cs = (1 + cd) / 2, (1 - cd) / 2, sd / 2
        bw, cw, bv, cv = w, n + w, v, n + v
        for (i, j), x in (((bw, bw), cc), ((bv, bv), cc), ((bw, bv), -cc), ((bv, bw), -cc),
                          ((cw, cw), cc), ((cv, cv), cc), ((cw, cv), -cc), ((cv, cw), -cc),
                          ((cw, bv), -cs), ((bv, cw), -cs), ((bw, cv), cs), ((cv, bw), cs)):
            add(i, j, x)
        # (gamma - 1) u u^T with u = (S, -C, S, C) on (b_w, c_w, b_v, c_v): entries are C^2, S^2 or CS
        idx = (bw, cw, bv, cv)
        prod = {(0, 0): ss, (0, 1): -cs, (0, 2): ss, (0, 3): cs, (1, 1): cc, (1, 2): -cs, (1, 3): -cc,
                (2, 2): ss, (2, 3): cs, (3, 3): cc}
        for (a, b), x in prod.items():
            add(idx[a], idx[b], g1 * x)
            if a != b:
                add(idx[b], idx[a], g1 * x)
    for k in range(n):
        ry, rz = rho[loop_of[k]]
        sigma = rz * c[k] - ry * s[k]
        r2 = ry * c[k] + rz * s[k]
        add(k, k, lengths[k] * sigma)
        add(k, n + k, -lengths[k] * r2 / 2)
        add(n + k, k, -lengths[k] * r2 / 2)
    closures = [[lengths[k] if loop_of[k] == loop else zero for k in range(n)] + [zero] * n for loop in range(len(rho))]
    one = zero + 1
    symmetries = [
        list(c) + [-x for x in s],  # the whole chain turned about the plane's y axis: v_k = Q_k^T y
        list(s) + list(c),  # ... about its z axis
        [zero] * n + [one] * n,  # every body spun about its own axis
    ]
    return H, closures, symmetries


# ------------------------------------------------------------------------------------------- any configuration
def qmul(a, b):
    """The quaternion product a b, quaternions as (w, x, y, z)."""
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)


def conj(a):
    return (a[0], -a[1], -a[2], -a[3])


def matrix(q):
    """The rotation matrix (rows of lists) of a unit quaternion."""
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def _add(a, b, f=1):
    return tuple(x + f * y for x, y in zip(a, b, strict=True))


def spatial(quats, lengths, force, gamma, hessian: bool = True):
    """(H, gradient, closure rows, symmetry rows) over v = (v_1, ..., v_n), 3 components each, of U - R . closure
    at the configuration of unit quaternions ``quats``: one loop, ``force`` the world vector rho = R h / c1^2.

    Joint k with base quaternion p and the perturbed p' = q(w)^* p q(v), q(v) = 1 + V + V^2/2 (V the pure
    quaternion v/2): p' = p + d1 + d2 with d1 = p V - W p and d2 = p V^2/2 + W^2 p/2 - W p V.  With
    D = diag(0, 1, 1, gamma) the energy is 2 p'^T D p', so its gradient is 4 p^T D d1 and its Hessian
    4 d1(x)^T D d1(y) + 8 p^T D d2(x, y) (d2 polarised).  The closure term -h_k R . Q_k exp([v]) z gives the
    gradient -h_k z x r and the Hessian -h_k [(r.v) v'_3/2 + (r.v') v_3/2 - r_3 v.v'], r = Q_k^T R.
    Without ``hessian`` only the gradient is computed (H stays 0).
    """
    n = len(quats)
    zero = quats[0][0] * 0
    half = (zero + 1) / 2
    weight = (zero, zero + 1, zero + 1, gamma)
    H = [[zero] * (3 * n) for _ in range(3 * n)]
    g = [zero] * (3 * n)

    def pure(i):  # V of the unit vector along component i of 6 (w then v)
        e = [zero, zero, zero, zero]
        e[1 + i % 3] = half
        return tuple(e)

    def dot(a, b):
        return sum((weight[i] * a[i] * b[i] for i in range(4)), zero)

    for k in range(n):
        w = (k - 1) % n
        p = qmul(conj(quats[w]), quats[k])
        basis = [pure(i) for i in range(6)]
        d1 = [(tuple(-x for x in qmul(basis[i], p)) if i < 3 else qmul(p, basis[i])) for i in range(6)]
        cols = [3 * w + i for i in range(3)] + [3 * k + i for i in range(3)]
        for i in range(6):
            g[cols[i]] = g[cols[i]] + 4 * dot(p, d1[i])
        for i in range(6 if hessian else 0):
            for j in range(i, 6):
                bi, bj = basis[i], basis[j]
                if i < 3 and j < 3:  # W W p terms: (Wi Wj + Wj Wi) p / 4
                    d2 = qmul(_add(qmul(bi, bj), qmul(bj, bi)), p)
                    d2 = tuple(x / 4 for x in d2)
                elif i >= 3 and j >= 3:  # p (Vi Vj + Vj Vi) / 4
                    d2 = qmul(p, _add(qmul(bi, bj), qmul(bj, bi)))
                    d2 = tuple(x / 4 for x in d2)
                else:  # -(W p V) / 2, W from i (i < 3), V from j
                    d2 = tuple(-x / 2 for x in qmul(qmul(bi, p), bj))
                x = 4 * dot(d1[i], d1[j]) + 8 * dot(p, d2)
                H[cols[i]][cols[j]] = H[cols[i]][cols[j]] + x
                if i != j:
                    H[cols[j]][cols[i]] = H[cols[j]][cols[i]] + x
    closures = [[zero] * (3 * n) for _ in range(3)]
    symmetries = [[zero] * (3 * n) for _ in range(4)]
    for k in range(n):
        Q = matrix(quats[k])
        r = [sum((Q[a][i] * force[a] for a in range(3)), zero) for i in range(3)]  # Q^T rho
        hk = lengths[k]
        g[3 * k] = g[3 * k] + hk * r[1]  # -h_k (z x r) = h_k (r_2, -r_1, 0)
        g[3 * k + 1] = g[3 * k + 1] - hk * r[0]
        for a in range(3):
            for b in range(3):
                x = -hk * ((r[a] if b == 2 else zero) / 2 + (r[b] if a == 2 else zero) / 2 - (r[2] if a == b else zero))
                H[3 * k + a][3 * k + b] = H[3 * k + a][3 * k + b] + x
        for a in range(3):  # d(h_k Q_k z) = h_k Q_k (v x z) = h_k Q_k (v_2, -v_1, 0)
            closures[a][3 * k] = -hk * Q[a][1]
            closures[a][3 * k + 1] = hk * Q[a][0]
            for i in range(3):  # the whole chain turned about world axis a: v_k = Q_k^T e_a
                symmetries[a][3 * k + i] = Q[a][i]
        symmetries[3][3 * k + 2] = zero + 1
    return H, g, closures, symmetries


def body_frame(cos_theta2, sin_theta2, cos_phi2, sin_phi2):
    """The quaternion of a body's frame Rx(theta) Rz(phi), from the cosines and sines of theta/2 and phi/2."""
    zero = cos_theta2 * 0
    return qmul((cos_theta2, sin_theta2, zero, zero), (cos_phi2, zero, zero, sin_phi2))


def twisted_ring(n: int, j: int, m: int, gamma, cos_pi, sin_pi, frac):
    """Quaternions, scaled force and energy of the ring of n equal bodies, winding j and twist m:
    Q_k = Rx(2 pi j k/n) Rz(2 pi m k/n).

    ``cos_pi(x)``/``sin_pi(x)`` give cos(pi x)/sin(pi x) of a fraction ``frac(a, b)`` in the arithmetic wanted.
    The ring is an equilibrium for every c1, c2 by symmetry (a shift of the bodies composed with a rotation
    about the ring's axis and a spin maps it onto itself, and the closed configurations fixed by it are the ring
    alone, up to rotation and spin); the closure force is normal to its plane, rho_x = gamma sin(2 pi j/n)
    sin(2 pi m/n) for h_k = 1, and U = (n/h) [c1^2 (1 - cos 2 pi j/n) + c2^2 (1 + cos 2 pi j/n)(1 - cos 2 pi m/n)/2].
    """
    half = [(frac(j * k, n), frac(m * k, n)) for k in range(1, n + 1)]  # half angles over pi
    quats = [body_frame(cos_pi(a), sin_pi(a), cos_pi(b), sin_pi(b)) for a, b in half]
    delta, tau = frac(2 * j, n), frac(2 * m, n)
    rho_x = gamma * sin_pi(delta) * sin_pi(tau)
    zero = rho_x * 0
    energy = n * ((1 - cos_pi(delta)) + gamma * (1 + cos_pi(delta)) * (1 - cos_pi(tau)) / 2)
    return quats, (rho_x, zero, zero), energy
