"""Atlas files: netCDF4 (``.nc``) or Zarr (``.zarr``), compressed, written atomically."""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TextIO

import dask
import netCDF4
import xarray as xr

from ..errors import StabmapError

ZARR_SUFFIX = ".zarr"
ATLAS_SUFFIXES = (".nc", ZARR_SUFFIX)  # what an atlas (or critical values) may be written to
NETCDF_CHUNK_CACHE = 4 << 20  # bytes, while streaming
_NETCDF_MAGIC = (b"\x89HDF\r\n\x1a\n", b"CDF\x01", b"CDF\x02", b"CDF\x05")  # netCDF4 (HDF5), netCDF3


def is_zarr(path: str | Path) -> bool:
    return Path(path).suffix.lower() == ZARR_SUFFIX


def kind_of(path: str | Path) -> str | None:
    """What an existing file holds, from its first bytes: "netCDF", "Zarr", "TOML" (a scene) or None (unknown)."""
    path = Path(path)
    if path.is_dir():
        return "Zarr" if _is_zarr_store(path) else None
    try:
        with open(path, "rb") as f:
            head = f.read(8)
    except OSError:
        return None
    if head.startswith(_NETCDF_MAGIC):
        return "netCDF"
    if path.suffix.lower() == ".toml":
        return "TOML"
    return None


def check_new_output(path: str | Path, overwrite: bool = False, option: str = "-o") -> Path:
    """An output file that may be written: it does not exist yet, or ``overwrite`` says to replace it.

    ``option`` names the command's option that gave ``path`` (for the message only).
    """
    path = check_writable(path)
    if not overwrite and (path.exists() or path.is_symlink()):
        raise StabmapError(f"{str(path)!r} ({option}) already exists; add --overwrite to replace it")
    return path


def check_atlas_output(path: str | Path, overwrite: bool = False) -> Path:
    """An atlas output (``-o``): a ``.nc`` or ``.zarr`` name, writable, new unless ``overwrite``."""
    suffix = Path(path).suffix.lower()
    if suffix not in ATLAS_SUFFIXES:
        raise StabmapError(
            f"cannot write {str(path)!r}: an atlas is written as netCDF4 (.nc) or Zarr (.zarr), "
            f"got {repr(suffix) if suffix else 'no suffix'}; name it e.g. atlas.nc"
        )
    return check_new_output(path, overwrite)


def check_writable(path: str | Path) -> Path:
    """Fail before any work if ``path`` cannot be written (missing directory, a directory given)."""
    path = Path(path)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise StabmapError(f"cannot write {str(path)!r}: directory {str(parent)!r} does not exist")
    if path.is_dir() and not (is_zarr(path) and _is_zarr_store(path)):
        raise StabmapError(f"cannot write {str(path)!r}: it is a directory; give a file name such as atlas.nc or atlas.zarr")
    if not os.access(parent, os.W_OK):
        raise StabmapError(f"cannot write {str(path)!r}: no write permission in {str(parent)!r}")
    return path


def _is_zarr_store(path: Path) -> bool:
    return any((path / name).exists() for name in ("zarr.json", ".zgroup", ".zattrs"))


def write_atlas(ds: xr.Dataset, path: str | Path, late_attrs: Callable[[], dict] | None = None) -> Path:
    """Write ``ds`` to ``path`` (netCDF4 with zlib level 4, or Zarr for ``.zarr``) atomically.

    The data go to a temporary file in the same directory, renamed over
    ``path`` only when complete, so a failure or Ctrl-C never leaves a partial file.  ``ds`` is written as it is:
    ``stabmap.write_atlas`` (``stabmap.read.subset.write_atlas``) also rewrites the stored scene of a part of
    an atlas (``ds.sel(...)``) to the part's grid.  ``late_attrs()``, called once the data are written, gives global
    attributes known only then (the seconds the writing took), added before the file takes its name.
    """
    path = check_writable(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        if is_zarr(path):
            with warnings.catch_warnings():  # consolidated so that a plain xr.open_zarr reads it quietly and fast;
                # zarr-python says that Zarr format 3 has no consolidated metadata in its spec yet: known, and harmless
                warnings.filterwarnings("ignore", message="Consolidated metadata is currently not part")
                ds.to_zarr(tmp, mode="w", consolidated=True)
                if late_attrs is not None:
                    import zarr

                    zarr.open_group(str(tmp), mode="r+").attrs.update(late_attrs())
                    zarr.consolidate_metadata(str(tmp))
        else:
            ds = _string_axes_as_labels(_cf_bounds(ds))
            encoding = {name: {"zlib": True, "complevel": 4, **_chunksizes(ds[name])} for name in ds.data_vars}
            # No _FillValue on coordinates or bounds: CF 2.5.1 forbids missing values in coordinate variables and
            # CF 7.1 recommends none on bounds; xarray would otherwise give every float variable a NaN _FillValue.
            for name in [*ds.coords, *_bounds_names(ds)]:
                encoding[name] = {**encoding.get(name, {}), "_FillValue": None}
            ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=encoding)
            if late_attrs is not None:
                with netCDF4.Dataset(tmp, "a") as nc:
                    nc.setncatts(late_attrs())
        _replace(tmp, path)
    except BaseException:
        _remove(tmp)
        raise
    return path


