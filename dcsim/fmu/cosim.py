"""Co-simulation of a plant FMU and a controller FMU through fmpy (``dcsim fmu cosim``).

Coupling is by name: every controller input takes the plant output of the same name,
every plant input the controller output of the same name. Each communication step runs
in Gauss–Seidel order, controller first::

    controller inputs  <- plant outputs at t
    controller.doStep(t, h)       # its outputs: the command held over [t, t + h]
    plant inputs       <- controller outputs
    plant.doStep(t, h)

which is how ``dcsim run`` closes its loop (the command computed from the state at t is
held over the control period). Inputs that nothing feeds keep their start values.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.fmu.instance import FmuDescription, FmuError, FmuInstance

_BRACKETED_UNIT = re.compile(r"\[([^\[\]]+)\]\s*$")
"""A unit at the end of a variable's description, as dcsim's FMUs write it: ``[N.m]``."""


@dataclass(frozen=True)
class Coupling:
    """Which outputs feed which inputs.

    Attributes
    ----------
    to_controller : tuple of str
        Names that are both a plant output and a controller input.
    to_plant : tuple of str
        Names that are both a controller output and a plant input.
    unfed : tuple of str
        Controller and plant inputs that nothing feeds (``controller:NAME``, ``plant:NAME``).
    """

    to_controller: tuple[str, ...]
    to_plant: tuple[str, ...]
    unfed: tuple[str, ...]


def couple(plant: FmuInstance, controller: FmuInstance) -> Coupling:
    """Connect equal names; raise if no signal goes either way.

    Returns
    -------
    Coupling
        The names connected each way and the inputs left unfed.

    Raises
    ------
    FmuError
        If no plant output feeds the controller, or no controller output the plant.
    """
    plant_in, plant_out = plant.description.names("input"), plant.description.names("output")
    ctrl_in, ctrl_out = (
        controller.description.names("input"),
        controller.description.names("output"),
    )
    to_controller = tuple(n for n in ctrl_in if n in plant_out)
    to_plant = tuple(n for n in plant_in if n in ctrl_out)
    if not to_controller or not to_plant:
        raise FmuError(
            f"{controller.path.name} and {plant.path.name} share no signal both ways: "
            f"plant outputs {', '.join(plant_out)}; controller inputs {', '.join(ctrl_in)}; "
            f"controller outputs {', '.join(ctrl_out)}; plant inputs {', '.join(plant_in)}"
        )
    unfed = tuple(f"controller:{n}" for n in ctrl_in if n not in to_controller) + tuple(
        f"plant:{n}" for n in plant_in if n not in to_plant
    )
    return Coupling(to_controller, to_plant, unfed)


def cosimulate(
    plant_path: str | Path,
    controller_path: str | Path,
    stop_time: float,
    step_size: float,
    start_values: Mapping[str, Mapping[str, float]] | None = None,
    progress: Callable[[float], None] | None = None,
) -> tuple[dict[str, np.ndarray], Coupling]:
    """Run a plant FMU and a controller FMU together from 0 to ``stop_time``.

    Parameters
    ----------
    plant_path, controller_path : str or Path
        The two FMI 2.0 co-simulation FMUs.
    stop_time : float
        End time, s.
    step_size : float
        Communication step, s.
    start_values : mapping, optional
        ``{"plant": {name: value}, "controller": {name: value}}``: parameters and input
        start values set before initialisation.
    progress : callable, optional
        Called with the simulated time after each step.

    Returns
    -------
    results : dict of str to ndarray
        ``time`` and every output of both, as ``plant.NAME`` and ``controller.NAME``.
    coupling : Coupling
        What was connected, and what was left to its start value.

    Raises
    ------
    FmuError
        If a file is not a usable FMU, the two share no signal, or the stop time is not
        a whole number of steps.
    FmuCallError
        If an FMU refuses a call (with what it logged).
    """
    if step_size <= 0 or stop_time <= 0:
        raise FmuError("stop time and step size must be positive")
    steps = round(stop_time / step_size)
    if steps < 1 or abs(steps * step_size - stop_time) > 1e-9 * stop_time:
        raise FmuError(f"stop time {stop_time:g} s is not a multiple of the step {step_size:g} s")
    start_values = start_values or {}
    with (
        FmuInstance(plant_path, "plant") as plant,
        FmuInstance(controller_path, "controller") as controller,
    ):
        coupling = couple(plant, controller)
        plant.initialise(start_values=start_values.get("plant", {}))
        controller.initialise(start_values=start_values.get("controller", {}))
        outputs = {
            "plant": plant.description.names("output"),
            "controller": controller.description.names("output"),
        }
        rows = [_sample(0.0, plant, controller, outputs)]
        for k in range(steps):
            t = k * step_size
            controller.set(plant.get(coupling.to_controller))
            controller.step(t, step_size)
            plant.set(controller.get(coupling.to_plant))
            plant.step(t, step_size)
            rows.append(_sample((k + 1) * step_size, plant, controller, outputs))
            if progress is not None:
                progress((k + 1) * step_size)
        plant.terminate()
        controller.terminate()
    columns = list(rows[0])
    return {c: np.array([row[c] for row in rows], dtype=float) for c in columns}, coupling


def _sample(
    time: float, plant: FmuInstance, controller: FmuInstance, outputs: dict[str, list[str]]
) -> dict[str, float]:
    row = {"time": time}
    for prefix, fmu in (("plant", plant), ("controller", controller)):
        row.update({f"{prefix}.{n}": float(v) for n, v in fmu.get(outputs[prefix]).items()})
    return row


def write_csv(results: dict[str, np.ndarray], path: Path) -> None:
    """Write the results as CSV, one column per signal, floats in round-trip form.

    Parameters
    ----------
    results : dict of str to ndarray
        ``time`` and the signals, as :func:`cosimulate` returns them.
    path : Path
        CSV file to write (its directory is created).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(results)
        writer.writerows(zip(*(values.tolist() for values in results.values()), strict=True))


