"""The variables of dcsim's FMUs: name, causality, type, unit and meaning.

The functions here define what an exported FMU offers, from the scenario it carries:
the slaves register exactly these variables and ``docs/fmu.md`` lists them for the
default scenario and for a manipulator (:mod:`dcsim.fmu.reference`, ``make docs``).
Vectors are three (or four) scalar variables named ``name.x``, ``name.y``, ``name.z``
(``.w`` for a quaternion's scalar part), world frame of the scenario.

A manipulator's FMUs have, besides its base's state, its joints' angles and rates
(``joint[i].angle``, ``joint[i].rate``, i = 1 … n in DH order from the base) and its
end effector's position; its plant FMU takes the joint torques (``joint_torque[i]``).
Only a robot that carries targets (a free flyer) has the ``captured`` and ``delivered``
counts.
"""

from __future__ import annotations

from dataclasses import dataclass

from dcsim.missions import mission_class
from dcsim.scenario.model import ManipulatorSection, RobotSection, Scenario

AXES = ("x", "y", "z")
QUATERNION = ("x", "y", "z", "w")

JOINT_ANGLE = "joint[{}].angle"
"""FMI name of joint i's angle (``JOINT_ANGLE.format(i)``, i from 1 in DH order), rad."""
JOINT_RATE = "joint[{}].rate"
"""FMI name of joint i's rate, rad/s."""
JOINT_TORQUE = "joint_torque[{}]"
"""FMI name of joint i's commanded torque (a plant input), N·m."""


@dataclass(frozen=True)
class FmuVariable:
    """One scalar variable of an FMU.

    Attributes
    ----------
    name : str
        FMI name (structured naming convention).
    causality : str
        ``parameter``, ``input`` or ``output``.
    type : type
        ``float`` (FMI Real), ``int`` (Integer) or ``bool`` (Boolean).
    unit : str
        Unit of the value ("" for a pure number).
    description : str
        What the value means.
    """

    name: str
    causality: str
    type: type
    unit: str
    description: str


def _vector(name: str, causality: str, unit: str, description: str) -> list[FmuVariable]:
    return [FmuVariable(f"{name}.{axis}", causality, float, unit, description) for axis in AXES]


def joint_count(robot: RobotSection | ManipulatorSection) -> int:
    """Number of joints of a scenario's robot (0 for a free flyer)."""
    return len(robot.links) if isinstance(robot, ManipulatorSection) else 0


def _body(robot: RobotSection | ManipulatorSection) -> str:
    """What the base state describes: the collector, or a manipulator's base."""
    return "Base" if isinstance(robot, ManipulatorSection) else "Collector"


