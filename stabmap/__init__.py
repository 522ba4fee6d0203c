"""stabmap: stability atlases of spinning chains and trees of gyroscopes with liquid-filled cavities.

>>> import stabmap
>>> scene = stabmap.example("paper-n3-fixed")     # or stabmap.load_scene("scene.toml")
>>> ds = stabmap.compute_atlas(scene)              # xarray.Dataset
>>> stabmap.write_atlas(ds, "atlas.nc")
>>> stabmap.compute_to_file(scene, "big.nc", client="tcp://HOST:8786")   # streamed, on a dask cluster
"""

from __future__ import annotations

__version__ = "0.1.0"

import kernels as _kernels

if getattr(_kernels, "STABMAP_KERNELS", None) != 1:
    raise ImportError(
        f"the 'kernels' package found at {getattr(_kernels, '__file__', '?')} is not stabmap's "
        "(an unrelated PyPI package has the same name); uninstall it: pip uninstall kernels"
    )

from . import accessor  # noqa: E402,F401  (registers the ds.stabmap accessor)
from . import cavity  # noqa: E402
from .atlas import compute as compute_atlas  # noqa: E402
from .atlas import compute_to_file  # noqa: E402
from .critical import critical  # noqa: E402
from .errors import StabmapError  # noqa: E402
from .examples import example, example_names  # noqa: E402
from .io import open_atlas, write_atlas  # noqa: E402
from .query import StableFraction, boundaries, label_at, smallest_stable, stable_fraction, summary  # noqa: E402
from .plot import atlas_figure, plot_atlas  # noqa: E402
from .refine import compute_refined  # noqa: E402
from .scene import Axis, Body, Scene  # noqa: E402
from .scene import load as load_scene  # noqa: E402
from .scene import loads as loads_scene  # noqa: E402

__all__ = [
    "Axis",
    "Body",
    "Scene",
    "StableFraction",
    "StabmapError",
    "atlas_figure",
    "boundaries",
    "cavity",
    "compute_atlas",
    "compute_refined",
    "compute_to_file",
    "critical",
    "example",
    "example_names",
    "label_at",
    "load_scene",
    "loads_scene",
    "open_atlas",
    "plot_atlas",
    "smallest_stable",
    "stable_fraction",
    "summary",
    "write_atlas",
]
