"""Cell geometry of a map: the edges of grid cells, runs and rectangles of marked cells, the boundary segments on
cell edges between differing neighbours and their widths, and the same for blocks of cells of a reduced map.

Maps draw the cells an atlas proves its labels on (:func:`proved_cell_edges`: midpoints, the scan's ends); everything
here follows log and irregular (``values``) grids. Nothing here draws.
"""

from __future__ import annotations

import numpy as np


def cell_edges(centres: np.ndarray, scale: str | None) -> np.ndarray:
    """Cell edges around grid values: midpoints (geometric midpoints on a log axis), half a step beyond the ends."""
    centres = np.asarray(centres, dtype=float)
    if len(centres) == 1:
        c = centres[0]
        if scale == "log" and c > 0:
            return np.array([c / 1.1, c * 1.1])
        h = 0.5 * abs(c) if c != 0 else 0.5
        return np.array([c - h, c + h])
    if scale == "log" and np.all(centres > 0):
        lc = np.log(centres)
        mid = (lc[1:] + lc[:-1]) / 2
        return np.exp(np.concatenate([[2 * lc[0] - mid[0]], mid, [2 * lc[-1] - mid[-1]]]))
    mid = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def proved_cell_edges(centres: np.ndarray, log: bool) -> np.ndarray:
    """The edges of the cells an atlas proves its labels on (:func:`stabmap.store.dataset.edges`, its CF bounds):
    midpoints, on a log axis too, and the first and last grid values at the ends, so that a map colours nothing
    beyond the scan. A one-value axis has a cell of width 0: it is drawn as :func:`cell_edges` draws it, a strip."""
    from ...store.dataset import edges

    centres = np.asarray(centres, dtype=float)
    return edges(centres) if len(centres) > 1 else cell_edges(centres, "log" if log else None)


def runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs of True along the last axis of a 2-D mask: (line, start, stop) with stop exclusive."""
    padded = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    d = np.diff(padded, axis=1)
    line, start = np.nonzero(d == 1)
    _, stop = np.nonzero(d == -1)
    return line, start, stop


def segments(mask_v: np.ndarray, mask_h: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> np.ndarray:
    """Line segments, shape (k, 2, 2), along the marked cell edges, collinear neighbours joined.

    ``mask_v[j, i]``: the edge between cells (j, i) and (j, i + 1), at x = xe[i + 1] from ye[j] to ye[j + 1].
    ``mask_h[j, i]``: the edge between cells (j, i) and (j + 1, i), at y = ye[j + 1] from xe[i] to xe[i + 1].
    """
    i, j0, j1 = runs(mask_v.T)
    vertical = np.stack([np.stack([xe[i + 1], ye[j0]], -1), np.stack([xe[i + 1], ye[j1]], -1)], 1)
    j, i0, i1 = runs(mask_h)
    horizontal = np.stack([np.stack([xe[i0], ye[j + 1]], -1), np.stack([xe[i1], ye[j + 1]], -1)], 1)
    return np.concatenate([vertical.reshape(-1, 2, 2), horizontal.reshape(-1, 2, 2)])


def cell_edge_boundaries(
    values: np.ndarray, xedges: np.ndarray, yedges: np.ndarray, stable: int | None = 0, *, state: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Boundaries of a 2-D class map on the edges of its grid cells.

    Parameters
    ----------
    values : array of int, shape (ny, nx)
        The label per grid point (or a code per block), rows along y.
    xedges, yedges : arrays of float, shapes (nx + 1,) and (ny + 1,)
        Cell edges in data coordinates (see :func:`cell_edges`).
    stable : int or None
        The stable label (None: a system without one).
    state : array of int, shape (ny, nx), optional
        Stability per cell (default: ``values == stable``); a thick line runs where it differs.

    Returns
    -------
    stability, classes : arrays of float, shape (k, 2, 2)
        Segments ``[[x0, y0], [x1, y1]]`` on every edge between two neighbouring cells whose stability differs,
        and on every other edge where the label differs. Collinear neighbouring segments are joined.
    """
    v = np.asarray(values)
    xe, ye = np.asarray(xedges, dtype=float), np.asarray(yedges, dtype=float)
    is_stable = v == stable if state is None else np.asarray(state)
    dv, dh = v[:, 1:] != v[:, :-1], v[1:, :] != v[:-1, :]
    sv, sh = is_stable[:, 1:] != is_stable[:, :-1], is_stable[1:, :] != is_stable[:-1, :]
    return segments(sv, sh, xe, ye), segments(dv & ~sv, dh & ~sh, xe, ye)


