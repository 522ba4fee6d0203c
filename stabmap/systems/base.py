"""What a system provides to the pipeline: the plug-in contract (docs/systems.md).

The pipeline is scene -> points -> decide -> store -> read.  The grid,
chunking, running (threads or a dask cluster), checkpoints, files, ``info``,
``query`` and ``plot`` are written once; a system fills in the parts that
belong to its physics:

- its **scene**: a frozen dataclass with ``title`` and ``grid`` fields (plus
  its own), validated in ``__post_init__`` (one place for scenes built in
  Python and read from TOML), and ``to_dict`` giving the TOML table back;
- ``scene_from_dict``: the TOML table of a scene file -> that dataclass;
- ``parameter``: units, long name and limits of every name its grid may scan;
- ``evaluate``: the decision at a block of points, as plain arrays;
- ``variables``: its outputs, declared once with CF metadata and flags.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import ClassVar

import numpy as np

from ..scene import text
from ..scene.grid import Axis
from ..scene.values import Parameter
from ..store.variables import CELL, Variable


class SceneBase:
    """What every system's scene dataclass shares (its own fields: ``title: str`` and ``grid: tuple[Axis, ...]``)."""

    system: ClassVar[str]  # the name of its System
    title: str
    grid: tuple[Axis, ...]

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.grid)

    def to_dict(self) -> dict:
        """The scene's TOML table, without the ``system`` key."""
        raise NotImplementedError

    def with_grid(self, grid: tuple[Axis, ...]) -> "SceneBase":
        """The same scene on ``grid`` (a subset of its own, ``read.subset``), with every choice this scene made from
        its grid kept as it is, so that each point is decided as before."""
        return replace(self, grid=tuple(grid))

    def to_toml(self) -> str:
        """The scene as TOML text that ``stabmap.loads_scene`` reads back to an equal scene."""
        return text.dumps({"system": self.system, **self.to_dict()})


@dataclass(frozen=True)
class Cost:
    """What one point costs, for sizing the tasks: seconds on one core, and bytes of its inputs."""

    seconds: float
    bytes: int


