"""FMI 2.0 co-simulation slaves (pythonfmu) over dcsim's runner and world.

An exported FMU carries a tiny script defining a subclass of :class:`ClosedLoopSlave` or
:class:`PlantSlave`, and the resolved scenario as the resource ``scenario.yaml``. The
slaves are thin adapters: the closed-loop one drives the :class:`~dcsim.run.loop.Runner`
that ``dcsim run`` uses, the plant one a :class:`~dcsim.world.World`. A slave declares
its variables when it is instantiated, from that scenario (:mod:`dcsim.fmu.variables`):
a manipulator's joints are variables of its FMUs.

Time. The world advances in whole control periods (``world.control_period``). A
``doStep`` from ``t`` to ``t + h`` flies every control period that ends at or before
``t + h``; outputs are the state at the last period boundary reached. With ``h`` a
multiple of the period the FMU is exact; otherwise it samples and holds (a step shorter
than the period may advance nothing), and a warning is logged once.

Errors. A NaN or infinite input is refused: the setter logs an error naming the
variable, and every ``doStep`` returns ``fmi2Discard`` (the state left as it was) until
a finite value is set. Parameters that make the scenario invalid, and a failure while
stepping (a plugin raising in the closed loop), are logged as errors and every later
``doStep`` returns ``fmi2Discard``. No Python exception leaves a slave (see
:meth:`_ScenarioSlave._guard`).
"""

from __future__ import annotations

import ctypes
import gc
import math
from pathlib import Path
from typing import Any

import numpy as np
from pythonfmu import Boolean, DefaultExperiment, Fmi2Causality, Fmi2Slave, Integer, Real
from pythonfmu.enums import Fmi2Initial, Fmi2Status, Fmi2Variability

from dcsim.fmu.native import release_own_library
from dcsim.fmu.variables import (
    AXES,
    DEFAULT_BEACONS,
    JOINT_ANGLE,
    JOINT_RATE,
    JOINT_TORQUE,
    QUATERNION,
    THRUSTER_DUTY,
    THRUSTER_ON_TIME,
    THRUSTERS_DIRECT,
    WHEEL_MOMENTUM,
    WHEEL_TORQUE,
    WHEELS_DIRECT,
    FmuVariable,
    closed_loop_variables,
    joint_count,
    plant_variables,
)
from dcsim.messages import RobotState
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import setup_run
from dcsim.scenario import Scenario, read_scenario
from dcsim.scenario.model import ManipulatorSection, point_to_cartesian, robot_hardware
from dcsim.world import World, WorldInputs

SCENARIO_RESOURCE = "scenario.yaml"
"""Name of the resolved scenario among an FMU's resources."""


def keep_namespace(namespace: dict[str, Any]) -> None:
    """Give an FMU slave module's namespace one reference that is never released.

    pythonfmu 0.7 runs the slave module's source again at every ``fmi2Instantiate`` and
    then releases a reference to the module's namespace that it does not own (a
    ``Py_DECREF`` of the borrowed ``PyModule_GetDict``). A slave module calls this at
    its top level, which those runs execute too: each run adds the reference that
    instantiation takes back, and the import's run one more, so the namespace outlives
    every instance and the interpreter.

    The reference must be one nothing gives back. Kept in a Python container, it is
    released again when the interpreter clears modules at exit, and the namespace is
    then released once per instantiation more than it was referenced: the last releases
    write to a freed dict.
    """
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(namespace))


class _RunFailed(Exception):
    """The closed-loop run failed (a plugin or a hook raised); the message says how."""


_RUN_STATUS = {None: 0, "completed": 1, "stopped": 2, "failed": 3}
_FMI_TYPES = {float: Real, int: Integer, bool: Boolean}


