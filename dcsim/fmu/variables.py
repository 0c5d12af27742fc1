"""The variables of dcsim's FMUs: name, causality, type, unit and meaning.

The functions here define what an exported FMU offers, from the scenario it carries:
the slaves register exactly these variables and ``docs/fmu.md`` lists them for the
default scenario (:mod:`dcsim.fmu.reference`, ``make docs``). Vectors are three (or
four) scalar variables named ``name.x``, ``name.y``, ``name.z`` (``.w`` for a
quaternion's scalar part), world frame of the scenario.
"""

from __future__ import annotations

from dataclasses import dataclass

from dcsim.missions import mission_class
from dcsim.scenario.model import Scenario

AXES = ("x", "y", "z")
QUATERNION = ("x", "y", "z", "w")


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


PARAMETERS = [
    FmuVariable("seed", "parameter", int, "", "Random seed of the run (scenario world.seed)."),
    FmuVariable("robot.mass", "parameter", float, "kg", "Collector wet mass at the start."),
    FmuVariable("robot.max_force", "parameter", float, "N", "Largest thrust magnitude."),
    FmuVariable("robot.max_torque", "parameter", float, "N.m", "Largest torque magnitude."),
    FmuVariable("robot.max_speed", "parameter", float, "m/s", "Speed limit of the collector."),
    FmuVariable("robot.sensor_range", "parameter", float, "m", "Object sensor range."),
]
"""Parameters of both FMUs; ``seed`` overrides ``world.seed``, the others the scenario
key of their own name."""

_STATE = [
    *_vector("position", "output", "m", "Collector position (true)."),
    *_vector("velocity", "output", "m/s", "Collector velocity (true)."),
    *[
        FmuVariable(f"attitude.{c}", "output", float, "", "Attitude quaternion (true).")
        for c in QUATERNION
    ],
    *_vector("angular_velocity", "output", "rad/s", "Collector angular velocity (true)."),
]


def closed_loop_variables(scenario: Scenario) -> list[FmuVariable]:
    """Variables of the closed-loop FMU of ``scenario`` (``dcsim fmu export``)."""
    mission = mission_class(scenario.mission.type)
    modes = ", ".join(f"{index} {mode}" for index, mode in enumerate(mission.modes))
    return [
        *PARAMETERS,
        *_vector("disturbance_force", "input", "N", "External force on the collector."),
        *_vector("disturbance_torque", "input", "N.m", "External torque on the collector."),
        *_STATE,
        FmuVariable(
            "mode", "output", int, "", f"Mission mode, by index ({mission.type}: {modes})."
        ),
        FmuVariable(
            "captured", "output", int, "", "Targets grabbed so far (carried or delivered)."
        ),
        FmuVariable("delivered", "output", int, "", "Targets delivered to the drop point."),
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
    return [
        *PARAMETERS,
        *_vector("force", "input", "N", "Commanded thrust (clipped to robot.max_force)."),
        *_vector("torque", "input", "N.m", "Commanded torque (clipped to robot.max_torque)."),
        *_STATE,
        FmuVariable("mass", "output", float, "kg", "Collector mass (with cargo, propellant)."),
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
