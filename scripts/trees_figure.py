"""The figures and matrices of docs/trees.md: the example graph, its S and T, and the tree example atlas.

    python scripts/trees_figure.py            # writes docs/figures/trees-graph.png and tree-carrier-above-below.png,
                                              # prints the matrices as they appear in docs/trees.md

The example graph has 7 bodies with arcs numbered and directed at will (arc 1 joins body 1 to the
base), then Wittenburg's regular numbering with every arc pointing away from the base.  The test
suite (tests/test_topology.py) recomputes the matrices and checks that docs/trees.md shows them.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
import numpy as np

import stabmap
from stabmap.systems.gyroscopes import topology

matplotlib.use("Agg")
import matplotlib.pyplot as plt

ROOT = Path(__file__).resolve().parents[1]
# Arc a leaves PLUS[a - 1] and enters MINUS[a - 1] (tests/test_topology.py has the same graph).
PLUS = (1, 3, 7, 1, 4, 5, 3)
MINUS = (0, 6, 5, 5, 6, 2, 1)


def _layout(parent) -> dict[int, tuple[float, float]]:
    """Vertex positions: the base at the bottom, every body above its parent, leaves spread evenly."""
    kids = topology.children(parent)
    pos, next_x = {}, [0.0]

    def place(v: int, depth: int) -> float:
        if not kids[v]:
            x = next_x[0]
            next_x[0] += 1.0
        else:
            x = float(np.mean([place(k, depth + 1) for k in kids[v]]))
        pos[v] = (x, float(depth))
        return x

    place(0, 0)
    return pos


def _draw(ax, plus, minus, title: str) -> None:
    parent, _ = topology.parent_from_arcs(plus, minus)
    pos = _layout(parent)
    for a, (u, v) in enumerate(zip(plus, minus), start=1):
        (x0, y0), (x1, y1) = pos[u], pos[v]
        ax.annotate("", xy=(x1, y1), xytext=(x0, y0),
                    arrowprops={"arrowstyle": "-|>", "lw": 1.4, "color": "0.25", "shrinkA": 13, "shrinkB": 13,
                                "mutation_scale": 14})
        ax.text((x0 + x1) / 2 + 0.08, (y0 + y1) / 2, f"$u_{a}$", color="tab:red", fontsize=11, va="center")
    for v, (x, y) in pos.items():
        shape, fill = ("square,pad=0.35", "0.85") if v == 0 else ("circle,pad=0.3", "white")
        style = {"boxstyle": shape, "fc": fill, "ec": "0.2"}
        ax.text(x, y, f"$s_{v}$", ha="center", va="center", fontsize=11, bbox=style)
    ax.set_title(title, fontsize=11)
    ax.set_xlim(-0.6, max(x for x, _ in pos.values()) + 0.6)
    ax.set_ylim(-0.5, max(y for _, y in pos.values()) + 0.5)
    ax.axis("off")


def matrix_text(M: np.ndarray) -> str:
    """A matrix as the docs print it: one row per line, integers right-aligned in width 3."""
    return "\n".join(" ".join(f"{int(x):3d}" for x in row) for row in M)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    parent, joint = topology.parent_from_arcs(PLUS, MINUS)
    order = topology.regular_numbering(parent)
    regular = topology.relabel(parent, order)
    plus_r, minus_r = topology.arcs(regular)

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    _draw(axes[0], PLUS, MINUS, "(a) any numbering, arcs directed at will")
    _draw(axes[1], plus_r, minus_r, "(b) regular numbering, arcs away from $s_0$")
    fig.tight_layout()
    fig.savefig(args.out / "trees-graph.png", dpi=110)
    plt.close(fig)

    ds = stabmap.compute_atlas(stabmap.example("tree-carrier-above-below"), progress=False)
    stabmap.plot_atlas(ds, args.out / "tree-carrier-above-below.png")

    print("i+ =", list(PLUS), " i- =", list(MINUS))
    print("parent =", list(parent), " joint of each body =", list(joint))
    print("S (rows s_0..s_7, columns u_1..u_7):\n" + matrix_text(topology.incidence(PLUS, MINUS)))
    print("T (rows u_1..u_7, columns s_1..s_7):\n" + matrix_text(topology.path_matrix(PLUS, MINUS)))
    print(f"order = {list(order)}")
    print(f"parent = {list(regular)}")
    print("S regular:\n" + matrix_text(topology.incidence(plus_r, minus_r)))
    print("T regular:\n" + matrix_text(topology.path_matrix(plus_r, minus_r)))


if __name__ == "__main__":
    main()
