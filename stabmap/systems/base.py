"""What a system provides to the pipeline: the plug-in contract (docs/systems.md).

The pipeline is scene -> points -> decide -> store -> read.  The grid,
chunking, running (threads or a dask cluster), checkpoints, files, ``info``,
``query`` and ``plot`` are written once; a system fills in the parts that
belong to its physics:

- its **scene** (``System.scene_type``, a ``SceneBase`` subclass): a frozen dataclass with ``title`` and ``grid``
  fields (plus its own), validated in ``__post_init__`` (one place for scenes built in Python and read from
  TOML); ``from_dict`` reads a scene file's table, ``to_dict`` gives it back, ``parameter`` names the units
  and limits of every name its grid may scan, ``fixed_values`` the scalars that are not grid axes, ``notes``
  what it chose for itself;
- ``evaluate``: the decision at a block of points, as plain arrays; ``input_bytes``: what one point's inputs
  weigh;
- ``variables``: its outputs, declared once with CF metadata and flags, and the ``label`` among them;
- ``default_axis``: the grid axis that critical values and the queries scan unless told otherwise;
- ``paper``: the module of its paper's check for ``stabmap paper`` (or None).

Both classes are abstract base classes (``abc``), not ``typing.Protocol``: a system inherits some forty
defaults (no box proofs, no refinement, no extra dimensions, ...) that a Protocol would make every system
restate, and an ABC refuses to instantiate a system that leaves a required member out, at import, with the
member's name, where a Protocol would only be checked by a type checker.  Required class attributes are
abstract properties that a subclass overrides with a plain class attribute.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import Field, replace
from pathlib import Path
from typing import Any, ClassVar, Generic, Self, TypeVar

import numpy as np

from ..scene import text
from ..scene.grid import Axis
from ..scene.values import Parameter
from ..store.variables import CELL, Variable


class SceneBase(ABC):
    """What every system's scene dataclass shares (its own fields: ``title: str`` and ``grid: tuple[Axis, ...]``)."""

    # every subclass is a dataclass (declared, not set: what ``dataclasses.replace`` needs to type-check)
    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]
    title: str
    grid: tuple[Axis, ...]

    @property
    def system(self) -> str:
        """The name of its System: a class attribute of most scenes (``system: ClassVar[str] = "closed"``), a property
        where the scene's content chooses it (a gyroscopes' scene with a viscous liquid is a ``viscous`` one)."""
        raise NotImplementedError(f"{type(self).__name__} does not name its system")

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.grid)

    @classmethod
    @abstractmethod
    def from_dict(cls, table: dict, base_dir: Path | None = None) -> Self:
        """The scene of a scene file's TOML table (its ``system`` key removed); errors name the key and the fix.
        Relative file names in the table are taken from ``base_dir``."""

    @abstractmethod
    def to_dict(self) -> dict:
        """The scene's TOML table, without the ``system`` key."""

    @abstractmethod
    def parameter(self, name: str) -> Parameter:
        """Units, long name and limits of the scannable ``name``; a StabmapError for a name this scene cannot scan."""

    @abstractmethod
    def fixed_values(self) -> dict[str, float]:
        """The scalar parameters that are not grid axes, by their scannable names (an atlas's scalar coordinates)."""

    def notes(self) -> list[tuple[str, str]]:
        """What the scene chose for itself that its file does not state, for ``stabmap info``: (group, text), the
        group a heading of ``System.fixed_groups`` (``""``: the whole scene).  Default: nothing."""
        return []

    def unused(self) -> list[str]:
        """Notes on values the scene gives that its model does not use (``note: ...`` lines that ``stabmap atlas``
        ends with); not refused, as a scene may be written that way naturally.  Default: none."""
        return []

    def with_grid(self, grid: tuple[Axis, ...]) -> Self:
        """The same scene on ``grid`` (a subset of its own, ``read.subset``), with every choice this scene made from
        its grid kept as it is, so that each point is decided as before."""
        return replace(self, grid=tuple(grid))

    def to_toml(self) -> str:
        """The scene as TOML text that ``stabmap.loads_scene`` reads back to an equal scene."""
        return text.dumps({"system": self.system, **self.to_dict()})


SceneT = TypeVar("SceneT", bound=SceneBase)


