"""Bodies joined as a tree: Wittenburg's directed graph, incidence matrix S and path matrix T.

Wittenburg, *Dynamics of Systems of Rigid Bodies*, 5.2.1 (docs/model.md, References);
the formalism and the lever arms it gives are derived in ``docs/trees.md``.

The bodies 1..n and the base, body 0, are the vertices of a tree; arc (joint) a
joins body a to its parent, the next body on its path to the base.  Body 1 is
the body on the base (Wittenburg's convention) and the only one: several joints
to the base would split the system into independent subsystems.  For a free
system body 0 is no body at all, and body 1 is the reference body.  A topology
is given by ``parent`` (1-based, parent[k - 1] of body k, 0 = the base), as in a
scene's ``[topology]`` table; a chain is parent = (0, 1, ..., n - 1).

A directed graph is given by Wittenburg's functions i+(a) and i-(a), the
vertices that arc a leaves and enters (``arcs`` makes them from ``parent``, arc a
being the joint of body a, pointing away from the base unless ``toward_base``).
Then

    S[i, a] = +1 if i = i+(a), -1 if i = i-(a), else 0     (i = 0..n, a = 1..n)
    T[a, i] = +1 (-1) if arc a lies on the path from the base to body i and
              points toward (away from) the base, else 0

and (seed, 5.5 and 5.6)  S_0 T = -1^T  and  S T = T S = E,  where S_0 is the base
row of S and S the rest.  Matrix rows and columns are 0-based here (row 0 of
``incidence`` is the base, column a - 1 is arc a; ``path_matrix`` row a - 1 is
arc a, column i - 1 body i).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import StabmapError
from ...scene.values import check_value
from .parameters import POSITION


@dataclass(frozen=True)
class Topology:
    """A tree of bodies: each body's parent and the position of its joint on the parent's axis.

    ``parent[k - 1]`` is the parent of body k (0: the base, or none for a free
    system; only body 1 has it).  ``at[k - 1]`` [m] is the position of the joint
    of body k on the parent's axis, measured from the parent's own joint, up
    positive (negative: the body hangs below its parent's joint); ``at[0]`` is 0.
    """

    parent: tuple[int, ...]
    at: tuple[float, ...]

    def __post_init__(self):
        object.__setattr__(self, "parent", check_parent(self.parent, "topology.parent"))
        if isinstance(self.at, (str, bytes)) or not hasattr(self.at, "__len__") or len(self.at) != len(self.parent):
            raise StabmapError(f"topology.at must be a list with one position per body ({len(self.parent)}), got {self.at!r}")
        at = tuple(check_value(f"topology.at[{k + 1}]", v, POSITION) for k, v in enumerate(self.at))
        if at[0] != 0.0:
            raise StabmapError(
                f"topology.at[1] must be 0, got {at[0]}: body 1's joint is the base point (or a free system's "
                "reference point), not a place on another body"
            )
        object.__setattr__(self, "at", at)

    @property
    def n(self) -> int:
        return len(self.parent)


def chain(n: int) -> tuple[int, ...]:
    """The parent array of a chain of n bodies, body 1 at the bottom."""
    return tuple(range(n))


def check_parent(parent, where: str = "topology.parent") -> tuple[int, ...]:
    """Return ``parent`` as a tuple of ints, or raise a StabmapError naming ``where`` and the fix.

    Valid: one entry per body, body 1 on the base (0), every other body on a body
    1..n other than itself, and every body's path of parents reaching the base
    (no loop): the graph of bodies and joints is then a tree.
    """
    if not isinstance(parent, (list, tuple)) or not parent:
        raise StabmapError(f"{where} must be a non-empty list with the parent of each body (0: the base), got {parent!r}")
    n = len(parent)
    for k, p in enumerate(parent, start=1):
        if isinstance(p, bool) or not isinstance(p, (int, np.integer)):
            raise StabmapError(f"{where}[{k}] must be a whole number (the parent of body {k}; 0: the base), got {p!r}")
        if not 0 <= p <= n:
            raise StabmapError(f"{where}[{k}] = {p}: bodies are numbered 1..{n} and 0 is the base")
        if p == k:
            raise StabmapError(f"{where}[{k}] = {k}: body {k} cannot be its own parent; give the body it is mounted on")
    parent = tuple(int(p) for p in parent)
    if parent[0] != 0:
        raise StabmapError(
            f"{where}[1] = {parent[0]}: body 1 is the body on the base (Wittenburg's numbering); "
            f"set {where}[1] = 0 and renumber the bodies so that the one on the base comes first"
        )
    others = [k for k, p in enumerate(parent, start=1) if p == 0 and k != 1]
    if others:
        raise StabmapError(
            f"{where}[{others[0]}] = 0: only body 1 may be joined to the base (body 0). A tree has one joint to "
            f"the base; several would split it into independent systems, each its own scene. Mount body "
            f"{others[0]} on a body 1..{n}"
        )
    for k in range(1, n + 1):
        seen = [k]
        j = parent[k - 1]
        while j != 0:
            if j in seen:
                loop = seen[seen.index(j):]
                chain_text = " -> ".join(str(b) for b in loop + [j])
                raise StabmapError(
                    f"{where}: bodies {chain_text} form a closed loop that never reaches the base, so the bodies "
                    f"are not joined as a tree; give one of them a parent on the way to body 1"
                )
            seen.append(j)
            j = parent[j - 1]
    return parent


def children(parent) -> list[list[int]]:
    """children[i] lists the bodies whose parent is i (i = 0..n, 0 the base), in increasing order."""
    out: list[list[int]] = [[] for _ in range(len(parent) + 1)]
    for k, p in enumerate(parent, start=1):
        out[p].append(k)
    return out


def path(parent, k: int) -> list[int]:
    """The bodies on the path from the base to body k, base side first (k included, the base not)."""
    out = []
    while k != 0:
        out.append(k)
        k = parent[k - 1]
    return out[::-1]


def arcs(parent, toward_base=False) -> tuple[np.ndarray, np.ndarray]:
    """Wittenburg's functions i+(a) and i-(a) when arc a is the joint of body a with its parent.

    ``toward_base``: one bool for every arc or a sequence with one per arc (True:
    the arc points from body a to its parent).  Returns int64 arrays (n,):
    entry a - 1 is the vertex arc a leaves, respectively enters.
    """
    parent = np.asarray(parent, dtype=np.int64)
    own = np.arange(1, len(parent) + 1)
    toward = np.broadcast_to(np.asarray(toward_base, dtype=bool), parent.shape)
    return np.where(toward, own, parent), np.where(toward, parent, own)


def check_arcs(i_plus, i_minus) -> None:
    """Raise a StabmapError unless the arcs (i+(a), i-(a)), a = 1..n, join the vertices 0..n as a tree.

    n arcs on n + 1 vertices form a tree exactly when they leave no vertex
    unreachable from vertex 0 (Wittenburg's example of a pair of functions that is
    no tree has a loop, and so an unreachable vertex).
    """
    i_plus, i_minus = list(i_plus), list(i_minus)
    n = len(i_plus)
    if len(i_minus) != n:
        raise StabmapError(f"i+ has {n} arcs but i- has {len(i_minus)}")
    for a, (u, v) in enumerate(zip(i_plus, i_minus, strict=True), start=1):
        if not (0 <= u <= n and 0 <= v <= n) or u == v:
            raise StabmapError(f"arc {a} = ({u}, {v}) must join two different vertices of 0..{n}")
    reached = _reach(i_plus, i_minus)
    if len(reached) != n + 1:
        missing = sorted(set(range(n + 1)) - set(reached))
        raise StabmapError(
            f"the arcs do not join the bodies as a tree: no path leads from body 0 to {missing} "
            "(so some arcs close a loop); every body needs exactly one path to body 0"
        )


def _reach(i_plus, i_minus) -> dict[int, tuple[int, int]]:
    """Vertices reachable from 0: vertex -> (arc leading to it from the base side, previous vertex)."""
    reached = {0: (0, -1)}
    todo = [0]
    while todo:
        v = todo.pop()
        for a, (x, y) in enumerate(zip(i_plus, i_minus, strict=True), start=1):
            for here, there in ((x, y), (y, x)):
                if here == v and there not in reached:
                    reached[there] = (a, v)
                    todo.append(there)
    return reached


def incidence(i_plus, i_minus) -> np.ndarray:
    """The incidence matrix, int (n + 1, n): S[i, a - 1] = +1 if i = i+(a), -1 if i = i-(a), else 0.

    Row 0 is the base row S_0.  For a topology given by ``parent``: ``incidence(*arcs(parent))``.
    """
    n = len(i_plus)
    S = np.zeros((n + 1, n), dtype=np.int64)
    S[np.asarray(i_plus, dtype=np.int64), np.arange(n)] = 1
    S[np.asarray(i_minus, dtype=np.int64), np.arange(n)] = -1
    return S


def path_matrix(i_plus, i_minus) -> np.ndarray:
    """The path matrix, int (n, n): T[a - 1, i - 1] = +1 (-1) if arc a is on the path from 0 to body i
    and points toward (away from) 0, else 0.  The arcs must form a tree (``check_arcs``)."""
    check_arcs(i_plus, i_minus)
    n = len(i_plus)
    reached = _reach(i_plus, i_minus)
    T = np.zeros((n, n), dtype=np.int64)
    for i in range(1, n + 1):
        v = i
        while v != 0:
            a, previous = reached[v]
            T[a - 1, i - 1] = 1 if i_minus[a - 1] == previous else -1
            v = previous
    return T


def parent_from_arcs(i_plus, i_minus) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(parent, joint): the parent of each body and the arc joining it to its parent (Wittenburg's
    preceding vertex and preceding arc)."""
    check_arcs(i_plus, i_minus)
    reached = _reach(i_plus, i_minus)
    n = len(i_plus)
    return tuple(reached[k][1] for k in range(1, n + 1)), tuple(reached[k][0] for k in range(1, n + 1))


def is_regular(parent) -> bool:
    """True if every parent comes before its children (a regular numbering: indices grow along every path)."""
    return all(p < k for k, p in enumerate(parent, start=1))


def regular_numbering(parent) -> tuple[int, ...]:
    """A regular numbering of the tree by Wittenburg's pruning: ``order[i - 1]`` is the old label of new body i.

    The terminal bodies (no children) get the largest free numbers, larger old
    labels first; they and their arcs are cut off, and the procedure repeats on
    the smaller tree until every body has a number.  Body 1 keeps number 1, every
    arc keeps the number of the body it leads to, and every parent gets a smaller
    number than its children.
    """
    parent = check_parent(list(parent))
    n = len(parent)
    left = [len(c) for c in children(parent)]
    remaining = set(range(1, n + 1))
    order = [0] * n
    free = n
    while remaining:
        terminal = sorted((k for k in remaining if left[k] == 0), reverse=True)
        for k in terminal:
            order[free - 1] = k
            free -= 1
            remaining.discard(k)
            left[parent[k - 1]] -= 1
    return tuple(order)


def relabel(parent, order) -> tuple[int, ...]:
    """The parent array in the numbering ``order`` (``order[i - 1]``: old label of new body i)."""
    new = {old: i for i, old in enumerate(order, start=1)}
    new[0] = 0
    return tuple(new[parent[old - 1]] for old in order)


def kernel_layout(parent) -> tuple[np.ndarray, np.ndarray]:
    """(order, kernel_parent) for the kernels: bodies in a regular numbering, 0-based.

    ``order`` (int64[n]) is the 0-based scene index of each kernel body: the
    identity when the scene's numbering is already regular, else Wittenburg's
    ``regular_numbering``.  ``kernel_parent[0] = -1`` and 0 <= kernel_parent[k] < k.
    """
    parent = tuple(parent)
    order = tuple(range(1, len(parent) + 1)) if is_regular(parent) else regular_numbering(parent)
    kparent = np.array(relabel(parent, order), dtype=np.int64) - 1
    return np.array(order, dtype=np.int64) - 1, kparent


def lever_arms(parent, at, c) -> np.ndarray:
    """The lever-arm matrix J of a fixed support from S and T: J = diag(c) - T^T diag(at) S+^T.

    S+ is the positive part of S without the base row: S+[i, a] = 1 if body i is
    the parent of body a, so S+^T theta takes each joint to the tilt of its parent's
    axis, diag(at) turns that into the joint's lateral displacement, and -T^T adds
    them up along the path of each body (docs/trees.md).  Arcs point away from the
    base.  Works on any element type numpy can multiply (floats, Fractions).
    """
    S_plus = np.maximum(incidence(*arcs(parent))[1:], 0).astype(object)
    T = path_matrix(*arcs(parent)).astype(object)
    return np.diag(np.asarray(c, dtype=object)) - T.T @ np.diag(np.asarray(at, dtype=object)) @ S_plus.T


__all__ = [
    "Topology",
    "arcs",
    "chain",
    "check_arcs",
    "check_parent",
    "children",
    "incidence",
    "is_regular",
    "kernel_layout",
    "lever_arms",
    "parent_from_arcs",
    "path",
    "path_matrix",
    "regular_numbering",
    "relabel",
]
