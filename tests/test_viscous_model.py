"""The viscous-liquid model (issue 31) against independent references (tests/viscous_reference.py).

Part 1 checks the claimed model itself, Φ_ε(λ) = Φ(λ) − i diag(ε_k λ²(λ + ω_k)) and its first-order growth rate
σ = −Σ_k ε_k λ₀²(λ₀ + ω_k) cof_kk(Φ(λ₀)) / p′(λ₀), against the vector equations of the heavy top and of the free
body, a time integration, Chernousko's Stokes solution for the sphere and the full cubic eigenproblem. Part 2
(at the end) checks stabmap's implementation of it, once stabmap.systems.viscous exists; it skips until then.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath as mp
import numpy as np
import pytest
import sympy

import reference as ref
import viscous_reference as vr

# A heavy top in SI units: m, A and C about the fixed point, liquid frozen. ω* = 7.0036 rad/s; Maievskii's
# ω_M = 6.862 rad/s (below it the roots of p are complex already).
TOP = dict(A=Fraction(3, 100), C=Fraction(5, 100), m=Fraction(1), g=Fraction(981, 100), c=Fraction(1, 10))


def q(x):
    """An exact Fraction as an mpf."""
    x = Fraction(x)
    return mp.mpf(x.numerator) / x.denominator


def omega_star(A, C, m, g, c):
    return mp.sqrt(q(m * g * c / (C - A)))


# ---------------------------------------------------------------------------------------------------------
# The sphere's tensor entry from the Stokes problem
# ---------------------------------------------------------------------------------------------------------

def test_sphere_tensor_is_the_stokes_solution():
    """P = 8πa⁷/525: u = (r² − a²)/(10ν)(b × r) solves Stokes with the Euler force, and ρ∫ r × u = −(ρ/ν)P b."""
    x, y, z, a, nu, rho, r, th, ph = sympy.symbols("x y z a nu rho r theta phi", positive=True)
    b = sympy.Matrix(sympy.symbols("b1 b2 b3", real=True))
    R = sympy.Matrix([x, y, z])
    u = (x**2 + y**2 + z**2 - a**2) / (10 * nu) * b.cross(R)
    lap = sympy.Matrix([sum(sympy.diff(ui, v, 2) for v in (x, y, z)) for ui in u])
    # in the body frame at small Re: 0 = −∇p/ρ + ν∇²u − ω̇ × r, with p constant and ω̇ = b
    assert sympy.simplify(nu * lap - b.cross(R)) == sympy.zeros(3, 1)
    assert sympy.simplify(sum(sympy.diff(u[i], v) for i, v in enumerate((x, y, z)))) == 0
    assert sympy.simplify(u.subs(z, sympy.sqrt(a**2 - x**2 - y**2))) == sympy.zeros(3, 1)
    sph = {x: r * sympy.sin(th) * sympy.cos(ph), y: r * sympy.sin(th) * sympy.sin(ph), z: r * sympy.cos(th)}
    L = (rho * R.cross(u)).subs(sph) * r**2 * sympy.sin(th)
    L = L.applyfunc(lambda e: sympy.integrate(sympy.expand(e), (ph, 0, 2 * sympy.pi), (th, 0, sympy.pi), (r, 0, a)))
    P = sympy.Rational(8, 525) * sympy.pi * a**7
    assert sympy.simplify(L + rho / nu * P * b) == sympy.zeros(3, 1)
    assert abs(vr.sphere_P(mp.mpf("0.03")) - mp.mpf(8) * mp.pi * mp.mpf("0.03") ** 7 / 525) < mp.mpf(10) ** -25


# ---------------------------------------------------------------------------------------------------------
# The vector top and the free body
# ---------------------------------------------------------------------------------------------------------

def test_vector_top_without_liquid_is_maievskii():
    """At ε → 0 the vector top's exponents are s = ±iλ with A λ² + C ω λ + m g c = 0 (docs/model.md, n = 1)."""
    A, C, m, g, c = TOP.values()
    w = Fraction(12)
    lam = sympy.Symbol("lam")
    want = sorted(float(v) for v in sympy.solve(A * lam**2 + C * w * lam + m * g * c, lam))
    eps = Fraction(1, 10**15)
    rates = vr.vector_top_rates(A, C, m, g, c, w, eps, dps=60)
    assert all(abs(r) < 1e-9 for r in rates)
    s = vr.vector_top_exponents(A, C, m, g, c, w, eps, 60)
    freqs = sorted({round(float(abs(mp.im(z))), 9) for z in s})
    assert np.allclose(freqs, sorted(abs(v) for v in want), rtol=1e-12)


