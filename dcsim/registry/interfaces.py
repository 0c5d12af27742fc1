"""The plugin kinds: abstract base classes a plugin class derives from.

A plugin is a class deriving from one of :class:`SensorModel`, :class:`Tracker`,
:class:`Localiser`, :class:`TaskPlanner`, :class:`PathPlanner` or :class:`Controller`.
It declares

- ``name``: unique within its kind, lower case (``"pd"``, ``"straight-line"``);
- ``summary``: one line saying what it is;
- ``Params``: a :class:`~dcsim.params.PluginParams` subclass (defaults, bounds, units);
- ``robots``: the robot types it supports (``("free-flyer",)`` unless it says otherwise);

and implements its kind's abstract methods. The framework constructs it with validated
parameters and its own random generator, spawned from the scenario seed, so that a
scenario and seed always give the same result. A plugin never sees ground truth, never
mutates its inputs, and returns within its time budget. The one exception is a sensor
model: it is part of the world, and turns the truth into what a sensor reports.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from dcsim.messages import (
    AttitudeReading,
    BeaconRange,
    Command,
    Detection,
    FrameDynamics,
    MotionInput,
    NoPath,
    ObjectTrack,
    PathProblem,
    Plan,
    Prior,
    RateReading,
    Reference,
    RobotSpec,
    SensedTruth,
    SensorSetup,
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


SENSOR_SLOTS: dict[str, str] = {
    "beacon_ranges": "a tuple of BeaconRange (possibly empty)",
    "star_tracker": "an AttitudeReading, or None when it gives no reading now",
    "gyros": "a RateReading, or None when they give no reading now",
    "objects": "a tuple of Detection (possibly empty)",
}
"""The sensors a robot carries (the keys of a scenario's ``sensors:`` section), each with
what its model's :meth:`SensorModel.measure` gives."""


class SensorModel(Plugin):
    """A model of one of the robot's sensors: what it reports, given the truth.

    A sensor model is part of the world: it is the one kind that reads the true state
    (:class:`~dcsim.messages.SensedTruth`) and it draws its errors from its own
    generator. The world calls :meth:`measure` once per control tick; a sensor slower
    than that gives nothing (None, or no detections) between its readings.

    Attributes
    ----------
    measures : str
        The sensor it models, one of :data:`SENSOR_SLOTS`: ``beacon_ranges``,
        ``star_tracker``, ``gyros`` or ``objects``.
    """

    kind = "sensor"
    measures: ClassVar[str]
    robots: ClassVar[tuple[str, ...]] = ("free-flyer", "manipulator")

    @abstractmethod
    def reset(self, setup: SensorSetup) -> None:
        """Prepare for a run in the world ``setup`` describes (time starts at 0)."""

    @abstractmethod
    def measure(
        self, truth: SensedTruth
    ) -> tuple[BeaconRange, ...] | AttitudeReading | RateReading | tuple[Detection, ...] | None:
        """What the sensor reports at ``truth.time``: the answer :data:`SENSOR_SLOTS`
        names for its ``measures``."""


class Tracker(Plugin):
    """Turns an object sensor's detections into tracks of the objects around the robot.

    Per control tick, after the localiser, the framework calls :meth:`update` with the
    detections made now (possibly none) and the robot's estimate (detections are
    relative to the robot). The tracks it returns are what the mission, the planners
    and the controller see. It runs only when the scenario has an object sensor model
    (``sensors.objects``); under ideal object sensing the tracks are the truth.
    """

    kind = "tracker"

    @abstractmethod
    def reset(self, frame: FrameDynamics, time: float) -> None:
        """Start with no tracks at scenario time ``time`` (s), in a frame whose free
        motion is ``frame`` (to predict the objects with)."""

    @abstractmethod
    def update(
        self, time: float, detections: Sequence[Detection], robot: StateEstimate
    ) -> tuple[ObjectTrack, ...]:
        """Fold in ``detections`` made at ``time`` (s) from the robot at ``robot``; return
        every live track, predicted to ``time``, each with its covariance."""


class Localiser(Plugin):
    """Estimates the robot's position and velocity from beacon ranges.

    Per control tick the framework calls :meth:`predict` with the motion commanded over
    the last period, then :meth:`update` with the ranges measured now (possibly none),
    then reads :meth:`estimate`. The estimate's joint states are the encoders'
    readings, and its attitude and angular velocity are the attitude sensors' (the
    truth under ideal sensing, else the star tracker's and the gyros' latest readings,
    :attr:`~dcsim.messages.Observations.attitude`): the runner puts them in before the
    mission and the controller see the estimate, unless the localiser estimates
    attitude itself.

    Attributes
    ----------
    estimates_attitude : bool
        Whether the localiser estimates attitude and angular velocity from the star
        tracker's and the gyros' readings (:meth:`update_attitude`); False by default.
        When True and sensing is not ideal, its estimate's attitude and angular
        velocity are kept.
    """

    kind = "localiser"
    estimates_attitude: ClassVar[bool] = False

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

    def update_attitude(self, attitude: AttitudeReading | None, rate: RateReading | None) -> None:  # noqa: B027 - a hook a localiser may leave alone
        """Correct the attitude belief with the star tracker's and the gyros' readings
        made now (None when a sensor gave none). Called each tick after :meth:`update`
        when :attr:`estimates_attitude` and the attitude sensors are not ideal."""


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
    cls.kind: cls for cls in (SensorModel, Tracker, Localiser, TaskPlanner, PathPlanner, Controller)
}
"""Every plugin kind by its name, in data-flow order."""
