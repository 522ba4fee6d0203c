"""The figure of docs/viscous.md: one heavy top with a liquid-filled sphere, ideal liquid beside viscous liquid.

    python scripts/viscous_figure.py                  # docs/figures/viscous-vs-ideal.png (160 x 110 points a side)
    python scripts/viscous_figure.py --quick --out D  # 24 x 16 points, into D (a quick look; nothing else differs)

The same scene is computed twice by ``stabmap.compute_atlas``: with the cavity's liquid ideal (the gyroscopes
system, label N_c) and with a viscosity added (the viscous system, label asymptotic stability).  Each atlas is
drawn by ``stabmap.atlas_figure`` (its own colours, legend and caption, the Reynolds-number caveat included); on
both the classical curves are drawn as thin lines, and on the viscous map the points that the ideal model calls
stable and the viscous one proves unstable are hatched.  The two pictures are put side by side under one caption.

The classical curves, for one heavy top on a fixed point (A' = A + m c^2 and C about the fixed point, liquid
frozen, m g c the gravity moment):

- ideal liquid in a sphere of radius a: the cavity has exactly one mode, kappa = 2 and E = (8 pi / 15) rho a^5
  (docs/model.md), and p(lambda) = lambda [(A' - E) lambda^2 + (C - E) omega lambda + m g c]: Maievskii's
  C^2 omega^2 = 4 A' m g c with the liquid's own inertia E taken off A' and C (a 0.1 % shift here);
- viscous liquid, first order in 1/nu: asymptotically stable exactly where (C - A') omega^2 > m g c.

Both are derived from the model, not from stabmap's code, so a curve that leaves its map's boundary would show
a wrong label.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import stabmap
from stabmap.read.plot import UNSTABLE_COLOUR, save_figure
from stabmap.scene.grid import resample

ROOT = Path(__file__).resolve().parents[1]
G = 9.81
# A top of 1 kg, its centre of mass 5 cm above the point, A = 0.004 kg m2 about it (A' = 0.0065 kg m2 about the
# point), with a sphere of 2 cm radius full of silicone oil (density 970 kg m-3, 50 000 cSt = 0.05 m2 s-1): at up to
# 100 rad/s the Reynolds number omega a^2 / nu stays below 0.8.  C_1 is scanned from a long top (C < A') to a flat one.
SCENE = """
title = "heavy top with a liquid-filled sphere"
support = "fixed"
omega = 50.0

[[bodies]]
m = 1.0
A = 0.004
C = 0.008
c = 0.05
cavity = { shape = "spheroid", radius = 0.02, half_height = 0.02, density = 970.0, viscosity = 0.05 }

[grid]
omega = { start = 1.0, stop = 100.0, num = 160 }
C_1 = { start = 0.002, stop = 0.016, num = 110 }
"""
LINE = "#CC0066"  # the classical curves: a colour no class has, seen on black boundary cells too


def scenes(quick: bool = False):
    """(ideal, viscous): the same top, its cavity's liquid without and with a viscosity."""
    import tomllib

    from stabmap.systems.gyroscopes import scene as scene_module

    viscous = scene_module.from_dict(tomllib.loads(SCENE))
    ideal = scene_module.from_dict(tomllib.loads(SCENE.replace(", viscosity = 0.05", "")))
    if quick:
        viscous, ideal = (resample(s, omega=24, C_1=16) for s in (viscous, ideal))
    return ideal, viscous


def curves(scene, C: np.ndarray) -> dict[str, np.ndarray]:
    """The spin rates [rad/s] of the classical boundaries at the axial inertias C [kg m2] (NaN where none)."""
    b, cav = scene.bodies[0], scene.bodies[0].cavity
    A1 = b.A + b.m * b.c**2  # about the fixed point
    mgc = b.m * G * b.c
    E = 8 * math.pi / 15 * cav.density * cav.radius**5
    with np.errstate(invalid="ignore", divide="ignore"):
        ideal = 2 * np.sqrt((A1 - E) * mgc) / (C - E)
        viscous = np.where(C > A1, np.sqrt(mgc / (C - A1)), np.nan)
    return {"ideal": ideal, "viscous": viscous, "A1": A1, "E": E}