@pytest.mark.parametrize("top", [TOP, dict(TOP, C=Fraction(9, 100), c=Fraction(2, 10))])
def test_vector_top_criterion_around_omega_star(top):
    """(C − A)ω² > m g c ⇔ every bounded mode decays: stable just above ω*, unstable just below (and far below)."""
    ws = omega_star(**top)
    eps = Fraction(1, 10**7)
    for d in ("-0.3", "-0.05", "-0.001", "0.001", "0.05", "1", "5"):
        w = ws * (1 + mp.mpf(d))
        rates = vr.vector_top_rates(omega=w, eps=eps, **top)
        stable = q(top["C"] - top["A"]) * w**2 > q(top["m"] * top["g"] * top["c"])
        assert (max(rates) < 0) == stable, (d, rates)
        assert stable == (mp.mpf(d) > 0)


@pytest.mark.parametrize("c", [Fraction(-1, 10), Fraction(1, 10)])
def test_vector_top_criterion_either_sign(c):
    """The criterion in general: C < A is stable only hanging (c < 0) and slow, ω² < m g c/(C − A)."""
    top = dict(TOP, A=Fraction(5, 100), C=Fraction(3, 100), c=c)
    for w in (Fraction(2), Fraction(6), Fraction(7), Fraction(8), Fraction(30)):
        rates = vr.vector_top_rates(omega=w, eps=Fraction(1, 10**7), **top)
        stable = (top["C"] - top["A"]) * w**2 > top["m"] * top["g"] * top["c"]
        assert (max(rates) < 0) == stable, (w, rates)
    if c < 0:
        assert (max(vr.vector_top_rates(omega=6, eps=Fraction(1, 10**7), **top)) < 0) != \
               (max(vr.vector_top_rates(omega=8, eps=Fraction(1, 10**7), **top)) < 0)


@pytest.mark.parametrize("w", [Fraction(7), Fraction(15, 2), Fraction(20), Fraction(-20), Fraction(60)])
def test_vector_top_equals_the_claimed_cubic_and_first_order_rate(w):
    """The vector top's bounded exponents are the roots of Φ_ε (n = 1) exactly, and σ/ε tends to the formula."""
    A, C, m, g, c = TOP.values()
    M, G, K = [[A]], [[C * w]], [[-m * g * c]]
    first = sorted(s for _, s in vr.first_order_rates_mp(M, G, K, [w], [1]))
    errs = []
    for e in (Fraction(1, 10**6), Fraction(1, 10**7), Fraction(1, 10**8)):
        vec = vr.vector_top_rates(A, C, m, g, c, w, e)
        cubic = sorted(s for _, _, s in vr.chain_rates_mp(M, G, K, [w], [e]))
        assert all(abs(p - q) < mp.mpf(10) ** -30 for p, q in zip(vec, cubic))
        errs.append(max(abs(v / q(e) - f) / abs(f) for v, f in zip(vec, first)))
    assert errs[2] < 1e-4 and errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1], errs


@pytest.mark.parametrize("A, C", [(Fraction(2, 100), Fraction(3, 100)), (Fraction(3, 100), Fraction(2, 100)),
                                  (Fraction(5, 100), Fraction(49, 1000))])
