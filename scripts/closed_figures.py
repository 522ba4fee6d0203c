"""The figures of docs/closed.md: the families' shapes at some lengths, and their classes along the length ratio.

    python scripts/closed_figures.py          # writes docs/figures/closed-shapes.png and docs/figures/closed-atlas.png,
                                              # prints the located boundaries quoted in docs/closed.md

Everything drawn is computed first by stabmap (``stabmap.closed.solve``, ``stabmap.compute_atlas``,
``stabmap.critical``); the plotting below only reads the results.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
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
FAMILIES = (("figure-eight-4", 0.05, 1.2), ("figure-eight-6", 3.0, 40.0), ("hinge", 0.05, 2.6), ("hinge-straight", 0.05, 2.6))


def shapes_figure(path: Path) -> None:
    found = [(closed.solve(shape, lengths, j=j), title) for shape, lengths, j, title in SHAPES]
    fig, axes = plt.subplots(2, 3, figsize=(10, 6.8), constrained_layout=True)
    for ax, (eq, title) in zip(axes.ravel(), found):
        O = eq.joints
        ax.plot(O[:, 0], O[:, 1], "-", color="#333333", lw=1.5)
        ax.plot(O[:-1, 0], O[:-1, 1], "o", ms=4, color=COLOURS[eq.stability], mec="#333333", mew=0.8)
        for k in range(eq.n):  # body numbers at the middle of each axis
            mid = 0.5 * (O[k] + O[k + 1])
            ax.annotate(f"{k + 1}", mid, fontsize=7, color="#555555", xytext=(3, 3), textcoords="offset points")
        force = eq.forces[~np.isnan(eq.forces).any(axis=1)]
        forces = ", ".join(f"({f[0]:.3g}, {f[1]:.3g})" for f in force) if force.size else "-"
        ax.set_title(f"{title}\n{eq.stability}: index {eq.index}, nullity {eq.nullity}, turns {eq.rotation_index}\n"
                     f"R [N] = {forces}, U = {eq.energy:.4g} J", fontsize=8.5)
        ax.set_aspect("equal")
        ax.margins(0.15)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle("planar equilibria of closed chains (c1² = 1 N m², h = min h_k); joints O_k coloured by stability", fontsize=10)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def atlas_figure(path: Path) -> list[str]:
    lines = []
    seen, decided = set(), {}
    fig, axes = plt.subplots(len(FAMILIES), 1, figsize=(9, 1.25 * len(FAMILIES) + 1.2), sharex=True, constrained_layout=True)
    for ax, (family, lo, hi) in zip(axes, FAMILIES):
        scene = stabmap.loads_scene(
            f'system = "closed"\nfamily = "{family}"\n[grid]\nratio = {{ start = {lo}, stop = {hi}, num = 600, scale = "log" }}\n'
        )
        ds = stabmap.compute_atlas(scene, progress=False)
        for k, v in stabmap.summary(ds)["decided_by"].items():
            decided[k] = decided.get(k, 0) + v
        crit = stabmap.critical(scene, "ratio", progress=False)
        r = ds["ratio"].values
        edges = np.sqrt(r[1:] * r[:-1])
        edges = np.concatenate([[r[0] ** 2 / edges[0]], edges, [r[-1] ** 2 / edges[-1]]])
        meanings = dict(zip(ds["stability"].attrs["flag_values"].tolist(), ds["stability"].attrs["flag_meanings"].split()))
        for i, v in enumerate(ds["stability"].values):
            seen.add(meanings[int(v)])
            ax.axvspan(edges[i], edges[i + 1], color=COLOURS[meanings[int(v)]], lw=0)
        # U h / c1^2 = sum (1 - cos of the joint angles): the shape's bending, free of the paper's h = min h_k
        bending = ds["energy"].values * np.minimum(1.0, r) / float(ds["c1sq"])
        twin = ax.twinx()
        twin.plot(r, bending, color="#333333", lw=1)
        twin.set_ylabel("U h / c1²", fontsize=8)
        bounds = crit["boundary_upper"].values.ravel()
        for b in np.unique(np.round(bounds[np.isfinite(bounds)], 9)):
            ax.axvline(b, color="k", lw=0.8, ls="--")
            ax.annotate(f"{b:.10g}", (b, 0.9), xycoords=("data", "axes fraction"), fontsize=7, rotation=90, ha="right", va="top")
            lines.append(f"{family}: class changes at ratio {b:.12g}")
        ax.set_yticks([])
        ax.set_ylabel(family, rotation=0, ha="right", va="center", fontsize=9)
    axes[-1].set_xscale("log")
    axes[-1].set_xlim(0.05, 40)
    axes[-1].set_xlabel("length ratio h2/h1 of the family's pattern (log scale)")
    shown = [k for k in COLOURS if k in seen or k != "undecided"]  # undecided only if a point is
    handles = [plt.Rectangle((0, 0), 1, 1, fc=COLOURS[k], ec="#888888", lw=0.5) for k in shown]
    fig.legend(handles, shown, loc="outside lower center", ncol=len(shown), fontsize=8, frameon=False)
    lines.append("decided by: " + ", ".join(f"{k} {v}" for k, v in sorted(decided.items())))
    fig.suptitle("stability of each family along its length ratio (curve: bending energy U h / c1²);\n"
                 "dashed: class changes located by stabmap critical to 1e-10", fontsize=9)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures", help="directory of the figures")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    shapes_figure(args.out / "closed-shapes.png")
    for line in atlas_figure(args.out / "closed-atlas.png"):
        print(line)
    print(f"wrote {args.out / 'closed-shapes.png'} and {args.out / 'closed-atlas.png'}")


if __name__ == "__main__":
    main()
