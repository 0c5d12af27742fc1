"""The mission seam: what a mission must tell the runner, and what the runner gives it.

A :class:`Mission` is the task side of a run (as dm_control splits a task from its
physics): the runner owns the world, the sensors, the localiser and the controller and
knows no mission; each control tick it hands the mission the estimate and the
observations, and the mission answers with the reference the controller tracks. On
the way it asks its planners, uses the world (attaching objects to the robot, say) and
reports events.
The mission also says which plugin roles it uses, which telemetry columns and summary
fields it adds, and when it is finished.
"""

from __future__ import annotations

import builtins
import math
import warnings
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, NamedTuple, Protocol

import numpy as np

from dcsim.errors import PlanOutlastsRunWarning
from dcsim.messages import (
    Observations,
    Reference,
    RobotSpec,
    RobotState,
    StateEstimate,
    Surroundings,
)
from dcsim.registry.calls import call_plugin
from dcsim.registry.interfaces import Plugin
from dcsim.scenario.model import MissionSettings, Scenario

if TYPE_CHECKING:
    from dcsim.world.capture_rig import CaptureRig
    from dcsim.world.objects import ObjectField

Emit = Callable[..., None]
"""``emit(event_name, **data)`` records an event at the current time."""


class MissionWorld(Protocol):
    """What a mission may use of the world: its objects, the robot, and its payload.

    The runner's world (:class:`dcsim.world.World`) is one; a mission is typed against
    this, not against the PyBullet engine, so that it depends on no more of the world
    than it uses. States are the truth, for the mission's bookkeeping; what the robot
    believes comes to :meth:`Mission.tick` as its estimate.

    Attributes
    ----------
    field : ObjectField
        The targets and obstacles: their kinds, shapes, status (free, carried,
        removed) and counts.
    capture : CaptureRig or None
        The gripper and the tumbling body with their contact and latch, in a world whose
        manipulator has a gripper and whose mission has a tumbling body; None otherwise.
    """

    field: ObjectField
    capture: CaptureRig | None

    def robot_spec(self) -> RobotSpec:
        """The robot's mass (cargo included), inertia, limits and model now."""
        ...

    def robot_state(self) -> RobotState:
        """The robot's true state now (base and joints)."""
        ...

    def assembly_mass(self) -> float:
        """Mass of the robot and everything it carries, kg."""
        ...

    def carried_ids(self) -> list[int]:
        """Ids of the objects the robot holds."""
        ...

    def cargo_protrusion(self) -> float:
        """How far carried objects reach beyond the robot's bounding sphere, m (0 if none)."""
        ...

    def surface_gap(self, object_id: int, within: float) -> float:
        """Gap between the robot's base and free object ``object_id``, m (``inf`` beyond
        ``within``, negative when they overlap)."""
        ...

    def attach(self, object_id: int) -> None:
        """Hold free object ``object_id`` rigidly where it is now (a fixed joint)."""
        ...

    def remove_payload(self) -> tuple[int, ...]:
        """Take every object the robot holds out of the world; their ids."""
        ...


class RoleKind(NamedTuple):
    """The plugin kind a mission's role takes, and the robot type its plugin must support.

    A role named after a plugin kind (``path_planner``, ``controller``...) takes that
    kind for the scenario's robot. A mission names its other roles in
    :attr:`Mission.role_kinds`: a second path planner, say, that plans a manipulator's
    base as a free flyer (``RoleKind("path_planner", "free-flyer")``).

    Attributes
    ----------
    kind : str
        A plugin kind (a key of :data:`~dcsim.registry.interfaces.PLUGIN_KINDS`).
    robot : str or None
        The robot type (``robot.type``) the role's plugin must support; None: the
        scenario's robot.
    """

    kind: str
    robot: str | None = None


