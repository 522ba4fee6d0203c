"""Asymptotic stability with a highly viscous liquid, proved to first order in 1/nu (docs/viscous.md).

The chain with its liquid frozen decides first (``gyroscopes.decide``): a complex root pair grows at order 1 and
no small dissipation stops it.  Where every frozen root is real, each simple nonzero root gets its first-order
growth rate sigma = -q/p' (``kernels.firstorder``) enclosed in ball arithmetic; points the balls leave open go to
the exact rational polynomial and FLINT/Arb.  The label never comes from a float guess, and never from the
large spurious root that putting the viscous term into the polynomial would create.
"""

from __future__ import annotations

import math
from fractions import Fraction

import flint
import numpy as np

from ...kernels import ROOTS_FAILED, layout, roots_block
from ...kernels.firstorder import RATE_OK, first_order_block
from ..gyroscopes import exact, ratios, stokes, topology
from ..gyroscopes.decide import decide as decide_frozen
from ..gyroscopes.decide import kernel_args
from ..gyroscopes.points import PointArrays, point_arrays
from ..gyroscopes.rates import down, outward_float32, up
from ..gyroscopes.rates import rates as frozen_rates
from .outputs import ASYMPTOTICALLY_STABLE, BY, DEGENERATE, UNDECIDED, UNSTABLE

U = 2.0**-53
ARB_PREC = 212  # bits for the exact path's evaluations (the roots themselves are isolated to whatever Arb needs)


def dissipation(scene, values: dict, points: PointArrays):
    """(eps, eps_r, liquid, reynolds): each viscous cavity's eps_k = rho_k P_k / nu_k as a ball (npts, nl), the
    kernel indices of those bodies (nl,), and each point's largest Reynolds number |omega_k| a_k^2 / nu_k."""
    arrays = {name: np.asarray(v, dtype=np.float64) for name, v in ratios.underlying(scene, values).items()}
    shape = np.broadcast_shapes(*(a.shape for a in arrays.values())) if arrays else ()
    npts = points.body.shape[0]
    order = np.arange(scene.n) if scene.topology is None else topology.kernel_layout(scene.topology.parent)[0]
    position = np.argsort(order)  # the kernel index of each scene body
    liquid, eps, eps_r, reynolds = [], [], [], np.zeros(npts)
    for k, b in enumerate(scene.bodies):
        cav = b.cavity
        if cav is None or not cav.viscous:
            continue

        def get(key, k=k, cav=cav):  # bound now: called only in this iteration, but bound all the same
            return np.broadcast_to(np.asarray(arrays.get(f"{key}_{k + 1}", getattr(cav, key)), dtype=np.float64), shape).reshape(-1)

        nu, rho, a = get("viscosity"), get("density"), get("radius")
        if cav.geometric:
            P, _, rel = stokes.tensor(cav.shape, a, get("half_height"))
        else:
            P, rel = np.full(npts, cav.tensor[0]), 0.0
        e = rho * np.asarray(P) / nu
        i = int(position[k])
        liquid.append(i)
        eps.append(e)
        # the roundings of the closed form (a few dozen operations) and of rho P / nu, and the tensor's stated accuracy
        eps_r.append(np.abs(e) * (np.asarray(rel) + 64.0 * U) + 1e-300)
        reynolds = np.maximum(reynolds, np.abs(points.body[:, i, layout.OMEGA]) * a * a / nu)
    return (np.ascontiguousarray(np.stack(eps, axis=1)), np.ascontiguousarray(np.stack(eps_r, axis=1)),
            np.array(liquid, dtype=np.int64), reynolds)


def structural_zeros(points: PointArrays) -> np.ndarray:
    """How many lambda = 0 roots each point has for every viscosity, at least (a lower bound is enough).

    A column j of K T (kernels/charpoly.py) that is exactly zero makes column j of the perturbed Phi T a multiple of
    lambda, whatever eps: the joint of body j is ideal (K_j = 0) and, on a fixed support, gravity is off (g = 0).
    A free system's column 0 is always zero (the rigid tilt of the whole).
    """
    ideal = points.joint == 0.0
    if points.free:
        return 1 + ideal[:, 1:].sum(axis=1)
    out = np.where(points.g == 0.0, ideal.sum(axis=1), 0)
    for p in np.flatnonzero((points.g != 0.0) & ideal.any(axis=1)):  # gravity too: its first moments, exactly
        out[p] = _gravity_free_columns(points.body[p], points.at[p], points.parent, ideal[p])
    return out


