"""The liquid a body carries: its cavity as a scene declares it, and its modes at every grid point.

A scene's body may carry ``cavity = {shape = ..., ...}`` beside or instead of
explicit ``fluid`` modes. Geometric cavities (spheroid, cylinder) give their
modes from ``stabmap.cavity``; their radius, half_height and density may be
grid axes (``radius_k``, ``half_height_k``, ``density_k``). A table gives the
modes directly. ``apply`` turns the cavity into the kernels' per-point E, kappa
and body columns.

A cavity with a ``viscosity`` holds a highly viscous liquid instead (docs/viscous.md): it has no modes, the
liquid moves with the body to zeroth order, and its shape enters through Chernousko's tensor (``stokes``), or
a table gives that tensor directly (``tensor = [P_t, P_a]``).
"""

from __future__ import annotations

import csv
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, cast

import numpy as np

from ...errors import StabmapError
from ...kernels import layout
from ...scene.values import check_value
from . import cavity
from .parameters import CAVITY

_KEYS = {
    "spheroid": {"shape", "radius", "half_height", "density", "modes", "mode_tolerance", "tail", "liquid_in_body", "centre", "viscosity"},
    "cylinder": {"shape", "radius", "half_height", "density", "modes", "mode_tolerance", "tail", "liquid_in_body", "centre", "viscosity"},
    "table": {"shape", "E", "kappa", "lambda_over_omega", "file", "inertia", "deficit", "tensor", "radius", "density", "viscosity"},
}
_MODE_KEYS = {"modes", "mode_tolerance", "tail"}  # an ideal liquid's; a viscous one has no modes
_TENSOR_KEYS = {"shape", "tensor", "radius", "density", "viscosity"}
AUTO = "auto"
# modes = "auto" keeps the fewest modes whose lumped tail is at most this share of the body's A at every grid point
# (docs/cavities.md, "Choosing N"): 8 modes at the truncation study's worst aspect ratio (scripts/bench_truncation.py).
DEFAULT_TOLERANCE = 1e-2
# The default keeps at most DEFAULT_MODES: N = 16 was no more accurate than 8 in that study, at 2.5 times the cost.
# A stated mode_tolerance may keep up to cavity.MAX_MODES.
AUTO_MAX_MODES = cavity.DEFAULT_MODES
_CACHE_LIMIT = 200_000
_scaled: dict[tuple[str, int, float], tuple[np.ndarray, np.ndarray, float]] = {}


