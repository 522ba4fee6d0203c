"""Atlas files: netCDF4, compressed, written atomically."""

from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

from .errors import StabmapError


def check_writable(path: str | Path) -> Path:
    """Fail before any work if ``path`` cannot be written (missing directory, a directory given)."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise StabmapError(f"cannot write {str(path)!r}: directory {str(parent)!r} does not exist")
    if path.is_dir():
        raise StabmapError(f"cannot write {str(path)!r}: it is a directory; give a file name such as atlas.nc")
    if not os.access(parent, os.W_OK):
        raise StabmapError(f"cannot write {str(path)!r}: no write permission in {str(parent)!r}")
    return path


def write_atlas(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (netCDF4, zlib level 4) atomically.

    The data go to a temporary file in the same directory, renamed over
    ``path`` only when complete, so a failure or Ctrl-C never leaves a partial file.
    """
    path = check_writable(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    encoding = {name: {"zlib": True, "complevel": 4} for name in ds.data_vars}
    try:
        ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=encoding)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def open_atlas(path: str | Path) -> xr.Dataset:
    """Open a saved atlas (loaded into memory; the file is closed on return)."""
    path = Path(path)
    if not path.is_file():
        raise StabmapError(f"atlas file {str(path)!r} does not exist")
    try:
        with xr.open_dataset(path, engine="netcdf4") as ds:
            ds = ds.load()
    except (OSError, ValueError) as exc:
        raise StabmapError(f"cannot read {str(path)!r} as a netCDF atlas: {exc}") from None
    if "stabmap_format_version" not in ds.attrs:
        raise StabmapError(f"{str(path)!r} is a netCDF file but not a stabmap atlas (no stabmap_format_version)")
    return ds
