"""The messages plugins exchange with the framework: immutable values in SI units.

By topic: :mod:`~dcsim.messages.state` (the robot's state, estimate, reference,
command and limits), :mod:`~dcsim.messages.sensing` (objects, ranges, observations),
:mod:`~dcsim.messages.planning` (path problems and trajectories) and
:mod:`~dcsim.messages.tasks` (the debris mission's task planning). Import them from
:mod:`dcsim.api`.
"""

from dcsim.messages.base import Message, array_field, message
from dcsim.messages.planning import (
    Bounds,
    ChiefOrbit,
    CostWeights,
    FrameDynamics,
    FrameKind,
    GoalRegion,
    GraspGoal,
    NoPath,
    OrbitModel,
    PathProblem,
    Trajectory,
)
from dcsim.messages.sensing import (
    AttitudeReading,
    BeaconRange,
    Detection,
    KnownObject,
    ObjectKind,
    ObjectTrack,
    Observations,
    RateReading,
    SensedTruth,
    SensorSetup,
    Shape,
    ShapeKind,
    Surroundings,
)
from dcsim.messages.state import (
    Command,
    MotionInput,
    Prior,
    Reference,
    RobotSpec,
    RobotState,
    StateEstimate,
)
from dcsim.messages.tasks import DropPoint, DropVisit, Plan, PlanTask, TaskRequest

__all__ = [
    "AttitudeReading",
    "BeaconRange",
    "Detection",
    "KnownObject",
    "RateReading",
    "SensedTruth",
    "SensorSetup",
    "Bounds",
    "Command",
    "CostWeights",
    "DropPoint",
    "DropVisit",
    "ChiefOrbit",
    "FrameDynamics",
    "FrameKind",
    "GoalRegion",
    "GraspGoal",
    "Message",
    "MotionInput",
    "NoPath",
    "OrbitModel",
    "ObjectKind",
    "ObjectTrack",
    "Observations",
    "PathProblem",
    "Plan",
    "PlanTask",
    "Prior",
    "Reference",
    "RobotSpec",
    "RobotState",
    "Shape",
    "ShapeKind",
    "StateEstimate",
    "Surroundings",
    "TaskRequest",
    "Trajectory",
    "array_field",
    "message",
]