@dataclass(frozen=True)
class Cavity:
    """A liquid-filled cavity of one body; lengths [m], density [kg m^-3], inertias [kg m^2].

    Its values are checked by the scene that holds it (``check``), so errors name the body.
    """

    shape: str  # "spheroid" | "cylinder" | "table"
    radius: float = 0.0  # equatorial semi-axis (spheroid) or radius (cylinder)
    half_height: float = 0.0  # polar semi-axis (spheroid) or half the height (cylinder)
    density: float = 0.0
    modes: int | str | None = None  # modes kept (largest E first), or "auto"; None: the shape's default count
    mode_tolerance: float | None = None  # "auto": the largest tail / A allowed; None: DEFAULT_TOLERANCE, at most AUTO_MAX_MODES
    tail: bool = True  # lump the remaining modes into A (geometric shapes; a table with deficit)
    liquid_in_body: bool = True  # m, A, C of the body already include the frozen liquid
    centre: float = 0.0  # cavity centre above the lower joint O_k (liquid_in_body = false)
    E: tuple[float, ...] = ()  # table
    kappa: tuple[float, ...] = ()  # table
    inertia: float | None = None  # table: the frozen liquid's transverse inertia, bounds sum(E)
    deficit: float | None = None  # table: J_rigid - J_Zh; with it the tail is deficit - sum(E)
    viscosity: float | None = None  # kinematic [m^2 s^-1]: a viscous liquid (docs/viscous.md); None: ideal
    tensor: tuple[float, float] | None = None  # viscous table: Chernousko's (P_t, P_a) [m^7] given directly
    # Set by the scene from its grid (``choose``): the modes kept, and the largest tail / A and tail / sum(E) over the grid.
    kept: int = field(default=0, compare=False)
    tail_over_A: float = field(default=math.nan, compare=False, repr=False)
    tail_share: float = field(default=math.nan, compare=False, repr=False)

    @property
    def geometric(self) -> bool:
        return self.shape != "table"

    @property
    def viscous(self) -> bool:
        return self.viscosity is not None

    def to_dict(self) -> dict:
        """The ``cavity`` table of the body in a scene file."""
        if self.viscous:
            keys: tuple[str, ...] = ("shape", "radius", "half_height", "density", "viscosity", "liquid_in_body") if self.geometric else \
                ("shape", "tensor", "radius", "density", "viscosity")
            out = {k: list(v) if isinstance(v := getattr(self, k), tuple) else v for k in keys}
            if self.geometric and not self.liquid_in_body:
                out["centre"] = self.centre
            return out
        if not self.geometric:
            out = {"shape": "table", "E": list(self.E), "kappa": list(self.kappa)}
            out.update({k: v for k in ("inertia", "deficit") if (v := getattr(self, k)) is not None})
            return out
        # "auto" is written back as such with its tolerance: the same grid chooses the same count again.
        keys = ("shape", "radius", "half_height", "density", "modes") + (("mode_tolerance",) if self.mode_tolerance is not None else ())
        out = {k: getattr(self, k) for k in keys + ("tail", "liquid_in_body")}
        if not self.liquid_in_body:
            out["centre"] = self.centre
        return out


def parse(raw, where: str, base_dir: Path | None) -> Cavity:
    """The Cavity of a body's ``cavity`` table (its layout checked here, its values by ``check``)."""
    if not isinstance(raw, dict):
        raise StabmapError(f"{where} must be a table such as {{ shape = \"cylinder\", radius = 0.05, half_height = 0.1, density = 1000 }}")
    shape = raw.get("shape")
    if shape not in _KEYS:
        raise StabmapError(f'{where}.shape must be "spheroid", "cylinder" or "table", got {shape!r}')
    unknown = sorted(set(raw) - _KEYS[shape])
    if unknown:
        raise StabmapError(f"{where}: unknown key {unknown[0]!r} for shape {shape!r}; allowed keys are {', '.join(sorted(_KEYS[shape]))}")
    if "viscosity" in raw:
        return _viscous(raw, where)
    if shape == "table":
        if "tensor" in raw:
            raise StabmapError(f"{where}.tensor is Chernousko's tensor of a viscous liquid; add viscosity [m2 s-1] and density, "
                               "or give the ideal liquid's modes as E and kappa")
        return _table(raw, where, base_dir)
    for key in ("radius", "half_height", "density"):
        if key not in raw:
            raise StabmapError(f"{where}.{key} is missing [{CAVITY[key].units}]; a {shape} needs radius, half_height and density")
    return Cavity(**raw)


def _viscous(raw: dict, where: str) -> Cavity:
    """A cavity of viscous liquid: a spheroid or cylinder by its sizes, or a table of its tensor."""
    shape = raw["shape"]
    if shape == "table":
        unknown = sorted(set(raw) - _TENSOR_KEYS)
        if unknown:
            raise StabmapError(f"{where}.{unknown[0]}: a viscous liquid has no modes; its table gives tensor = [P_t, P_a] [m7], "
                               f"radius (its length for the Reynolds number), density and viscosity; remove {unknown[0]}")
        need = ("tensor", "radius", "density")
    else:
        modes = sorted(set(raw) & _MODE_KEYS)
        if modes:
            raise StabmapError(f"{where}.{modes[0]}: a viscous liquid has no modes (it moves with the body to zeroth order, "
                               f"docs/viscous.md); remove {modes[0]}, or remove viscosity for an ideal liquid")
        need = ("radius", "half_height", "density")
    for key in need:
        if key not in raw:
            units = "m7" if key == "tensor" else CAVITY[key].units
            raise StabmapError(f"{where}.{key} is missing [{units}]; a viscous {shape} cavity needs {', '.join(need)} and viscosity")
    values = dict(raw)
    if "tensor" in values:
        values["tensor"] = tuple(values["tensor"]) if isinstance(values["tensor"], list) else values["tensor"]
    return Cavity(**values)


