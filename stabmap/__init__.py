"""stabmap: stability atlases of spinning multibody systems, every label proved.

>>> import stabmap
>>> scene = stabmap.example("paper-n3-fixed")     # or stabmap.load_scene("scene.toml")
>>> ds = stabmap.compute_atlas(scene)              # xarray.Dataset
>>> stabmap.write_atlas(ds, "atlas.nc")
>>> stabmap.compute_to_file(scene, "big.nc", client="tcp://HOST:8786")   # streamed, on a dask cluster

The pipeline is scene -> points -> decide -> store -> read: ``stabmap.systems``
(one subpackage per system, with its scenes and its decision), ``stabmap.run``
(grid, chunks, tasks here or on a cluster, refinement, critical values),
``stabmap.store`` (outputs, files, checkpoints) and ``stabmap.read`` (query,
plot).  The names below are loaded when first used, so ``import stabmap`` is light.
"""

from __future__ import annotations

import importlib

import wrapt

from .errors import StabmapError as StabmapError
from .version import __version__ as __version__

_API: dict[str, str | tuple[str, str]] = {
    "Axis": "stabmap.scene.grid",
    "Body": "stabmap.systems.gyroscopes.scene",
    "Hold": "stabmap.systems.gyroscopes.ratios",
    "Scene": "stabmap.systems.gyroscopes.scene",
    "StableFraction": "stabmap.read.query",
    "atlas_figure": "stabmap.read.plot",
    "boundaries": "stabmap.read.query",
    "compute_atlas": ("stabmap.run.atlas", "compute"),
    "compute_refined": "stabmap.run.refine",
    "compute_to_file": "stabmap.run.atlas",
    "critical": "stabmap.run.critical",
    "example": "stabmap.examples",
    "example_names": "stabmap.examples",
    "explore": "stabmap.read.explore",
    "label_at": "stabmap.read.query",
    "load_scene": "stabmap.systems",
    "loads_scene": "stabmap.systems",
    "open_atlas": "stabmap.store.files",
    "plot_atlas": "stabmap.read.plot",
    "plot_critical": "stabmap.read.plot",
    "roots": "stabmap.read.roots",
    "smallest_stable": "stabmap.read.query",
    "stable_fraction": "stabmap.read.query",
    "summary": "stabmap.read.summary",
    "variable_figure": "stabmap.read.plot",
    "write_atlas": "stabmap.read.subset",
}
_MODULES = {"cavity": "stabmap.systems.gyroscopes.cavity", "closed": "stabmap.closed", "reactions": "stabmap.reactions"}

__all__ = sorted(["StabmapError", "__version__", *_API, *_MODULES])


def __getattr__(name: str):
    if name in _MODULES:
        return importlib.import_module(_MODULES[name])
    if name not in _API:
        raise AttributeError(f"module 'stabmap' has no attribute {name!r}")
    where = _API[name]
    module, attr = where if isinstance(where, tuple) else (where, name)
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return __all__


def _register_accessor(_xarray) -> None:
    importlib.import_module("stabmap.read.accessor")


# ``ds.stabmap`` on every Dataset: registered as soon as xarray is imported (at once if it already is).
wrapt.register_post_import_hook(_register_accessor, "xarray")
