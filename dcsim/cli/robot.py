"""``dcsim robot``: the robot of a scenario file, as a model for other tools."""

from __future__ import annotations

from pathlib import Path

import click

from dcsim.cli.options import out_file_option, overrides_option, scenario_argument


@click.group("robot")
def robot_group() -> None:
    """The robot of a scenario file: its model for other tools."""


@robot_group.command("urdf", short_help="Write the URDF of a scenario's manipulator.")
@scenario_argument()
@out_file_option("URDF file to write (.urdf).")
@overrides_option("Override one scenario value first (as for dcsim run). Repeatable.")
def robot_urdf_command(scenario: Path, out: Path, overrides: tuple[str, ...]) -> None:
    """Write the URDF of SCENARIO's manipulator (robot.type: manipulator) to OUT.

    It is the file the world loads: base link at the base's centre of mass, one
    revolute joint and link per DH row, a fixed end_effector link, inertias to be used as
    given (PyBullet: URDF_USE_INERTIA_FROM_FILE; Pinocchio: a free-flyer root joint).
    """
    from dcsim.robots.loading import load_robot_model

    model = load_robot_model(scenario, overrides)
    out.write_text(model.urdf(), encoding="utf-8")
    click.echo(f"URDF of {model.n_joints}-joint manipulator written to {out}")