class System(ABC, Generic[SceneT]):
    """A system: one subpackage of ``stabmap.systems`` holds a subclass and registers its instance.

    Required (abstract): ``name``, ``title``, ``references``, ``variables``, ``label``, ``label_symbol``,
    ``label_title``, ``scene_type``, ``default_axis``, ``evaluate`` and ``input_bytes``; every other member has
    a default.

    Attributes
    ----------
    name : str
        The scene files' ``system = "..."`` and the atlases' ``stabmap_system``.
    title : str
        One line saying what the system is.
    references : str
        The atlases' CF ``references``.
    variables : tuple of Variable
        Every output of ``evaluate``, in file order.
    label : str
        The integer class that maps are coloured by and that refinement, critical values and the
        queries follow. Negative values mean "no class" (degenerate points, drawn grey).
    label_symbol : str
        The label's short name in text, e.g. ``"N_c"``.
    label_title : str
        The legend's title for the label, e.g. ``"complex root pairs N$_c$"``.
    stable_label : int or None
        The label value of a stable point; None for a system without a notion of stability.
    absent_label : int or None
        The (negative) label value of a point where there is nothing to decide, e.g. a family of equilibria
        that does not exist there; summaries count such points apart from the degenerate ones and figures
        leave them white. None: every point has something to decide.
    stable_word : str
        What a point of ``stable_label`` is called in titles and summaries (e.g. ``"asymptotically stable"``).
    undecided_label : int or None
        The (negative) label value of a point whose class was not proved (a system that proves its labels
        flags such points instead of guessing); summaries count them apart from the degenerate ones and figures
        draw them dark grey. None: the system has no such value.
    proves_labels : bool
        True when every label is a proof, or carries ``undecided_label`` (the texts of critical values say
        "proved"); False for a system that
        decides its labels in floating point with stated tolerances (they say "decided").
    provenance : str or None
        A flag variable saying how each point was decided. A system that allows adaptive
        refinement (``inferred``) has ``store.variables.INFERRED`` among its meanings.
    symbols : dict
        Mathtext symbols of parameter names for figures (``{"omega": r"\\omega"}``; ``m_2`` -> ``$m_{2}$``).
    scene_type : type
        The system's scene, a ``SceneBase`` subclass.
    default_axis : str
        The grid axis that ``critical``, ``smallest_stable`` and ``boundaries`` scan when not told which (e.g.
        the spin rate ``"omega"``).
    paper : str or None
        The module (``stabmap.paper.<name>``) whose ``run(out=..., quick=..., **options)`` is this system's
        ``stabmap paper`` check; None: the system has none.
    stages : tuple of str
        Optional parts of its work that the system times itself, each wrapped in
        ``stabmap.systems.stages.stage(name)`` (e.g. ``("rates",)``); an atlas stores their seconds beside the
        labels' (``stabmap info``), and ``skip_stage`` says how a scene turns each off.
    """

    @property
    @abstractmethod
    def name(self) -> str: ...

    @property
    @abstractmethod
    def title(self) -> str: ...

    @property
    @abstractmethod
    def references(self) -> str: ...

    @property
    @abstractmethod
    def variables(self) -> tuple[Variable, ...]: ...

    @property
    @abstractmethod
    def label(self) -> str: ...

    @property
    @abstractmethod
    def label_symbol(self) -> str: ...

    @property
    @abstractmethod
    def label_title(self) -> str: ...

    @property
    @abstractmethod
    def scene_type(self) -> type[SceneT]: ...

    @property
    @abstractmethod
    def default_axis(self) -> str: ...

    paper: str | None = None
    stable_label: int | None = None
    absent_label: int | None = None
    undecided_label: int | None = None
    proves_labels: bool = True
    stable_word: str = "stable"  # what ``stable_label`` is called in titles and summaries
    provenance: str | None = None
    symbols: dict[str, str] = {}
    stages: tuple[str, ...] = ()

    def __init__(self) -> None:
        # What abstract members cannot say: the label is one of the variables, an integer with a fill value (it pads
        # the tables of boundaries, smallest stable values and critical values where a line has no value).
        label = next((v for v in self.variables if v.name == self.label), None)
        if label is None:
            raise TypeError(f"{type(self).__name__}: label {self.label!r} is not one of its variables")
        if not np.issubdtype(np.dtype(label.dtype), np.integer) or label.fill is None:
            raise TypeError(f"{type(self).__name__}: its label {self.label!r} must be an integer variable with a fill, a "
                            "value the label never takes (e.g. fill=-2), that pads tables where a line has no value")

    # ------------------------------------------------------------------ scenes
    def scene_from_dict(self, table: dict, base_dir: Path | None = None) -> SceneT:
        """The scene of a TOML table (without its ``system`` key); errors name the key and the fix.
        Default: ``scene_type.from_dict``."""
        return self.scene_type.from_dict(table, base_dir)

    def parameter(self, scene: SceneT, name: str) -> Parameter:
        """Units, long name and limits of the scannable ``name``; a StabmapError for a name this scene cannot scan."""
        return scene.parameter(name)

    def fixed_values(self, scene: SceneT) -> dict[str, float]:
        """The scene's scalar parameters that are not grid axes, by their scannable names (scalar coordinates)."""
        return scene.fixed_values()

    def derived_coords(self, scene: SceneT) -> dict[str, tuple]:
        """Auxiliary coordinates computed from the grid, ``{name: (dims, values, attrs)}``, dims among the grid
        axes (e.g. what a ratio axis moves).  They replace a fixed parameter of the same name.  Default: none."""
        return {}

    def attrs(self, scene: SceneT) -> dict:
        """Global attributes that describe the scene beyond its TOML (netCDF-safe values)."""
        return {}

    def describe(self, attrs: dict) -> list[str]:
        """Lines that ``stabmap info`` prints about an atlas of this system, from its global attributes."""
        return []

    def caveats(self, ds) -> list[str]:
        """What a reader of an atlas of this system must know beyond its counts, one sentence each, for ``stabmap info``
        and figure captions: e.g. the share of the map where the model's assumptions fail.  Default: none."""
        return []

    def fixed_groups(self, names: list[str]) -> list[tuple[str, list[str]]]:
        """The fixed parameters ``names`` in groups for ``stabmap info`` and figure captions: (heading, names).

        A heading such as ``"body 2"`` lets a name be printed without its index (``m`` for ``m_2``); the
        heading ``""`` holds the parameters of the whole scene.  Default: one group of every name.
        """
        return [("", list(names))] if names else []

    # ------------------------------------------------------------------ points
    def skip_stage(self, scene: SceneT, stage: str) -> tuple[str, str] | None:
        """What the stage ``stage`` (one of ``stages``) computes for ``scene`` and how the scene skips it, e.g.
        ``("growth rates", "set growth_rate = false in the scene to skip them")``: a run whose stage cost more
        than its labels ends with that advice.  None (the default): nothing to skip."""
        return None

    def labels_only(self, scene: SceneT) -> SceneT:
        """``scene`` with every optional output off: what a computation that needs the label alone (critical
        values) evaluates.  Default: the scene itself."""
        return scene

    def dims(self, scene: SceneT) -> dict[str, int]:
        """Sizes of the dimensions of ``variables`` beyond the grid's."""
        return {}

    def dim_coords(self, scene: SceneT) -> dict[str, tuple[np.ndarray, dict]]:
        """Coordinates of the dimensions beyond the grid's: ``{dim: (values, attrs)}`` (default: none)."""
        return {}

    def fastest_axes(self, scene: SceneT) -> tuple[int, ...]:
        """Grid axes that should vary fastest within a block (e.g. those that leave the expensive set-up alone)."""
        return ()

    @abstractmethod
    def input_bytes(self, scene: SceneT) -> int:
        """Bytes of one point's inputs to ``evaluate`` (its share of a block's arrays): caps the chunks' size."""

    @abstractmethod
    def evaluate(self, scene: SceneT, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Decide points: ``values`` maps grid-axis names to arrays that broadcast to the points' shape S.

        Returns every variable of ``variables``, each an array of shape S + its own ``dims``.
        Axes not in ``values`` take the scene's fixed values.
        """

    def prove_boxes(self, scene: SceneT, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]):
        """(label, proved) of each box: ``proved[i]`` says that the label is ``label[i]`` at every point of box i.

        Box i holds the points whose grid-axis values lie between ``lower[name][i]`` and ``upper[name][i]``
        (closed, equal-length 1-D arrays; axes not named take the scene's fixed values).  A proof says that
        the label is the same at every point of the box, so a label change cannot hide inside it; where
        ``proved`` is False, ``label`` means nothing.  None (the default): the system proves labels at
        points only.
        """
        return None

    def prove_and_cut_boxes(self, scene: SceneT, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]):
        """``prove_boxes``, and for each box not proved the grid axes worth cutting it along: (label, proved, cut),
        ``cut[name][i]`` for each axis named (``stabmap.run.cells`` halves box i along those).  Default: every axis."""
        label, proved = self.prove_boxes(scene, lower, upper)
        return label, proved, {k: np.ones(np.shape(label), dtype=bool) for k in lower}

    def box_cost(self, scene: SceneT) -> float:
        """What one box proof of a box along this scene's grid axes costs, in proofs of one point (default 1):
        the budget of box proofs in an atlas (``stabmap.run.cells``)."""
        return 1.0

    def prove_boxes_cheaply(self, scene: SceneT, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray],
                            batch: np.ndarray | None = None):
        """(label, proved) as ``prove_boxes``, by a proof that costs ``cheap_box_cost`` a box, which an atlas tries
        first; the boxes it leaves go on to ``prove_and_cut_boxes``.  None (the default): no such proof.

        ``batch`` (one integer a box; None: one batch): a box's result may depend only on the boxes of its own
        batch before it (a proof may steer a box by its neighbour's), so that the cells of an atlas, one batch a
        tile, do not depend on which tiles share a chunk."""
        return None

    def cheap_box_cost(self, scene: SceneT) -> float:
        """What one ``prove_boxes_cheaply`` costs, in proofs of one point; 0 where the system has none."""
        return 0.0

    def box_axes(self, scene: SceneT) -> set[str]:
        """The grid axes along which ``prove_boxes`` can prove a box of this scene (default: none)."""
        return set()

    def proved_box(self, label: np.ndarray) -> dict[str, np.ndarray]:
        """The other variables of nodes whose ``label`` a box proof holds (``prove_boxes``), not computed one by one.

        Required of a system whose ``box_axes`` are not empty: its provenance flag says "proved over a box".
        """
        raise NotImplementedError(f"the {self.name} system proves boxes but does not say what a box-proved node holds")

    def roots(self, scene: SceneT, values: dict[str, float]) -> tuple[list, str] | None:
        """Every characteristic root at one point (``stabmap.read.roots``): a list of records with ``value``,
        ``radius``, ``multiplicity``, ``kind``, ``origin``, ``liquid_share`` and ``growth_rate``, and the rule that
        decided ``origin``.  None (the default): the system has no such roots."""
        return None

    def at_proved_nodes(self, scene: SceneT, values: dict[str, np.ndarray], label: np.ndarray) -> dict[str, np.ndarray] | None:
        """Variables of ``outputs(scene)`` that the system computes at nodes whose ``label`` a box proof holds (1-D arrays
        of grid-axis ``values``), over ``proved_box``'s.  None (the default): ``proved_box`` says all."""
        return None

    def finish(self, scene: SceneT, ds):
        """The atlas Dataset ``ds`` of ``scene``, once every point is in, with what needs whole lines of the grid
        (modes followed along an axis, say); lazy where ``ds`` is.  Default: ``ds`` as it is."""
        return ds

    def inferred(self, label: np.ndarray) -> dict[str, np.ndarray] | None:
        """The other variables of points given ``label`` without being computed (adaptive refinement).

        None (the default): the system does not allow refinement.
        """
        return None

    # ------------------------------------------------------------------ outputs
    def outputs(self, scene: SceneT) -> tuple[Variable, ...]:
        """The ``variables`` that ``evaluate`` returns and an atlas of ``scene`` stores (default: all of them);
        a system whose scenes opt in or out of some outputs names those left out here."""
        return tuple(self.variables)

    def atlas_outputs(self, scene: SceneT) -> tuple[Variable, ...]:
        """Every variable of an atlas of ``scene``: its ``outputs`` and ``cell``."""
        return self.outputs(scene) + (CELL,)

    @property
    def atlas_variables(self) -> tuple[Variable, ...]:
        """Every variable of an atlas file: the system's ``variables`` and ``cell`` (``stabmap.run.cells``)."""
        return tuple(self.variables) + (CELL,)

    def variable(self, name: str) -> Variable:
        for v in self.atlas_variables:
            if v.name == name:
                return v
        raise KeyError(f"the {self.name} system has no variable {name!r}")

    def class_name(self, value: int) -> str:
        """Legend text of one label value."""
        var = self.variable(self.label)
        return var.meaning(value).replace("_", " ") if var.flags else f"{self.label} = {value}"

    # figures
    def figure_text(self, text: str, units: Callable[[str], str]) -> str:
        """``text`` of this system (a coordinate's ``long_name``, a note of its scene) as a figure writes it.

        A figure has less room than ``stabmap info``: a system may shorten a phrase its names all repeat, and write
        the units in its notes with ``units`` (a function that turns a CF unit string such as ``"kg m2"`` into the
        figure's text of it).  The default writes ``text`` as it is.
        """
        return text