class _ScenarioSlave(Fmi2Slave):
    """What both slaves share: the scenario, parameters, inputs and stepping in periods.

    Subclasses implement ``_declare`` (their variables for the scenario), ``_open``,
    ``_advance``, ``_world``, ``_outputs`` and ``_close``.

    Attributes
    ----------
    scenario : Scenario
        The resolved scenario the FMU carries.
    variables : list of FmuVariable
        The FMU's variables, declared from :attr:`scenario`.
    values : dict of str to object
        Every variable's current value, by name.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        release_own_library(self.resources, self.modelName)  # see dcsim.fmu.native
        self.scenario_path = Path(self.resources) / SCENARIO_RESOURCE
        self.scenario: Scenario = read_scenario(self.scenario_path)
        self.variables: list[FmuVariable] = self._declare()
        self._joints = joint_count(self.scenario.robot)
        self.author = "dcsim"
        self.description = f"dcsim scenario {self.scenario.name!r}: {self.scenario.description}"
        self.default_experiment = DefaultExperiment(
            start_time=0.0,
            stop_time=self.scenario.world.duration,
            step_size=self.scenario.world.control_period,
        )
        self.values: dict[str, Any] = self._initial_values()
        self._refused: dict[str, float] = {}
        self._start_time = 0.0
        self._periods = 0
        self._period = self.scenario.world.control_period
        self._warned_step = False
        self._open_now = False
        self._failure: str | None = None
        for variable in self.variables:
            self.register_variable(self._fmi_variable(variable))

    # ------------------------------------------------------------------ variables
    def _declare(self) -> list[FmuVariable]:
        """The FMU's variables for :attr:`scenario`."""
        raise NotImplementedError

    def _initial_values(self) -> dict[str, Any]:
        """Start values: parameters from the scenario, the state at t = 0, zeros."""
        values: dict[str, Any] = {v.name: v.type(0) for v in self.variables}
        values["seed"] = self.scenario.world.seed
        robot = self.scenario.robot
        for variable in self.variables:
            if variable.causality == "parameter" and variable.name.startswith("robot."):
                values[variable.name] = float(getattr(robot, variable.name.removeprefix("robot.")))
        state = _initial_state(self.scenario)
        end_effector = None
        if isinstance(robot, ManipulatorSection):
            model = ManipulatorModel(robot.dh_robot())
            end_effector = model.forward_kinematics(state.configuration).end_effector
        self._put_state(values, state, end_effector)
        return values

    def _put_state(
        self, values: dict[str, Any], state: RobotState, end_effector: np.ndarray | None
    ) -> None:
        """Put the base's state, and a manipulator's joints and end effector, into ``values``."""
        self._put_vector(values, "position", state.position)
        self._put_vector(values, "velocity", state.velocity)
        self._put_vector(values, "attitude", state.attitude)
        self._put_vector(values, "angular_velocity", state.angular_velocity)
        for i in range(1, self._joints + 1):
            values[JOINT_ANGLE.format(i)] = float(state.joint_positions[i - 1])
            values[JOINT_RATE.format(i)] = float(state.joint_velocities[i - 1])
        if end_effector is not None:
            self._put_vector(values, "end_effector", end_effector)

    @staticmethod
    def _put_vector(values: dict[str, Any], name: str, vector: np.ndarray) -> None:
        for axis, value in zip(QUATERNION, vector, strict=False):  # x, y, z (and w)
            values[f"{name}.{axis}"] = float(value)

    def _vector(self, name: str) -> np.ndarray:
        return np.array([self.values[f"{name}.{axis}"] for axis in AXES])

    def _joint_torques(self) -> np.ndarray:
        """The joint torque inputs, DH order, N·m ((0,) for a free flyer)."""
        return np.array([self.values[JOINT_TORQUE.format(i)] for i in range(1, self._joints + 1)])

    def _fmi_variable(self, variable: FmuVariable) -> Any:
        cls = _FMI_TYPES[variable.type]
        name = variable.name
        unit = f" [{variable.unit}]" if variable.unit else ""
        description = f"{variable.description}{unit}"
        getter = lambda: self.values[name]  # noqa: E731
        if variable.causality == "output":
            variability = Fmi2Variability.continuous if cls is Real else Fmi2Variability.discrete
            return cls(
                name,
                causality=Fmi2Causality.output,
                variability=variability,
                initial=Fmi2Initial.exact,
                description=description,
                getter=getter,
            )
        if variable.causality == "parameter":
            return cls(
                name,
                causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed,
                description=description,
                getter=getter,
                setter=lambda value: self._set_parameter(name, value),
            )
        return cls(
            name,
            causality=Fmi2Causality.input,
            variability=Fmi2Variability.continuous if cls is Real else Fmi2Variability.discrete,
            description=description,
            getter=getter,
            setter=lambda value: self._set_input(variable, value),
        )

    def _set_parameter(self, name: str, value: Any) -> None:
        if self._open_now:
            self.log(f"parameter {name} cannot change after initialisation", Fmi2Status.error)
            return
        self.values[name] = value

    def _set_input(self, variable: FmuVariable, value: float | bool) -> None:
        name = variable.name
        if not math.isfinite(value):
            self._refused[name] = value
            self.log(f"input {name} = {value} refused: inputs must be finite", Fmi2Status.error)
            return
        self._refused.pop(name, None)
        self.values[name] = variable.type(value)

    def _overrides(self) -> list[str]:
        """The parameters as scenario overrides (each parameter name is a scenario key)."""
        return [
            f"{v.name}={self.values[v.name]!r}"
            for v in self.variables
            if v.causality == "parameter" and v.name != "seed"
        ]

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(
        self, start_time: float, stop_time: float | None, tolerance: float | None
    ) -> None:
        """Remember the start time (the scenario's clock starts at 0 there)."""
        self._start_time = start_time

    def exit_initialization_mode(self) -> None:
        """Parameters are final: build the world (and the run) and publish t = 0."""
        gc.collect()  # a reset drops the previous slave in a reference cycle
        self._periods = 0
        self._failure = self._guard(self._start, "cannot start")

    def _start(self) -> None:
        self._open()
        self._open_now = True
        self._healthy()
        self._publish()

    def do_step(self, current_time: float, step_size: float) -> bool:
        """Fly the control periods that end within the step; False refuses the step."""
        if self._failure is not None:
            self.log(f"step refused: {self._failure}", Fmi2Status.error)
            return False
        if self._refused:
            names = ", ".join(f"{n} = {v}" for n, v in self._refused.items())
            self.log(f"step refused: non-finite input {names}", Fmi2Status.error)
            return False
        periods = (current_time + step_size - self._start_time) / self._period
        target = math.floor(periods + 1e-6)
        if abs(periods - round(periods)) > 1e-6 and not self._warned_step:
            self._warned_step = True
            self.log(
                f"communication step {step_size:g} s is not a multiple of the control period "
                f"{self._period:g} s: outputs hold the last period boundary",
                Fmi2Status.warning,
            )
        if target < self._periods:
            self.log(f"cannot step back to t = {current_time + step_size:g} s", Fmi2Status.error)
            return False
        self._failure = self._guard(lambda: self._fly(target), "step failed")
        return self._failure is None

    def _fly(self, periods: int) -> None:
        while self._periods < periods:
            self._advance()
            self._periods += 1
        self._healthy()
        self._publish()

    def terminate(self) -> None:
        """Close the world."""
        if self._open_now:
            self._open_now = False
            self._guard(self._close, "cannot close")

    def _guard(self, call: Any, what: str) -> str | None:
        """Call ``call``; log and return the reason if it raises, else None.

        No exception may leave a slave: pythonfmu 0.7 answers one with ``fmi2Fatal`` and
        releases the slave's Python objects twice when the instance is freed afterwards,
        which crashes the importing process.
        """
        try:
            call()
        except Exception as error:
            kind = "run failed" if isinstance(error, _RunFailed) else type(error).__name__
            reason = f"{what}: {kind}: {error}"
            self.log(reason, Fmi2Status.error)
            return reason
        return None

    def _publish(self) -> None:
        """Copy the current outputs into the FMU's variables."""
        values, out, world = self.values, self._outputs(), self._world()
        end_effector = world.end_effector() if self._joints else None
        self._put_state(values, world.robot_state(), end_effector)
        values["collisions"] = int(out["collisions"])
        values["fuel_used"] = float(out["fuel_used"])
        values["delta_v"] = float(out["delta_v"])
        for i, momentum in enumerate(out.get("wheel_momentum", ()), 1):
            values[WHEEL_MOMENTUM.format(i)] = float(momentum)
        for i, duty in enumerate(out.get("thruster_duty", ()), 1):
            values[THRUSTER_DUTY.format(i)] = float(duty)
        if "attitude_fuel_used" in values:  # a robot with thrusters
            values["attitude_fuel_used"] = world.attitude_fuel_used
        self._publish_more(out)

    def _publish_more(self, out: dict[str, Any]) -> None:
        """Outputs only one kind of slave has."""

    def _healthy(self) -> None:
        """Raise :class:`_RunFailed` (caught by :meth:`_guard`) if the model has failed."""

    def _open(self) -> None:
        raise NotImplementedError

    def _advance(self) -> None:
        raise NotImplementedError

    def _world(self) -> World:
        raise NotImplementedError

    def _outputs(self) -> dict[str, Any]:
        raise NotImplementedError

    def _close(self) -> None:
        raise NotImplementedError


