"""``fmu`` controller: any FMI 2.0 co-simulation FMU as the collector's controller.

The FMU runs in-process through fmpy. Every control period the controller sets the
FMU's mapped inputs from dcsim's signals at time ``t``, steps it from ``t`` over
``step_size`` (which must be the scenario's control period) and reads the force (and
torque) it outputs after the step: the command held over the coming period.

Signals a mapping can take (world frame, SI units):

- ``time`` (s);
- ``position.x|y|z`` (m), ``velocity.x|y|z`` (m/s): the localiser's estimate;
- ``reference.position.x|y|z``, ``reference.velocity.x|y|z``,
  ``reference.acceleration.x|y|z``: where the mission wants the collector;
- ``speed_limit`` (m/s): the robot's speed limit, or the leg's lower one;
- ``mass`` (kg), ``max_force`` (N), ``max_torque`` (N·m), ``radius`` (m): the robot now
  (mass and radius change with cargo);
- ``obstacles``: obstacles tracked; ``nearest_gap`` (m): the smallest surface gap from
  the estimate to a tracked obstacle (1e12 when none is tracked);
  ``safety_distance`` (m).

Command components an FMU output can give: ``force.x|y|z`` (N), ``torque.x|y|z`` (N·m);
those not mapped are zero, and the command is clipped to the robot's force and torque
limits. A call earlier than the start of the last step (a new run) resets the FMU and
initialises it again.

Mappings. ``inputs`` maps FMU input names to signal names and ``outputs`` maps command
components to FMU output names. Left empty, they connect by equal names (an FMU with an
input ``position.x`` gets the estimate's x). Both are checked against the FMU's model
description when the scenario is loaded: an unknown variable, an input that is not an
input, an output that is not an output or a variable that is not a Real is an error
naming it.
"""

from __future__ import annotations

import weakref

import numpy as np
from pydantic import model_validator

from dcsim.api import (
    Command,
    Controller,
    FmuDescription,
    FmuError,
    FmuInstance,
    PluginParams,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    clip_norm,
    hookimpl,
    quantity,
)

AXES = ("x", "y", "z")
SIGNALS = (
    "time",
    *(f"{v}.{a}" for v in ("position", "velocity") for a in AXES),
    *(f"reference.{v}.{a}" for v in ("position", "velocity", "acceleration") for a in AXES),
    "speed_limit",
    "mass",
    "max_force",
    "max_torque",
    "radius",
    "obstacles",
    "nearest_gap",
    "safety_distance",
)
"""Names of the dcsim signals an FMU input can be mapped to."""

COMMANDS = tuple(f"{v}.{a}" for v in ("force", "torque") for a in AXES)
"""Command components an FMU output can be mapped to."""

NO_OBSTACLE_GAP = 1e12
"""``nearest_gap`` when no obstacle is tracked, m (FMUs need finite inputs)."""


class FmuControllerParams(PluginParams):
    """Parameters of :class:`FmuController`."""

    path: str = quantity(
        description="The FMI 2.0 co-simulation FMU (path relative to the working directory)."
    )
    inputs: dict[str, str] = quantity(
        default_factory=dict,
        description="FMU input name -> dcsim signal; empty: inputs named like a signal.",
    )
    outputs: dict[str, str] = quantity(
        default_factory=dict,
        description="Command component (force.x ... torque.z) -> FMU output; empty: same names.",
    )
    parameters: dict[str, float] = quantity(
        default_factory=dict, description="FMU parameter name -> value, set before it starts."
    )
    step_size: float = quantity(
        0.1, unit="s", gt=0, description="Communication step: the scenario's control period."
    )

    @model_validator(mode="after")
    def _matches_the_fmu(self) -> FmuControllerParams:
        try:
            connect(FmuDescription(self.path), self)
        except FmuError as error:
            raise ValueError(str(error)) from None
        return self


