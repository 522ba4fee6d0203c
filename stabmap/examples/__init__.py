"""Bundled example scenes (the paper's cases n = 1, 2, 3, fixed and free; a cavity; trees of bodies; reactions of joints)."""

from __future__ import annotations

from importlib import resources

from ..errors import StabmapError
from ..systems import loads_scene
from ..systems.base import SceneBase


def example_names() -> list[str]:
    """Names accepted by ``example`` and ``stabmap atlas --example``."""
    return sorted(p.name[:-5] for p in resources.files(__package__).iterdir() if p.name.endswith(".toml"))


def example(name: str) -> SceneBase:
    """Load a bundled example scene by name."""
    if name not in example_names():
        raise StabmapError(f"unknown example {name!r}; choose one of: {', '.join(example_names())}")
    text = resources.files(__package__).joinpath(name + ".toml").read_text(encoding="utf-8")
    return loads_scene(text, source=f"example {name}")
