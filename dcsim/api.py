"""dcsim's public API: everything a plugin author or a scenario script needs.

Import from here, not from dcsim's internal modules::

    from dcsim.api import Controller, Command, PluginParams, quantity, hookimpl
    from dcsim.api import run

Contents
--------
Runs (docs/python.md)
    :func:`run` (a scenario flown to its end, in memory or into a run directory),
    :func:`load_scenario`, :func:`open_run` and :func:`close_run` (a run stepped one
    control period at a time), :func:`read_run` (a run directory read back); each
    gives a :class:`RunResult`: summary, telemetry (a pandas DataFrame, units in the
    column names), events, plugins.
Plugin kinds
    :class:`SensorModel` (one of :data:`SENSOR_SLOTS`), :class:`Tracker`,
    :class:`Localiser`, :class:`TaskPlanner`, :class:`PathPlanner`, :class:`Controller`
    (and their common base :class:`Plugin`).
Parameters
    :class:`PluginParams`, :func:`quantity`; :class:`PathPlannerParams` (the base of
    path planners' models, which refuses the retired ``clearance``).
Missions (docs/plugins.md, "Writing a mission")
    :class:`Mission` (the task side of a run), :class:`MissionSettings` (its scenario
    section), :class:`MissionWorld` (what a mission may use of the world, for its type
    hints), :class:`RoleKind` (the plugin kind of a role not named after one),
    :func:`register_mission` (a mission class made at run time; a
    distribution declares its missions in the ``dcsim.missions`` entry point group).
Messages
    The robot: :class:`RobotState`, :class:`StateEstimate`, :class:`Prior`,
    :class:`MotionInput`, :class:`Reference`, :class:`Command`, :class:`RobotSpec`;
    the typed contract of its ``model``, :class:`RobotModel`.
    Sensing: :class:`ObjectTrack`, :class:`ObjectKind`, :class:`Shape`, :class:`ShapeKind`,
    :class:`BeaconRange`, :class:`Observations`, :class:`Surroundings`; the readings of
    sensor models, :class:`AttitudeReading`, :class:`RateReading`, :class:`Detection`,
    and what they read, :class:`SensorSetup`, :class:`SensedTruth`, :class:`KnownObject`.
    Path planning: :class:`PathProblem`, :class:`GoalRegion`, :class:`GraspGoal`,
    :class:`FrameDynamics`, :class:`FrameKind`, :class:`ChiefOrbit`, :class:`OrbitModel`,
    :class:`Bounds`, :class:`CostWeights`, :class:`Trajectory`, :class:`NoPath`.
    Task planning (debris): :class:`TaskRequest`, :class:`PlanTask`, :class:`DropVisit`,
    :class:`Plan`, :class:`DropPoint`.
    Your own messages: :class:`Message`, :func:`message`, :func:`array_field`.
Motion models
    :class:`MotionModel`, :class:`StaticMotion`, :class:`LinearMotion`,
    :class:`SphericalMotion`, :class:`ClohessyWiltshireMotion`, :func:`mean_motion`.
Path clearance (the yardstick of path planners)
    :func:`path_clearance`, :func:`min_clearance`, :class:`Clearance`,
    :func:`surface_distance`, :func:`body_surface_distance`, :func:`resolution_step`.
Plan cost
    :func:`plan_delta_v`, :func:`plan_duration`, :func:`plan_cost`, :func:`legs_delta_v`,
    :func:`leg_delta_v`.
Kinematics
    :func:`rest_to_rest_time`, :func:`shortest_leg`, :func:`cruise_speed`; the
    minimum-jerk (quintic) rest-to-rest law: :func:`shortest_duration`,
    :func:`minimum_jerk_profile`, :func:`minimum_jerk_move`, :func:`minimum_jerk_legs`.
Space manipulator model (DH kinematics and dynamics of the space manipulator thesis)
    :class:`ManipulatorModel` (forward kinematics, generalised and free-floating
    Jacobians, inverse kinematics, det(J Jᵀ), M(q), C(q, q̇)), built by
    :func:`manipulator_model` from a :class:`DHRobot` (a :class:`ManipulatorBase` and
    :class:`DHLink` rows); :func:`thesis_manipulator` (the thesis's robot),
    :func:`manipulator_urdf`, :func:`load_robot_model` (the model of a scenario file's
    manipulator), :func:`load_reach_problem` (the path problem of a reach scenario);
    results :class:`ForwardKinematics`, :class:`InverseKinematicsResult`;
    :class:`PosePath` (joint references along an end-effector pose trajectory, with
    their :class:`PoseTracking` figures).
Rigid-body rotation
    :class:`TorqueFreeRotation` (a body's torque-free tumble, fourth-order accurate).
Geometry
    :func:`spherical_to_cartesian`, :func:`quaternion_between`, :func:`rotate`,
    :func:`cross`, :func:`length`, :func:`row_lengths`, :func:`unit`, :func:`clip_norm`,
    :func:`quaternion_multiply`,
    :func:`quaternion_conjugate`, :func:`rotation_vector`,
    :func:`quaternion_from_rotation_vector`, :func:`quaternion_from_matrix`,
    :func:`rotation_matrix`,
    :func:`slerp`, :func:`facing_axis`, :func:`sight_angle`.
FMUs (FMI 2.0 co-simulation, through fmpy)
    :class:`FmuDescription`, :class:`FmuInstance`, :class:`FmuError`,
    :class:`FmuCallError`.
Campaigns (many cases of a scenario on Dask; docs/campaigns.md)
    :func:`run_campaign`.
Registry and hooks
    :data:`hookimpl`, :class:`PluginRegistry`.
Benches (a plugin's own ``dcsim bench`` command, added through the
``dcsim_register_commands`` hook; docs/plugins.md)
    Exact yardsticks on plain arrays: :func:`layered_optimum` (the cheapest path
    through a layered graph, a :class:`LayeredOptimum`), :func:`optimality_gap`;
    :func:`optimal_values`, :func:`reachable_cells` and :func:`working_cells` on a
    deterministic cell task. Problems: :class:`BenchProblem`, :func:`load_bench_problem`
    (a seeded obstacle field or a transfer scenario file), :func:`expand_bench_specs`,
    :func:`packaged_scenario_path`. Options: :func:`comma_words`,
    :func:`comma_numbers`, :func:`plugin_spec`. Figures: :func:`pyplot` (Agg),
    :func:`save_figure`, :func:`shape_outline`, :func:`shape_wireframe`.
Errors
    :class:`DcsimError` and its subclasses.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from dcsim.bench.cell_optimum import optimal_values, reachable_cells, working_cells
from dcsim.bench.figures import pyplot
from dcsim.bench.figures import save as save_figure
from dcsim.bench.layered_optimum import LayeredOptimum, layered_optimum, optimality_gap
from dcsim.bench.options import comma_numbers, comma_words, plugin_spec
from dcsim.errors import (
    CwValidityWarning,
    DcsimError,
    DuplicatePluginError,
    PlannerModelWarning,
    PlanOutlastsRunWarning,
    PluginError,
    PluginInterfaceError,
    PluginLoadError,
    PluginLoadWarning,
    PluginNotFoundError,
    PluginParameterError,
    RobotTypeError,
    ScenarioError,
)
from dcsim.fmu.instance import FmuCallError, FmuDescription, FmuError, FmuInstance
from dcsim.geometry import (
    clip_norm,
    cross,
    facing_axis,
    length,
    quaternion_between,
    quaternion_conjugate,
    quaternion_from_matrix,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotate,
    rotation_vector,
    row_lengths,
    sight_angle,
    slerp,
    spherical_to_cartesian,
    unit,
)
from dcsim.messages import (
    AttitudeReading,
    BeaconRange,
    Bounds,
    ChiefOrbit,
    Command,
    CostWeights,
    Detection,
    DropPoint,
    DropVisit,
    FrameDynamics,
    FrameKind,
    GoalRegion,
    GraspGoal,
    KnownObject,
    Message,
    MotionInput,
    NoPath,
    ObjectKind,
    ObjectTrack,
    Observations,
    OrbitModel,
    PathProblem,
    Plan,
    PlanTask,
    Prior,
    RateReading,
    Reference,
    RobotSpec,
    RobotState,
    SensedTruth,
    SensorSetup,
    Shape,
    ShapeKind,
    StateEstimate,
    Surroundings,
    TaskRequest,
    Trajectory,
    array_field,
    message,
)
from dcsim.minimum_jerk import (
    minimum_jerk_legs,
    minimum_jerk_move,
    minimum_jerk_profile,
    shortest_duration,
)
from dcsim.missions import Mission, register_mission
from dcsim.missions.base import MissionWorld, RoleKind
from dcsim.motion import (
    ClohessyWiltshireMotion,
    LinearMotion,
    MotionModel,
    SphericalMotion,
    StaticMotion,
    mean_motion,
)
from dcsim.params import PluginParams, quantity
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.hookspecs import hookimpl
from dcsim.registry.interfaces import (
    PLUGIN_KINDS,
    SENSOR_SLOTS,
    Controller,
    Localiser,
    PathPlanner,
    PathPlannerParams,
    Plugin,
    SensorModel,
    TaskPlanner,
    Tracker,
)
from dcsim.rest_to_rest import cruise_speed, rest_to_rest_time, shortest_leg
from dcsim.robots.dh import DHLink, DHRobot, ManipulatorBase, thesis_manipulator
from dcsim.robots.kinematics import rotation_matrix
from dcsim.robots.loading import load_reach_problem, load_robot_model
from dcsim.robots.manipulator import (
    ForwardKinematics,
    InverseKinematicsResult,
    ManipulatorModel,
    manipulator_model,
)
from dcsim.robots.model import RobotModel
from dcsim.robots.pose_path import PosePath, PoseTracking
from dcsim.robots.urdf import urdf_text as manipulator_urdf
from dcsim.run.scripting import RunResult, close_run, load_scenario, open_run, read_run, run
from dcsim.scenario.loader import packaged_scenario_path
from dcsim.scenario.model import MissionSettings
from dcsim.torque_free import TorqueFreeRotation
from dcsim.yardsticks.clearance import (
    Clearance,
    body_surface_distance,
    min_clearance,
    path_clearance,
    resolution_step,
    surface_distance,
)
from dcsim.yardsticks.plan_cost import (
    leg_delta_v,
    legs_delta_v,
    plan_cost,
    plan_delta_v,
    plan_duration,
)

if TYPE_CHECKING:
    import pandas

    from dcsim.bench.path_problems import BenchProblem
    from dcsim.bench.path_problems import expand_specs as expand_bench_specs
    from dcsim.bench.path_problems import load_problem as load_bench_problem
    from dcsim.report.outlines import outline as shape_outline
    from dcsim.report.outlines import wireframe as shape_wireframe

_LAZY = {
    "BenchProblem": ("dcsim.bench.path_problems", "BenchProblem"),
    "expand_bench_specs": ("dcsim.bench.path_problems", "expand_specs"),
    "load_bench_problem": ("dcsim.bench.path_problems", "load_problem"),
    "shape_outline": ("dcsim.report.outlines", "outline"),
    "shape_wireframe": ("dcsim.report.outlines", "wireframe"),
}
"""Names loaded on first use: their modules load the missions and the world engine, or
SciPy's spatial algorithms, which a plugin that does not use them need not wait for."""