@pytest.mark.parametrize("w", [Fraction(10), Fraction(-35)])
def test_free_body_major_axis_rule(A, C, w):
    """A free body spinning about its symmetry axis: the tilt stays neutral, the nutation decays iff C > A.

    The rate also equals the closed form of the claimed formula, σ = ε λ₀² (A − C)/(A C) at λ₀ = −Cω/A.
    """
    eps = Fraction(1, 10**8)
    neutral, nut = sorted(vr.free_body_rate(A, C, w, eps), key=abs)
    assert abs(neutral) < mp.mpf(10) ** -35
    assert (nut < 0) == (C > A)
    lam0 = -C * w / A
    closed = lam0**2 * (A - C) / (A * C)
    assert abs(nut / q(eps) - q(closed)) < 1e-4 * abs(float(closed))


@pytest.mark.parametrize("args, t_span", [
    ((1, Fraction(3, 2), 1, 1, 1, 3, Fraction(1, 100)), 80),          # stable: both modes decay
    ((1, Fraction(3, 2), 1, 1, 1, Fraction(13, 10), Fraction(1, 100)), 20),  # between ω_M and ω*: one grows
    ((Fraction(3, 2), 1, 1, 0, 0, 3, Fraction(1, 100)), 60),          # free body, C < A: the nutation grows
])
def test_time_integration_agrees_with_the_eigenvalues(args, t_span):
    """solve_ivp on the linear vector ODE, rates fitted from the solution, equal the eigenvalues' rates."""
    want = [float(v) for v in vr.vector_top_rates(*args)]
    got = vr.integrate_top(*args, t_span)
    assert np.allclose(got, want, rtol=1e-6, atol=1e-10), (got, want)
    if args[3] == 0:
        assert got[1] > 0 and want[0] == 0
    else:
        assert max(got) < 0 if args[5] == 3 else max(got) > 0


# ---------------------------------------------------------------------------------------------------------
# Chains: the first-order formula against the full cubic problem
# ---------------------------------------------------------------------------------------------------------

BODIES = [dict(m=1, A=0.5, C=0.8, c=0.4, s=1.0), dict(m=0.7, A=0.3, C=0.5, c=0.3, s=0.8),
          dict(m=0.5, A=0.2, C=0.35, c=0.25)]
WEIGHTS = [1, Fraction(3, 5), Fraction(17, 10)]
CHAINS = {
    ("fixed", 2, "common"): [20, 20], ("fixed", 2, "distinct"): [30, 22],
    ("fixed", 3, "common"): [20, 20, 20], ("fixed", 3, "distinct"): [30, 22, 40],
    ("free", 2, "common"): [8, 8], ("free", 2, "distinct"): [15, -9],
    ("free", 3, "common"): [8, 8, 8], ("free", 3, "distinct"): [5, -3, 7],
}


def chain(support, omegas):
    bodies = [dict(BODIES[k], omega=omegas[k]) for k in range(len(omegas))]
    joints = [6.0, 4.0][: len(omegas) - 1]
    if support == "fixed":
        return vr.fixed_chain_matrices(bodies, joints), bodies, joints
    return vr.free_chain_matrices(bodies, joints), bodies, joints


@pytest.mark.parametrize("key", list(CHAINS))
def test_chain_matrices_agree_with_the_sympy_reference(key):
    """The retyped M, G, K equal tests/reference.py's (another restatement of docs/model.md)."""
    support, n, _ = key
    (M, G, K), bodies, joints = chain(support, CHAINS[key])
    bodies = [dict({"s": 0}, **b) for b in bodies]  # the top body's s is unused; the sympy reference wants a value
    RM, RG, RK = ref.system_matrices(bodies, support, g=Fraction(981, 100) if support == "fixed" else 0, joints=joints)
    for X, R in ((M, RM), (G, RG), (K, RK)):
        assert all(sympy.Rational(X[i][j].numerator, X[i][j].denominator) == R[i, j] for i in range(n) for j in range(n))


@pytest.mark.parametrize("support, n, omegas, K0, dry", [("fixed", 2, [30, 22], 3.0, None),
                                                         ("fixed", 3, [30, 22, 40], 0, None),
                                                         ("fixed", 3, [30, 22, 40], 0, 1),
                                                         ("free", 2, [15, -9], 0, None),
                                                         ("free", 3, [5, -3, 7], 0, None),
                                                         ("free", 3, [5, -3, 7], 0, 0)])
