"""The figures of docs/closed.md: the families' shapes at some lengths, their classes along the length ratio (in
space at c2 = c1, and in the plane), and the class in space over the ratio x c2^2/c1^2 of the figure-eight-6 and the hinge.

    python scripts/closed_figures.py               # writes docs/figures/closed-{shapes,atlas,space-eight,space-hinge}.png,
                                                   # prints the located boundaries quoted in docs/closed.md (about a minute)
    python scripts/closed_figures.py --only space  # only the two ratio x c2^2/c1^2 figures

Everything drawn is computed first by stabmap (``stabmap.closed.solve``, ``stabmap.compute_atlas``,
``stabmap.critical``); the plotting below only reads the results.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
import matplotlib.colors
import matplotlib.lines
import numpy as np

import stabmap
from stabmap import closed

matplotlib.use("Agg")
import matplotlib.pyplot as plt

ROOT = Path(__file__).resolve().parents[1]
COLOURS = {"stable": "#56B4E9", "unstable": "#E69F00", "degenerate": "#999999", "absent": "#FFFFFF", "undecided": "#707070"}
SHAPES = (
    ("ring", [1.0] * 8, 1, "ring n = 8, j = 1"),
    ("ring", [1.0, 0.5] * 4, 3, "ring n = 8, j = 3, h2/h1 = 0.5"),
    ("figure-eight-4", [1.0, 0.6, 1.0, 0.6], 1, "figure-eight-4, h2/h1 = 0.6"),
    ("figure-eight-6", [1.0, 7.0, 1.0, 1.0, 7.0, 1.0], 1, "figure-eight-6, h2/h1 = 7"),
    ("hinge", [1.0, 1.0, 1.0, 1.0, 1.0, 1.0], 1, "hinge, h2/h1 = 1"),
    ("hinge-straight", [1.0, 1.0, 1.5, 1.0, 1.0, 1.5], 1, "hinge-straight, h2/h1 = 1.5"),
)
EIGHT_PLANAR = 5.98605461610344  # figure-eight-6: its class in the plane changes here
HINGE_SPACE = (17**0.5 - 1) / 4  # the hinge in space at c2 = c1: stable only below this ratio
FAMILIES = (("figure-eight-4", 0.05, 1.2), ("figure-eight-6", 3.0, 40.0), ("hinge", 0.05, 2.6), ("hinge-straight", 0.05, 2.6))


def shapes_figure(path: Path) -> None:
    found = [(closed.solve(shape, lengths, j=j), title) for shape, lengths, j, title in SHAPES]
    fig, axes = plt.subplots(2, 3, figsize=(11, 7.2), constrained_layout=True)
    for ax, (eq, title) in zip(axes.ravel(), found):
        O = eq.joints
        ax.plot(O[:, 0], O[:, 1], "-", color="#333333", lw=1.5)
        ax.plot(O[:-1, 0], O[:-1, 1], "o", ms=4, color=COLOURS[eq.stability], mec="#333333", mew=0.8)
        for k in range(eq.n):  # body numbers at the middle of each axis
            mid = 0.5 * (O[k] + O[k + 1])
            ax.annotate(f"{k + 1}", mid, fontsize=7, color="#555555", xytext=(3, 3), textcoords="offset points")
        force = eq.forces[~np.isnan(eq.forces).any(axis=1)]
        forces = ", ".join(f"({f[0]:.3g}, {f[1]:.3g})" for f in force) if force.size else "-"
        ax.set_title(f"{title}\nspace: {eq.stability}, index {eq.index}, nullity {eq.nullity} | plane: "
                     f"{eq.planar_stability}, index {eq.planar_index}\nturns {eq.rotation_index}, "
                     f"R [N] = {forces}, U = {eq.energy:.4g} J", fontsize=8)
        ax.set_aspect("equal")
        ax.margins(0.15)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle("planar equilibria of closed chains (c1² = c2² = 1 N m², h = min h_k); joints O_k coloured by the class in space",
                 fontsize=10)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _strip(ax, ds, variable: str, seen: set) -> None:
    """Colour each scan value's cell of ``ax`` by the class ``variable`` of the 1-D atlas ``ds`` (log ratio axis)."""
    r = ds["ratio"].values
    edges = np.sqrt(r[1:] * r[:-1])
    edges = np.concatenate([[r[0] ** 2 / edges[0]], edges, [r[-1] ** 2 / edges[-1]]])
    meanings = _meanings(ds, variable)
    for i, v in enumerate(ds[variable].values):
        seen.add(meanings[int(v)])
        ax.axvspan(edges[i], edges[i + 1], color=COLOURS[meanings[int(v)]], lw=0)