def connect(
    description: FmuDescription, params: FmuControllerParams
) -> tuple[dict[str, str], dict[str, str]]:
    """Resolve and check the mappings against the FMU's model description.

    Returns
    -------
    inputs, outputs : dict of str to str
        FMU input -> signal, and command component -> FMU output.

    Raises
    ------
    FmuError
        Naming the first variable or signal that does not fit.
    """
    inputs = params.inputs or {n: n for n in description.names("input") if n in SIGNALS}
    outputs = params.outputs or {n: n for n in COMMANDS if n in description.names("output")}
    for fmu_input, signal in inputs.items():
        if signal not in SIGNALS:
            raise FmuError(f"unknown dcsim signal {signal!r}; signals: {', '.join(SIGNALS)}")
        description.variable(fmu_input, ("input",), ("Real",))
    for component, fmu_output in outputs.items():
        if component not in COMMANDS:
            raise FmuError(f"unknown command component {component!r}; use {', '.join(COMMANDS)}")
        description.variable(fmu_output, ("output",), ("Real",))
    for name in params.parameters:
        description.variable(name, ("parameter",), ("Real",))
    if not outputs:
        raise FmuError(f"{description.path.name} gives no command: map an output to force.x etc.")
    return inputs, outputs


def signals(
    time: float,
    estimate: StateEstimate,
    reference: Reference,
    surroundings: Surroundings,
    robot: RobotSpec,
) -> dict[str, float]:
    """The value of every signal in :data:`SIGNALS` now."""
    values = {"time": time}
    vectors = {
        "position": estimate.position,
        "velocity": estimate.velocity,
        "reference.position": reference.position,
        "reference.velocity": reference.velocity,
        "reference.acceleration": reference.acceleration,
    }
    for name, vector in vectors.items():
        values.update({f"{name}.{a}": float(v) for a, v in zip(AXES, vector, strict=True)})
    obstacles = surroundings.obstacles
    centres = np.array([track.position for track in obstacles]).reshape(-1, 3)
    radii = np.array([track.radius for track in obstacles])
    gaps = np.linalg.norm(centres - estimate.position, axis=1) - radii - robot.radius
    values.update(
        speed_limit=min(robot.max_speed, reference.max_speed),
        mass=robot.mass,
        max_force=robot.max_force,
        max_torque=robot.max_torque,
        radius=robot.radius,
        obstacles=float(len(obstacles)),
        nearest_gap=float(gaps.min()) if len(gaps) else NO_OBSTACLE_GAP,
        safety_distance=surroundings.safety_distance,
    )
    return values


class FmuController(Controller):
    """Runs an FMI 2.0 co-simulation FMU as the controller (through fmpy)."""

    name = "fmu"
    summary = "Any FMI 2.0 co-simulation FMU as the controller (fmpy), mapped by name"
    Params = FmuControllerParams
    params: FmuControllerParams

    def reset(self, robot: RobotSpec) -> None:
        """Start the FMU at the first reset; later resets (cargo changed) update the robot."""
        self.robot = robot
        if getattr(self, "fmu", None) is not None:
            return
        self.fmu = FmuInstance(self.params.path, instance_name=f"dcsim-{self.name}")
        weakref.finalize(self, self.fmu.close)
        self.inputs, self.outputs = connect(self.fmu.description, self.params)
        self.fmu.initialise(start_values=self.params.parameters)
        self.next_time: float | None = None

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Set the FMU's inputs, step it over one control period, read the command.

        The FMU's force and torque are clipped to the robot's limits. A time earlier than
        the last step's start begins a new run: the FMU is reset and initialised again.
        """
        step = self.params.step_size
        if self.next_time is not None and time < self.next_time - step * (1 + 1e-6):
            self.fmu.reset()  # earlier than the last step's start: a new run
            self.fmu.initialise(start_values=self.params.parameters)
        elif self.next_time is not None and abs(time - self.next_time) > 1e-6 * step:
            raise FmuError(
                f"called at t = {time:g} s, expected {self.next_time:g} s: set step_size "
                f"to the scenario's control period"
            )
        now = signals(time, estimate, reference, surroundings, self.robot)
        self.fmu.set({fmu_input: now[signal] for fmu_input, signal in self.inputs.items()})
        self.fmu.step(time, step)
        self.next_time = time + step
        values = self.fmu.get(self.outputs.values())
        command = {c: values[name] for c, name in self.outputs.items()}
        return Command(
            force=clip_norm([command.get(f"force.{a}", 0.0) for a in AXES], self.robot.max_force),
            torque=clip_norm(
                [command.get(f"torque.{a}", 0.0) for a in AXES], self.robot.max_torque
            ),
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the FMU controller."""
    return [FmuController]
