"""The four plugin kinds: abstract base classes a plugin class derives from.

A plugin is a class deriving from one of :class:`Localiser`, :class:`TaskPlanner`,
:class:`PathPlanner` or :class:`Controller`. It declares

- ``name``: unique within its kind, lower case (``"pd"``, ``"straight-line"``);
- ``summary``: one line saying what it is;
- ``Params``: a :class:`~dcsim.params.PluginParams` subclass (defaults, bounds, units);
- ``robots``: the robot types it supports (``("free-flyer",)`` unless it says otherwise);

and implements its kind's abstract methods. The framework constructs it with validated
parameters and its own random generator, spawned from the scenario seed, so that a
scenario and seed always give the same result. A plugin never sees ground truth, never
mutates its inputs, and returns within its time budget.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from dcsim.messages import (
    BeaconRange,
    Command,
    MotionInput,
    NoPath,
    PathProblem,
    Plan,
    Prior,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    TaskRequest,
    Trajectory,
)
from dcsim.params import PluginParams


class Plugin(ABC):
    """Common base of all plugin kinds.

    Parameters
    ----------
    params : PluginParams or mapping, optional
        Parameters; a mapping is validated against ``Params``; None means defaults.
    rng : numpy.random.Generator, optional
        The plugin's own random generator; a fixed-seed one if omitted.

    Attributes
    ----------
    kind : str
        The plugin kind (set on the four kind classes).
    name : str
        Unique name within the kind.
    summary : str
        One line describing the plugin.
    Params : type of PluginParams
        The parameter model.
    robots : tuple of str
        The robot types (``robot.type`` in a scenario) the plugin supports.
    params : PluginParams
        The validated parameters of this instance.
    rng : numpy.random.Generator
        This instance's random generator.
    """

    kind: ClassVar[str]
    name: ClassVar[str]
    summary: ClassVar[str]
    Params: ClassVar[type[PluginParams]] = PluginParams
    robots: ClassVar[tuple[str, ...]] = ("free-flyer",)

    def __init__(
        self,
        params: PluginParams | Mapping[str, Any] | None = None,
        rng: np.random.Generator | None = None,
    ) -> None:
        if not isinstance(params, self.Params):
            params = self.Params.parse(self.name, params)  # type: ignore[arg-type]
        self.params = params
        self.rng = rng if rng is not None else np.random.default_rng(0)


class Localiser(Plugin):
    """Estimates the robot's position and velocity from beacon ranges.

    Per control tick the framework calls :meth:`predict` with the motion commanded over
    the last period, then :meth:`update` with the ranges measured now (possibly none),
    then reads :meth:`estimate`. The estimate's attitude, angular velocity and joint
    states are the attitude sensors' and encoders' readings: the runner puts them in
    before the mission and the controller see the estimate.
    """

    kind = "localiser"

    @abstractmethod
    def reset(self, prior: Prior, time: float) -> None:
        """Start over from the initial belief ``prior`` at scenario time ``time`` (s)."""

    @abstractmethod
    def predict(self, motion: MotionInput, dt: float) -> None:
        """Propagate the belief over ``dt`` seconds under the commanded ``motion``."""

    @abstractmethod
    def update(self, ranges: Sequence[BeaconRange]) -> None:
        """Correct the belief with the beacon ranges measured now (may be empty)."""

    @abstractmethod
    def estimate(self) -> StateEstimate:
        """Return the current estimate; ``converged`` says whether to trust it."""


class TaskPlanner(Plugin):
    """Orders pickups of moving targets, with drop-point visits when full.

    Attributes
    ----------
    orbit_models : tuple of str
        The orbit models (``world.orbit.model``: ``cw``, ``two-body``, ``j2``) the planner
        plans with exactly; ``("cw",)`` by default. In a world whose model is not among
        them the planner plans with the Clohessy–Wiltshire linearisation, and the run
        records a ``planner_model_differs`` event saying so.
    """

    kind = "task_planner"
    orbit_models: ClassVar[tuple[str, ...]] = ("cw",)

    @abstractmethod
    def plan(self, request: TaskRequest) -> Plan:
        """Plan pickups of ``request.targets``.

        Returns
        -------
        Plan
            Tasks with strictly increasing pickup times later than ``request.time``,
            each target at most once, a drop visit whenever the collector is full and
            after the last pickup; an empty plan when there is nothing to plan.
        """


MARGIN_MOVED = (
    "the margin kept from obstacles is the same for every path planner now: the problem's "
    "safety_margin, which the mission sets from its safety_distance; set "
    "mission.safety_distance instead"
)
"""What a scenario that still gives a path planner its own ``clearance`` is told."""


class PathPlannerParams(PluginParams):
    """Base class of path planners' parameter models: ``clearance`` is refused with
    :data:`MARGIN_MOVED` (the margin is :attr:`PathProblem.safety_margin`)."""

    retired: ClassVar[Mapping[str, str]] = {"clearance": MARGIN_MOVED}


class PathPlanner(Plugin):
    """Finds a time-stamped trajectory to a goal region among moving obstacles.

    Every planner keeps the problem's ``safety_margin`` from every obstacle and answers
    by ``problem.due()`` (``time.monotonic()`` seconds), which it reads once when it
    starts.

    Attributes
    ----------
    handles_moving_obstacles : bool
        Whether the planner plans around obstacles in motion (the default). A planner
        that declares False answers every problem with a moving obstacle with a
        :class:`NoPath` saying so; the conformance suite then poses its path checks with
        the obstacles held where they are at the start, and checks that refusal.
    orbit_models : tuple of str
        The orbit models (``world.orbit.model``: ``cw``, ``two-body``, ``j2``) the planner
        plans with exactly; ``("cw",)`` by default. In a world whose model is not among
        them the planner plans with the Clohessy–Wiltshire linearisation the problem's
        frame gives, and the run records a ``planner_model_differs`` event saying so.
    """

    kind = "path_planner"
    Params: ClassVar[type[PluginParams]] = PathPlannerParams
    handles_moving_obstacles: ClassVar[bool] = True
    orbit_models: ClassVar[tuple[str, ...]] = ("cw",)

    @abstractmethod
    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Solve ``problem``; return a :class:`Trajectory` or a :class:`NoPath` with a reason."""


class Controller(Plugin):
    """Turns an estimate and a reference into force, torque and joint-torque commands."""

    kind = "controller"

    @abstractmethod
    def reset(self, robot: RobotSpec) -> None:
        """Prepare for a run of the robot described by ``robot``; called again whenever the
        robot changes (a grab or a release changes its mass and size)."""

    @abstractmethod
    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Return the command for the coming control period, within the robot's limits."""


PLUGIN_KINDS: dict[str, type[Plugin]] = {
    cls.kind: cls for cls in (Localiser, TaskPlanner, PathPlanner, Controller)
}
"""Every plugin kind by its name, in data-flow order."""
