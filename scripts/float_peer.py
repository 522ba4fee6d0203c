"""The float peer: the dense atlas kernel a researcher would write by hand, without certification.

    python scripts/float_peer.py                          # paper-n3-fixed at 1000 x 1000: peer and compute_atlas
    python scripts/float_peer.py --scene paper-n2-fixed --size 400 --threads 2

Same model as stabmap (docs/model.md, docs/cavities.md) and the same inputs (``point_arrays``), so the
peer decides exactly the points stabmap decides; but every number is a plain float64: the polynomial
matrix P = diag(Q) Phi T, its determinant by Laplace expansion, and a Sturm sequence on the float
coefficients with no tolerance, no rounding bound and no fallback.  Its labels are what such a kernel
reports: right away from boundaries, unverified near them.

Importable: ``from float_peer import float_atlas, float_charpoly, float_count``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numba
import numpy as np
from numba import prange

from stabmap.kernels import layout
from stabmap.systems.gyroscopes.points import point_arrays

CHUNK = 256  # points per prange task: scratch is allocated once a task, not once a point
BLOCK_POINTS = 1 << 18  # grid points per point_arrays call: bounds memory (about 30 MB of inputs at n = 3)


@numba.njit(cache=True)
def _matrix(body, joint, at, g, E, kappa, nmodes, parent, free, J, MT, KT, sub, T, q, w, P):
    """P = diag(Q) Phi T of one point into P (n, n, Lmax + 3), ascending powers of lambda.

    Multiplying by the path matrix T (det T = 1) leaves det unchanged but makes K T exact and
    sparse, so a free system's rigid tilt and ideal joints give exact zero coefficients here as
    in stabmap, instead of rounding noise that would pose as tiny roots.
    """
    n = body.shape[0]
    # Lever arms J: J[k, k] = c_k, J[k, i] = position on i's axis of the joint where the path to k leaves i.
    J[:] = 0.0
    T[:] = False
    for k in range(n):
        J[k, k] = body[k, layout.CM]
        T[k, k] = True
        child = k
        i = parent[k]
        while i >= 0:
            J[k, i] = at[child]
            T[k, i] = True
            child = i
            i = parent[i]
    if free:
        # The centre of mass stays at rest: subtract each column's mass-weighted mean.
        mt = 0.0
        for k in range(n):
            mt += body[k, layout.M]
        for i in range(n):
            s = 0.0
            for k in range(n):
                s += body[k, layout.M] * J[k, i]
            s /= mt
            for k in range(n):
                J[k, i] -= s
    # M = diag(A) + J^T diag(m) J, then M T by adding every column into its parent's, children first.
    for i in range(n):
        for j in range(n):
            acc = body[i, layout.A] if i == j else 0.0
            for k in range(n):
                acc += body[k, layout.M] * J[k, i] * J[k, j]
            MT[i, j] = acc
    for k in range(n):
        for j in range(n - 1, 0, -1):
            MT[k, parent[j]] += MT[k, j]
    # K T: the elastic Laplacian maps column j of T to K_j (e_j - e_parent(j)).
    KT[:] = 0.0
    for j in range(1, n):
        KT[j, j] = joint[j]
        KT[parent[j], j] = -joint[j]
    if not free:
        KT[0, 0] = joint[0]
        # a_k = m_k c_k + sum over children j of at_j * (mass of the subtree of j); children come after parents.
        for k in range(n - 1, -1, -1):
            a = body[k, layout.M] * body[k, layout.CM]
            sub[k] = body[k, layout.M]
            for j in range(k + 1, n):
                if parent[j] == k:
                    a += at[j] * sub[j]
                    sub[k] += sub[j]
            ga = g * a
            j = k
            while j >= 0:  # row k of -g diag(a) T
                KT[k, j] -= ga
                j = parent[j]
    P[:] = 0.0
    for k in range(n):
        L = nmodes[k]
        omega = body[k, layout.OMEGA]
        # Q = prod (lambda + beta_l), R = sum_l E_l prod_{l' != l} (lambda + beta_l'), beta = omega (kappa - 2) / kappa.
        q[:] = 0.0
        w[:] = 0.0
        q[0] = 1.0
        for l in range(L):
            beta = omega * (kappa[k, l] - 2.0) / kappa[k, l]
            El = E[k, l]
            for a in range(l + 1, 0, -1):
                w[a] = w[a] * beta + w[a - 1] + El * q[a]
            w[0] = w[0] * beta + El * q[0]
            for a in range(l + 1, 0, -1):
                q[a] = q[a] * beta + q[a - 1]
            q[0] *= beta
        G = body[k, layout.C] * omega
        for j in range(n):
            # P_kj = Q (lambda^2 MT_kj + lambda G T_kj - KT_kj) - T_kj lambda^2 (lambda + omega) R
            mk, kk = MT[k, j], KT[k, j]
            for a in range(L + 1):
                P[k, j, a] -= q[a] * kk
                P[k, j, a + 2] += q[a] * mk
                if T[k, j]:
                    P[k, j, a + 1] += q[a] * G
            if T[k, j]:
                for a in range(L):
                    P[k, j, a + 3] -= w[a]
                    P[k, j, a + 2] -= omega * w[a]


@numba.njit(cache=True)
def _det(P, nmodes, D, out):
    """det P by Laplace expansion: minors of the first rows for every column set (bit mask), each along its last row.

    Cheaper than interpolation at roots of unity for the few bodies of a chain, and division-free,
    so P's exact zeros stay exact; interpolation would also smear the coefficients' wide range of
    magnitudes into absolute errors of the largest.  Writes deg + 1 coefficients into out.
    """
    n = P.shape[0]
    full = (1 << n) - 1
    deg = 0
    for k in range(n):
        rd = nmodes[k] + 2
        sub = deg
        deg += rd
        for mask in range(1, full + 1):
            bits = 0
            x = mask
            while x:
                x &= x - 1
                bits += 1
            if bits != k + 1:
                continue
            Dm = D[mask]
            Dm[: deg + 1] = 0.0
            pos = 0
            for j in range(n):
                if not (mask >> j) & 1:
                    continue
                if k == 0:
                    Dm[: rd + 1] = P[0, j, : rd + 1]
                    break
                S = D[mask ^ (1 << j)]
                sign = 1.0 if (k + pos) % 2 == 0 else -1.0
                pos += 1
                for a in range(rd + 1):
                    e = sign * P[k, j, a]
                    if e == 0.0:
                        continue
                    for b in range(sub + 1):
                        Dm[a + b] += e * S[b]
    out[: deg + 1] = D[full, : deg + 1]


@numba.njit(cache=True)
def _sturm_pairs(c, x, y):
    """N_c = (deg - real roots) / 2 of the float polynomial c (ascending) by a plain Sturm sequence.

    No tolerance: a remainder coefficient is zero only if it is exactly zero, and the sequence stops
    only at an exactly zero remainder.  Real roots are counted without multiplicity (a float
    sequence never sees a repeated root but by exact structure), roots at 0 from exact zero low
    coefficients with it.  x, y: scratch of len(c).  Returns -1 for p == 0.
    """
    top = c.shape[0] - 1
    while top >= 0 and c[top] == 0.0:
        top -= 1
    if top < 0:
        return -1
    low = 0
    while c[low] == 0.0:
        low += 1
    d = top - low
    a, b = x, y
    s = abs(c[top])  # scale once: the sequence's magnitudes stay far from overflow
    for i in range(d + 1):
        a[i] = c[low + i] / s
    for i in range(d):
        b[i] = (i + 1) * a[i + 1]
    da, db = d, d - 1
    sp_prev = 1.0 if a[d] > 0 else -1.0
    sm_prev = sp_prev if d % 2 == 0 else -sp_prev
    vp = vm = 0
    while True:
        while db >= 0 and b[db] == 0.0:
            db -= 1
        if db < 0:
            break
        sp = 1.0 if b[db] > 0 else -1.0
        sm = sp if db % 2 == 0 else -sp
        vp += sp != sp_prev
        vm += sm != sm_prev
        sp_prev, sm_prev = sp, sm
        if db == 0:
            break
        # a <- -(a mod b), scaled to max 1; then the pair moves down one step
        # Divisions, not reciprocal products: the same roundings as scripts/bench_accuracy.py's _float_sturm,
        # so the accuracy table's "float Sturm, no tolerance" row and this peer are one method.
        for j in range(da, db - 1, -1):
            f = a[j] / b[db]
            for i in range(db):
                a[j - db + i] -= f * b[i]
        m = 0.0
        for i in range(db):
            m = max(m, abs(a[i]))
        if m == 0.0:
            break
        for i in range(db):
            a[i] = -a[i] / m
        a, b = b, a
        da, db = db, db - 1
    real = low + vm - vp
    return (top - real) // 2


@numba.njit(cache=True)
def _workspace(n, lmax, degree):
    return (np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty(n), np.empty((n, n), np.bool_),
            np.empty(lmax + 1), np.empty(lmax + 1), np.empty((n, n, lmax + 3)), np.empty((1 << n, degree + 1)))


@numba.njit(parallel=True, cache=True)
def count_kernel(body, joint, g, E, kappa, nmodes, free, parent, at, out_nc):
    """N_c of every point (inputs: kernels.charpoly_block's layout) into out_nc, in parallel over points."""
    npts, n = body.shape[0], body.shape[1]
    degree = 0
    for k in range(n):
        degree += nmodes[k] + 2
    lmax = max(1, nmodes.max())
    for t in prange((npts + CHUNK - 1) // CHUNK):
        J, MT, KT, sub, T, q, w, P, D = _workspace(n, lmax, degree)
        c = np.empty(degree + 1)
        x = np.empty(degree + 1)
        y = np.empty(degree + 1)
        for p in range(t * CHUNK, min(npts, (t + 1) * CHUNK)):
            _matrix(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, J, MT, KT, sub, T, q, w, P)
            _det(P, nmodes, D, c)
            out_nc[p] = _sturm_pairs(c, x, y)


@numba.njit(parallel=True, cache=True)
def charpoly_kernel(body, joint, g, E, kappa, nmodes, free, parent, at, out):
    """Float coefficients of p (ascending) of every point into out (npts, degree + 1)."""
    npts, n = body.shape[0], body.shape[1]
    degree = out.shape[1] - 1
    lmax = max(1, nmodes.max())
    for t in prange((npts + CHUNK - 1) // CHUNK):
        J, MT, KT, sub, T, q, w, P, D = _workspace(n, lmax, degree)
        for p in range(t * CHUNK, min(npts, (t + 1) * CHUNK)):
            _matrix(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, J, MT, KT, sub, T, q, w, P)
            _det(P, nmodes, D, out[p])


def float_charpoly(pts) -> np.ndarray:
    """Float64 coefficients (npts, degree + 1), ascending, of the points ``pts`` (a PointArrays)."""
    degree = int((pts.nmodes + 2).sum())
    out = np.empty((pts.body.shape[0], degree + 1))
    charpoly_kernel(*pts.kernel_args(), out)
    return out


def float_count(pts) -> np.ndarray:
    """N_c (int16[npts]) of the points ``pts`` (a PointArrays); -1 where p == 0."""
    out = np.empty(pts.body.shape[0], np.int16)
    count_kernel(*pts.kernel_args(), out)
    return out


def float_atlas(scene) -> np.ndarray:
    """N_c (int16, scene.shape) at every grid node of a stabmap scene, a block of rows of the first axis at a time."""
    shape = scene.shape
    out = np.empty(shape, np.int16)
    if not shape:
        out[()] = float_count(point_arrays(scene, {}))[0]
        return out
    per_row = int(np.prod(shape[1:], dtype=np.int64))
    rows = max(1, BLOCK_POINTS // max(1, per_row))
    for r0 in range(0, shape[0], rows):
        r1 = min(shape[0], r0 + rows)
        values = {}
        for d, axis in enumerate(scene.grid):
            view = [None] * len(shape)
            view[d] = slice(None)
            values[axis.name] = (axis.array[r0:r1] if d == 0 else axis.array)[tuple(view)]
        out[r0:r1] = float_count(point_arrays(scene, values)).reshape((r1 - r0,) + shape[1:])
    return out


def main(argv=None) -> dict:
    import stabmap
    from stabmap.scene.grid import resample

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="paper-n3-fixed")
    ap.add_argument("--size", type=int, default=1000, help="grid points per axis")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--no-stabmap", action="store_true", help="time the peer only")
    args = ap.parse_args(argv)
    numba.set_num_threads(args.threads)
    scene = resample(stabmap.example(args.scene), **{a.name: args.size for a in stabmap.example(args.scene).grid})
    npts = int(np.prod(scene.shape))
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}, "
          f"numba {numba.__version__}, {numba.get_num_threads()} numba threads")
    warm = resample(scene, **{a.name: 3 for a in scene.grid})
    float_atlas(warm)  # compile or load the kernels outside the timings
    stabmap.compute_atlas(warm, progress=False)

    t0 = time.perf_counter()
    pts = point_arrays(scene, {a.name: a.array[(slice(None),) + (None,) * (len(scene.grid) - 1 - d)] for d, a in enumerate(scene.grid)}) if npts <= 4_000_000 else None
    t_inputs = time.perf_counter() - t0
    result = {"scene": args.scene, "points": npts, "degree": scene.degree}
    if pts is not None:
        t0 = time.perf_counter()
        float_count(pts)
        result["kernel_us"] = 1e6 * (time.perf_counter() - t0) / npts
        result["inputs_us"] = 1e6 * t_inputs / npts
        del pts
    t0 = time.perf_counter()
    peer = float_atlas(scene)
    result["peer_s"] = time.perf_counter() - t0
    result["peer_us"] = 1e6 * result["peer_s"] / npts
    print(f"{args.scene} (degree {scene.degree}) at {' x '.join(map(str, scene.shape))} = {npts:,} points")
    if "kernel_us" in result:
        print(f"  peer kernel alone:        {result['kernel_us']:.3f} us/point (inputs built apart: {result['inputs_us']:.3f} us/point)")
    print(f"  peer float_atlas:         {result['peer_s']:.2f} s = {result['peer_us']:.3f} us/point")
    if not args.no_stabmap:
        t0 = time.perf_counter()
        ds = stabmap.compute_atlas(scene, progress=False)
        result["stabmap_s"] = time.perf_counter() - t0
        nc = ds["n_complex_pairs"].values
        result["differ"] = int((nc != peer).sum())
        print(f"  stabmap compute_atlas:    {result['stabmap_s']:.2f} s = {1e6 * result['stabmap_s'] / npts:.3f} us/point "
              f"({result['stabmap_s'] / result['peer_s']:.1f}x the peer)")
        print(f"  labels differing from stabmap's proved ones: {result['differ']} of {npts:,}")
    return result


if __name__ == "__main__":
    main()