def _hatch(ax, mask: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
    """Hatch the grid cells of ``mask`` (y, x), cell edges halfway between grid values (linear axes)."""
    def edges(v):
        mid = (v[1:] + v[:-1]) / 2
        return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])

    shown = np.ma.masked_where(~mask, np.ones(mask.shape))
    mesh = ax.pcolor(edges(x), edges(y), shown, facecolor="none", edgecolor=UNSTABLE_COLOUR[2], linewidth=0.0,
                     hatch="////", zorder=4)
    mesh.set_facecolor("none")


def draw(ds, scene, which: str, path: Path, ideal_stable=None) -> Path:
    fig = stabmap.atlas_figure(ds, x="omega", y="C_1")
    ax = fig.axes[0]
    C = np.linspace(float(ds.C_1.min()), float(ds.C_1.max()), 400)
    lines = curves(scene, C)
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    ax.plot(lines["ideal"], C, color=LINE, lw=1.3, ls="--", zorder=6,
            label="(C\u2212E)\u00b2\u03c9\u00b2 = 4(A\u2032\u2212E) m g c")
    ax.plot(lines["viscous"], C, color=LINE, lw=1.5, ls=":", zorder=6, label="(C\u2212A\u2032)\u03c9\u00b2 = m g c")
    ax.axhline(lines["A1"], color=LINE, lw=0.5, ls="-", alpha=0.5, zorder=5)
    if ideal_stable is not None:
        lost = ideal_stable & (ds["asymptotic_stability"] == 1)
        lost = lost.transpose("C_1", "omega").values
        _hatch(ax, lost, ds.omega.values, ds.C_1.values)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    handles, _ = ax.get_legend_handles_labels()
    if ideal_stable is not None:
        from matplotlib.patches import Patch

        handles.append(Patch(facecolor="none", edgecolor=UNSTABLE_COLOUR[2], hatch="////", lw=0.0,
                             label="stable if ideal, unstable if viscous"))
    ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.9).set_zorder(10)
    save_figure(fig, path)
    return path


def compose(images: list[tuple[str, Path]], caption: str, path: Path, dpi: int = 150) -> Path:
    """The two pictures side by side at their own scale, each under its heading, the caption below."""
    import textwrap

    from matplotlib.figure import Figure
    from matplotlib.image import imread

    pictures = [np.asarray(imread(p)) for _, p in images]
    gap, head = 0.1, 0.3  # [in]
    w = [p.shape[1] / dpi for p in pictures]
    tall = max(p.shape[0] for p in pictures) / dpi
    width = sum(w) + gap * (len(w) + 1)
    text = textwrap.fill(caption, int(width * 13))
    foot = 0.2 + 0.17 * (text.count("\n") + 1)
    height = head + tall + foot
    fig = Figure(figsize=(width, height), dpi=dpi)
    x = gap
    for (heading, _), picture, wk in zip(images, pictures, w):
        hk = picture.shape[0] / dpi
        ax = fig.add_axes((x / width, (height - head - hk) / height, wk / width, hk / height))
        ax.imshow(picture, interpolation="antialiased")
        ax.set_title(heading, fontsize=12, fontweight="bold", loc="left")
        ax.set_axis_off()
        x += wk + gap
    fig.text(gap / width, 0.1 / height, text, fontsize=9.5, va="bottom")
    fig.savefig(path, dpi=dpi, facecolor="white")
    return path