def output_units(plant_path: str | Path, controller_path: str | Path) -> dict[str, str]:
    """The unit of each output of the two FMUs, by its column name in the results.

    A variable's unit is the one its model description declares, else one written in
    brackets at the end of its description (``[N]``, as dcsim's FMUs give it). A
    controller output without one takes the unit of the plant input it feeds.

    Parameters
    ----------
    plant_path, controller_path : str or Path
        The two FMUs, as given to :func:`cosimulate`.

    Returns
    -------
    dict of str to str
        ``plant.NAME`` and ``controller.NAME`` → unit; outputs without a known unit are
        left out.
    """
    plant, controller = FmuDescription(plant_path), FmuDescription(controller_path)
    fed = {name: _unit(plant.variables[name]) for name in plant.names("input")}
    units = {f"plant.{name}": _unit(plant.variables[name]) for name in plant.names("output")}
    for name in controller.names("output"):
        units[f"controller.{name}"] = _unit(controller.variables[name]) or fed.get(name, "")
    return {name: unit for name, unit in units.items() if unit}


def plot_panels(
    results: Mapping[str, np.ndarray], units: Mapping[str, str]
) -> list[tuple[str, str, list[str]]]:
    """The panels of :func:`plot`: plant position and velocity, controller outputs by unit.

    Parameters
    ----------
    results : mapping of str to ndarray
        ``time`` and the signals, as :func:`cosimulate` returns them.
    units : mapping of str to str
        Unit of each signal (:func:`output_units`).

    Returns
    -------
    list of (str, str, list of str)
        Per panel: its axis label (with the unit), the prefix left out of the legend,
        and the columns drawn.
    """
    plant = [("plant position, m", "plant.position."), ("plant velocity, m/s", "plant.velocity.")]
    panels = [
        (label, prefix, [n for n in results if n.startswith(prefix)]) for label, prefix in plant
    ]
    controller = [name for name in results if name.startswith("controller.")]
    for unit in dict.fromkeys(units.get(name, "") for name in controller):
        label = f"controller outputs, {unit}" if unit else "controller outputs (no unit given)"
        panels.append((label, "controller.", [n for n in controller if units.get(n, "") == unit]))
    return panels


def _unit(variable: Any) -> str:
    """An fmpy variable's unit, declared or bracketed in its description; "" if none."""
    if variable.unit:
        return str(variable.unit)
    found = _BRACKETED_UNIT.search(variable.description or "")
    return found.group(1) if found else ""


def plot(
    results: dict[str, np.ndarray], path: Path, units: Mapping[str, str] | None = None
) -> None:
    """Plant position and velocity, and the controller's outputs by unit, against time.

    Parameters
    ----------
    results : dict of str to ndarray
        ``time`` and the signals, as :func:`cosimulate` returns them.
    path : Path
        Image file to write (PNG).
    units : mapping of str to str, optional
        Unit of each signal (:func:`output_units`); the controller's outputs get one
        panel per unit, those without a unit one of their own.
    """
    from dcsim.bench.figures import pyplot, save

    plt = pyplot()
    panels = plot_panels(results, units or {})
    figure, axes = plt.subplots(len(panels), 1, figsize=(8, 2.7 * len(panels)), sharex=True)
    for axis, (label, prefix, names) in zip(axes, panels, strict=True):
        for name in names:
            axis.plot(results["time"], results[name], label=name.removeprefix(prefix))
        axis.set_ylabel(label)
        axis.grid(alpha=0.3)
        if axis.lines:
            axis.legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("time, s")
    save(figure, path)