def rectangles(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> list[np.ndarray]:
    """The marked cells as few rectangles: runs along x, merged with identical runs in the rows above."""
    line, start, stop = runs(mask)
    open_: dict[tuple[int, int], tuple[int, int]] = {}  # a run (start, stop) along x -> its rows [j0, j1)
    done: list[tuple[int, int, int, int]] = []
    previous = -1
    for j, a, b in zip(line, start, stop, strict=True):
        if j != previous:  # close runs that did not continue into this row
            for key, (j0, j1) in list(open_.items()):
                if j1 < j:
                    done.append((key[0], key[1], j0, j1))
                    del open_[key]
            previous = j
        key = (int(a), int(b))
        if key in open_ and open_[key][1] == j:
            open_[key] = (open_[key][0], j + 1)
        else:
            if key in open_:
                done.append((key[0], key[1], *open_[key]))
            open_[key] = (j, j + 1)
    done.extend((k[0], k[1], j0, j1) for k, (j0, j1) in open_.items())
    return [np.array([[xe[a], ye[j0]], [xe[b], ye[j0]], [xe[b], ye[j1]], [xe[a], ye[j1]]]) for a, b, j0, j1 in done]


def block_edges(edges: np.ndarray, k: int) -> np.ndarray:
    """Edges of blocks of ``k`` cells from the cells' edges: every k-th edge and the last."""
    n = len(edges) - 1
    return edges[np.r_[0:n:k, n]]


def block_classes(blocks, stable: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Codes and stability states of the blocks, for drawing boundaries between blocks.

    A block of one label keeps it as its code; a block of several labels gets a code of its own (one for those
    holding stable and unstable points, one for the others), so that a line runs wherever the codes of
    neighbouring blocks differ. The state is 1 for a stable block, 2 for a block holding stable and unstable
    points, 0 otherwise: a thick line runs wherever the states differ, so a block holding a stability boundary is
    drawn black between two thick lines.
    """
    codes = blocks.low.astype(np.int64)
    top = int(max(blocks.high.max(initial=0), 0))
    codes[blocks.mixed] = top + 1
    codes[blocks.mixed_stability] = top + 2
    if stable is None:
        return codes, np.zeros(codes.shape, dtype=np.int8)
    state = np.where(blocks.mixed_stability, 2, (blocks.low == stable) & ~blocks.mixed).astype(np.int8)
    return codes, state


def boundary_widths(segs: np.ndarray, xe: np.ndarray, ye: np.ndarray, span: tuple[float, float], widest: float,
                    log: tuple[bool, bool] = (False, False), codes: np.ndarray | None = None) -> np.ndarray:
    """Line widths [pt] of boundary segments: ``widest``, but at most a third of the narrower of the two bands a
    segment separates (at least 0.35 pt), so that a band one cell wide keeps its class colour between its two
    boundary lines instead of turning into a black bar, while a boundary between wide regions stays thick.

    A band is the run of cells of one class in ``codes`` (shape (ny, nx)) across the segment, measured along the
    whole segment (its narrowest place counts); without ``codes`` every cell is a band of its own.
    ``span`` is the map's size in points along (y, x); ``log`` says which of (x, y) is drawn on a log scale.
    """
    segs = np.asarray(segs, dtype=float).reshape(-1, 2, 2)
    if not len(segs):
        return np.full(0, widest)
    if codes is None:
        codes = np.arange((len(ye) - 1) * (len(xe) - 1)).reshape(len(ye) - 1, len(xe) - 1)

    def cells(edges: np.ndarray, is_log: bool, points: float) -> np.ndarray:
        e = np.log(edges) if is_log else np.asarray(edges, dtype=float)
        return np.abs(np.diff(e)) / max(abs(e[-1] - e[0]), 1e-300) * points

    def bands(c: np.ndarray, size: np.ndarray) -> np.ndarray:
        """Per cell, the width [pt] of its run of equal codes along the last axis."""
        start = np.ones(c.shape, dtype=bool)
        start[:, 1:] = c[:, 1:] != c[:, :-1]  # a run never crosses into the next line
        run = np.cumsum(start.ravel()) - 1
        width = np.bincount(run, weights=np.broadcast_to(size, c.shape).ravel())
        return width[run].reshape(c.shape)

    def narrowest(table: np.ndarray, line: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """min of table[line, a:b] for every segment, in one pass."""
        flat = np.append(table.ravel(), np.inf)
        starts = np.stack([line * table.shape[1] + a, line * table.shape[1] + b], 1).ravel()
        return np.minimum.reduceat(flat, starts)[::2]

    def index(edges: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The edge nearest each of ``v`` (a segment's ends lie on edges), by bisection: no segments x edges table."""
        order = np.argsort(edges)
        e = edges[order]
        i = np.clip(np.searchsorted(e, v), 1, len(e) - 1)
        i -= (v - e[i - 1]) < (e[i] - v)
        return order[i]

    codes = np.asarray(codes)
    along_x = bands(codes, cells(xe, log[0], span[1]))
    along_y = bands(codes.T, cells(ye, log[1], span[0])).T
    vertical = segs[:, 0, 0] == segs[:, 1, 0]
    out = np.empty(len(segs))
    for mask, table, edges, ends, at, pos in (
        (vertical, np.minimum(along_x[:, :-1], along_x[:, 1:]).T, xe, ye, 0, 1),
        (~vertical, np.minimum(along_y[:-1, :], along_y[1:, :]), ye, xe, 1, 0),
    ):
        if mask.any():
            s = segs[mask]
            i0, i1 = index(ends, s[:, 0, pos]), index(ends, s[:, 1, pos])
            out[mask] = narrowest(table, index(edges, s[:, 0, at]) - 1, np.minimum(i0, i1), np.maximum(i0, i1))
    return np.clip(out / 3.0, 0.35, widest)
