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

A robot whose base has ``robot.actuators`` hardware has, in both FMUs, each reaction wheel's
momentum (``wheel_momentum[i]``) and each thruster's duty cycle (``thruster_duty[i]``),
and with thrusters the propellant burnt for attitude; its closed-loop FMU also outputs
the attitude error, its plant FMU takes per-thruster on-times and per-wheel torques,
used while ``thrusters_direct`` and ``wheels_direct`` are true. Without the hardware
none of these exist.
"""

from __future__ import annotations

from dataclasses import dataclass

from dcsim.missions import mission_class
from dcsim.scenario.model import (
    ManipulatorSection,
    RobotSection,
    Scenario,
    ThrusterSpec,
    robot_hardware,
)

AXES = ("x", "y", "z")
QUATERNION = ("x", "y", "z", "w")

JOINT_ANGLE = "joint[{}].angle"
"""FMI name of joint i's angle (``JOINT_ANGLE.format(i)``, i from 1 in DH order), rad."""
JOINT_RATE = "joint[{}].rate"
"""FMI name of joint i's rate, rad/s."""
JOINT_TORQUE = "joint_torque[{}]"
"""FMI name of joint i's commanded torque (a plant input), N·m."""
THRUSTER_ON_TIME = "thruster_on_time[{}]"
"""FMI name of thruster i's on-time from the control period's start (a plant input), s;
i from 1 in the order of ``robot.actuators.thrusters``."""
WHEEL_TORQUE = "wheel_torque[{}]"
"""FMI name of reaction wheel i's torque about its spin axis (a plant input), N·m; i
from 1 in the order of ``robot.actuators.reaction_wheels``."""
THRUSTERS_DIRECT = "thrusters_direct"
"""FMI name of the plant input that makes the on-time inputs fire the thrusters."""
WHEELS_DIRECT = "wheels_direct"
"""FMI name of the plant input that makes the wheel torque inputs drive the wheels."""
WHEEL_MOMENTUM = "wheel_momentum[{}]"
"""FMI name of reaction wheel i's angular momentum about its spin axis, N·m·s."""
THRUSTER_DUTY = "thruster_duty[{}]"
"""FMI name of the fraction of the last control period thruster i fired."""


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


def hardware_inputs(scenario: Scenario) -> list[FmuVariable]:
    """The plant's per-thruster on-times (s) and per-wheel torques (N·m), each set with
    the Boolean that makes them replace the allocation of ``force`` and ``torque``."""
    thrusters, wheels = robot_hardware(scenario.robot)
    period = scenario.world.control_period
    inputs = [
        FmuVariable(
            THRUSTER_ON_TIME.format(i),
            "input",
            float,
            "s",
            f"Firing time of thruster {i} from the control period's start, flown while "
            f"{THRUSTERS_DIRECT} is true ({_on_time_rounding(spec, period)}).",
        )
        for i, spec in enumerate(thrusters, 1)
    ]
    if thrusters:
        inputs.append(
            FmuVariable(
                THRUSTERS_DIRECT,
                "input",
                bool,
                "",
                f"True: the {THRUSTER_ON_TIME.format('i')} inputs fire the thrusters; false "
                "(the default): "
                f"{'force (and unloading) is' if wheels else 'force and torque are'} "
                "allocated to them.",
            )
        )
    inputs += [
        FmuVariable(
            WHEEL_TORQUE.format(i),
            "input",
            float,
            "N.m",
            f"Torque of reaction wheel {i} about its spin axis, flown while {WHEELS_DIRECT} "
            f"is true; the base receives the reaction (clipped to ±{spec.max_torque:g} N.m "
            "and to the momentum limit).",
        )
        for i, spec in enumerate(wheels, 1)
    ]
    if wheels:
        inputs.append(
            FmuVariable(
                WHEELS_DIRECT,
                "input",
                bool,
                "",
                f"True: the {WHEEL_TORQUE.format('i')} inputs drive the wheels; false (the "
                "default): torque is allocated to them.",
            )
        )
    return inputs


def _on_time_rounding(spec: ThrusterSpec, period: float) -> str:
    """What the world does with an on-time of the thruster ``spec`` (s): clips it to the
    control period and rounds one shorter than the minimum impulse bit's."""
    clipped = f"clipped to [0, {period:g}] s"
    shortest = spec.min_impulse_bit / spec.max_thrust
    if shortest == 0.0:
        return clipped
    return (
        f"{clipped}; shorter than the minimum impulse bit's {shortest:g} s: flown as 0 "
        f"below {shortest / 2:g} s, else as {shortest:g} s"
    )


def hardware_outputs(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """Both FMUs' outputs of the hardware: each wheel's momentum (N·m·s), each thruster's
    duty cycle over the last control period, and with thrusters the propellant burnt for
    attitude (kg)."""
    thrusters, wheels = robot_hardware(robot)
    outputs = [
        FmuVariable(
            WHEEL_MOMENTUM.format(i),
            "output",
            float,
            "N.m.s",
            f"Angular momentum of reaction wheel {i} about its spin axis "
            f"(limit ±{spec.max_momentum:g} N.m.s).",
        )
        for i, spec in enumerate(wheels, 1)
    ]
    outputs += [
        FmuVariable(
            THRUSTER_DUTY.format(i),
            "output",
            float,
            "",
            f"Fraction of the last control period thruster {i} fired.",
        )
        for i in range(1, len(thrusters) + 1)
    ]
    if thrusters:
        outputs.append(
            FmuVariable(
                "attitude_fuel_used",
                "output",
                float,
                "kg",
                "Propellant burnt for attitude: what each period's firing burnt beyond what "
                "its mean force alone needs (part of fuel_used).",
            )
        )
    return outputs


def attitude_error_output(robot: RobotSection | ManipulatorSection) -> list[FmuVariable]:
    """The closed loop's attitude error (rad), for a robot with thrusters or reaction
    wheels only."""
    if not any(robot_hardware(robot)):
        return []
    return [
        FmuVariable(
            "attitude_error",
            "output",
            float,
            "rad",
            "Angle from the attitude to the mission reference's (the telemetry's "
            "attitude_error); NaN while the reference leaves the attitude free.",
        )
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
        *hardware_outputs(robot),
        *attitude_error_output(robot),
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
        *hardware_inputs(scenario),
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
        *hardware_outputs(robot),
    ]


def _ordinal(k: int) -> str:
    return {1: "1st", 2: "2nd", 3: "3rd"}.get(k, f"{k}th")