def parameters(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """Parameters of both FMUs of a scenario with ``robot``.

    ``seed`` overrides ``world.seed``, the others the scenario key of their own name.
    """
    body = _body(robot)
    return [
        FmuVariable("seed", "parameter", int, "", "Random seed of the run (scenario world.seed)."),
        FmuVariable("robot.mass", "parameter", float, "kg", f"{body} wet mass at the start."),
        FmuVariable("robot.max_force", "parameter", float, "N", "Largest thrust magnitude."),
        FmuVariable("robot.max_torque", "parameter", float, "N.m", "Largest torque magnitude."),
        FmuVariable(
            "robot.max_speed", "parameter", float, "m/s", f"Speed limit of the {body.lower()}."
        ),
        FmuVariable("robot.sensor_range", "parameter", float, "m", "Object sensor range."),
    ]


def _state(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """The true state: the base's, then a manipulator's joints and end effector."""
    body = _body(robot)
    return [
        *_vector("position", "output", "m", f"{body} position (true)."),
        *_vector("velocity", "output", "m/s", f"{body} velocity (true)."),
        *[
            FmuVariable(f"attitude.{c}", "output", float, "", "Attitude quaternion (true).")
            for c in QUATERNION
        ],
        *_vector("angular_velocity", "output", "rad/s", f"{body} angular velocity (true)."),
        *arm_outputs(robot),
    ]


def arm_outputs(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """A manipulator's joint angles (rad) and rates (rad/s), i = 1 … n in DH order, then its
    end effector's position (m, world frame); none for a free flyer."""
    joints = [
        variable
        for i in range(1, joint_count(robot) + 1)
        for variable in (
            FmuVariable(JOINT_ANGLE.format(i), "output", float, "rad", f"Joint {i} angle (true)."),
            FmuVariable(JOINT_RATE.format(i), "output", float, "rad/s", f"Joint {i} rate (true)."),
        )
    ]
    if not joints:
        return []
    return [*joints, *_vector("end_effector", "output", "m", "End-effector position (true).")]


def joint_torque_inputs(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """The plant's joint torque inputs of a manipulator, N·m, DH order (none for a free
    flyer)."""
    if not isinstance(robot, ManipulatorSection):
        return []
    return [
        FmuVariable(
            JOINT_TORQUE.format(i),
            "input",
            float,
            "N.m",
            f"Commanded torque of joint {i}, positive towards a larger angle "
            f"({_torque_clipping(link.torque_limit)}).",
        )
        for i, link in enumerate(robot.links, 1)
    ]


def _torque_clipping(limit: float | None) -> str:
    return "unlimited" if limit is None else f"clipped to ±{limit:g} N.m, the link's torque_limit"


def _cargo(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """The target counts, for a robot that carries targets (a free flyer)."""
    if robot.capacity == 0:
        return []
    return [
        FmuVariable(
            "captured", "output", int, "", "Targets grabbed so far (carried or delivered)."
        ),
        FmuVariable("delivered", "output", int, "", "Targets delivered to the drop point."),
    ]


def closed_loop_variables(scenario: Scenario) -> list[FmuVariable]:
    """Variables of the closed-loop FMU of ``scenario`` (``dcsim fmu export``)."""
    robot, mission = scenario.robot, mission_class(scenario.mission.type)
    body = _body(robot).lower()
    modes = ", ".join(f"{index} {mode}" for index, mode in enumerate(mission.modes))
    return [
        *parameters(robot),
        *_vector("disturbance_force", "input", "N", f"External force on the {body}."),
        *_vector("disturbance_torque", "input", "N.m", f"External torque on the {body}."),
        *_state(robot),
        FmuVariable(
            "mode", "output", int, "", f"Mission mode, by index ({mission.type}: {modes})."
        ),
        *_cargo(robot),
        FmuVariable("collisions", "output", int, "", "Collisions so far."),
        FmuVariable("fuel_used", "output", float, "kg", "Propellant used."),
        FmuVariable("delta_v", "output", float, "m/s", "Delta-v spent."),
        FmuVariable(
            "localisation_error", "output", float, "m", "Distance from the estimate to the truth."
        ),
        FmuVariable(
            "run_status",
            "output",
            int,
            "",
            "0 running, 1 completed, 2 stopped by a stop rule, 3 failed (then the world coasts).",
        ),
    ]


DEFAULT_BEACONS = 4
"""How many nearest beacons' ranges the plant FMU outputs unless told otherwise (K)."""


def plant_variables(scenario: Scenario, beacons: int) -> list[FmuVariable]:
    """Variables of the plant-only FMU of ``scenario`` (``dcsim fmu export --plant-only``).

    Parameters
    ----------
    scenario : Scenario
        The scenario exported.
    beacons : int
        How many nearest beacons' ranges the FMU outputs (K).
    """
    robot = scenario.robot
    ranges = [
        variable
        for k in range(1, beacons + 1)
        for variable in (
            FmuVariable(
                f"beacon[{k}].id",
                "output",
                int,
                "",
                f"Scenario index of the {_ordinal(k)} nearest beacon in range, −1 if none.",
            ),
            FmuVariable(
                f"beacon[{k}].range",
                "output",
                float,
                "m",
                "Measured (noisy) range to that beacon, 0 if none.",
            ),
        )
    ]
    mass = (
        "Mass of the base and the arm (with propellant)."
        if isinstance(robot, ManipulatorSection)
        else "Collector mass (with cargo, propellant)."
    )
    return [
        *parameters(robot),
        *_vector("force", "input", "N", "Commanded thrust (clipped to robot.max_force)."),
        *_vector("torque", "input", "N.m", "Commanded torque (clipped to robot.max_torque)."),
        *joint_torque_inputs(robot),
        *_state(robot),
        FmuVariable("mass", "output", float, "kg", mass),
        *ranges,
        FmuVariable("tracked", "output", int, "", "Objects within sensor range."),
        FmuVariable(
            "nearest_obstacle", "output", float, "m", "Surface gap to the nearest obstacle."
        ),
        FmuVariable("collision", "output", bool, "", "A collision started during the last step."),
        FmuVariable("collisions", "output", int, "", "Collisions so far."),
        FmuVariable("fuel_used", "output", float, "kg", "Propellant used."),
        FmuVariable("delta_v", "output", float, "m/s", "Delta-v spent."),
    ]


def _ordinal(k: int) -> str:
    return {1: "1st", 2: "2nd", 3: "3rd"}.get(k, f"{k}th")
