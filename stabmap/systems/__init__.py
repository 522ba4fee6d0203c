"""The systems stabmap computes, one subpackage each, and the scenes that name them.

Adding a system is adding a subpackage that defines a ``System`` (``base.py``)
as ``SYSTEM``, and one line to ``SYSTEMS`` below (docs/systems.md).  Subpackages
are imported when first named, so a command pays only for the system it uses.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from ..errors import StabmapError
from ..scene import text
from .base import SceneBase, System

SYSTEMS = {
    "gyroscopes": "stabmap.systems.gyroscopes",
    "closed": "stabmap.systems.closed",
    "reactions": "stabmap.systems.reactions",
    "viscous": "stabmap.systems.viscous",
}
DEFAULT = "gyroscopes"  # scene files and atlases from before the ``system`` key


def names() -> list[str]:
    return list(SYSTEMS)


def get(name: str) -> System:
    """The registered system called ``name``."""
    if name not in SYSTEMS:
        raise StabmapError(f"system = {name!r} is not a system stabmap knows; choose one of: {', '.join(SYSTEMS)}")
    return importlib.import_module(SYSTEMS[name]).SYSTEM


def of(scene: SceneBase) -> System:
    """The system of a scene.

    A system that is not in ``SYSTEMS`` here but was registered in the process that made the scene (a cluster's
    worker receives scenes of systems its own registry never saw: a plug-in added at run time) is the ``SYSTEM``
    of the module that defines the scene's type, or of a package above it.
    """
    if scene.system not in SYSTEMS:
        module = type(scene).__module__
        while module:
            found = getattr(importlib.import_module(module), "SYSTEM", None)
            if isinstance(found, System) and found.name == scene.system:
                return found
            module = module.rpartition(".")[0]
    return get(scene.system)


def of_atlas(attrs: dict) -> System:
    """The system of an atlas, from its global attributes."""
    return get(str(attrs.get("stabmap_system", DEFAULT)))


def scene_from_dict(table: dict, base_dir: str | Path | None = None) -> SceneBase:
    """The scene of a TOML table; ``system = "..."`` chooses the system (default: gyroscopes)."""
    if not isinstance(table, dict):
        raise StabmapError(f"a scene must be a TOML table, got {table!r}")
    table = dict(table)
    name = table.pop("system", DEFAULT)
    if not isinstance(name, str):
        raise StabmapError(f"system must be a string such as {DEFAULT!r}, got {name!r}")
    return get(name).scene_from_dict(table, None if base_dir is None else Path(base_dir))


def loads_scene(source_text: str, source: str = "<scene>", base_dir: str | Path | None = None) -> SceneBase:
    """Parse and validate scene TOML text; relative file names in it are taken from ``base_dir``."""
    return scene_from_dict(text.parse(source_text, source), base_dir)


def load_scene(path: str | Path) -> SceneBase:
    """Read and validate a scene file; every problem is a StabmapError naming the key."""
    table, base_dir = text.read(path)
    return scene_from_dict(table, base_dir)