def _table(raw: dict, where: str, base_dir: Path | None) -> Cavity:
    if "file" in raw:
        if {"E", "kappa", "lambda_over_omega"} & set(raw):
            raise StabmapError(f"{where}: give the modes either in file or as E and kappa, not both")
        columns = _read_table(raw["file"], f"{where}.file", base_dir)
    else:
        columns = {k: raw[k] for k in ("E", "kappa", "lambda_over_omega") if k in raw}
    if "kappa" in columns and "lambda_over_omega" in columns:
        raise StabmapError(f"{where}: give kappa or lambda_over_omega (= 2 / kappa), not both")
    if "E" not in columns or not ({"kappa", "lambda_over_omega"} & set(columns)):
        raise StabmapError(f"{where}: a table needs E and kappa (or lambda_over_omega), one value per mode")
    freq_key = "kappa" if "kappa" in columns else "lambda_over_omega"
    E, freq = columns["E"], columns[freq_key]
    if not isinstance(E, list) or not isinstance(freq, list) or not E:
        raise StabmapError(f"{where}: E and {freq_key} must be non-empty lists of numbers")
    if freq_key == "lambda_over_omega":
        if len(E) != len(freq):
            raise StabmapError(f"{where}: E has {len(E)} values but {freq_key} has {len(freq)}; give one per mode")
        freq = [check_value(f"{where}.{freq_key}[{i + 1}]", v, CAVITY["kappa"]) for i, v in enumerate(freq)]
        bad = [i for i, v in enumerate(freq) if v == 0.0 or abs(v) >= 2.0]
        if bad:
            raise StabmapError(f"{where}.lambda_over_omega[{bad[0] + 1}] = {freq[bad[0]]}: a cavity mode has 0 < |lambda/omega| < 2")
        freq = [2.0 / v for v in freq]
    extra = {k: raw[k] for k in ("inertia", "deficit") if k in raw}
    return Cavity(shape="table", E=tuple(E), kappa=tuple(freq), tail="deficit" in extra, **extra)


def check(c: Cavity, where: str) -> Cavity:
    """The cavity with its values checked and normalised; errors name ``where`` (e.g. ``bodies[2].cavity``)."""
    if not isinstance(c, Cavity):
        raise StabmapError(f"{where} must be a Cavity, got {c!r}")
    if c.shape not in _KEYS:
        raise StabmapError(f'{where}.shape must be "spheroid", "cylinder" or "table", got {c.shape!r}')
    if c.viscous:
        return _check_viscous(c, where)
    if not c.geometric:
        return _check_table(c, where)
    sizes: dict[str, Any] = {key: check_value(f"{where}.{key}", getattr(c, key), CAVITY[key]) for key in ("radius", "half_height", "density")}
    modes, tolerance = _check_modes(c, where)
    for key in ("tail", "liquid_in_body"):
        if not isinstance(getattr(c, key), bool):
            raise StabmapError(f"{where}.{key} must be true or false, got {getattr(c, key)!r}")
    if c.centre and c.liquid_in_body:
        raise StabmapError(f"{where}.centre is used only with liquid_in_body = false (the body's m, A, C, c already place the liquid); remove it")
    centre = check_value(f"{where}.centre", c.centre, CAVITY["centre"])
    return replace(c, modes=modes, mode_tolerance=tolerance, centre=centre, **sizes)


