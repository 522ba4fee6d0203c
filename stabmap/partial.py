"""The finished chunks of an atlas run, kept on disk so an interrupted run can be resumed.

``atlas.nc`` is computed into the directory ``atlas.nc.partial/``: a manifest
(the scene and the chunk layout) and one ``.npy`` file per finished chunk.
Every file appears by an atomic rename, so a run killed at any instant leaves
only whole chunks; a temporary file left half-written is ignored and removed.
The directory is deleted once the atlas file is complete.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np

from .errors import StabmapError

FORMAT = 1
MANIFEST = "manifest.json"


def partial_dir(output: str | Path) -> Path:
    output = Path(output)
    return output.with_name(output.name + ".partial")


class PartialRun:
    """Finished chunks of one atlas (scene TOML, shape and chunk sizes fixed by the manifest)."""

    def __init__(self, path: Path, scene_toml: str, shape: tuple[int, ...], chunks: tuple[int, ...]):
        self.path, self.scene_toml, self.shape, self.chunks = Path(path), scene_toml, tuple(shape), tuple(chunks)

    @classmethod
    def create(cls, path: Path, scene_toml: str, shape, chunks) -> PartialRun:
        run = cls(path, scene_toml, shape, chunks)
        path.mkdir()
        manifest = {"stabmap_partial_format": FORMAT, "shape": list(run.shape), "chunks": list(run.chunks), "scene": scene_toml}
        _atomic_write(path / MANIFEST, json.dumps(manifest, indent=1).encode())
        return run

    @classmethod
    def open(cls, path: Path) -> PartialRun:
        try:
            manifest = json.loads((path / MANIFEST).read_text())
            if manifest.get("stabmap_partial_format") != FORMAT:
                raise ValueError(f"format {manifest.get('stabmap_partial_format')!r}, expected {FORMAT}")
            run = cls(path, manifest["scene"], manifest["shape"], manifest["chunks"])
        except (OSError, ValueError, KeyError) as exc:
            raise StabmapError(f"{str(path)!r} is not a readable partial stabmap run ({exc}); delete it to start over") from None
        for stale in path.glob("*.tmp"):
            stale.unlink(missing_ok=True)
        return run

    def chunk_file(self, index: int) -> Path:
        return self.path / f"chunk-{index:08d}.npy"

    def done(self) -> set[int]:
        return {int(p.stem.split("-")[1]) for p in self.path.glob("chunk-*.npy")}

    def save(self, index: int, block: np.ndarray) -> None:
        target = self.chunk_file(index)
        tmp = target.with_name(target.name + ".tmp")
        with open(tmp, "wb") as f:
            np.save(f, block, allow_pickle=False)
        os.replace(tmp, target)

    def load(self, index: int) -> np.ndarray:
        return np.load(self.chunk_file(index), allow_pickle=False)

    def remove(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


def _atomic_write(path: Path, data: bytes) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)