LABEL_SUFFIX = "_label"  # the string-valued auxiliary coordinate that holds a string axis's values in a netCDF file


def _string_axes_as_labels(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with each dimension whose coordinate holds strings (a reactions atlas's ``component``: x, y, z) left
    without a coordinate variable, its strings in the auxiliary coordinate ``NAME_label`` instead.

    A CF coordinate variable is numeric and monotonic (CF 1.10 section 1.3); strings along a dimension are labels,
    a string-valued auxiliary coordinate (section 6.1).  ``open_atlas`` turns them back into the dimension's
    coordinate, so ``ds.R.sel(component="z")`` reads a file as it read the Dataset that was written.
    """
    strings = [d for d in ds.dims if d in ds.coords and ds[d].dtype.kind in "OUS"]
    if not strings:
        return ds
    ds = ds.drop_indexes(strings).rename_vars({d: f"{d}{LABEL_SUFFIX}" for d in strings}).copy(deep=False)
    for var in ds.variables.values():  # a file's 'coordinates' read back would name the old coordinate, not the label
        var.encoding.pop("coordinates", None)
    return ds


def _labels_as_string_axes(ds: xr.Dataset) -> xr.Dataset:
    """The inverse of ``_string_axes_as_labels`` on a file read: each ``NAME_label`` of a dimension NAME that has no
    coordinate becomes NAME's coordinate again (files written before have the string coordinate itself)."""
    for d in list(ds.dims):
        label = f"{d}{LABEL_SUFFIX}"
        if d not in ds.variables and label in ds.coords and ds[label].dims == (d,) and ds[label].dtype.kind in "OUS":
            ds = ds.assign_coords({d: (d, ds[label].values, ds[label].attrs)}).drop_vars(label)
    return ds


def _bounds_names(ds: xr.Dataset) -> list[str]:
    """The bounds variables of ``ds``: those a variable names in its ``bounds`` attribute (CF 7.1)."""
    names = (ds[name].attrs.get("bounds") for name in ds.variables)
    return [b for b in names if isinstance(b, str) and b in ds.variables]


def _cf_bounds(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with its bounds variables as CF 7.1 recommends: no ``units`` or ``long_name`` of their own.

    A bounds variable shares its coordinate's units and names, and any of those attributes it carries must equal
    the coordinate's.  Older atlases gave each bounds variable a ``long_name`` of its own describing the edges; one
    of them rewritten (``stabmap.write_atlas`` of a part) keeps that text as a ``comment`` instead.
    """
    out = ds
    for name in ds.variables:
        b = ds[name].attrs.get("bounds")
        if not (isinstance(b, str) and b in ds.variables):
            continue
        attrs = dict(ds[b].attrs)
        if "long_name" in attrs and attrs["long_name"] != ds[name].attrs.get("long_name"):
            attrs.setdefault("comment", attrs["long_name"])
        for key in ("long_name", "units"):
            attrs.pop(key, None)
        if attrs != ds[b].attrs:
            var = ds[b].variable.copy(deep=False)
            var.attrs = attrs
            out = out.assign_coords({b: var}) if b in ds.coords else out.assign({b: var})
    return out


def write_text(text: str, path: str | Path) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (``atomic_text``)."""
    path = check_writable(path)
    with atomic_text(path) as f:
        f.write(text)
    return path


@contextlib.contextmanager
def atomic_text(path: str | Path, newline: str | None = None) -> Iterator[TextIO]:
    """A UTF-8 text file to write ``path`` through: a temporary file in the same directory, renamed onto ``path``
    when the block ends, removed if it raises, so that a reader never sees part of it (``newline`` as for ``open``)."""
    path = check_writable(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8", newline=newline) as f:
            yield f
        os.replace(tmp, path)
    except BaseException:
        _remove(tmp)
        raise


def _chunksizes(var: xr.DataArray) -> dict:
    """netCDF chunks equal to the dask chunks of a streamed variable (each one written once, whole)."""
    if var.chunks is None or var.ndim == 0:
        return {}
    return {"chunksizes": tuple(c[0] for c in var.chunks)}


def _replace(tmp: Path, path: Path) -> None:
    """Move ``tmp`` to ``path``; a Zarr store (a directory) replaces the old one only once it is complete."""
    if not tmp.is_dir() or not path.exists():
        os.replace(tmp, path)
        return
    old = path.with_name(f".{path.name}.{os.getpid()}.old")
    os.replace(path, old)
    os.replace(tmp, path)
    _remove(old)


def _remove(path: Path) -> None:
    if path.is_dir():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


def write_streamed(ds: xr.Dataset, path: Path, late_attrs: Callable[[], dict] | None = None) -> Path:
    """Write ``ds``, whose variables are dask arrays read chunk by chunk, holding one chunk at a time (``late_attrs``:
    as for ``write_atlas``)."""
    # Synchronous: the chunks are on this machine, and one chunk at a time bounds the memory. Each netCDF
    # chunk is written once, whole, so netCDF's chunk cache (64 MiB a variable by default, the largest use of
    # memory here) only needs to hold one.
    with _small_chunk_cache(), dask.config.set(scheduler="synchronous"):
        return write_atlas(ds, path, late_attrs)


READ_CHUNK_POINTS = 1 << 20  # grid points per dask chunk of a lazily opened atlas (a few MiB per variable)


def open_atlas(path: str | Path, *, lazy: bool = False) -> xr.Dataset:
    """Open a saved atlas, netCDF or Zarr.

    By default it is loaded into memory and the file closed on return.  With ``lazy`` the variables are dask
    arrays read chunk by chunk as they are used (bounded memory for any size); close the Dataset after use.
    A lazy chunk holds whole chunks of the file, about ``READ_CHUNK_POINTS`` grid points (:func:`read_chunks`),
    so that neither one chunk nor the number of chunks grows with the atlas.
    """
    path = Path(path)
    zarr = is_zarr(path) and path.is_dir()
    if not (path.is_file() or zarr):
        raise StabmapError(f"atlas file {str(path)!r} does not exist")
    kind = "Zarr" if zarr else kind_of(path)
    if kind == "TOML":
        raise StabmapError(
            f"{str(path)!r} is a scene (TOML), not an atlas; an atlas is a .nc or .zarr file that "
            f"'stabmap atlas {path} -o atlas.nc' writes"
        )
    if kind is None:
        raise StabmapError(
            f"{str(path)!r} is not an atlas: expected a netCDF4 (.nc) or Zarr (.zarr) file written by 'stabmap atlas' "
            "or 'stabmap critical'"
        )

    def opened(chunks):
        if zarr:
            return xr.open_zarr(path, consolidated=False, chunks=chunks)
        return xr.open_dataset(path, engine="netcdf4", chunks=chunks, cache=not lazy)

    try:
        if lazy:
            with opened(None) as plain:  # metadata only: the file's own chunks
                chunks = read_chunks(plain)
            with _small_chunk_cache():  # netCDF fixes each variable's chunk cache when it opens the file
                ds = opened(chunks)
        else:
            with opened(None) as ds:
                ds = ds.load()
    except (OSError, ValueError, KeyError) as exc:
        raise StabmapError(f"cannot read {str(path)!r} as a {'Zarr' if zarr else 'netCDF'} atlas: {exc}") from None
    if "stabmap_format_version" not in ds.attrs:
        ds.close()
        raise StabmapError(f"{str(path)!r} is a netCDF file but not a stabmap atlas (no stabmap_format_version)")
    return _labels_as_string_axes(ds)


@contextlib.contextmanager
def _small_chunk_cache():
    """netCDF's chunk cache lowered to ``NETCDF_CHUNK_CACHE`` for the files opened meanwhile.

    A lazy atlas is read one dask chunk at a time, each chunk of the file once, so the cache gains nothing; at
    its default size (64 MiB a variable) it would keep up to that much of every variable read.
    """
    previous = netCDF4.get_chunk_cache()
    netCDF4.set_chunk_cache(NETCDF_CHUNK_CACHE)
    try:
        yield
    finally:
        netCDF4.set_chunk_cache(*previous)


def read_chunks(ds: xr.Dataset, points: int | None = None) -> dict[str, int]:
    """Dask chunks for reading ``ds`` lazily: whole chunks of the file, grown to about ``points`` grid points.

    The file's chunks (netCDF ``chunksizes``, Zarr ``chunks``) of its largest variable are multiplied along the
    trailing dimensions first (the order in which stabmap writes, so a read stays contiguous) until a dask chunk
    holds about ``points`` points (default ``READ_CHUNK_POINTS``); a file chunk already larger is kept as it is.  Every variable is read in the
    same chunks, so operations between variables need no rechunking.
    """
    points = READ_CHUNK_POINTS if points is None else points
    variables = [v for v in ds.data_vars.values() if v.ndim]
    if not variables:
        return {}
    big = max(variables, key=lambda v: v.size)
    preferred = big.encoding.get("preferred_chunks") or {}
    disk = [int(preferred.get(d, n)) for d, n in big.sizes.items()]
    shape = list(big.sizes.values())
    chunks = list(disk)
    for i in reversed(range(len(shape))):
        rest = math.prod(chunks) // chunks[i]
        k = max(1, points // max(1, rest * chunks[i]))
        chunks[i] = min(shape[i], chunks[i] * k)
    out = dict(zip(big.dims, chunks, strict=True))
    for v in variables:  # dimensions of other variables (e.g. per node) are read whole
        out.update({d: out.get(d, n) for d, n in v.sizes.items()})
    return out
