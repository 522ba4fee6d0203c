"""Counts that describe a whole atlas, read chunk by chunk when the atlas is lazy (any size, bounded memory)."""

from __future__ import annotations

import xarray as xr

from .. import systems


def _counts(values) -> dict[int, int]:
    """How often each value occurs; a dask array is counted chunk by chunk (:func:`stabmap.read.blocks.counts`)."""
    from .blocks import counts

    return counts(values)


def summary(ds: xr.Dataset) -> dict:
    """Points, the stable fraction, a histogram of the label and of who decided.

    Keys: ``points``, ``stable``, ``degenerate`` (label < 0, but for ``absent`` and ``undecided``), ``absent`` (the
    system's ``absent_label``: nothing to decide there), ``undecided`` (its ``undecided_label``: not proved),
    ``stable_fraction``, the label's name (a
    histogram, e.g. ``n_complex_pairs``) and the provenance variable's name (counts by flag meaning, e.g.
    ``decided_by``).
    """
    system = systems.of_atlas(ds.attrs)
    label = _counts(ds[system.label].data)
    points = sum(label.values())
    stable = label.get(system.stable_label, 0) if system.stable_label is not None else 0
    out = {
        "points": points,
        "stable": stable,
        "degenerate": sum(c for v, c in label.items() if v < 0 and v not in (system.absent_label, system.undecided_label)),
        "absent": label.get(system.absent_label, 0) if system.absent_label is not None else 0,
        "undecided": label.get(system.undecided_label, 0) if system.undecided_label is not None else 0,
        "stable_fraction": stable / points if points else float("nan"),
        system.label: dict(sorted(label.items())),
    }
    if system.provenance is not None and system.provenance in ds:
        flags = system.variable(system.provenance)
        by = _counts(ds[system.provenance].data)
        out[system.provenance] = {m: by.get(v, 0) for v, m in flags.flags}
    return out
