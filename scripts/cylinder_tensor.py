"""Chernousko's viscous cavity tensor P¹ of a circular cylinder, by finite elements (scikit-fem), and the table.

The auxiliary Stokes problem (docs/viscous-tensors.md): for a unit vector e, ∇²w − ∇π = e × r, div w = 0 in the
cavity, w = 0 on its wall; then P e = −∫ r × w dV, and e·P e = ∫ |∇w|² dV (the forcing is e × r, so
−∫(r × w)·e = −∫(e × r)·w, which the weak form with w as test function equals to the Dirichlet energy).

An axisymmetric cavity reduces both problems to the meridional half-plane (r, z), r ≥ 0:

- axial (e = e_z, m = 0 swirl): w = v(r, z) e_θ, no pressure, −(Δv − v/r²) = −r; v = 0 on the wall and the axis.
- transverse (e = e_x, m = 1): w_r = a sin θ, w_θ = b cos θ, w_z = c sin θ, π = p sin θ. With d = a − b the 3-D
  Dirichlet energy per unit π is ∫∫ [|∇a|² + |∇(a − d)|² + |∇c|² + 2 d²/r² + c²/r²] r dr dz and div w =
  (a_r + d/r + c_z) sin θ. A smooth field has d = c = 0 on the axis (w_y single valued, w_z single valued),
  a is free there. Taylor–Hood P2/P1 with r-weighted forms.

The same functions solve the spheroid (isoparametric P2 mesh of the half-ellipse), where the closed form checks them
(tests/test_viscous_tensors.py). Run ``python scripts/cylinder_tensor.py`` to rewrite the bundled table
stabmap/systems/gyroscopes/data/cylinder_tensor.csv (``--quick``: a coarse run that writes nothing).
"""

from __future__ import annotations

import argparse
import math
import pathlib
import time

import numpy as np
import scipy.sparse as sp
from scipy.spatial import Delaunay
from skfem import Basis, BilinearForm, ElementTriP1, ElementTriP2, LinearForm, MeshTri1, MeshTri2, condense, solve
from skfem.helpers import dot, grad

TABLE = pathlib.Path(__file__).resolve().parents[1] / "stabmap" / "systems" / "gyroscopes" / "data" / "cylinder_tensor.csv"


# ---- meshes ---------------------------------------------------------------------------------------------------------
def half_ellipse_mesh(radius: float, half_height: float, n: int) -> MeshTri2:
    """Isoparametric P2 mesh of r²/radius² + z²/half_height² ≤ 1, r ≥ 0, with about n rings of elements."""
    pts = [(0.0, 0.0)]
    for k in range(1, n + 1):
        rho = k / n
        phi = np.linspace(0.0, np.pi, 2 * k + 1)  # angle from +z, the axis at both ends
        pts += list(zip(rho * np.sin(phi), rho * np.cos(phi)))
    pts = np.array(pts)
    pts[np.abs(pts[:, 0]) < 1e-14, 0] = 0.0
    tri = Delaunay(pts).simplices
    m1 = MeshTri1(pts.T.copy(), tri.T.copy())
    m2 = MeshTri2.from_mesh(m1)
    doflocs = m2.doflocs.copy()
    axis = m2.facets_satisfying(lambda x: x[0] < 1e-12, boundaries_only=True)
    arc = np.setdiff1d(m2.boundary_facets(), axis)
    dofs = m2.dofs.get_facet_dofs(arc).flatten()
    # edge midpoints onto the unit circle, then the affine stretch puts every boundary node on the ellipse
    doflocs[:, dofs] /= np.linalg.norm(doflocs[:, dofs], axis=0)
    doflocs[0] *= radius
    doflocs[1] *= half_height
    return MeshTri2(doflocs, m2.t)


def _one_sided(length: float, h0: float, hmax: float, ratio: float = 1.15) -> np.ndarray:
    """Nodes on [0, length], spacing h0 at 0 growing by ratio up to hmax, stretched to end exactly at length."""
    steps, h = [], h0
    while sum(steps) < length:
        steps.append(h)
        h = min(h * ratio, hmax)
    nodes = np.concatenate([[0.0], np.cumsum(steps)])
    return nodes * (length / nodes[-1])


def cylinder_mesh(radius: float, half_height: float, n: int) -> MeshTri2:
    """P2 mesh of the meridional rectangle 0 ≤ r ≤ radius, |z| ≤ half_height: spacing min(radius, half_height)/n
    at the wall, where the corners are, growing by 15 % a cell up to 4 / n of the shorter side."""
    scale = min(radius, half_height)
    h0, hmax = scale / n, 4.0 * scale / n
    r = radius - _one_sided(radius, h0, hmax)[::-1]
    r[0] = 0.0
    zh = _one_sided(half_height, h0, hmax)  # from the lid inwards
    z = np.concatenate([-half_height + zh, half_height - zh[-2::-1]])
    return MeshTri2.from_mesh(MeshTri1.init_tensor(r, z))