def main(argv: list[str] | None = None) -> dict:
    import tempfile

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="24 x 16 points")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures", help="directory of viscous-vs-ideal.png")
    args = parser.parse_args(argv)
    ideal, viscous = scenes(args.quick)
    di = stabmap.compute_atlas(ideal, progress=False)
    dv = stabmap.compute_atlas(viscous, progress=False)
    stable = di["n_complex_pairs"] == 0
    lost = stable & (dv["asymptotic_stability"] == 1)
    re_ = dv["reynolds"]
    c = curves(viscous, np.array([0.0]))
    b, cav = viscous.bodies[0], viscous.bodies[0].cavity
    # the classical criteria at every node, from the model alone (the visible check of the curves, counted)
    w, C1 = dv["omega"], dv["C_1"]
    mgc = b.m * G * b.c
    ideal_closed = (C1 - c["E"]) ** 2 * w**2 >= 4 * (c["A1"] - c["E"]) * mgc
    viscous_closed = (C1 - c["A1"]) * w**2 > mgc
    decided = dv["asymptotic_stability"] >= 0
    facts = {
        "points": int(stable.size), "ideal_stable": int(stable.sum()), "viscous_stable": int((dv["asymptotic_stability"] == 0).sum()),
        "undecided": int((dv["asymptotic_stability"] == -3).sum()), "lost": int(lost.sum()),
        "ideal_off_closed_form": int((stable != ideal_closed).sum()),
        "viscous_off_closed_form": int(((dv["asymptotic_stability"] == 0) != viscous_closed).where(decided, False).sum()),
        "re_min": float(re_.min()), "re_max": float(re_.max()), "re_over_1": float((re_ >= 1).mean()),
        "tau_min": float(dv["time_constant"].where(dv["asymptotic_stability"] == 0).min()),
        "tau_max": float(dv["time_constant"].where(dv["asymptotic_stability"] == 0).max()),
    }
    caption = (
        f"One heavy top (m = {b.m:g} kg, c = {b.c:g} m, A = {b.A:g} kg m\u00b2 about its centre of mass, so A\u2032 = "
        f"{c['A1']:.4g} kg m\u00b2 about the fixed point; C\u2081 scanned) with a sphere of radius {cav.radius:g} m full of liquid "
        f"(\u03c1 = {cav.density:g} kg m\u207b\u00b3), ideal on the left and of kinematic viscosity \u03bd = {cav.viscosity:g} m\u00b2 s\u207b\u00b9 "
        f"on the right: Re = \u03c9a\u00b2/\u03bd from {facts['re_min']:.2g} to {facts['re_max']:.2g} over the map. "
        f"Dashed: Maievskii's boundary of the ideal model, (C\u2212E)\u00b2\u03c9\u00b2 = 4(A\u2032\u2212E) m g c, with "
        f"E = 8\u03c0\u03c1a\u2075/15 = {c['E']:.2g} kg m\u00b2 the liquid's own inertia (the sphere's one liquid mode; with the liquid "
        f"frozen it is C\u00b2\u03c9\u00b2 = 4A\u2032 m g c). Dotted: the viscous criterion (C\u2212A\u2032)\u03c9\u00b2 = m g c, "
        f"asymptotically stable only for C > A\u2032 (thin line). Both curves follow from the model alone and lie on the "
        f"maps' boundaries. Hatched: {facts['lost']} of {facts['points']} points ({100 * facts['lost'] / facts['points']:.0f} %) "
        f"that the ideal model calls stable and the viscous one proves unstable, the long tops (C < A\u2032) "
        f"included. On the stable side the slowest mode decays with time constants from {facts['tau_min']:.2g} s "
        f"({facts['tau_min'] / 3600:.0f} h) to {facts['tau_max']:.2g} s: at Re < 1 the liquid turns with the body almost as a solid "
        f"and dissipates little (the rate is proportional to Re), yet it decides the sign."
    )
    with tempfile.TemporaryDirectory() as tmp:
        left = draw(di, ideal, "ideal", Path(tmp) / "ideal.png")
        right = draw(dv, viscous, "viscous", Path(tmp) / "viscous.png", ideal_stable=stable)
        args.out.mkdir(parents=True, exist_ok=True)
        path = compose([("ideal liquid", left), (f"viscous liquid, \u03bd = {cav.viscosity:g} m\u00b2/s", right)], caption,
                       args.out / "viscous-vs-ideal.png")
    print(f"wrote {path}")
    print(", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in facts.items()))
    return {"path": path, **facts}


if __name__ == "__main__":
    main()
