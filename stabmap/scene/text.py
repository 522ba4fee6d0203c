"""Scenes as TOML text: read with ``tomllib``, written with ``tomli_w`` (so any string survives the trip)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import StabmapError


def read(path: str | Path) -> tuple[dict, Path]:
    """The TOML table of a scene file and its directory (relative file names in it are taken from there)."""
    from ..store.files import kind_of

    path = Path(path)
    if kind_of(path) in ("netCDF", "Zarr"):  # an atlas where a scene was expected
        raise StabmapError(
            f"{str(path)!r} is an atlas ({kind_of(path)}), not a scene; a scene is a TOML text file "
            f"(see 'stabmap examples --show NAME'); to look into this atlas: 'stabmap info {path}'"
        )
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise StabmapError(f"scene file {str(path)!r} does not exist") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as exc:
        what = "a directory" if isinstance(exc, IsADirectoryError) else "binary" if isinstance(exc, UnicodeDecodeError) else "no read permission"
        raise StabmapError(f"cannot read scene file {str(path)!r} ({what}): a scene is a TOML text file") from None
    return parse(text, str(path)), path.parent


def parse(text: str, source: str = "<scene>") -> dict:
    """The TOML table of scene text; a syntax error names ``source``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StabmapError(f"{source}: TOML syntax error: {exc}") from None


def dumps(table: dict) -> str:
    """TOML text of a scene's table (``Scene.to_dict``)."""
    import tomli_w

    return tomli_w.dumps(table)