def _check_viscous(c: Cavity, where: str) -> Cavity:
    from .stokes import check_tensor

    nu = check_value(f"{where}.viscosity", c.viscosity, CAVITY["viscosity"])
    if c.E or c.kappa or (c.modes not in (None, 0)) or c.mode_tolerance is not None:
        raise StabmapError(f"{where}: a viscous liquid has no modes (docs/viscous.md); remove modes, E and kappa, or remove viscosity")
    keys = ("radius", "half_height", "density") if c.geometric else ("radius", "density")
    sizes: dict[str, Any] = {key: check_value(f"{where}.{key}", getattr(c, key), CAVITY[key]) for key in keys}
    if c.geometric:
        if not isinstance(c.liquid_in_body, bool):
            raise StabmapError(f"{where}.liquid_in_body must be true or false, got {c.liquid_in_body!r}")
        if c.centre and c.liquid_in_body:
            raise StabmapError(f"{where}.centre is used only with liquid_in_body = false (the body's m, A, C, c already place the liquid); remove it")
        centre = check_value(f"{where}.centre", c.centre, CAVITY["centre"])
        return replace(c, viscosity=nu, modes=0, tail=False, centre=centre, **sizes)
    if c.tensor is None:
        raise StabmapError(f"{where}.tensor is missing [m7]: give Chernousko's tensor as [P_t, P_a]")
    if not c.liquid_in_body:
        raise StabmapError(f"{where}.liquid_in_body = false needs the cavity's shape and sizes; a tensor table's liquid is in m, A, C")
    return replace(c, viscosity=nu, modes=0, tail=False, tensor=check_tensor(c.tensor, f"{where}.tensor"), **sizes)


def _check_modes(c: Cavity, where: str) -> tuple[int | str, float | None]:
    """(modes, mode_tolerance) normalised: an explicit count and no tolerance, or "auto" and its tolerance."""
    if c.mode_tolerance is not None and c.modes not in (None, AUTO):
        raise StabmapError(
            f"{where}: give modes = {c.modes!r} (a count) or mode_tolerance = {c.mode_tolerance!r} (the fewest modes "
            f"meeting it), not both; remove one"
        )
    if c.modes is None and c.mode_tolerance is None:
        # A count, not "auto": the tail bound says nothing about the resonance bands of the modes it
        # drops, and on a free chain those covered 46 % of the map (docs/cavities.md, "Choosing N").
        return cavity.check_shape(c.shape, None), None
    if c.modes is None or c.modes == AUTO:
        if c.mode_tolerance is None:
            return AUTO, None
        t = c.mode_tolerance
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not 0.0 < t < 1.0:
            raise StabmapError(
                f"{where}.mode_tolerance must be a number with 0 < mode_tolerance < 1 (the largest lumped tail allowed, "
                f"as a share of the body's A; e.g. 1e-2), got {t!r}"
            )
        return AUTO, float(t)
    if isinstance(c.modes, str):
        raise StabmapError(f'{where}.modes must be a whole number or "auto", got {c.modes!r}')
    try:
        return cavity.check_shape(c.shape, c.modes), None
    except StabmapError as exc:
        raise StabmapError(f"{where}.{exc}") from None


def _check_table(c: Cavity, where: str) -> Cavity:
    if not c.E:
        raise StabmapError(f"{where}: E and kappa must be non-empty lists of numbers")
    if len(c.E) != len(c.kappa):
        raise StabmapError(f"{where}: E has {len(c.E)} values but kappa has {len(c.kappa)}; give one per mode")
    E = tuple(check_value(f"{where}.E[{i + 1}]", v, CAVITY["E"]) for i, v in enumerate(c.E))
    kappa = tuple(check_value(f"{where}.kappa[{i + 1}]", v, CAVITY["kappa"]) for i, v in enumerate(c.kappa))
    bad = [i for i, v in enumerate(kappa) if abs(v) <= 1.0]
    if bad:
        raise StabmapError(f"{where}.kappa[{bad[0] + 1}] = {kappa[bad[0]]}: a cavity mode has |kappa| > 1")
    extra: dict[str, Any] = {k: check_value(f"{where}.{k}", v, CAVITY["E"]) for k in ("inertia", "deficit") if (v := getattr(c, k)) is not None}
    total = math.fsum(E)
    if "inertia" in extra and total > extra["inertia"]:
        raise StabmapError(f"{where}: sum(E) = {total:g} exceeds the frozen liquid's transverse inertia {extra['inertia']:g}; "
                           "the modes cannot hold more than the liquid")
    if "deficit" in extra and total > extra["deficit"]:
        raise StabmapError(f"{where}: sum(E) = {total:g} exceeds deficit = {extra['deficit']:g} (the sum over all modes); check both")
    return replace(c, E=E, kappa=kappa, tail="deficit" in extra, **extra)


