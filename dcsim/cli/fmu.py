"""``dcsim fmu``: export scenarios as FMI 2.0 co-simulation FMUs, and couple FMUs."""

from __future__ import annotations

from pathlib import Path

import click

from dcsim.cli.common import plugin_registry
from dcsim.cli.options import (
    out_dir_option,
    out_file_option,
    overrides_option,
    positive_option,
    scenario_argument,
)


@click.group("fmu", short_help="FMI 2.0 co-simulation: export scenarios, couple FMUs.")
def fmu_group() -> None:
    """FMI 2.0 co-simulation: export scenarios as FMUs, couple FMUs (docs/fmu.md)."""


@fmu_group.command("export", short_help="Build an FMI 2.0 co-simulation FMU of a scenario.")
@scenario_argument(required=False)
@out_file_option("FMU file to write (.fmu).")
@click.option(
    "--plant-only",
    is_flag=True,
    help="Export the world alone: force and torque (and a manipulator's joint torques, a "
    "free flyer's thruster on-times and wheel torques) in, true state and sensors out.",
)
@click.option(
    "--beacons",
    type=click.IntRange(min=1),
    help="With --plant-only: how many nearest beacons' ranges to output.  [default: 4]",
)
@overrides_option("Override one scenario value before export (as for dcsim run). Repeatable.")
def fmu_export_command(
    scenario: Path | None,
    out: Path,
    plant_only: bool,
    beacons: int | None,
    overrides: tuple[str, ...],
) -> None:
    """Build an FMI 2.0 co-simulation FMU of SCENARIO (default: the packaged one).

    The closed-loop FMU runs the whole scenario (world, localiser, planners, controller,
    mission) with disturbance force and torque as inputs; --plant-only exports the world
    alone. A manipulator's FMUs also output its joint angles and rates and its end
    effector, and its plant FMU takes the joint torques. The base's thrusters and
    reaction wheels add their duty cycles and momenta (and the attitude error to the
    closed loop), and the plant takes their on-times and torques one by one. The
    resolved scenario travels inside the FMU; importing it needs Python with dcsim
    installed.
    """
    from dcsim.fmu.export import export_fmu
    from dcsim.fmu.variables import DEFAULT_BEACONS

    if beacons is not None and not plant_only:
        raise click.BadParameter("only the plant FMU outputs beacon ranges", param_hint="--beacons")
    beacons = DEFAULT_BEACONS if beacons is None else beacons
    path = export_fmu(scenario, out, plant_only, overrides, beacons, registry=plugin_registry())
    kind = "plant-only" if plant_only else "closed-loop"
    click.echo(f"{kind} FMU written to {path}")


@fmu_group.command("cosim", short_help="Couple a plant FMU with a controller FMU through fmpy.")
@click.argument("plant", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--controller",
    required=True,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="The controller FMU.",
)
@positive_option("--stop", 60.0, "Stop time, s.")
@positive_option("--step", 0.1, "Communication step, s.")
@click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="FMU:NAME=VALUE",
    help="Start value of a parameter or input, FMU being plant or controller, e.g. "
    "--set controller:reference.position.x=5. Repeatable.",
)
@out_dir_option("Directory for results.csv and results.png.", default=Path("cosim"))
def fmu_cosim_command(
    plant: Path,
    controller: Path,
    stop: float,
    step: float,
    settings: tuple[str, ...],
    out: Path,
) -> None:
    """Couple the PLANT FMU with a controller FMU through fmpy; write a CSV and a plot.

    Signals connect by equal names (controller inputs from plant outputs, plant inputs
    from controller outputs); each step runs the controller, then the plant.
    """
    from dcsim.fmu.cosim import cosimulate, output_units, plot, write_csv

    results, coupling = cosimulate(plant, controller, stop, step, _start_values(settings))
    click.echo(f"connected to the controller: {', '.join(coupling.to_controller)}")
    click.echo(f"connected to the plant: {', '.join(coupling.to_plant)}")
    if coupling.unfed:
        click.echo(f"left at their start values: {', '.join(coupling.unfed)}")
    write_csv(results, out / "results.csv")
    plot(results, out / "results.png", output_units(plant, controller))
    click.echo(f"results in {out}/results.csv and {out}/results.png")


def _start_values(settings: tuple[str, ...]) -> dict[str, dict[str, float]]:
    values: dict[str, dict[str, float]] = {"plant": {}, "controller": {}}
    for setting in settings:
        fmu, _, assignment = setting.partition(":")
        name, equals, text = assignment.partition("=")
        if fmu not in values or not equals or not name:
            raise click.BadParameter(
                f"{setting!r}: write plant:NAME=VALUE or controller:NAME=VALUE",
                param_hint="--set",
            )
        try:
            values[fmu][name] = float(text)
        except ValueError:
            raise click.BadParameter(
                f"{setting!r}: {text!r} is not a number", param_hint="--set"
            ) from None
    return values