class ClosedLoopSlave(_ScenarioSlave):
    """The whole scenario (world, localiser, planners, controller, mission) as an FMU.

    Each control period is one :meth:`Runner.advance` with the disturbance inputs; the
    outputs at a period boundary equal the telemetry row ``dcsim run`` records there.
    """

    def _declare(self) -> list[FmuVariable]:
        return closed_loop_variables(self.scenario)

    def _open(self) -> None:
        setup = setup_run(self.scenario_path, self._overrides(), seed=self.values["seed"])
        self.runner = Runner(setup, keep_rows=False)
        self.runner.open()

    def _advance(self) -> None:
        self.runner.advance(self._vector("disturbance_force"), self._vector("disturbance_torque"))

    def _world(self) -> World:
        world = self.runner.world
        assert world is not None  # the run is opened before the slave is stepped
        return world

    def _outputs(self) -> dict[str, Any]:
        return self.runner.outputs

    def _publish_more(self, out: dict[str, Any]) -> None:
        runner, values = self.runner, self.values
        values["mode"] = runner.mission_class.modes.index(runner.mode)
        if "captured" in values:  # a robot that carries targets
            values["captured"] = int(out["captured"])
            values["delivered"] = int(out["delivered"])
        estimate = runner.estimate
        assert estimate is not None  # every decided control period makes one
        values["localisation_error"] = float(np.linalg.norm(out["position"] - estimate.position))
        values["run_status"] = _RUN_STATUS[runner.status]
        if "attitude_error" in values and "attitude_error" in out:  # hardware, run going on
            values["attitude_error"] = float(out["attitude_error"])

    def _healthy(self) -> None:
        if self.runner.status == "failed":
            self.values["run_status"] = _RUN_STATUS["failed"]
            raise _RunFailed(self.runner.reason)

    def _close(self) -> None:
        self.runner.close()