class System:
    """A system: one subpackage of ``stabmap.systems`` holds a subclass and registers its instance.

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
    """

    name: str
    title: str
    references: str
    variables: tuple[Variable, ...]
    label: str
    label_symbol: str
    label_title: str
    stable_label: int | None = None
    absent_label: int | None = None
    undecided_label: int | None = None
    proves_labels: bool = True
    stable_word: str = "stable"  # what ``stable_label`` is called in titles and summaries
    provenance: str | None = None
    symbols: dict[str, str] = {}

    # ------------------------------------------------------------------ scenes
    # The module of the system's scene, if it has ``from_dict(table, base_dir)`` and ``fixed_values(scene)``:
    # the three members below then need no code in the subclass.
    scene_module = None

    def scene_from_dict(self, table: dict, base_dir: Path | None = None) -> SceneBase:
        """The scene of a TOML table (without its ``system`` key); errors name the key and the fix."""
        if self.scene_module is None:
            raise NotImplementedError
        return self.scene_module.from_dict(table, base_dir)

    def parameter(self, scene: SceneBase, name: str) -> Parameter:
        """Units, long name and limits of the scannable ``name``; a StabmapError for a name this scene cannot scan."""
        return scene.parameter(name)

    def fixed_values(self, scene: SceneBase) -> dict[str, float]:
        """The scene's scalar parameters that are not grid axes, by their scannable names (scalar coordinates)."""
        return {} if self.scene_module is None else self.scene_module.fixed_values(scene)

    def derived_coords(self, scene: SceneBase) -> dict[str, tuple]:
        """Auxiliary coordinates computed from the grid, ``{name: (dims, values, attrs)}``, dims among the grid
        axes (e.g. what a ratio axis moves).  They replace a fixed parameter of the same name.  Default: none."""
        return {}

    def attrs(self, scene: SceneBase) -> dict:
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
    def labels_only(self, scene: SceneBase) -> SceneBase:
        """``scene`` with every optional output off: what a computation that needs the label alone (critical
        values) evaluates.  Default: the scene itself."""
        return scene

    def dims(self, scene: SceneBase) -> dict[str, int]:
        """Sizes of the dimensions of ``variables`` beyond the grid's."""
        return {}

    def dim_coords(self, scene: SceneBase) -> dict[str, tuple[np.ndarray, dict]]:
        """Coordinates of the dimensions beyond the grid's: ``{dim: (values, attrs)}`` (default: none)."""
        return {}

    def fastest_axes(self, scene: SceneBase) -> tuple[int, ...]:
        """Grid axes that should vary fastest within a block (e.g. those that leave the expensive set-up alone)."""
        return ()

    def cost(self, scene: SceneBase) -> Cost:
        """The cost of one point, for the default task size."""
        raise NotImplementedError

    def evaluate(self, scene: SceneBase, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Decide points: ``values`` maps grid-axis names to arrays that broadcast to the points' shape S.

        Returns every variable of ``variables``, each an array of shape S + its own ``dims``.
        Axes not in ``values`` take the scene's fixed values.
        """
        raise NotImplementedError

    def prove_boxes(self, scene: SceneBase, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]):
        """(label, proved) of each box: ``proved[i]`` says that the label is ``label[i]`` at every point of box i.

        Box i holds the points whose grid-axis values lie between ``lower[name][i]`` and ``upper[name][i]``
        (closed, equal-length 1-D arrays; axes not named take the scene's fixed values).  A proof says that
        the label is the same at every point of the box, so a label change cannot hide inside it; where
        ``proved`` is False, ``label`` means nothing.  None (the default): the system proves labels at
        points only.
        """
        return None

    def prove_and_cut_boxes(self, scene: SceneBase, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]):
        """``prove_boxes``, and for each box not proved the grid axes worth cutting it along: (label, proved, cut),
        ``cut[name][i]`` for each axis named (``stabmap.run.cells`` halves box i along those).  Default: every axis."""
        label, proved = self.prove_boxes(scene, lower, upper)
        return label, proved, {k: np.ones(np.shape(label), dtype=bool) for k in lower}

    def box_cost(self, scene: SceneBase) -> float:
        """What one box proof of a box along this scene's grid axes costs, in proofs of one point (default 1):
        the budget of box proofs in an atlas (``stabmap.run.cells``)."""
        return 1.0

    def box_axes(self, scene: SceneBase) -> set[str]:
        """The grid axes along which ``prove_boxes`` can prove a box of this scene (default: none)."""
        return set()

    def proved_box(self, label: np.ndarray) -> dict[str, np.ndarray]:
        """The other variables of nodes whose ``label`` a box proof holds (``prove_boxes``), not computed one by one.

        Required of a system whose ``box_axes`` are not empty: its provenance flag says "proved over a box".
        """
        raise NotImplementedError(f"the {self.name} system proves boxes but does not say what a box-proved node holds")

    def roots(self, scene: SceneBase, values: dict[str, float]) -> tuple[list, str] | None:
        """Every characteristic root at one point (``stabmap.read.roots``): a list of records with ``value``,
        ``radius``, ``multiplicity``, ``kind``, ``origin``, ``liquid_share`` and ``growth_rate``, and the rule that
        decided ``origin``.  None (the default): the system has no such roots."""
        return None

    def at_proved_nodes(self, scene: SceneBase, values: dict[str, np.ndarray], label: np.ndarray) -> dict[str, np.ndarray] | None:
        """Variables of ``outputs(scene)`` that the system computes at nodes whose ``label`` a box proof holds (1-D arrays
        of grid-axis ``values``), over ``proved_box``'s.  None (the default): ``proved_box`` says all."""
        return None

    def inferred(self, label: np.ndarray) -> dict[str, np.ndarray] | None:
        """The other variables of points given ``label`` without being computed (adaptive refinement).

        None (the default): the system does not allow refinement.
        """
        return None

    # ------------------------------------------------------------------ outputs
    def outputs(self, scene: SceneBase) -> tuple[Variable, ...]:
        """The ``variables`` that ``evaluate`` returns and an atlas of ``scene`` stores (default: all of them);
        a system whose scenes opt in or out of some outputs names those left out here."""
        return tuple(self.variables)

    def atlas_outputs(self, scene: SceneBase) -> tuple[Variable, ...]:
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
    def figure_text(self, text: str, units) -> str:
        """``text`` of this system (a coordinate's ``long_name``, a note of its scene) as a figure writes it.

        A figure has less room than ``stabmap info``: a system may shorten a phrase its names all repeat, and write
        the units in its notes with ``units`` (a function that turns a CF unit string such as ``"kg m2"`` into the
        figure's text of it).  The default writes ``text`` as it is.
        """
        return text