# ---- solvers --------------------------------------------------------------------------------------------------------
def _bases(mesh):
    ub = Basis(mesh, ElementTriP2(), intorder=6)
    return ub, ub.with_element(ElementTriP1())


def _axis_and_wall(ub):
    axis = ub.mesh.facets_satisfying(lambda x: x[0] < 1e-12, boundaries_only=True)
    wall = np.setdiff1d(ub.mesh.boundary_facets(), axis)
    return ub.get_dofs(axis).all(), ub.get_dofs(wall).all()


def axial(mesh) -> float:
    """The axial entry P_a = 2π ∫∫ (|∇v|² + v²/r²) r dr dz of the m = 0 swirl problem [length⁷]."""
    ub, _ = _bases(mesh)

    @BilinearForm
    def k(u, v, w):
        r = w.x[0]
        return (dot(grad(u), grad(v)) + u * v / r**2) * r

    @LinearForm
    def f(v, w):
        r = w.x[0]
        return -r * v * r

    K, F = k.assemble(ub), f.assemble(ub)
    axis, wall = _axis_and_wall(ub)
    v = solve(*condense(K, F, D=np.union1d(axis, wall)))
    return float(2.0 * math.pi * v @ K @ v)


def transverse(mesh) -> float:
    """The transverse entry P_t = π ∫∫ [...] r dr dz (module docstring) of the m = 1 problem [length⁷]."""
    ub, pb = _bases(mesh)

    @BilinearForm
    def lap(u, v, w):
        return dot(grad(u), grad(v)) * w.x[0]

    @BilinearForm
    def mass_r(u, v, w):
        return u * v / w.x[0]

    @BilinearForm
    def div_a(u, q, w):  # q (a_r) r
        return q * grad(u)[0] * w.x[0]

    @BilinearForm
    def div_d(u, q, w):  # q (d/r) r
        return q * u

    @BilinearForm
    def div_c(u, q, w):  # q c_z r
        return q * grad(u)[1] * w.x[0]

    @LinearForm
    def f_z(v, w):
        return w.x[1] * v * w.x[0]

    @LinearForm
    def f_r(v, w):
        return w.x[0] * v * w.x[0]

    L, M = lap.assemble(ub), mass_r.assemble(ub)
    Ba, Bd, Bc = (form.assemble(ub, pb) for form in (div_a, div_d, div_c))  # (n_p, n_u)
    Fz, Fr = f_z.assemble(ub), f_r.assemble(ub)
    # energy = ∫ |∇a|² + |∇a − ∇d|² + |∇c|² + 2 d²/r² + c²/r²; forcing −∫ f·v = ∫ (2 z a' − z d' − r c') r
    A = sp.bmat([[2 * L, -L, None, -Ba.T],
                 [-L, L + 2 * M, None, -Bd.T],
                 [None, None, L + M, -Bc.T],
                 [-Ba, -Bd, -Bc, None]], format="csr")
    n_u, n_p = ub.N, pb.N
    F = np.concatenate([2 * Fz, -Fz, -Fr, np.zeros(n_p)])
    axis, wall = _axis_and_wall(ub)
    D = np.concatenate([wall, n_u + wall, 2 * n_u + wall, n_u + axis, 2 * n_u + axis])
    x = solve(*condense(A, F, D=np.unique(D)))
    return float(math.pi * (F[:3 * n_u] @ x[:3 * n_u]))


# ---- the table ------------------------------------------------------------------------------------------------------
Q_MIN, Q_MAX, N_NODES = 0.05, 20.0, 65  # aspect ratios half_height / radius, geometric spacing
MESH_N = 64  # cells per shorter side at the wall (cylinder_mesh); MESH_N / 2 gives the error estimate


def cylinder_entries(q: float, n: int) -> tuple[float, float]:
    """(f_t, f_a) = (P_t, P_a) / radius⁷ of the cylinder of aspect ratio q on cylinder_mesh(1, q, n)."""
    mesh = cylinder_mesh(1.0, q, n)
    return transverse(mesh), axial(mesh)