class PlantSlave(_ScenarioSlave):
    """The world alone as an FMU: force and torque (and a manipulator's joint torques, the
    base's thruster on-times and wheel torques) in, true state and sensors out.

    The on-times replace the allocation of force (and of torque without wheels) while
    ``thrusters_direct`` is true, the wheel torques that of torque while
    ``wheels_direct`` is; otherwise they are not used, and a non-zero one is warned of
    once.

    Attributes
    ----------
    nearest_beacons : int
        K, how many nearest beacons' ranges are output (a class attribute set at export).
    """

    nearest_beacons = DEFAULT_BEACONS

    def _declare(self) -> list[FmuVariable]:
        return plant_variables(self.scenario, self.nearest_beacons)

    def _initial_values(self) -> dict[str, Any]:
        values = super()._initial_values()
        robot = self.scenario.robot
        arm = robot.links if isinstance(robot, ManipulatorSection) else []
        values["mass"] = float(robot.mass) + sum(link.mass for link in arm)
        for k in range(1, self.nearest_beacons + 1):
            values[f"beacon[{k}].id"] = -1
        return values

    def _open(self) -> None:
        scenario = read_scenario(
            self.scenario_path, [*self._overrides(), f"world.seed={self.values['seed']}"]
        )
        self.world = World(scenario, component_rng(scenario.world.seed, "world"))
        self._collided = False
        self._ignored: set[str] = set()
        thrusters, wheels = robot_hardware(scenario.robot)
        self._thrusters, self._wheels = len(thrusters), len(wheels)

    def _advance(self) -> None:
        inputs = WorldInputs(
            force=self._vector("force"),
            torque=self._vector("torque"),
            joint_torques=self._joint_torques(),
            thruster_on_times=self._direct(THRUSTERS_DIRECT, THRUSTER_ON_TIME, self._thrusters),
            wheel_torques=self._direct(WHEELS_DIRECT, WHEEL_TORQUE, self._wheels),
        )
        self._collided |= bool(self.world.step(inputs))

    def _direct(self, switch: str, name: str, count: int) -> np.ndarray:
        """The ``count`` inputs ``name.format(i)`` while the Boolean input ``switch`` is
        true, else none (the world allocates); non-zero ones unused are warned of once."""
        given = np.array([self.values[name.format(i)] for i in range(1, count + 1)])
        if count and self.values[switch]:
            return given
        if given.any() and switch not in self._ignored:
            self._ignored.add(switch)
            self.log(
                f"{name.format('i')} inputs are not used while {switch} is false: set "
                f"{switch} to true to fly them",
                Fmi2Status.warning,
            )
        return np.zeros(0)

    def _world(self) -> World:
        return self.world

    def _outputs(self) -> dict[str, Any]:
        return self.world.outputs()

    def do_step(self, current_time: float, step_size: float) -> bool:
        """Step as the base class does; the collision flag covers this step only."""
        self._collided = False
        return super().do_step(current_time, step_size)

    def _publish_more(self, out: dict[str, Any]) -> None:
        world, values = self.world, self.values
        values["mass"] = float(out["mass"])
        values["nearest_obstacle"] = float(out["nearest_obstacle_distance"])
        values["tracked"] = len(world.object_tracks())
        values["collision"] = self._collided
        ranges = sorted(world.beacon_ranges(), key=lambda r: r.range)
        for k in range(1, self.nearest_beacons + 1):
            found = ranges[k - 1] if k <= len(ranges) else None
            values[f"beacon[{k}].id"] = found.beacon_id if found else -1
            values[f"beacon[{k}].range"] = found.range if found else 0.0

    def _close(self) -> None:
        self.world.close()


def _initial_state(scenario: Scenario) -> RobotState:
    """The robot's true state at t = 0 as the scenario gives it (base and joints)."""
    robot = scenario.robot
    initial = robot.initial
    attitude = np.asarray(initial.attitude, dtype=float)
    if isinstance(robot, ManipulatorSection):
        angles, rates = robot.initial_joints()
    else:
        angles = rates = np.zeros(0)
    return RobotState(
        position=point_to_cartesian(initial.position),
        velocity=np.array(initial.velocity),
        attitude=attitude / np.linalg.norm(attitude),
        angular_velocity=np.array(initial.angular_velocity),
        joint_positions=angles,
        joint_velocities=rates,
    )
