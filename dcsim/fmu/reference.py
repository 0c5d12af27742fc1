"""Generate the variable tables of docs/fmu.md (``make docs``).

The free flyer's tables are those of the packaged default scenario; the manipulator's
table is generated from the repository's reach scenario
(``scenarios/space_manipulator_reach.yaml``, six joints), the thrusters' and the
wheels' table from ``scenarios/default_hardware.yaml`` (twelve thrusters, four wheels).
"""

from __future__ import annotations

import sys
from pathlib import Path

from dcsim.fmu.variables import (
    DEFAULT_BEACONS,
    FmuVariable,
    arm_outputs,
    attitude_error_output,
    closed_loop_variables,
    hardware_inputs,
    hardware_outputs,
    joint_torque_inputs,
    plant_variables,
)
from dcsim.report.docgen import update_block
from dcsim.scenario import read_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
MANIPULATOR_SCENARIO = SCENARIOS / "space_manipulator_reach.yaml"
"""The scenario the manipulator's table is generated from."""
HARDWARE_SCENARIO = SCENARIOS / "default_hardware.yaml"
"""The scenario the table of the thrusters' and the wheels' variables is generated from."""


def variables_table(variables: list[FmuVariable]) -> str:
    """A Markdown table of ``variables``."""
    types = {float: "Real", int: "Integer", bool: "Boolean"}
    lines = ["| name | causality | type | unit | meaning |", "|---|---|---|---|---|"]
    lines += [
        f"| `{v.name}` | {v.causality} | {types[v.type]} | {v.unit or '–'} | {v.description} |"
        for v in variables
    ]
    return "\n".join(lines) + "\n"


BEGIN_CLOSED = "<!-- begin: closed-loop variables (make docs) -->"
END_CLOSED = "<!-- end: closed-loop variables -->"
BEGIN_PLANT = "<!-- begin: plant variables (make docs) -->"
END_PLANT = "<!-- end: plant variables -->"
BEGIN_MANIPULATOR = "<!-- begin: manipulator variables (make docs) -->"
END_MANIPULATOR = "<!-- end: manipulator variables -->"
BEGIN_HARDWARE = "<!-- begin: hardware variables (make docs) -->"
END_HARDWARE = "<!-- end: hardware variables -->"


def generated_blocks() -> list[tuple[str, str, str]]:
    """``(begin marker, end marker, table)`` of every generated block of docs/fmu.md.

    The closed-loop and plant tables of the default scenario (the plant with K =
    :data:`DEFAULT_BEACONS`), and the variables a manipulator's FMUs add (the plant's
    joint torque inputs, then the joint and end-effector outputs of both variants) for
    :data:`MANIPULATOR_SCENARIO`, and those thrusters and wheels add (the plant's inputs,
    the outputs of both variants, the closed loop's attitude error) for
    :data:`HARDWARE_SCENARIO`.
    """
    default = read_scenario()
    robot = read_scenario(MANIPULATOR_SCENARIO).robot
    hardware = read_scenario(HARDWARE_SCENARIO)
    return [
        (BEGIN_CLOSED, END_CLOSED, variables_table(closed_loop_variables(default))),
        (BEGIN_PLANT, END_PLANT, variables_table(plant_variables(default, DEFAULT_BEACONS))),
        (
            BEGIN_MANIPULATOR,
            END_MANIPULATOR,
            variables_table([*joint_torque_inputs(robot), *arm_outputs(robot)]),
        ),
        (
            BEGIN_HARDWARE,
            END_HARDWARE,
            variables_table(
                [
                    *hardware_inputs(hardware),
                    *hardware_outputs(hardware.robot),
                    *attitude_error_output(hardware.robot),
                ]
            ),
        ),
    ]


def write_reference(path: Path) -> bool:
    """Regenerate every variable table in ``path``; return True if it changed."""
    changed = False
    for begin, end, table in generated_blocks():
        changed = update_block(path, begin, end, table) or changed
    return changed


if __name__ == "__main__":
    target = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/fmu.md")
    changed = write_reference(target)
    print(f"{target}: {'updated' if changed else 'already up to date'}")