def _gravity_free_columns(body, at, parent, ideal) -> int:
    """How many columns j of K T vanish on a fixed support with gravity: K_j = 0 and a_k = 0 exactly for every body
    k beyond joint j, a_k = m_k c_k + sum over the bodies i mounted on k of at_i times the mass beyond i."""
    n = len(parent)
    beyond = [[k] for k in range(n)]  # the bodies whose path to the base passes body k (k included)
    for k in range(n - 1, 0, -1):  # a regular numbering: children after their parents
        beyond[parent[k]] += beyond[k]
    mass = [sum((Fraction(body[i, layout.M]) for i in beyond[k]), Fraction(0)) for k in range(n)]
    a = [Fraction(body[k, layout.M]) * Fraction(body[k, layout.CM]) for k in range(n)]
    for i in range(1, n):
        a[parent[i]] += Fraction(at[i]) * mass[i]
    return sum(1 for j in range(n) if ideal[j] and all(a[k] == 0 for k in beyond[j]))


def evaluate(scene, values: dict) -> dict[str, np.ndarray]:
    """Every variable of ``outputs.ALL_VARIABLES`` at the points ``values`` (flat arrays); where the frozen chain is
    unstable its growth rates are computed only if the scene stores them (``growth_rate``), NaN otherwise."""
    points = point_arrays(scene, values)
    npts, D = points.body.shape[0], int((points.nmodes + 2).sum())
    eps, eps_r, liquid, reynolds = dissipation(scene, values, points)
    nc, _ = decide_frozen(points)
    label = np.full(npts, UNDECIDED, dtype=np.int8)
    by = np.full(npts, BY["zero_rate"], dtype=np.int8)
    rate = {key: np.full(npts, np.nan) for key in ("best", "lower", "upper", "frequency")}
    label[nc < 0], by[nc < 0] = DEGENERATE, BY["degenerate"]
    unstable = np.flatnonzero(nc > 0)
    label[unstable], by[unstable] = UNSTABLE, BY["frozen_chain_unstable"]
    if unstable.size and scene.growth_rate:  # the frozen chain's rates only for a scene that stores them
        grown = frozen_rates(points.take(unstable), nc[unstable], growth=True)
        rate["best"][unstable], rate["lower"][unstable], rate["upper"][unstable] = (
            grown["growth_rate"], grown["growth_rate_lower"], grown["growth_rate_upper"])
    todo = np.flatnonzero(nc == 0)
    if todo.size:
        _first_order(points.take(todo), eps[todo], eps_r[todo], liquid, structural_zeros(points)[todo], D, todo, label, by, rate)
    return {"asymptotic_stability": label, "decided_by": by, "reynolds": reynolds.astype(np.float32), **_rate_variables(rate)}


def _first_order(points, eps, eps_r, liquid, zeros, D, rows, label, by, rate) -> None:
    """Decide the points whose frozen roots are all real (N_c = 0 proved): balls first, Arb for the rest."""
    npts = points.body.shape[0]
    args = kernel_args(points)
    z, r = np.empty((npts, D), np.complex128), np.empty((npts, D))
    kind, status = np.empty((npts, D), np.int8), np.empty(npts, np.int8)
    roots_block(*args, z, r, kind, np.empty((npts, 3)), status)
    mid, rad = np.empty((npts, D)), np.empty((npts, D))
    ok = np.empty((npts, D), np.int8)
    first_order_block(*args, liquid, eps, eps_r, z, r, kind, mid, rad, ok)
    exact_zero = (z == 0) & (r == 0)
    # NaN padding beyond the degree of p is neither a root nor a failure
    present = ~np.isnan(z.real)
    nonzero = present & ~exact_zero
    decided = nonzero & (ok == RATE_OK) & (np.abs(mid) > rad)
    settled = (status != ROOTS_FAILED) & np.all(~nonzero | decided, axis=1) & (exact_zero.sum(axis=1) <= zeros)
    for i in np.flatnonzero(settled):
        sig = mid[i, nonzero[i]]
        _put(rows[i], sig, rad[i, nonzero[i]], z[i, nonzero[i]].real, label, by, rate, BY["first_order_balls"])
    for i in np.flatnonzero(~settled):
        _exact(points, i, eps[i], eps_r[i], liquid, int(zeros[i]), rows[i], label, by, rate)


def _put(row, sig, sig_r, freq, label, by, rate, method) -> None:
    """Store a decided point's label and its largest growth rate (``sig`` the balls' midpoints, ``sig_r`` radii)."""
    if sig.size == 0:  # only neutral lambda = 0 roots
        label[row], by[row] = ASYMPTOTICALLY_STABLE, method
        rate["best"][row] = rate["lower"][row] = rate["upper"][row] = 0.0
        return
    top = int(np.argmax(sig))
    label[row] = UNSTABLE if np.any(sig - sig_r > 0) else ASYMPTOTICALLY_STABLE
    by[row] = method
    rate["best"][row] = sig[top]
    # mid -+ radius rounds to nearest: one step outward keeps the enclosure
    rate["lower"][row] = float(np.max(np.nextafter(sig - sig_r, -np.inf)))
    rate["upper"][row] = float(np.max(np.nextafter(sig + sig_r, np.inf)))
    rate["frequency"][row] = freq[top]