def test_newton_euler_chain_is_the_claimed_cubic(support, n, omegas, K0, dry):
    """The chain placed body by body in inertial axes (vector Newton–Euler, its own sympy derivation) has exactly
    the exponents s = iλ, −iλ̄ of the claimed det Φ_ε(λ) = 0, the spurious roots included: the liquid term is
    diagonal, with each body's own ω_k, in fixed and free chains, also with a body without liquid (``dry``)."""
    bodies = [dict(BODIES[k], omega=omegas[k]) for k in range(n)]
    joints = [6.0, 4.0][: n - 1]
    eps = [Fraction(1, 100), Fraction(3, 500), Fraction(17, 1000)][:n]
    if dry is not None:
        eps[dry] = 0
    g = Fraction(981, 100) if support == "fixed" else 0
    if support == "fixed":
        M, G, K = vr.fixed_chain_matrices(bodies, joints, g=g, K0=K0)
    else:
        M, G, K = vr.free_chain_matrices(bodies, joints)
    with mp.workdps(40):
        s = vr.vector_chain_exponents(bodies, joints, support, eps, g=g, K0=K0)
        lam = vr.cubic_roots_mp(M, G, K, omegas, eps)
        assert len(s) == 2 * len(lam) == 2 * (2 * n + sum(1 for e in eps if e))
        for want in [1j * z for z in lam] + [-1j * mp.conj(z) for z in lam]:
            j = min(range(len(s)), key=lambda i: abs(s[i] - want))
            assert abs(s.pop(j) - want) <= mp.mpf(10) ** -30 * (1 + abs(want))


@pytest.mark.parametrize("support, omegas, dry", [("fixed", [30, 22, 40], 1), ("free", [5, -3, 7], 0)])
def test_chain_with_a_dry_body_converges_to_the_first_order_formula(support, omegas, dry):
    """A body without liquid (ε_k = 0): one spurious root fewer, and σ(ε)/ε still tends to the formula."""
    (M, G, K), _, _ = chain(support, omegas)
    weights = list(WEIGHTS)
    weights[dry] = 0
    first = vr.first_order_rates_mp(M, G, K, omegas, weights)
    errs = []
    for e in (Fraction(1, 10**4), Fraction(1, 10**5), Fraction(1, 10**6)):
        got = vr.chain_rates_mp(M, G, K, omegas, [e * w for w in weights])
        errs.append(max(abs(s / q(e) - s1) / abs(s1) for (lam0, s1), (_, _, s) in zip(first, got)
                        if abs(lam0) > mp.mpf(10) ** -30))
        assert len(vr.cubic_roots_mp(M, G, K, omegas, [e * w for w in weights])) == 2 * 3 + 2
    assert errs[2] < 1e-2 and errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1], errs


def test_a_double_root_splits_at_order_sqrt_eps():
    """Maievskii's boundary with λ₀ + ω ≠ 0 (A = 1/16 about the fixed point, C = 1/4, m g c = 1, ω = 2: λ₀ = −4
    double): the first-order formula does not apply; the pair splits as ±√(iεX/A), X = λ₀²(λ₀ + ω), so one root
    grows like √(ε|X|/(2A)) = 16√ε. A multiple root is therefore not neutral: it is unstable unless X = 0."""
    A, C, mgc, w = Fraction(1, 16), Fraction(1, 4), Fraction(1), Fraction(2)
    with mp.workdps(50):
        for e in (Fraction(1, 10**8), Fraction(1, 10**10)):
            lam = sorted(vr.cubic_roots_mp([[A]], [[C * w]], [[-mgc]], [w], [e], dps=50), key=abs)[:2]
            rates = sorted(-mp.im(z) / mp.sqrt(q(e)) for z in lam)
            assert abs(rates[0] + 16) < 5e-3 * 16 and abs(rates[1] - 16) < 5e-3 * 16, rates  # next term O(ε)
            assert all(abs(z + 4) < 10 * mp.sqrt(q(e)) * 16 for z in lam)


