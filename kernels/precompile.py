"""Compile the kernels an atlas calls into the on-disk cache, ahead of the first run.

    python -m stabmap.kernels.precompile            # fill this machine's cache (a cluster worker, say)
    python -m stabmap.kernels.precompile --ship DIR # and copy numba's cache files to DIR/kernels-<digest>

The build step of ``pip install .`` runs the second form (setup.py), so the
cache travels in the package and ``options.seed`` copies it into place on the
first run.  Compiling takes about 20 s on 2 cores; with a filled cache this
only loads the kernels.
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

import numba
import numpy as np

from . import options
from .block import box_block, decide_block, linearise_block, nodes_box_block
from .firstorder import first_order_block
from .kreinbox import NINFO, krein_box_block
from .rates import rate_block
from .roots import roots_block


def signatures() -> list[tuple]:
    """Argument types of every (kernel, signature) the labelled layer calls on C arrays: ``decide_block`` for
    points, ``box_block``, ``nodes_box_block`` and ``krein_box_block`` for boxes (cells, critical values), ``rate_block`` for growth rates,
    ``roots_block`` for frequencies, ``linearise_block`` for the roots' origin (``stabmap query --roots``)."""
    npts, n, lmax = 1, 1, 1
    body, joint, g = np.empty((npts, n, 6)), np.empty((npts, n)), np.empty(npts)
    E, kappa, nmodes = np.empty((npts, n, lmax)), np.empty((npts, n, lmax)), np.empty(n, np.int64)
    parent, at = np.empty(n, np.int64), np.empty((npts, n))
    out = (np.empty(npts, np.int16), np.empty(npts, np.int8))
    args = (body, joint, g, E, kappa, nmodes, False, parent, at) + out
    box = (body, body.copy(), joint, joint.copy(), g, g.copy(), E, kappa, nmodes, False, parent, at, at.copy()) + out
    # nodes_box_block: the inputs at each node (a node axis after the box axis), the nodes t, t_lo, t_hi of the
    # first axis and t2, t2_lo, t2_hi of the second (one node at 0 for a box along one axis), and whether t is u
    b4, j3, g2, a3 = body[:, None], joint[:, None], g[:, None], at[:, None]
    nodes = (b4, b4.copy(), j3, j3.copy(), g2, g2.copy(), E, kappa, nmodes, False, parent, a3, a3.copy(), g2.copy(), g.copy(), g.copy(),
             g2.copy(), g.copy(), g.copy(), False) + out + (np.empty(npts, np.int8),)
    roots = args[:9] + (np.empty((npts, 2), np.complex128), np.empty((npts, 2)), np.empty((npts, 2), np.int8), np.empty((npts, 3)),
                        np.empty(npts, np.int8))
    linear = args[:9] + (np.empty((npts, 2, 2)),)
    rate = args[:9] + (np.empty(npts, np.int64), np.empty((npts, 3)), np.empty(npts, np.int8))
    # first_order_block: the viscous cavities' bodies, eps and its radius, the roots of roots_block, and its outputs
    first = args[:9] + (np.empty(1, np.int64), np.empty((npts, 1)), np.empty((npts, 1))) + roots[9:12] + (
        np.empty((npts, 2)), np.empty((npts, 2)), np.empty((npts, 2), np.int8))
    # krein_box_block: the inputs at the two ends of the box's mechanical axis, u's interval, warm starts, N_c,
    # status and the info columns
    krein = (b4.repeat(2, 1), j3.repeat(2, 1), g2.repeat(2, 1), a3.repeat(2, 1), E, kappa, nmodes, False, parent, g.copy(), g.copy(),
             True) + out + (np.empty((npts, NINFO), np.int64),)
    return [(decide_block, tuple(numba.typeof(a) for a in args)), (box_block, tuple(numba.typeof(a) for a in box)),
            (krein_box_block, tuple(numba.typeof(a) for a in krein)),
            (nodes_box_block, tuple(numba.typeof(a) for a in nodes)), (roots_block, tuple(numba.typeof(a) for a in roots)),
            (rate_block, tuple(numba.typeof(a) for a in rate)),
            (linearise_block, tuple(numba.typeof(a) for a in linear)), (first_order_block, tuple(numba.typeof(a) for a in first))]


def precompile() -> dict:
    """Compile (or load from the cache) every kernel of ``signatures``; say what it took.

    Returns a dict with ``seconds``, ``cache_path`` (numba's directory, None if the
    cache is off) and ``compiled``/``loaded`` counts of signatures.
    """
    t0 = time.perf_counter()
    compiled = loaded = 0
    for dispatcher, sig in signatures():
        hits = sum(dispatcher.stats.cache_hits.values())
        dispatcher.compile(sig)
        if sum(dispatcher.stats.cache_hits.values()) > hits:
            loaded += 1
        else:
            compiled += 1
    path = signatures()[0][0].stats.cache_path
    return {"seconds": time.perf_counter() - t0, "cache_path": path, "compiled": compiled, "loaded": loaded}


def ship(cache_path: str | Path, out: str | Path) -> Path:
    """Copy numba's cache files (``*.nbi``, ``*.nbc``) from ``cache_path`` to ``out/kernels-<digest>``."""
    target = Path(out) / f"kernels-{options.DIGEST}"
    target.mkdir(parents=True, exist_ok=True)
    for f in Path(cache_path).iterdir():
        if f.suffix in {".nbi", ".nbc"}:
            shutil.copyfile(f, target / f.name)
    return target


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m stabmap.kernels.precompile", description=__doc__.splitlines()[0])
    parser.add_argument("--ship", metavar="DIR", help="also copy the cache files to DIR/kernels-<digest>")
    args = parser.parse_args(argv)
    done = precompile()
    print(f"kernels: {done['compiled']} compiled, {done['loaded']} loaded from the cache in {done['seconds']:.1f} s; "
          f"cache: {done['cache_path']}")
    if args.ship:
        if done["cache_path"] is None:
            raise SystemExit("the kernel cache is off (STABMAP_NUMBA_CACHE=0 or an unwritable cache dir): nothing to ship")
        print(f"shipped to {ship(done['cache_path'], args.ship)}")


if __name__ == "__main__":
    main()