def _meanings(ds, variable: str) -> dict[int, str]:
    return dict(zip(ds[variable].attrs["flag_values"].tolist(), ds[variable].attrs["flag_meanings"].split()))


def _boundaries(crit) -> list[tuple[float, float]]:
    """The located brackets (lower, upper) of the boundaries, each once (width < 1e-10 relative)."""
    lo, hi = crit["boundary_lower"].values.ravel(), crit["boundary_upper"].values.ravel()
    pairs = sorted((float(a), float(b)) for a, b in zip(lo, hi) if np.isfinite(a))
    return [p for i, p in enumerate(pairs) if i == 0 or p[0] - pairs[i - 1][1] > 1e-9 * p[0]]


def atlas_figure(path: Path) -> list[str]:
    """Two strips a family: its class in space at c2 = c1 (the default ``stability``) and its class in the plane
    (scene ``model = "planar"``), with the changes of each located by ``stabmap.critical`` along the ratio."""
    lines = []
    seen, decided = set(), {}
    fig, axes = plt.subplots(2 * len(FAMILIES), 1, figsize=(9, 0.78 * 2 * len(FAMILIES) + 1.4), sharex=True,
                             constrained_layout=True)
    for k, (family, lo, hi) in enumerate(FAMILIES):
        body = f'system = "closed"\nfamily = "{family}"\n[grid]\nratio = {{ start = {lo}, stop = {hi}, num = 600, scale = "log" }}\n'
        for ax, model, what in ((axes[2 * k], "spatial", "in space, c2 = c1"), (axes[2 * k + 1], "planar", "in the plane")):
            scene = stabmap.loads_scene(body if model == "spatial" else 'model = "planar"\n' + body)
            ds = stabmap.compute_atlas(scene, progress=False)
            for key, v in stabmap.summary(ds)["decided_by"].items():
                decided[key] = decided.get(key, 0) + v
            _strip(ax, ds, "stability", seen)
            crit = stabmap.critical(scene, "ratio", progress=False)
            for lo_b, hi_b in _boundaries(crit):
                b = 0.5 * (lo_b + hi_b)
                ax.axvline(b, color="k", lw=0.8, ls="--")
                first = (lo_b, hi_b) == _boundaries(crit)[0]  # the first one's value left of its line, the others right
                ax.annotate(f"{b:.10g}", (b, 0.5), xycoords=("data", "axes fraction"), xytext=(-3 if first else 3, 0),
                            textcoords="offset points", fontsize=7, ha="right" if first else "left", va="center",
                            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
                lines.append(f"{family}: class {what} changes at ratio {b:.10g} (bracket [{lo_b:.12g}, {hi_b:.12g}])")
                if family == "hinge" and model == "spatial" and lo_b <= HINGE_SPACE <= hi_b:
                    lines.append(f"  the bracket holds (sqrt 17 - 1)/4 = {HINGE_SPACE:.12g} (width {hi_b - lo_b:.0e}; the root of "
                                 "2 r^2 + r - 2; the hinge's out-of-plane boundary c2²/c1² = r² (5 + 2 r)/4 at c2 = c1)")
            if model == "spatial":  # U h / c1^2 = sum (1 - cos of the joint angles): the shape's bending
                r = ds["ratio"].values
                bending = ds["energy"].values * np.minimum(1.0, r) / float(ds["c1sq"])
                twin = ax.twinx()
                twin.plot(r, bending, color="#333333", lw=1)
                twin.set_ylabel("U h / c1²", fontsize=7)
                twin.tick_params(labelsize=7)
            ax.set_yticks([])
            ax.set_ylabel(f"{family}\n{what}", rotation=0, ha="right", va="center", fontsize=8)
    axes[-1].set_xscale("log")
    axes[-1].set_xlim(0.05, 40)
    axes[-1].set_xlabel("length ratio h2/h1 of the family's pattern (log scale)")
    shown = [k for k in COLOURS if k in seen or k != "undecided"]  # undecided only if a point is
    handles = [plt.Rectangle((0, 0), 1, 1, fc=COLOURS[k], ec="#888888", lw=0.5) for k in shown]
    fig.legend(handles, shown, loc="outside lower center", ncol=len(shown), fontsize=8, frameon=False)
    lines.append("decided by: " + ", ".join(f"{k} {v}" for k, v in sorted(decided.items())))
    fig.suptitle("stability of each family along its length ratio: in space at c2 = c1 (upper strip; curve: bending "
                 "energy U h / c1²)\nand in the plane (lower strip); dashed: class changes located by stabmap critical to 1e-10",
                 fontsize=9)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return lines


def _edges(x: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid values (geometric means on a log axis)."""
    y = np.log(x) if log else x
    mid = 0.5 * (y[1:] + y[:-1])
    e = np.concatenate([[2 * y[0] - mid[0]], mid, [2 * y[-1] - mid[-1]]])
    return np.exp(e) if log else e


def space_figure(path: Path, family: str, ratio: tuple, gamma: tuple, planar: float, planar_text: str, dots: tuple,
                 log_x: bool, num: tuple = (60, 40), curve=None) -> list[str]:
    """The class in space of ``family`` over its length ratio x c2²/c1² (c1² = 1), the planar boundary dashed and
    the boundary in c2²/c1² located by ``stabmap.critical`` at the ratios ``dots``."""
    scale = ', scale = "log"' if log_x else ""
    scene = stabmap.loads_scene(
        f'system = "closed"\nfamily = "{family}"\nc1sq = 1.0\n[grid]\n'
        f'ratio = {{ start = {ratio[0]}, stop = {ratio[1]}, num = {num[0]}{scale} }}\n'
        f'c2sq = {{ start = {gamma[0]}, stop = {gamma[1]}, num = {num[1]}, scale = "log" }}\n')
    ds = stabmap.compute_atlas(scene, progress=False).transpose("c2sq", "ratio", ...)
    meanings = _meanings(ds, "stability")
    names = list(COLOURS)
    codes = np.vectorize(lambda v: names.index(meanings[int(v)]))(ds["stability"].values)
    seen = {names[c] for c in np.unique(codes)}
    decided = stabmap.summary(ds)["decided_by"]
    r, g = ds["ratio"].values, ds["c2sq"].values
    crit = stabmap.critical(stabmap.loads_scene(
        f'system = "closed"\nfamily = "{family}"\nc1sq = 1.0\n[grid]\nratio = {{ values = {list(dots)} }}\n'
        f'c2sq = {{ start = {gamma[0]}, stop = {gamma[1]}, num = 16, scale = "log" }}\n'), "c2sq", progress=False)

    undecided = int((codes == names.index("undecided")).sum())
    proved = f"{undecided} undecided" if undecided else "every class proved"
    fig, ax = plt.subplots(figsize=(7.6, 5.0), constrained_layout=True)
    cmap = matplotlib.colors.ListedColormap([COLOURS[k] for k in names])
    ax.pcolormesh(_edges(r, log_x), _edges(g, True), codes, cmap=cmap, vmin=-0.5, vmax=len(names) - 0.5, shading="flat")
    ax.axvline(planar, color="k", ls="--", lw=1.1)
    left, right = planar_text  # the class in the plane left and right of the dashed line, written on the wider side
    mid = np.sqrt(r[0] * r[-1]) if log_x else 0.5 * (r[0] + r[-1])
    ax.annotate(f"in the plane: {left} | {right}", (planar, 0.97), xycoords=("data", "axes fraction"),
                xytext=(4 if planar < mid else -4, 0), textcoords="offset points", ha="left" if planar < mid else "right",
                va="top", fontsize=7.5, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.85))
    if curve is not None:  # a closed form the dots are compared with (printed below), drawn thin
        rr = np.linspace(r[0], min(r[-1], planar), 400)
        ax.plot(rr, curve[0](rr), "-", color="#333333", lw=0.8)
    ax.axhline(1.0, color="#333333", ls=":", lw=0.9)
    lines = []
    xs, ys = [], []
    for i, rv in enumerate(crit["ratio"].values):
        lo, hi = crit["boundary_lower"].values[i], crit["boundary_upper"].values[i]
        below, above = crit["stability_below"].values[i], crit["stability_above"].values[i]
        found = [(0.5 * (a + b), meanings[int(u)], meanings[int(v)]) for a, b, u, v in zip(lo, hi, below, above) if np.isfinite(a)]
        for x, u, v in found:
            xs.append(rv)
            ys.append(x)
        start = meanings[int(crit["stability_at_scan_start"].values[i])]
        text = "; ".join(f"{u} -> {v} at c2²/c1² = {x:.10g}" for x, u, v in found) or f"no change in [{gamma[0]}, {gamma[1]}] ({start})"
        if curve is not None and found:
            text += f" (|{curve[1]} - it| = {abs(curve[0](rv) - found[0][0]):.1e})"
        lines.append(f"{family}, ratio {rv:g}: {text}")
    ax.plot(xs, ys, "o", color="k", ms=4.5, mfc="white", mew=1.2)
    if log_x:
        ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(_edges(r, log_x)[[0, -1]])
    ax.set_ylim(_edges(g, True)[[0, -1]])
    ax.set_xlabel("length ratio h2/h1 (dimensionless)" + (" (log scale)" if log_x else ""))
    ax.set_ylabel("c2²/c1²: torsional over bending stiffness (log scale)")
    ax.set_title(f"{family}: stability in space over h2/h1 x c2²/c1² ({num[0]} x {num[1]} points, {proved})\n"
                 "dashed: the class in the plane changes; dots: boundary in c2²/c1² located by stabmap critical to 1e-10",
                 fontsize=9)
    handles = [plt.Rectangle((0, 0), 1, 1, fc=COLOURS[k], ec="#888888", lw=0.5) for k in names if k in seen]
    labels = [f"{k} in space" if k != "absent" else "absent (no equilibrium)" for k in names if k in seen]
    handles += [matplotlib.lines.Line2D([], [], color="k", ls="--"), matplotlib.lines.Line2D([], [], color="#333333", ls=":"),
                matplotlib.lines.Line2D([], [], color="k", marker="o", mfc="white", ls="")]
    labels += ["class in the plane changes", "c2 = c1", "located boundary (critical)"]
    if curve is not None:
        handles.append(matplotlib.lines.Line2D([], [], color="#333333", lw=0.8))
        labels.append(f"c2²/c1² = {curve[1]}")
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    lines.append(f"{family} space atlas: " + ", ".join(f"{k} {v}" for k, v in decided.items() if v) +
                 "; classes " + ", ".join(f"{k} {int((codes == names.index(k)).sum())}" for k in names if k in seen))
    return lines


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures", help="directory of the figures")
    parser.add_argument("--only", nargs="+", default=None, help="only the figures whose file names contain these words (e.g. space)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    written = ["closed-shapes.png", "closed-atlas.png", "closed-space-eight.png", "closed-space-hinge.png"]
    if args.only:
        written = [w for w in written if any(o in w for o in args.only)]
    if "closed-shapes.png" in written:
        shapes_figure(args.out / "closed-shapes.png")
    if "closed-atlas.png" in written:
        for line in atlas_figure(args.out / "closed-atlas.png"):
            print(line)
    if "closed-space-eight.png" in written:
        for line in space_figure(args.out / "closed-space-eight.png", "figure-eight-6", (4.9, 14.0), (0.05, 5.0), EIGHT_PLANAR,
                                 ("unstable", f"stable (h2/h1 = {EIGHT_PLANAR:.10g})"),
                                 (6.05, 6.3, 7.0, 8.0, 9.0, 10.5, 12.0, 14.0), log_x=False):
            print(line)
    if "closed-space-hinge.png" in written:
        for line in space_figure(args.out / "closed-space-hinge.png", "hinge", (0.05, 2.6), (0.05, 20.0), 2**0.5,
                                 ("stable", "unstable (h2/h1 = √2)"), (0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.2, 1.4),
                                 log_x=True, curve=(lambda r: r * r * (5 + 2 * r) / 4, "r² (5 + 2r)/4")):
            print(line)
    print("wrote " + ", ".join(str(args.out / w) for w in written))


if __name__ == "__main__":
    main()