def test_the_spurious_root_of_the_top():
    """The singular perturbation's root: λ = −iA/ε + (C − A)ω/A + O(ε), a growth rate of +A/ε, to be left out."""
    A, C, m, g, c = TOP.values()
    w, e = Fraction(20), Fraction(1, 10**7)
    lam = vr.cubic_roots_mp([[A]], [[C * w]], [[-m * g * c]], [w], [e])
    with mp.workdps(40):
        far = max(lam, key=abs)
        assert abs(far - (-1j * q(A / e) + q((C - A) * w / A))) < 1e-2  # the O(ε) term is 1.4e-3 here
        assert -mp.im(far) > 0


@pytest.mark.parametrize("key", list(CHAINS))
def test_chain_rates_converge_to_the_first_order_formula(key):
    """σ(ε)/ε of the cubic's bounded roots → the claimed σ, with error O(ε); free chains' λ = 0 stays neutral."""
    support, n, _ = key
    w = CHAINS[key]
    (M, G, K), _, _ = chain(support, w)
    first = vr.first_order_rates_mp(M, G, K, w, WEIGHTS[:n])
    assert len(first) == 2 * n
    errs = []
    for e in (Fraction(1, 10**4), Fraction(1, 10**5), Fraction(1, 10**6)):
        got = vr.chain_rates_mp(M, G, K, w, [e * q for q in WEIGHTS[:n]])
        err = 0
        for (lam0, s1), (r, lam, s) in zip(first, got):
            assert abs(lam0 - r) < mp.mpf(10) ** -30
            if abs(lam0) < mp.mpf(10) ** -30:  # the free chain's rigid tilt: exact zero for every ε
                assert support == "free" and abs(lam) < mp.mpf(10) ** -30
                continue
            assert abs(s1) > 1e-3  # the comparison below is relative
            err = max(err, abs(s / q(e) - s1) / abs(s1))
        errs.append(err)
    assert errs[2] < 1e-2 and errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1], errs


# ---------------------------------------------------------------------------------------------------------
# stabmap's implementation (stabmap.systems.viscous): skips until it is merged
# ---------------------------------------------------------------------------------------------------------

RHO, NU = 1000.0, 1e-3  # [kg m-3], [m2 s-1]: a glycerol-like liquid
VISCOUS_SCENES = {
    # one top (A about its centre of mass; about the fixed point 0.03): ω_M = 6.862, ω* = 7.0036 rad/s
    "top": ("fixed", [dict(m=1.0, A=0.02, C=0.05, c=0.1)], [], [0.03],
            [5.0, 6.9, 6.98, 7.03, 8.0, 12.0, 25.0, 60.0]),
    # the rigid chain's roots turn real near 7.1 rad/s; the liquid destabilises it up to about 7.6 rad/s
    "fixed2": ("fixed", [dict(m=1.0, A=0.02, C=0.1, c=0.1, s=0.25), dict(m=0.5, A=0.01, C=0.04, c=0.08)], [50.0],
               [0.03, 0.025], [6.0, 7.25, 7.5, 8.0, 9.0, 15.0, 40.0, 120.0]),
    # body 2 spins about its minor axis (C < A): stable while the joint holds it, unstable at high spin
    # the same chain with a dry upper body (no cavity: ε_2 = 0)
    "fixed2_dry": ("fixed", [dict(m=1.0, A=0.02, C=0.1, c=0.1, s=0.25), dict(m=0.5, A=0.01, C=0.04, c=0.08)], [50.0],
                   [0.03, None], [6.0, 7.25, 7.5, 8.0, 9.0, 15.0, 40.0, 120.0]),
    "free2": ("free", [dict(m=1.0, A=0.02, C=0.05, c=0.1, s=0.25), dict(m=0.5, A=0.01, C=0.008, c=0.08)], [20.0],
              [0.03, 0.025], [1.0, 5.0, 10.0, 20.0, 40.0, 60.0, 80.0, 160.0]),
}


