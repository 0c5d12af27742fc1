"""dcsim's public API: everything a plugin author or a scenario script needs.

Import from here, not from dcsim's internal modules::

    from dcsim.api import Controller, Command, PluginParams, quantity, hookimpl

Contents
--------
Plugin kinds
    :class:`Localiser`, :class:`TaskPlanner`, :class:`PathPlanner`, :class:`Controller`
    (and their common base :class:`Plugin`).
Parameters
    :class:`PluginParams`, :func:`quantity`.
Messages
    :class:`ObjectTrack`, :class:`ObjectKind`, :class:`BeaconRange`, :class:`MotionInput`,
    :class:`LocationEstimate`, :class:`Prior`, :class:`TaskRequest`, :class:`PlanTask`,
    :class:`DropVisit`, :class:`Plan`, :class:`DropPoint`, :class:`RobotSpec`,
    :class:`PathProblem`, :class:`PathState`, :class:`GoalRegion`, :class:`Bounds`,
    :class:`CostWeights`, :class:`Trajectory`, :class:`NoPath`, :class:`Reference`,
    :class:`Surroundings`, :class:`Command`, :class:`MoveCommand`.
Motion models
    :class:`MotionModel`, :class:`StaticMotion`, :class:`LinearMotion`,
    :class:`SphericalMotion`, :class:`ClohessyWiltshireMotion`, :func:`mean_motion`.
Plan cost
    :func:`plan_delta_v`, :func:`plan_duration`, :func:`plan_cost`, :func:`legs_delta_v`,
    :func:`leg_delta_v`.
Kinematics
    :func:`rest_to_rest_time`, :func:`shortest_leg`, :func:`cruise_speed`.
Geometry
    :func:`spherical_to_cartesian`, :func:`quaternion_between`, :func:`rotate`, :func:`unit`,
    :func:`clip_norm`.
FMUs (FMI 2.0 co-simulation, through fmpy)
    :class:`FmuDescription`, :class:`FmuInstance`, :class:`FmuError`,
    :class:`FmuCallError`.
Registry and hooks
    :data:`hookimpl`, :class:`PluginRegistry`.
Errors
    :class:`DcsimError` and its subclasses.
"""

from dcsim.errors import (
    DcsimError,
    DuplicatePluginError,
    PluginError,
    PluginInterfaceError,
    PluginLoadWarning,
    PluginNotFoundError,
    PluginParameterError,
    ScenarioError,
)
from dcsim.fmu.instance import FmuCallError, FmuDescription, FmuError, FmuInstance
from dcsim.geometry import clip_norm, quaternion_between, rotate, spherical_to_cartesian, unit
from dcsim.hookspecs import hookimpl
from dcsim.interfaces import PLUGIN_KINDS, Controller, Localiser, PathPlanner, Plugin, TaskPlanner
from dcsim.kinematics import cruise_speed, rest_to_rest_time, shortest_leg
from dcsim.messages import (
    BeaconRange,
    Bounds,
    Command,
    CostWeights,
    DropPoint,
    DropVisit,
    GoalRegion,
    LocationEstimate,
    MotionInput,
    MoveCommand,
    NoPath,
    ObjectKind,
    ObjectTrack,
    PathProblem,
    PathState,
    Plan,
    PlanTask,
    Prior,
    Reference,
    RobotSpec,
    Surroundings,
    TaskRequest,
    Trajectory,
)
from dcsim.motion import (
    ClohessyWiltshireMotion,
    LinearMotion,
    MotionModel,
    SphericalMotion,
    StaticMotion,
    mean_motion,
)
from dcsim.params import PluginParams, quantity
from dcsim.plancost import leg_delta_v, legs_delta_v, plan_cost, plan_delta_v, plan_duration
from dcsim.registry import PluginRegistry

__all__ = [
    "FmuCallError",
    "FmuDescription",
    "FmuError",
    "FmuInstance",
    "PLUGIN_KINDS",
    "BeaconRange",
    "Bounds",
    "ClohessyWiltshireMotion",
    "Command",
    "Controller",
    "clip_norm",
    "cruise_speed",
    "CostWeights",
    "DcsimError",
    "DropPoint",
    "DropVisit",
    "DuplicatePluginError",
    "GoalRegion",
    "LinearMotion",
    "Localiser",
    "LocationEstimate",
    "MotionInput",
    "MotionModel",
    "MoveCommand",
    "NoPath",
    "ObjectKind",
    "ObjectTrack",
    "PathPlanner",
    "PathProblem",
    "PathState",
    "Plan",
    "PlanTask",
    "Plugin",
    "PluginError",
    "PluginInterfaceError",
    "PluginLoadWarning",
    "PluginNotFoundError",
    "PluginParameterError",
    "PluginParams",
    "PluginRegistry",
    "Prior",
    "Reference",
    "RobotSpec",
    "ScenarioError",
    "SphericalMotion",
    "StaticMotion",
    "Surroundings",
    "TaskPlanner",
    "TaskRequest",
    "Trajectory",
    "hookimpl",
    "leg_delta_v",
    "legs_delta_v",
    "mean_motion",
    "plan_cost",
    "plan_delta_v",
    "plan_duration",
    "quantity",
    "quaternion_between",
    "rest_to_rest_time",
    "rotate",
    "shortest_leg",
    "spherical_to_cartesian",
    "unit",
]