def _exact(points, i, eps, eps_r, liquid, zeros, row, label, by, rate) -> None:
    """One point from its exact rational polynomial: Arb isolates the roots, evaluates sigma on each."""
    args = (points.body[i], points.joint[i], points.g[i], points.E[i], points.kappa[i], points.nmodes, points.free,
            points.parent, points.at[i])
    p = exact.char_poly(*args)
    if p == 0:
        label[row], by[row] = DEGENERATE, BY["degenerate"]
        return
    coeffs = p.coeffs()
    m0 = next(j for j, c in enumerate(coeffs) if c != 0)
    if m0 > zeros:
        label[row], by[row] = UNDECIDED, BY["zero_root"]
        return
    derivs = []
    for k in liquid:
        body = points.body[i].copy()
        h = body[k, layout.A] if body[k, layout.A] != 0.0 else 1.0
        body[k, layout.A] += h
        derivs.append((exact.char_poly(body, *args[1:]) - p) / exact._q(h))
    nonzero = flint.fmpq_poly(coeffs[m0:])
    sig, sig_r, freq, open_ = [], [], [], []
    old = flint.ctx.prec
    flint.ctx.prec = ARB_PREC
    try:
        dk = [flint.arb_poly([flint.arb(c) for c in d.coeffs()]) for d in derivs]
        for root, mult in nonzero.complex_roots():
            x = root.real  # every root is real here (N_c = 0 proved)
            q = sum((flint.arb(float(eps[j]), float(eps_r[j])) * (x + flint.arb(float(points.body[i, k, layout.OMEGA]))) * dk[j](x)
                     for j, k in enumerate(liquid)), flint.arb(0))
            s = _split(p, x, q, mult)
            if s is None:
                open_.append("multiple_root" if mult > 1 else "zero_rate")
                continue
            mid = float(s.mid())
            lo, hi = down(s), up(s)
            sig.append(mid)
            sig_r.append(max(mid - lo, hi - mid) * (1.0 + 4.0 * U))
            freq.append(float(x.mid()))
            if mult > 1:
                open_.append("split")  # proved growing, at order eps^(1/m): not a first-order rate
    finally:
        flint.ctx.prec = old
    sig, sig_r, freq = np.array(sig), np.array(sig_r), np.array(freq)
    undecided = [w for w in open_ if w != "split"]
    grows = bool(np.any(sig - sig_r > 0))
    if undecided and not grows:
        label[row], by[row] = UNDECIDED, BY[undecided[0]]
        return
    _put(row, sig, sig_r, freq, label, by, rate, BY["split_multiple_root"] if "split" in open_ else BY["first_order_arb"])
    if undecided:  # another root grows, so the label is proved; the largest rate is not (a root's rate is unknown)
        rate["upper"][row] = np.nan


def _split(p, x, q, mult: int):
    """The growth rate of the fastest branch of the root x of p (multiplicity ``mult``) as an arb, or None if its
    sign is not proved.  A simple root moves by i q / p'(x): sigma = -q / p'(x).  A root of multiplicity m >= 2 that
    the liquid feels (q(x) != 0) splits as delta^m = i m! q / p^(m)(x) (Puiseux): m branches of size
    eps^(1/m) spread evenly around x, and one of them always lies in the growing half plane."""
    if mult == 1:
        dp = flint.arb_poly([flint.arb(c) for c in p.derivative().coeffs()])
        s = -q / dp(x)
        return s if (s > 0 or s < 0) else None
    if not (q > 0 or q < 0):
        return None
    d = p
    for _ in range(mult):
        d = d.derivative()
    pm = flint.arb_poly([flint.arb(c) for c in d.coeffs()])(x)
    c = q * math.factorial(mult) / pm  # delta^m = i c
    phase = flint.arb.pi() / 2 if c > 0 else -flint.arb.pi() / 2
    size = abs(c).root(mult)
    branch = max((-((phase + 2 * k * flint.arb.pi()) / mult).sin() for k in range(mult)), key=lambda v: float(v.mid()))
    return size * branch


def _rate_variables(rate: dict) -> dict[str, np.ndarray]:
    lo, hi = outward_float32(rate["lower"], rate["upper"])
    best = np.clip(rate["best"].astype(np.float32), lo, hi)
    with np.errstate(divide="ignore"):
        tau = (np.float32(1) / np.abs(best)).astype(np.float32)
    return {"growth_rate": best, "growth_rate_lower": lo, "growth_rate_upper": hi, "time_constant": tau,
            "frequency": rate["frequency"].astype(np.float32)}