def __getattr__(name: str) -> Any:
    """The names of :data:`_LAZY`, imported when first asked for."""
    if name not in _LAZY:
        raise AttributeError(f"module 'dcsim.api' has no attribute '{name}'")
    module, attribute = _LAZY[name]
    value = getattr(importlib.import_module(module), attribute)
    globals()[name] = value
    return value


__all__ = [
    "BenchProblem",
    "comma_numbers",
    "comma_words",
    "expand_bench_specs",
    "layered_optimum",
    "LayeredOptimum",
    "load_bench_problem",
    "optimal_values",
    "optimality_gap",
    "packaged_scenario_path",
    "plugin_spec",
    "pyplot",
    "reachable_cells",
    "save_figure",
    "shape_outline",
    "shape_wireframe",
    "working_cells",
    "close_run",
    "load_scenario",
    "open_run",
    "read_run",
    "run",
    "run_campaign",
    "RunResult",
    "array_field",
    "BeaconRange",
    "body_surface_distance",
    "Bounds",
    "Clearance",
    "clip_norm",
    "ClohessyWiltshireMotion",
    "Command",
    "Controller",
    "CostWeights",
    "AttitudeReading",
    "cruise_speed",
    "Detection",
    "KnownObject",
    "RateReading",
    "SensedTruth",
    "SENSOR_SLOTS",
    "SensorModel",
    "SensorSetup",
    "Tracker",
    "DcsimError",
    "DHLink",
    "DHRobot",
    "DropPoint",
    "DropVisit",
    "DuplicatePluginError",
    "FmuCallError",
    "FmuDescription",
    "FmuError",
    "FmuInstance",
    "ForwardKinematics",
    "ChiefOrbit",
    "FrameDynamics",
    "FrameKind",
    "GoalRegion",
    "GraspGoal",
    "hookimpl",
    "InverseKinematicsResult",
    "leg_delta_v",
    "legs_delta_v",
    "LinearMotion",
    "Localiser",
    "load_robot_model",
    "load_reach_problem",
    "manipulator_model",
    "manipulator_urdf",
    "ManipulatorBase",
    "ManipulatorModel",
    "mean_motion",
    "Message",
    "message",
    "min_clearance",
    "minimum_jerk_legs",
    "minimum_jerk_move",
    "minimum_jerk_profile",
    "Mission",
    "MissionWorld",
    "MissionSettings",
    "RoleKind",
    "MotionInput",
    "MotionModel",
    "NoPath",
    "OrbitModel",
    "ObjectKind",
    "ObjectTrack",
    "Observations",
    "path_clearance",
    "PathPlanner",
    "PathPlannerParams",
    "PathProblem",
    "Plan",
    "plan_cost",
    "plan_delta_v",
    "plan_duration",
    "PlanTask",
    "PosePath",
    "PoseTracking",
    "Plugin",
    "PLUGIN_KINDS",
    "CwValidityWarning",
    "PlannerModelWarning",
    "PlanOutlastsRunWarning",
    "PluginError",
    "RobotTypeError",
    "PluginInterfaceError",
    "PluginLoadError",
    "PluginLoadWarning",
    "PluginNotFoundError",
    "PluginParameterError",
    "PluginParams",
    "PluginRegistry",
    "Prior",
    "quantity",
    "quaternion_between",
    "quaternion_conjugate",
    "quaternion_from_matrix",
    "quaternion_from_rotation_vector",
    "quaternion_multiply",
    "Reference",
    "register_mission",
    "resolution_step",
    "rest_to_rest_time",
    "RobotModel",
    "RobotSpec",
    "RobotState",
    "rotate",
    "cross",
    "length",
    "row_lengths",
    "facing_axis",
    "sight_angle",
    "rotation_matrix",
    "rotation_vector",
    "ScenarioError",
    "Shape",
    "ShapeKind",
    "shortest_duration",
    "shortest_leg",
    "slerp",
    "spherical_to_cartesian",
    "SphericalMotion",
    "StateEstimate",
    "StaticMotion",
    "surface_distance",
    "Surroundings",
    "TaskPlanner",
    "TaskRequest",
    "thesis_manipulator",
    "TorqueFreeRotation",
    "Trajectory",
    "unit",
]


