"""Independent references for the viscous-liquid model (issue 31): a test oracle, no tests in it.

The model under test (the lead's claim, docs of stabmap.systems.viscous) adds to stabmap's characteristic
matrix Φ(λ) = λ²M + λG − K (docs/model.md, solutions ∝ e^{iλt}) the first-order (small Reynolds number)
moment of a viscous liquid, Chernousko's λ_k = −(ρ_k/ν_k) P_k ω̇_k:

    Φ_ε(λ) = Φ(λ) − i diag_k(ε_k λ² (λ + ω_k)),        ε_k = ρ_k P_k / ν_k   [kg m2 s],

and claims the first-order growth rate of a simple real root λ₀ of p = det Φ

    σ = −Im λ = −Σ_k ε_k λ₀² (λ₀ + ω_k) cof_kk(Φ(λ₀)) / p′(λ₀)          [s-1], negative = decays.

Nothing here imports stabmap. Three references, each built without the thing it checks:

* :func:`vector_top_rates` and :func:`free_body_rate` derive the heavy symmetric top (and the free symmetric
  body) from the vector law d/dt(H + λ) = r × F in inertial axes with sympy, linearise it about the upright
  spin and take the eigenvalues of the real first-order system in mpmath: no Φ, no convention for λ.
  :func:`integrate_top` integrates the same linear ODE with scipy and fits the rates from the solution.
* :func:`chain_rates_mp` takes the eigenvalues of the cubic matrix polynomial Φ_ε itself (companion
  linearisation in mpmath), so the first-order formula is checked against the full perturbed problem.
  :func:`fixed_chain_matrices` and :func:`free_chain_matrices` retype docs/model.md's M, G, K in fractions.
* :func:`first_order_rates_mp` is the claimed formula, with cofactors and p′ (Jacobi's formula) in mpmath.

The Chernousko term is a singular perturbation: the cubic has n extra roots of size ~ A/ε (for the top
λ ≈ −iA/ε, a growth rate of +A/ε), outside the model's validity. The references report only the 2n roots
that stay bounded as ε → 0 and check that the others are far away.
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

import mpmath as mp
import numpy as np
import sympy

__all__ = [
    "sphere_P",
    "vector_top_ode",
    "vector_top_exponents",
    "vector_top_rates",
    "free_body_rate",
    "integrate_top",
    "vector_chain_ode",
    "vector_chain_exponents",
    "cubic_roots_mp",
    "fixed_chain_matrices",
    "free_chain_matrices",
    "phi_eps",
    "rigid_roots_mp",
    "chain_rates_mp",
    "first_order_rates_mp",
]


def sphere_P(a):
    """Chernousko's transverse tensor entry of a spherical cavity of radius ``a`` [m], 8πa⁷/525 [m7], in mpmath.

    The tests check it against the Stokes solution u = (r² − a²)/(10ν) (ω̇ × r) by quadrature.
    """
    a = mp.mpf(a)
    return 8 * mp.pi * a**7 / 525


# ---------------------------------------------------------------------------------------------------------
# 1a, 1b: the heavy top and the free body in vector form
# ---------------------------------------------------------------------------------------------------------

_A, _C, _m, _g, _c, _w, _eps = sympy.symbols("A C m g c omega epsilon", real=True)


@lru_cache(maxsize=None)
def vector_top_ode():
    """Linearise the vector equations of the heavy symmetric top with a viscous-liquid cavity.

    Inertial axes x, y, z (z up); the fixed point at the origin; gravity −g ẑ; the symmetry axis
    e₃ = (x, y, √(1 − x² − y²)); the centre of mass at c e₃. The body's angular velocity is
    Ω = e₃ × ė₃ + ω e₃ (the spin component ω stays constant: no axial torque), its angular momentum about
    the fixed point, the liquid frozen, H = A (e₃ × ė₃) + C ω e₃ (A, C about the fixed point). The liquid's
    relative angular momentum is λ = −ε Ω̇_⊥, with Ω̇ the derivative of Ω in the body (equal to its
    inertial derivative, since Ω × Ω = 0) and ⊥ the part transverse to e₃ (P isotropic about the axis; the
    axial part vanishes here). Euler: d/dt(H + λ) = c e₃ × (−m g ẑ).

    Returns
    -------
    tuple of four 2×2 sympy matrices (B0, B1, B2, B3)
        The x and y components linearised about x = y = 0: Σ_j B_j q⁽ʲ⁾ = 0 with q = (x, y).
    """
    t, d = sympy.symbols("t delta", real=True)
    x, y = sympy.Function("x")(t), sympy.Function("y")(t)
    e3 = sympy.Matrix([d * x, d * y, sympy.sqrt(1 - d**2 * (x**2 + y**2))])
    e3d = e3.diff(t)
    W = e3.cross(e3d) + _w * e3
    Wd = W.diff(t)
    lam = -_eps * (Wd - (Wd.dot(e3)) * e3)
    H = _A * e3.cross(e3d) + _C * _w * e3
    torque = (_c * e3).cross(sympy.Matrix([0, 0, -_m * _g]))
    eq = (H + lam).diff(t) - torque
    # first order in the tilt: d/dδ at δ = 0; then each derivative q_k^(j) becomes a symbol, highest first
    lin = [sympy.expand(sympy.diff(eq[i], d).subs(d, 0)) for i in range(2)]
    q = [x, y]
    sym = [[sympy.Symbol(f"q{k}_{j}") for k in range(2)] for j in range(4)]
    for j in (3, 2, 1, 0):
        for k in range(2):
            lin = [e.subs(q[k].diff(t, j) if j else q[k], sym[j][k]) for e in lin]
    flat = [s for row in sym for s in row]
    assert all(e.free_symbols <= set(flat) | {_A, _C, _m, _g, _c, _w, _eps} for e in lin)
    B = [sympy.Matrix(2, 2, lambda i, k: sympy.diff(lin[i], sym[j][k])) for j in range(4)]
    # linear: nothing is left once Σ B_j q^(j) is taken away
    for i in range(2):
        assert sympy.expand(lin[i] - sum(B[j][i, k] * sym[j][k] for j in range(4) for k in range(2))) == 0
    return tuple(B)


def _state_matrix_mp(params, dps):
    """The real 6×6 first-order system z' = S z, z = (q, q', q''), of the linearised vector top, in mpmath."""
    B = vector_top_ode()
    sub = {_A: params[0], _C: params[1], _m: params[2], _g: params[3], _c: params[4], _w: params[5], _eps: params[6]}
    with mp.workdps(dps):
        Bm = [mp.matrix([[_mp_rational(Bj[i, k].subs(sub)) for k in range(2)] for i in range(2)]) for Bj in B]
        inv3 = mp.inverse(Bm[3])
        S = mp.zeros(6, 6)
        for i in range(4):
            S[i, i + 2] = 1
        for j in range(3):
            blk = -inv3 * Bm[j]
            for i in range(2):
                for k in range(2):
                    S[4 + i, 2 * j + k] = blk[i, k]
        return S


def _mp_rational(r):
    r = sympy.Rational(r)
    return mp.mpf(int(r.p)) / int(r.q)


def _exact(v):
    """An exact sympy Rational of a float (its binary value), int, Fraction or mpf, so the oracle stays exact."""
    if isinstance(v, mp.mpf):
        man, exp = mp.mpf(v).man_exp
        return sympy.Rational(man) * sympy.Rational(2) ** exp
    if isinstance(v, Fraction):
        return sympy.Rational(v.numerator, v.denominator)
    return sympy.Rational(Fraction(v))


def vector_top_exponents(A, C, m, g, c, omega, eps, dps=40):
    """The four exponents s (motions ∝ e^{st}) of the linearised vector top that stay bounded as ε → 0 (mpmath).

    The real 6-D system's other pair (|s| ≈ A/ε) is the singular perturbation's; it is checked to lie 10× out.
    """
    params = tuple(_exact(v) for v in (A, C, m, g, c, omega, eps))
    with mp.workdps(dps):
        S = _state_matrix_mp(params, dps)
        s = sorted(mp.eig(S, left=False, right=False), key=abs)
        phys, spur = s[:4], s[4:]
        # the singular perturbation's pair sits near |s| = A/ε, far beyond the bounded four
        if min(abs(z) for z in spur) < 10 * max(abs(z) for z in phys):
            raise ValueError("eps is not small: the spurious roots are not separated from the physical ones")
        return phys


def _pairs(rates, dps):
    rates = sorted(rates)
    tol = mp.mpf(10) ** (-dps // 2) * (1 + max(abs(r) for r in rates))
    assert abs(rates[0] - rates[1]) <= tol and abs(rates[2] - rates[3]) <= tol, rates
    return [rates[0], rates[2]]


def vector_top_rates(A, C, m, g, c, omega, eps, dps=40):
    """Growth rates [s-1] of the heavy top's two bounded modes, from the vector equations (:func:`vector_top_ode`).

    Parameters
    ----------
    A, C : float
        Equatorial and axial moments of inertia about the fixed point, liquid frozen [kg m2].
    m, g, c : float
        Mass [kg], gravity [m s-2] and height of the centre of mass above the fixed point [m].
    omega : float
        Spin rate [rad s-1].
    eps : float
        ρP/ν of the cavity [kg m2 s]; small (the spurious pair must lie 10× beyond the physical roots).

    Returns
    -------
    list of two mpf, ascending
        The real parts of the exponents s (motions ∝ e^{st}) of the 6-D real system that stay bounded as
        ε → 0. Each mode is a conjugate pair of s; one rate per mode is returned.
    """
    with mp.workdps(dps):
        return _pairs([mp.re(z) for z in vector_top_exponents(A, C, m, g, c, omega, eps, dps)], dps)


def free_body_rate(A, C, omega, eps, dps=40):
    """Growth rates [s-1] of a free symmetric body spinning about its axis: the neutral tilt's 0 and the nutation's.

    The body is :func:`vector_top_ode` without gravity (a free body turns about its centre of mass as about a
    fixed point, A and C central). Returns the two bounded modes' rates in ascending order: one is the
    neutral tilt's (exactly 0), the other the nutation's.
    """
    return vector_top_rates(A, C, 1, 0, 0, omega, eps, dps)


def integrate_top(A, C, m, g, c, omega, eps, t_span, samples=4000, tilt=1e-3, method="DOP853"):
    """Integrate the linearised vector top with scipy and fit the growth rates of its bounded modes.

    The spurious mode grows like e^{At/ε} forward in time, so any rounding would swamp the solution; backward
    in time it decays at that rate instead, while the physical modes keep their exponents. So the ODE is
    integrated from t = 0 to t = −t_span (DOP853, rtol 1e-12; its step control keeps the decaying spurious
    mode stable; ``method="Radau"`` gives the same at ~20× the cost), starting from a small tilt with a
    kick (x = tilt, ẏ = tilt [s-1], the rest 0; without the kick a free body would just stay tilted).

    The fit: z = x + iy is a sum of e^{s t} over the physical exponents of one of the two conjugate complex
    equations once the spurious part has died out. With g = 0 one exponent is 0, so the nutation is the only
    one in ż and its rate is the slope of log|ż| (the envelope). With gravity both modes are present and
    the two exponents come from a linear-prediction (Prony) fit z_{j+2} = a₁ z_{j+1} + a₀ z_j of the samples.

    Returns
    -------
    list of float, ascending
        The fitted rates [s-1]: ``[0, σ]`` for g·m·c = 0 (the 0 is not fitted), else both modes' rates.
    """
    from scipy.integrate import solve_ivp

    params = tuple(_exact(v) for v in (A, C, m, g, c, omega, eps))
    S = np.array(_state_matrix_mp(params, 30).tolist(), dtype=float)
    z0 = np.zeros(6)
    z0[0] = tilt
    z0[3] = tilt  # a kick: without one a free body would just stay tilted
    sol = solve_ivp(lambda t, z: S @ z, (0.0, -t_span), z0, method=method, rtol=1e-12, atol=1e-18,
                    dense_output=True)
    if not sol.success:
        raise RuntimeError(sol.message)
    # skip the first stretch, where the spurious mode (rate A/ε) is still dying out
    t = np.linspace(-0.1 * t_span, -t_span, samples)
    Z = sol.sol(t)
    if float(g) * float(m) * float(c) == 0.0:
        zd = np.abs(Z[2] + 1j * Z[3])
        slope = np.polyfit(t, np.log(zd), 1)[0]
        return sorted([0.0, float(slope)])
    z = Z[0] + 1j * Z[1]
    h = t[1] - t[0]
    X = np.column_stack([z[1:-1], z[:-2]])
    a1, a0 = np.linalg.lstsq(X, z[2:], rcond=None)[0]
    mu = np.roots([1.0, -a1, -a0])
    return sorted(float(np.real(np.log(u) / h)) for u in mu)


@lru_cache(maxsize=None)
def vector_chain_ode(n, support):
    """Newton–Euler equations of a chain of n symmetric bodies with viscous cavities, linearised (sympy).

    Independent of docs/model.md's M, G, K, J and of the claimed Φ_ε: every body is placed in inertial axes
    (z up) by its axis e_k = (x_k, y_k, √(1 − x_k² − y_k²)): O_{k+1} = O_k + s_k e_k, centre of mass
    r_k = O_k + c_k e_k. O_1 is the fixed point (``"fixed"``) or placed so that the centre of mass of the
    system stays at the origin (``"free"``, no gravity). The force of body k−1 on body k at O_k is
    R_k = Σ_{j≥k} m_j (r̈_j + g ẑ) (R_1 is the support's reaction; it vanishes for a free chain). Each body's
    Euler equation about its own centre of mass:

        d/dt(H_k + λ_k) = (O_k − r_k) × R_k − (O_{k+1} − r_k) × R_{k+1} + τ_k,

    H_k = A_k (e_k × ė_k) + C_k ω_k e_k (A_k about the centre of mass), λ_k = −ε_k Ω̇_k⊥ as in
    :func:`vector_top_ode`, and τ_k the elastic torques: joint j (stiffness K_j, potential K_j |e_{j+1} − e_j|²/2)
    acts with K_j e_{j+1} × e_j on body j+1 and the opposite on body j; the base (K_0, potential
    K_0 |e_1 − ẑ|²/2) with K_0 e_1 × ẑ on body 1.

    Returns
    -------
    (B, symbols)
        B = (B0, B1, B2, B3), 2n×2n sympy matrices with Σ_j B_j q⁽ʲ⁾ = 0, q = (x_1, y_1, …, x_n, y_n); symbols a
        dict of the parameter symbols: m, A, C, c, s, omega, eps (lists of n), g, K (list of n−1), K0.
    """
    t, d = sympy.symbols("t delta", real=True)
    S = {key: [sympy.Symbol(f"{key}{k + 1}", real=True) for k in range(n)]
         for key in ("m", "A", "C", "c", "s", "omega", "eps")}
    S["K"] = [sympy.Symbol(f"K{k + 1}", real=True) for k in range(n - 1)]
    S["g"], S["K0"] = sympy.symbols("g K0", real=True)
    g = S["g"] if support == "fixed" else 0
    X = [(sympy.Function(f"x{k + 1}")(t), sympy.Function(f"y{k + 1}")(t)) for k in range(n)]
    e = [sympy.Matrix([d * x, d * y, sympy.sqrt(1 - d**2 * (x**2 + y**2))]) for x, y in X]
    zhat = sympy.Matrix([0, 0, 1])
    O = [sympy.zeros(3, 1)]
    for k in range(n):
        O.append(O[k] + S["s"][k] * e[k])
    r = [O[k] + S["c"][k] * e[k] for k in range(n)]
    if support == "free":
        shift = sum((S["m"][k] * r[k] for k in range(n)), sympy.zeros(3, 1)) / sum(S["m"])
        O = [o - shift for o in O]
        r = [p - shift for p in r]
    acc = [p.diff(t, 2) for p in r]
    R = [sum((S["m"][j] * (acc[j] + g * zhat) for j in range(k, n)), sympy.zeros(3, 1)) for k in range(n)]
    R.append(sympy.zeros(3, 1))
    tau = [sympy.zeros(3, 1) for _ in range(n)]
    for j in range(n - 1):
        tau[j + 1] += S["K"][j] * e[j + 1].cross(e[j])
        tau[j] += S["K"][j] * e[j].cross(e[j + 1])
    if support == "fixed":
        tau[0] += S["K0"] * e[0].cross(zhat)
    eqs = []
    for k in range(n):
        ed = e[k].diff(t)
        W = e[k].cross(ed) + S["omega"][k] * e[k]
        Wd = W.diff(t)
        lam = -S["eps"][k] * (Wd - Wd.dot(e[k]) * e[k])
        H = S["A"][k] * e[k].cross(ed) + S["C"][k] * S["omega"][k] * e[k]
        rhs = (O[k] - r[k]).cross(R[k]) - (O[k + 1] - r[k]).cross(R[k + 1]) + tau[k]
        eq = (H + lam).diff(t) - rhs
        eqs += [eq[0], eq[1]]
    lin = [sympy.expand(sympy.diff(q, d).subs(d, 0)) for q in eqs]
    q = [v for pair in X for v in pair]
    sym = [[sympy.Symbol(f"q{k}_{j}") for k in range(2 * n)] for j in range(4)]
    for j in (3, 2, 1, 0):
        for k in range(2 * n):
            lin = [ex.subs(q[k].diff(t, j) if j else q[k], sym[j][k]) for ex in lin]
    B = [sympy.Matrix(2 * n, 2 * n, lambda i, k: sympy.diff(lin[i], sym[j][k])) for j in range(4)]
    for i in range(2 * n):
        assert sympy.expand(lin[i] - sum(B[j][i, k] * sym[j][k] for j in range(4) for k in range(2 * n))) == 0
    return tuple(B), S


def vector_chain_exponents(bodies, joints, support, eps, g=0, K0=0, dps=40):
    """All 6n exponents s (motions ∝ e^{st}) of :func:`vector_chain_ode` for the given numbers, in mpmath.

    ``bodies``: dicts with m, A (about the centre of mass), C, c, s (the top body's may be left out), omega;
    ``eps``: ε_k ≥ 0 [kg m2 s]. Values are taken at their exact binary value. Returns the finite exponents.
    """
    n = len(bodies)
    B, S = vector_chain_ode(n, support)
    sub = {S["g"]: _exact(g), S["K0"]: _exact(K0)}
    for k, b in enumerate(bodies):
        for key in ("m", "A", "C", "c", "omega"):
            sub[S[key][k]] = _exact(b[key])
        sub[S["s"][k]] = _exact(b.get("s", 0))
        sub[S["eps"][k]] = _exact(eps[k])
    for k, Kk in enumerate(joints):
        sub[S["K"][k]] = _exact(Kk)
    with mp.workdps(dps):
        Bm = [mp.matrix([[_mp_rational(Bj[i, k].xreplace(sub)) for k in range(2 * n)] for i in range(2 * n)])
              for Bj in B]
        return list(_companion_eigs(Bm))


# ---------------------------------------------------------------------------------------------------------
# 1c: chains, from docs/model.md retyped in fractions
# ---------------------------------------------------------------------------------------------------------

def _F(v):
    return v if isinstance(v, Fraction) else Fraction(v)


def _lever(bodies, free):
    """J of docs/model.md: J_ki = s_i (i < k), c_k (i = k), 0 (i > k); free: minus the mass-weighted column mean."""
    n = len(bodies)
    m = [_F(b["m"]) for b in bodies]
    J = [[_F(bodies[i]["s"]) if i < k else (_F(bodies[k]["c"]) if i == k else Fraction(0)) for i in range(n)]
         for k in range(n)]
    if free:
        mt = sum(m)
        for i in range(n):
            mean = sum(m[j] * J[j][i] for j in range(n)) / mt
            for k in range(n):
                J[k][i] -= mean
    return J


def _chain(bodies, joints, free, g=0, K0=0):
    n = len(bodies)
    m = [_F(b["m"]) for b in bodies]
    J = _lever(bodies, free)
    M = [[(_F(bodies[i]["A"]) if i == k else Fraction(0)) + sum(J[j][i] * m[j] * J[j][k] for j in range(n))
          for k in range(n)] for i in range(n)]
    G = [[_F(bodies[i]["C"]) * _F(bodies[i]["omega"]) if i == k else Fraction(0) for k in range(n)] for i in range(n)]
    K = [[Fraction(0)] * n for _ in range(n)]
    for k, Kk in enumerate(joints):  # joint k+1 joins body k+2 to body k+1 (0-based k, k+1)
        Kk = _F(Kk)
        K[k][k] += Kk
        K[k + 1][k + 1] += Kk
        K[k][k + 1] -= Kk
        K[k + 1][k] -= Kk
    if not free:
        K[0][0] += _F(K0)
        for k in range(n):
            a_k = m[k] * _F(bodies[k]["c"]) + (_F(bodies[k]["s"]) * sum(m[k + 1:]) if k < n - 1 else 0)
            K[k][k] -= _F(g) * a_k
    return M, G, K


def fixed_chain_matrices(bodies, joints=(), g=Fraction(981, 100), K0=0):
    """M, G, K [fractions] of a chain on a fixed point (docs/model.md, "Linearised equations").

    ``bodies``: dicts with m, A (about the body's centre of mass), C, c, s (s unused for the top body), omega.
    ``joints``: K_1..K_{n-1}. Values are taken at their exact binary value.
    """
    return _chain(bodies, joints, free=False, g=g, K0=K0)


def free_chain_matrices(bodies, joints=()):
    """M, G, K [fractions] of a free chain (docs/model.md: J minus its mass-weighted column means, no gravity)."""
    return _chain(bodies, joints, free=True)


def _mpf(v):
    """An mpf of a Fraction, int, float (its binary value) or mpf, exact up to the working precision."""
    if isinstance(v, Fraction):
        return mp.mpf(v.numerator) / v.denominator
    if isinstance(v, sympy.Rational):
        return mp.mpf(int(v.p)) / int(v.q)
    return mp.mpf(v)


def _mpm(X):
    return mp.matrix([[_mpf(v) for v in row] for row in X])


def phi_eps(M, G, K, omega, eps, lam):
    """Φ_ε(λ) = λ²M + λG − K − i diag(ε_k λ²(λ + ω_k)) as an mpmath matrix (the claimed model)."""
    n = len(M)
    P = lam**2 * _mpm(M) + lam * _mpm(G) - _mpm(K)
    for k in range(n):
        P[k, k] -= 1j * _mpf(eps[k]) * lam**2 * (lam + _mpf(omega[k]))
    return P


def _companion_eigs(coeffs, shift=None):
    """Finite eigenvalues of Σ_j coeffs[j] λ^j (n×n mpmath matrices) from a block companion.

    With a singular leading coefficient (a body without liquid: ε_k = 0) the problem is first moved to
    μ = 1/(λ − shift): Σ_j T_j μ^{d−j} with T_j the Taylor coefficients at the shift, whose leading one Φ(shift)
    is invertible; μ = 0 are the infinite λ and are dropped.
    """
    d = len(coeffs) - 1
    n = coeffs[0].rows
    if shift is None and abs(mp.det(coeffs[d])) == 0:
        shift = mp.mpc("0.5377", "0.3141") * (1 + mp.mnorm(coeffs[0], 1) / (1 + mp.mnorm(coeffs[d - 1], 1)))
    if shift is not None:
        taylor = [sum((mp.binomial(i, j) * shift ** (i - j) * coeffs[i] for i in range(j, d + 1)), mp.zeros(n, n))
                  for j in range(d + 1)]
        mus = _companion_eigs(taylor[::-1])
        tiny = mp.mpf(10) ** (-mp.mp.dps // 2)
        return [shift + 1 / u for u in mus if abs(u) > tiny * max(abs(v) for v in mus)]
    inv = mp.inverse(coeffs[d])
    L = mp.zeros(d * n, d * n)
    for i in range((d - 1) * n):
        L[i, i + n] = 1
    for j in range(d):
        blk = -inv * coeffs[j]
        for r in range(n):
            for q in range(n):
                L[(d - 1) * n + r, j * n + q] = blk[r, q]
    return mp.eig(L, left=False, right=False)


def rigid_roots_mp(M, G, K, dps=40):
    """The 2n roots of p = det(λ²M + λG − K), from the quadratic companion in mpmath, sorted by real part."""
    with mp.workdps(dps):
        return sorted(_companion_eigs([-_mpm(K), _mpm(G), _mpm(M)]), key=lambda z: (mp.re(z), mp.im(z)))


def _cubic_coeffs(M, G, K, omega, eps):
    n = len(M)
    w = [_mpf(v) for v in omega]
    e = [_mpf(v) for v in eps]
    A2 = _mpm(M)
    A3 = mp.zeros(n, n)
    for k in range(n):
        A2[k, k] -= 1j * e[k] * w[k]
        A3[k, k] = -1j * e[k]
    return [-_mpm(K), _mpm(G), A2, A3]


def cubic_roots_mp(M, G, K, omega, eps, dps=40):
    """The finite roots of det Φ_ε(λ) (the claimed model), bounded and spurious: 2n + #{k: ε_k > 0}."""
    with mp.workdps(dps):
        if any(_mpf(e) < 0 for e in eps):
            raise ValueError("every eps_k must be positive, or 0 for a body without liquid")
        return list(_companion_eigs(_cubic_coeffs(M, G, K, omega, eps)))


def chain_rates_mp(M, G, K, omega, eps, dps=40):
    """The bounded roots of det Φ_ε = 0 (the full cubic problem) matched to the roots of det Φ.

    Parameters
    ----------
    M, G, K : n×n nested lists of numbers (fractions are exact), n ≤ 3
    omega : sequence of n spin rates [rad s-1]
    eps : sequence of n ε_k = ρ_k P_k / ν_k ≥ 0 [kg m2 s] (0: a body without liquid)

    Returns
    -------
    list of (λ₀, λ, σ) sorted by Re λ₀
        λ₀ a root of det Φ, λ the root of det Φ_ε nearest to it, σ = −Im λ its growth rate [s-1]. The roots
        left over (size ~ A/ε, one per body with ε_k > 0) are the singular perturbation's and are checked to lie
        10× farther out.
    """
    with mp.workdps(dps):
        cubic = cubic_roots_mp(M, G, K, omega, eps, dps)
        rigid = rigid_roots_mp(M, G, K, dps)
        out = []
        for r in rigid:
            j = min(range(len(cubic)), key=lambda i: abs(cubic[i] - r))
            out.append((r, cubic.pop(j), None))
        far = min(abs(z) for z in cubic)
        if far < 10 * max(abs(r) for r in rigid):
            raise ValueError("eps is not small: the spurious roots are not separated from the bounded ones")
        return [(r, z, -mp.im(z)) for r, z, _ in out]


def _cofactor(P, i, j):
    n = P.rows
    if n == 1:
        return mp.mpf(1)
    rows = [r for r in range(n) if r != i]
    cols = [q for q in range(n) if q != j]
    sub = mp.matrix([[P[r, q] for q in cols] for r in rows])
    return (-1) ** (i + j) * mp.det(sub)


def first_order_rates_mp(M, G, K, omega, eps, dps=40):
    """The claimed first-order rates σ = −Σ_k ε_k λ₀²(λ₀ + ω_k) cof_kk(Φ(λ₀)) / p′(λ₀), in mpmath.

    p′(λ₀) by Jacobi's formula, Σ_ij cof_ij(Φ) Φ′_ij with Φ′ = 2λM + G. Only for real simple roots.

    Returns
    -------
    list of (λ₀, σ) sorted by λ₀
    """
    n = len(M)
    with mp.workdps(dps):
        Mm, Gm = _mpm(M), _mpm(G)
        out = []
        for r in rigid_roots_mp(M, G, K, dps):
            if abs(mp.im(r)) > mp.mpf(10) ** (-dps // 2) * (1 + abs(r)):
                raise ValueError(f"root {mp.nstr(r, 8)} of det Phi is not real: no first-order rate")
            lam0 = mp.re(r)
            P = phi_eps(M, G, K, omega, [0] * n, lam0)
            P = mp.matrix([[mp.re(P[i, j]) for j in range(n)] for i in range(n)])
            dP = 2 * lam0 * Mm + Gm
            dp = mp.fsum(_cofactor(P, i, j) * dP[i, j] for i in range(n) for j in range(n))
            num = mp.fsum(_mpf(eps[k]) * lam0**2 * (lam0 + _mpf(omega[k])) * _cofactor(P, k, k) for k in range(n))
            out.append((lam0, -num / dp))
        return out