def viscous_toml(support, bodies, joints, radii, omegas):
    lines = ['title = "viscous reference"', f'support = "{support}"', "omega = 1.0"]
    if support == "fixed":
        lines.append("g = 9.81")
    if joints:
        lines.append(f"joints = [{', '.join(repr(k) for k in joints)}]")
    for b, a in zip(bodies, radii):
        lines.append("[[bodies]]")
        lines += [f"{k} = {v!r}" for k, v in b.items()]
        if a is not None:
            lines.append(f'cavity = {{ shape = "spheroid", radius = {a!r}, half_height = {a!r}, density = {RHO!r}, '
                         f"viscosity = {NU!r} }}")
    lines += ["[grid]", f"omega = {{ values = [{', '.join(repr(w) for w in omegas)}] }}"]
    return "\n".join(lines) + "\n"


def viscous_expected(support, bodies, joints, radii, w):
    """(label, growth rate, frequency, first_order) of one point, from the references alone.

    Real roots of det Φ: the largest first-order rate σ and the Re λ₀ of its root. A free chain's λ = 0 roots are
    the neutral rigid tilts: their rate is exactly 0 at every ε (chain_rates_mp) and they are left out. Complex
    roots: unstable at zeroth order; the rate is then the frozen chain's largest |Im λ₀| (stabmap's documented
    choice: the O(ε) correction of a complex root is not added) and the frequency its Re λ₀.
    """
    bs = [dict(b, omega=w) for b in bodies]
    build = vr.fixed_chain_matrices if support == "fixed" else vr.free_chain_matrices
    M, G, K = build(bs, joints, g=9.81) if support == "fixed" else build(bs, joints)
    eps = [0 if a is None else RHO * vr.sphere_P(a) / NU for a in radii]
    try:
        rates = vr.first_order_rates_mp(M, G, K, [w] * len(bs), eps)
    except ValueError:
        with mp.workdps(40):
            worst = max(vr.rigid_roots_mp(M, G, K), key=lambda z: abs(mp.im(z)))
            return "unstable", abs(mp.im(worst)), mp.re(worst), False
    lam0, top = max(((lam0, s) for lam0, s in rates if abs(lam0) > mp.mpf(10) ** -25), key=lambda r: r[1])
    return ("asymptotically_stable" if top < 0 else "unstable"), top, lam0, True


@pytest.mark.parametrize("name", list(VISCOUS_SCENES))
def test_reference_labels_span_the_cases(name):
    """The scenes below are worth testing: each has both labels, and the top's follow the classical criterion."""
    support, bodies, joints, radii, omegas = VISCOUS_SCENES[name]
    labels = [viscous_expected(support, bodies, joints, radii, w)[0] for w in omegas]
    assert {"asymptotically_stable", "unstable"} <= set(labels)
    if name == "top":
        b = bodies[0]
        A_O = b["A"] + b["m"] * b["c"] ** 2
        assert labels == ["asymptotically_stable" if (b["C"] - A_O) * w**2 > b["m"] * 9.81 * b["c"] else "unstable"
                          for w in omegas]


def _flag(da):
    meanings = da.attrs["flag_meanings"].split()
    values = [int(v) for v in np.atleast_1d(da.attrs["flag_values"])]
    return [meanings[values.index(int(v))] for v in np.asarray(da.values).ravel()]


@pytest.mark.parametrize("name", list(VISCOUS_SCENES))
def test_stabmap_viscous_atlas_matches_the_references(name):
    pytest.importorskip("stabmap.systems.viscous")
    import stabmap

    support, bodies, joints, radii, omegas = VISCOUS_SCENES[name]
    ds = stabmap.compute_atlas(stabmap.loads_scene(viscous_toml(support, bodies, joints, radii, omegas)),
                               progress=False, threads=1)
    st = ds["asymptotic_stability"]
    assert {"asymptotically_stable", "unstable", "undecided"} <= set(st.attrs["flag_meanings"].split())
    assert list(ds["omega"].values) == omegas
    labels = _flag(st)
    # growth rates are stored as float32 (as the ideal model's): compare to that storage precision, else to 1e-9
    rtol = 2.0**-22 if ds["growth_rate"].dtype == np.float32 else 1e-9
    rate, lo, hi = (np.asarray(ds[v].values, dtype=float).ravel()
                    for v in ("growth_rate", "growth_rate_lower", "growth_rate_upper"))
    for i, w in enumerate(omegas):
        want, sigma, freq, first_order = viscous_expected(support, bodies, joints, radii, w)
        assert labels[i] == want, (w, labels[i], want)
        assert abs(rate[i] - sigma) <= rtol * abs(sigma), (w, rate[i], sigma)
        assert lo[i] <= sigma <= hi[i], (w, lo[i], sigma, hi[i])
        if first_order:  # stabmap leaves the frequency of a frozen complex pair NaN
            f = float(ds["frequency"].values[i])
            assert abs(f - freq) <= rtol * abs(freq), (w, f, freq)
        assert abs(float(ds["time_constant"].values[i]) * abs(sigma) - 1) <= rtol, w
        re = max(abs(w) * a * a / NU for a in radii if a is not None)
        assert abs(float(ds["reynolds"].values[i]) - re) <= rtol * re