def run_campaign(
    campaign: str | Path,
    out: str | Path,
    *,
    scheduler: str | None = None,
    connect_timeout: float | None = None,
    workers: int | None = None,
    cases: int | None = None,
    force: bool = False,
) -> pandas.DataFrame:
    """Run a campaign file's cases on Dask and return their results table.

    The same as ``dcsim campaign run`` (docs/campaigns.md): each case's run directory
    and the results files are written under ``out``.

    Parameters
    ----------
    campaign : str or Path
        The campaign file.
    out : str or Path
        The campaign directory to write.
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:port``); a local cluster
        when None.
    connect_timeout : float, optional
        Seconds to wait for the scheduler at ``scheduler`` (10 when None); only with
        ``scheduler``.
    workers : int, optional
        Worker processes of the local cluster (one per core when None).
    cases : int, optional
        Run only the first ``cases`` cases.
    force : bool
        Replace ``out`` if it holds anything.

    Returns
    -------
    pandas.DataFrame
        One row per case: index, seed, dispersed values, status, reason, metrics.

    Raises
    ------
    ValueError
        If ``connect_timeout`` is not positive, or given without ``scheduler``.
    dcsim.errors.DcsimError
        If the campaign file or its scenario is invalid, or the cluster cannot start or
        be reached (a ``ClusterError``; among its causes, a script that calls this
        without its ``if __name__ == "__main__":`` guard, whose worker processes import
        it again).
    """
    from dcsim.campaign import ClusterOptions
    from dcsim.campaign import run_campaign as run

    options = ClusterOptions(scheduler, workers, connect_timeout=connect_timeout)
    return run(Path(campaign), Path(out), options, cases, force).table