def _read_table(name, where: str, base_dir: Path | None) -> dict:
    """Columns of a CSV (header row naming E and kappa or lambda_over_omega) or TOML file."""
    if not isinstance(name, str):
        raise StabmapError(f"{where} must be a path string, got {name!r}")
    path = Path(name)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise StabmapError(f"{where}: cannot read {str(path)!r}: {exc.strerror or exc}") from None
    if path.suffix.lower() == ".toml":
        try:
            return tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise StabmapError(f"{where}: TOML syntax error in {str(path)!r}: {exc}") from None
    rows = list(csv.reader(line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")))
    if not rows:
        raise StabmapError(f"{where}: {str(path)!r} is empty; give a header row (E,kappa) and one row per mode")
    header = [h.strip() for h in rows[0]]
    columns: dict[str, list] = {h: [] for h in header}
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise StabmapError(f"{where}: {str(path)!r} row {number} has {len(row)} fields; the header has {len(header)}")
        for h, cell in zip(header, row, strict=True):  # lengths checked just above
            try:
                columns[h].append(float(cell))
            except ValueError:
                raise StabmapError(f"{where}: {str(path)!r} row {number}, column {h}: {cell.strip()!r} is not a number") from None
    return columns


def n_modes(c: Cavity | None) -> int:
    if c is None or c.viscous:
        return 0
    if not c.geometric:
        return len(c.E)
    return c.kept if c.modes == AUTO else cast(int, c.modes)  # a whole number once the scene has checked it


def choose(c: Cavity, where: str, axes: dict[str, np.ndarray], inertia: float) -> Cavity:
    """The cavity with its modes chosen for the grid: ``kept``, ``tail_over_A`` and ``tail_share`` set.

    ``axes`` holds the grid values (or the one fixed value) of radius, half_height and
    density; ``inertia`` [kg m^2] is the smallest transverse inertia A of the body,
    liquid included, on the grid. With modes = "auto" the count is the smallest N
    whose tail, at every grid pairing of sizes, is at most mode_tolerance * inertia:
    one count serves every point, as the kernels take one per body.
    """
    a, h = (np.unique(np.asarray(axes[k], dtype=np.float64)) for k in ("radius", "half_height"))
    ratio = (h[None, :] / a[:, None]).ravel()
    q, rows = np.unique(ratio, return_inverse=True)
    # Tails scale as density radius^5 at a fixed ratio: per N, the largest over the grid.
    unit = (float(np.max(axes["density"])) * np.repeat(a, len(h)) ** 5)[:, None]
    if c.modes != AUTO:
        modes = cast(int, c.modes)  # a whole number once the scene has checked it
        _, _, tails = cavity.scaled_tails(c.shape, q, modes)
        return _chosen(c, modes, tails, rows, unit, inertia)
    tolerance = tolerance_of(c)
    limit = AUTO_MAX_MODES if c.mode_tolerance is None else cavity.MAX_MODES
    n_max = 1 if c.shape == "spheroid" else min(8, limit)
    while True:
        _, _, tails = cavity.scaled_tails(c.shape, q, n_max)
        worst = (tails[rows] * unit).max(axis=0)
        meets = np.flatnonzero(worst[1:] <= tolerance * inertia)
        if len(meets) or n_max >= limit or c.shape == "spheroid":
            break
        n_max = min(2 * n_max, limit)
    if len(meets):
        return _chosen(c, int(meets[0]) + 1, tails, rows, unit, inertia)
    if c.mode_tolerance is None:  # the default tolerance: keep the cap rather than let the cost explode
        return _chosen(c, limit, tails, rows, unit, inertia)
    raise StabmapError(
        f"{where}.mode_tolerance = {c.mode_tolerance:g} needs more than {limit} modes (with {limit}, the tail is "
        f"{worst[limit] / inertia:.3g} of A at the grid's worst point); raise mode_tolerance or give modes = N"
    )


def tolerance_of(c: Cavity) -> float:
    """The tail / A that modes = "auto" allows: the stated mode_tolerance or the default."""
    return DEFAULT_TOLERANCE if c.mode_tolerance is None else c.mode_tolerance


def describe(c: Cavity) -> str:
    """How many modes the cavity keeps and why, in one line (``stabmap info``)."""
    if c.viscous:
        tensor = cast(tuple[float, float], c.tensor)  # a viscous table has one (checked with the scene)
        what = f"a {c.shape}" if c.geometric else f"a tensor table (P_t = {tensor[0]:.4g} m7, P_a = {tensor[1]:.4g} m7)"
        return f"viscous liquid in {what}: no modes, Chernousko's first order (docs/viscous.md)"
    if not c.geometric:
        return f"table cavity, {len(c.E)} modes" + (", the rest lumped into A (deficit given)" if c.tail else "")
    n = n_modes(c)
    head = f"{c.shape} cavity, {n} liquid mode{'s' if n > 1 else ''} kept"
    if c.shape == "spheroid":
        return head + " (a spheroid has exactly one)"
    if c.modes == AUTO:
        tol = tolerance_of(c)
        stated = f"mode_tolerance = {tol:g}" if c.mode_tolerance is not None else f'modes = "auto", tail <= {tol:g} of A'
        why = f"the fewest with {stated}" if c.tail_over_A <= tol else f"{stated} not met within the default's {n}; state mode_tolerance to keep more"
    elif c.modes == cavity.DEFAULT_MODES:  # the scene may not name it: a stored scene writes the default out
        why = f"modes = {c.modes}, the default count"
    else:
        why = f"as the scene's modes = {c.modes} asks"
    lumped = "lumped into A as rigid inertia" if c.tail else "dropped (tail = false)"
    return (
        f"{head} ({why}); the modes left out are {lumped}: at most {100 * c.tail_over_A:.2g} % of A "
        f"and {100 * c.tail_share:.3g} % of the liquid's ΣE over the grid"
    )


def _chosen(c: Cavity, n: int, tails: np.ndarray, rows: np.ndarray, unit: np.ndarray, inertia: float) -> Cavity:
    """``c`` keeping n modes; ``tails`` (aspect ratios, N = 0..) scaled, ``rows`` the aspect ratio of each grid pairing."""
    over_A = float((tails[rows, n] * unit[:, 0]).max()) / inertia
    share = float((tails[:, n] / tails[:, 0]).max())
    return replace(c, kept=n, tail_over_A=max(over_A, 0.0), tail_share=max(share, 0.0))


def check_body(c: Cavity, where: str, extremes: dict[str, tuple[float, float]]) -> None:
    """A body whose m, A, C include the liquid must hold at least the frozen liquid at every grid point.

    The grid is an outer product and the liquid's mass and inertias grow with each
    of radius, half_height and density, so the worst point pairs each body value's
    smallest grid value with every cavity size's largest.
    """
    if not c.liquid_in_body:
        return
    if not c.geometric:
        total = math.fsum(c.E)
        if total > extremes["A"][0]:
            raise StabmapError(f"{where}: sum(E) = {total:g} exceeds A = {extremes['A'][0]:g}, which includes the frozen liquid; "
                               "the modes cannot hold more than the liquid")
        return
    big = {k: extremes[k][1] for k in ("radius", "half_height", "density")}
    m_f = float(cavity.frozen_mass(c.shape, **big))
    J_f, Jz_f = (float(v) for v in cavity.frozen_inertia(c.shape, **big))
    for key, need in (("m", m_f), ("A", J_f), ("C", Jz_f)):
        if extremes[key][0] < need:
            raise StabmapError(
                f"{where}: {key} = {extremes[key][0]:g} is less than the frozen liquid's {need:g} "
                f"(at radius {big['radius']:g}, half_height {big['half_height']:g}, density {big['density']:g}); "
                f"{key} must include the liquid, or set liquid_in_body = false to have it added"
            )


def forget_modes() -> None:
    """Empty the memo of modes per aspect ratio (so that a benchmark measures what a first run pays)."""
    _scaled.clear()


def scaled(shape: str, q: np.ndarray, n: int):
    """(E / (density radius^5), kappa, tail / (density radius^5)) at aspect ratios q, memoised per value."""
    q = np.asarray(q, dtype=np.float64)
    unique, inverse = np.unique(q, return_inverse=True)
    # Atlas chunks run on threads: read each entry once and never rely on it staying cached.
    found: dict[float, Any] = {float(v): _scaled.get((shape, n, float(v))) for v in unique}
    missing = np.array([v for v, row in found.items() if row is None])
    if len(missing):
        e, kappa = cavity.scaled_modes(shape, missing, n)
        deficit = cavity.scaled_deficit(shape, missing)
        if len(_scaled) + len(missing) > _CACHE_LIMIT:
            _scaled.clear()
        for i, v in enumerate(missing.tolist()):
            found[v] = _scaled[(shape, n, v)] = (e[i], kappa[i], float(deficit[i] - math.fsum(e[i])))
    rows = [found[float(v)] for v in unique]
    e = np.stack([r[0] for r in rows])[inverse]
    kappa = np.stack([r[1] for r in rows])[inverse]
    tail = np.array([r[2] for r in rows])[inverse]
    return e.reshape(q.shape + (n,)), kappa.reshape(q.shape + (n,)), tail.reshape(q.shape)


def apply(c: Cavity, body: np.ndarray, sizes: dict[str, np.ndarray]):
    """Modes of the cavity at every point: returns (E, kappa), each (..., L), and updates ``body``.

    ``body`` is the (..., 6) array of one body's columns m, A, C, c, s, omega at
    the points; ``sizes`` holds radius, half_height and density broadcast to the
    points. The tail is subtracted from A; a liquid not in the body is added to
    m, A, C and moves c.
    """
    if c.viscous and not c.geometric:
        return np.zeros(body.shape[:-1] + (0,)), np.ones(body.shape[:-1] + (0,))
    if not c.geometric:
        E = np.broadcast_to(np.array(c.E), body.shape[:-1] + (len(c.E),))
        kappa = np.broadcast_to(np.array(c.kappa), E.shape)
        if c.tail:
            body[..., layout.A] -= cast(float, c.deficit) - math.fsum(c.E)  # a table's tail comes with its deficit
        return E, kappa
    a, h, rho = sizes["radius"], sizes["half_height"], sizes["density"]
    e, kappa, tail = (np.zeros(a.shape + (0,)), np.ones(a.shape + (0,)), 0.0) if c.viscous else scaled(c.shape, h / a, n_modes(c))
    unit = rho * a**5
    if not c.liquid_in_body:
        m_f = cavity.frozen_mass(c.shape, a, h, rho)
        J_f, Jz_f = cavity.frozen_inertia(c.shape, a, h, rho)
        m, A, C, cm = (body[..., i].copy() for i in (layout.M, layout.A, layout.C, layout.CM))
        total = m + m_f
        new_c = (m * cm + m_f * c.centre) / total
        body[..., layout.M] = total
        body[..., layout.A] = A + m * (cm - new_c) ** 2 + J_f + m_f * (c.centre - new_c) ** 2
        body[..., layout.C] = C + Jz_f
        body[..., layout.CM] = new_c
    if c.tail and not c.viscous:
        body[..., layout.A] -= unit * tail
    return unit[..., None] * e, kappa