def test_stabmap_viscous_top_at_its_exact_threshold():
    """A top whose threshold is a double: ω* = 8 exactly (A about the fixed point 3/64, C = 1/16, m g c = 1).

    The classical criterion, in exact rationals, decides every grid value down to 2⁻⁴⁰ from ω*, where the rate
    is 2e-16 s⁻¹; at ω* itself λ₀ = −ω is a root of p and the liquid term λ²(λ + ω) vanishes there, so the
    first-order rate is exactly 0 and no label may be claimed: undecided.
    """
    pytest.importorskip("stabmap.systems.viscous")
    import stabmap

    body = dict(m=1.0, A=0.03125, C=0.0625, c=0.125)
    omegas = [7.5, 8 - 2**-20, 8 - 2**-40, 8.0, 8 + 2**-40, 8 + 2**-20, 8.5]
    toml = viscous_toml("fixed", [body], [], [0.03], omegas).replace("g = 9.81", "g = 8.0")
    ds = stabmap.compute_atlas(stabmap.loads_scene(toml), progress=False, threads=1)
    labels = _flag(ds["asymptotic_stability"])
    A_O = Fraction(body["A"]) + Fraction(body["m"]) * Fraction(body["c"]) ** 2
    for i, w in enumerate(omegas):
        margin = (Fraction(body["C"]) - A_O) * Fraction(w) ** 2 - Fraction(body["m"]) * 8 * Fraction(body["c"])
        want = "undecided" if margin == 0 else ("asymptotically_stable" if margin > 0 else "unstable")
        assert labels[i] == want, (w, labels[i], want)
        if margin != 0:
            M, G, K = vr.fixed_chain_matrices([dict(body, omega=w)], [], g=8.0)
            sigma = max(s for _, s in vr.first_order_rates_mp(M, G, K, [w], [RHO * vr.sphere_P(0.03) / NU]))
            assert (sigma > 0) == (margin < 0)
            lo, hi = float(ds["growth_rate_lower"].values[i]), float(ds["growth_rate_upper"].values[i])
            assert lo <= sigma <= hi, (w, lo, sigma, hi)


def test_stabmap_viscous_double_root_is_never_stable():
    """At the double root above (ω = 2 exactly) stabmap may say undecided (a multiple root) or unstable (it is:
    ±16√ε), never asymptotically_stable. Just above it one of the two real roots grows at first order, up to
    ω* = √(1/(C − A)) = 2.309, where the classical criterion turns stable."""
    pytest.importorskip("stabmap.systems.viscous")
    import stabmap

    body = dict(m=1.0, A=0.046875, C=0.25, c=0.125)  # about the fixed point 3/64 + 1/64 = 1/16; m g c = 1 at g = 8
    omegas = [1.5, 2.0, 2.1, 2.5]
    toml = viscous_toml("fixed", [body], [], [0.03], omegas).replace("g = 9.81", "g = 8.0")
    ds = stabmap.compute_atlas(stabmap.loads_scene(toml), progress=False, threads=1)
    labels = _flag(ds["asymptotic_stability"])
    assert labels[0] == labels[2] == "unstable" and labels[1] in ("undecided", "unstable"), labels
    assert labels[3] == "asymptotically_stable"