class Mission(ABC):
    """Base of every mission type.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario; ``scenario.mission`` is an instance of :attr:`Settings`.
    world : MissionWorld
        The world, for its payload and bookkeeping.
    plugins : mapping of str to Plugin
        The constructed plugin of each role in :attr:`roles`.
    emit : callable
        ``emit(event_name, **data)`` records an event.

    Attributes
    ----------
    type : str
        The ``mission.type`` that selects this mission in a scenario file.
    summary : str
        One line saying what the mission is.
    Settings : type of MissionSettings
        The scenario's ``mission`` section for this mission.
    roles : tuple of str
        Plugin roles the mission needs, in data-flow order; a role its ``Settings``
        make optional (``role_defaults`` of None) is used when the scenario names a
        plugin for it (without a localiser the mission is fed the true state). A role
        is a plugin kind's name, or a name of :attr:`role_kinds`.
    role_kinds : mapping of str to RoleKind
        The kind of each role that is not named after a plugin kind (none by default).
    modes : tuple of str
        The mission's modes; :attr:`mode` is one of them (telemetry records its name,
        FMU outputs its index).
    columns : tuple of str
        The mission's own telemetry columns, recorded after ``mode`` and ``converged``
        (:meth:`telemetry_columns` gives them for a scenario).
    units : mapping of str to str
        The unit suffix of each of its columns that has a unit (a key of
        :data:`dcsim.run.recording.UNITS`: ``m``, ``mps``, ``rad``...), written into the
        header of ``telemetry.csv`` (:meth:`telemetry_units` gives them for a scenario).
    robots : tuple of str
        The robot types (``robot.type``) it can fly; a scenario pairing it with another
        is refused before the run.
    summary_names : tuple of str
        The keys of :meth:`summary_fields`, known before a run (a campaign checks the
        metrics it collects against them).
    """

    type: ClassVar[str]
    summary: ClassVar[str]
    Settings: ClassVar[builtins.type[MissionSettings]]
    roles: ClassVar[tuple[str, ...]]
    role_kinds: ClassVar[Mapping[str, RoleKind]] = {}
    modes: ClassVar[tuple[str, ...]]
    columns: ClassVar[tuple[str, ...]] = ()
    units: ClassVar[Mapping[str, str]] = {}
    robots: ClassVar[tuple[str, ...]] = ("free-flyer",)
    summary_names: ClassVar[tuple[str, ...]] = ()

    def __init__(
        self, scenario: Scenario, world: MissionWorld, plugins: Mapping[str, Plugin], emit: Emit
    ) -> None:
        self.scenario = scenario
        self.settings = scenario.mission_as(self.Settings)
        self.world = world
        self.plugins = plugins
        self.emit = emit

    # ------------------------------------------------------------------ the tick
    @property
    @abstractmethod
    def mode(self) -> str:
        """The mode decided for the current control period (one of :attr:`modes`)."""

    @abstractmethod
    def tick(self, time: float, estimate: StateEstimate, observations: Observations) -> Reference:
        """Decide at ``time`` (s) and return the reference for the coming control period."""

    def note_plan_end(self, time: float, end: float) -> None:
        """Say so when a plan made at ``time`` (s) ends at ``end`` (s), after the run does.

        A plan that ends after ``world.duration`` would be cut short in silence: this
        records a ``plan_outlasts_run`` event (the plan's end and the duration, s) and
        issues a :class:`~dcsim.errors.PlanOutlastsRunWarning` (``dcsim run`` prints it
        on stderr). Nothing is said for a plan that ends within the run.
        """
        duration = self.scenario.world.duration
        if end <= duration + 1e-9:
            return
        self.emit("plan_outlasts_run", plan_end=end, duration=duration)
        warnings.warn(
            f"the plan made at t = {time:.1f} s ends at t = {end:.1f} s, after the run's "
            f"world.duration of {duration:g} s: the run stops before the plan is flown to "
            f"its end; lengthen world.duration to {math.ceil(end)} s or more to fly it",
            PlanOutlastsRunWarning,
            stacklevel=2,
        )

    def call(self, role: str, method: str, *args: Any) -> Any:
        """Call the plugin of ``role``; an exception becomes a recorded plugin failure."""
        return call_plugin(self.plugins, role, method, *args)

    @property
    def safety_distance(self) -> float:
        """Least surface gap to keep from obstacles, m (0 unless the mission sets one)."""
        return 0.0

    def surroundings(self, observations: Observations) -> Surroundings:
        """What the controller is told of its neighbourhood: the tracked obstacles."""
        return Surroundings(observations.obstacles(), self.safety_distance)

    # ------------------------------------------------------------------ records
    @classmethod
    def telemetry_columns(cls, scenario: Scenario) -> tuple[str, ...]:
        """The mission's own telemetry columns for ``scenario``: :attr:`columns`, unless
        the mission's columns depend on the robot (one per joint, say)."""
        return cls.columns

    @classmethod
    def telemetry_units(cls, scenario: Scenario) -> Mapping[str, str]:
        """The unit suffix of each of the mission's columns for ``scenario`` that has
        one: :attr:`units`, unless the columns depend on the robot."""
        return cls.units

    def telemetry(self, outputs: Mapping[str, Any]) -> dict[str, Any]:
        """Values of the mission's columns now, given the world's outputs
        (:meth:`World.outputs`, with the controller's ``command`` of this tick added)."""
        return {}

    def plot(
        self,
        out_dir: Path,
        telemetry: Mapping[str, np.ndarray],
        events: Sequence[Mapping[str, Any]],
    ) -> list[Path]:
        """Draw the run's pictures into ``out_dir/plots``; return the files written.

        The default draws what every run shows: the motion (speed, thrust, attitude,
        angular rate) and the estimation error with its ±3σ envelope
        (:func:`dcsim.report.plots.write_plots`); a mission adds its own pictures by overriding
        this. ``telemetry`` is thinned for plotting.
        """
        from dcsim.report.plots import write_plots  # on use: it loads matplotlib

        return write_plots(out_dir, self.scenario, telemetry)

    def records(self) -> dict[str, str]:
        """Further files for the run directory, by name (written when the run ends)."""
        return {}

    def progress(self) -> str:
        """A few words on how far the mission is, for the progress line and the summary."""
        return ""

    def finished(self) -> tuple[str, str] | None:
        """``(status, reason)`` once the mission is over (``completed`` or ``stopped``)."""
        return None

    def goal_met(self) -> bool | None:
        """Whether the mission's goal was met so far: True or False, or None for a
        mission that has no goal to meet (``hold``: its errors, in the summary's
        figures, say how well it held)."""
        return None

    def summary_fields(self) -> dict[str, Any]:
        """The mission's own fields of the run summary (kept as running figures: the
        telemetry is on disk, not in memory)."""
        return {}