def _solve_nodes(qs, n):
    """(f at n, relative change from n/2 to n) for every q: the change bounds the error of the finer value when the
    error falls at least like n⁻¹ (convergence table in docs/viscous-tensors.md: about n⁻¹·⁵ to n⁻²)."""
    fine = np.array([cylinder_entries(q, n) for q in qs])
    coarse = np.array([cylinder_entries(q, n // 2) for q in qs])
    return fine, np.abs(fine / coarse - 1.0)


def convergence(qs=(0.05, 1.0, 20.0), levels=(8, 16, 32, 64)) -> str:
    """A markdown table of f_t, f_a against the mesh parameter n, with the change from the previous n."""
    rows = ["| h/a | n | triangles | f_t | change | f_a | change |", "|---|---|---|---|---|---|---|"]
    for q in qs:
        prev = None
        for n in levels:
            f = cylinder_entries(q, n)
            ch = ["", ""] if prev is None else [f"{abs(f[i] / prev[i] - 1):.1e}" for i in (0, 1)]
            rows.append(f"| {q:g} | {n} | {cylinder_mesh(1.0, q, n).t.shape[1]} | {f[0]:.8e} | {ch[0]} | {f[1]:.8e} | {ch[1]} |")
            prev = f
    return "\n".join(rows)


def build(n_nodes: int = N_NODES, mesh_n: int = MESH_N):
    """Nodes q, values f (len(q), 2), their error bounds, and the interpolation error measured at the geometric
    midpoints (cubic spline of log f against log q, as stabmap.systems.gyroscopes.stokes reads the table)."""
    from scipy.interpolate import CubicSpline

    q = np.geomspace(Q_MIN, Q_MAX, n_nodes)
    f, disc = _solve_nodes(q, mesh_n)
    mid = np.sqrt(q[1:] * q[:-1])
    f_mid = np.array([cylinder_entries(x, mesh_n) for x in mid])
    interp = np.column_stack([np.exp(CubicSpline(np.log(q), np.log(f[:, i]))(np.log(mid))) for i in (0, 1)])
    return q, f, disc, np.abs(interp / f_mid - 1.0)


def write(path, q, f, disc, interp_err, mesh_n, seconds) -> float:
    rel_error = float(np.max(disc) + np.max(interp_err))
    # a margin of 1.5, then rounded up to one significant digit
    mantissa, exponent = f"{rel_error * 1.5:.6e}".split("e")
    rel_error = math.ceil(float(mantissa)) * 10.0 ** int(exponent)
    header = [
        "Chernousko's viscous cavity tensor P¹ of the circular cylinder |z| <= h, r <= a: P_t = P_11 = P_22 = a^7 f_t(h/a),",
        "P_a = P_33 = a^7 f_a(h/a). Written by scripts/cylinder_tensor.py (scikit-fem "
        f"{__import__('skfem').__version__}, {seconds:.0f} s): the auxiliary Stokes problem reduced to the meridional",
        "half-plane (m = 1 Taylor-Hood P2/P1 for f_t, m = 0 swirl P2 for f_a), on cylinder_mesh(1, h/a, "
        f"{mesh_n}) (spacing min(a, h)/{mesh_n} at the wall, growing 15 % a cell).",
        f"err_t, err_a: relative change from mesh n = {mesh_n // 2} to {mesh_n}, a bound on the error of the value "
        f"(largest {np.max(disc):.1e}). Cubic-spline interpolation of log f in log(h/a), measured against",
        f"fresh solves at the {len(q) - 1} geometric midpoints: largest relative error {np.max(interp_err):.1e}.",
        f"rel_error = {rel_error:g}",
        "columns: h/a, f_t, f_a, err_t, err_a",
    ]
    rows = np.column_stack([q, f, disc])
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("".join(f"# {line}\n" for line in header))
        for row in rows:
            fh.write(",".join(f"{v:.12e}" for v in row) + "\n")
    return rel_error


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a coarse run (few nodes, coarse mesh); writes nothing")
    parser.add_argument("--convergence", action="store_true", help="print the convergence table (markdown)")
    parser.add_argument("-o", "--output", default=str(TABLE), help="the CSV to write (default: the bundled table)")
    args = parser.parse_args(argv)
    if args.convergence:
        print(convergence())
        return
    t0 = time.perf_counter()
    n_nodes, mesh_n = (5, 8) if args.quick else (N_NODES, MESH_N)
    q, f, disc, interp = build(n_nodes, mesh_n)
    seconds = time.perf_counter() - t0
    print(f"{len(q)} nodes, mesh n = {mesh_n}: largest change n/2 -> n {np.max(disc):.2e}, "
          f"largest interpolation error {np.max(interp):.2e}, {seconds:.1f} s")
    if not args.quick:
        print(f"rel_error = {write(args.output, q, f, disc, interp, mesh_n, seconds):g} -> {args.output}")


if __name__ == "__main__":
    main()
