"""The peer side of ``dcsim bench peers``: the same closed loop built from Basilisk modules.

Basilisk (``pip install bsk``, the ``peers`` extra) is optional: :func:`basilisk_missing`
says why it cannot be used, and nothing here imports it before :func:`fly_basilisk`.
Its ``unitTestSupport`` module imports pytest and is not used.

The loop, in two tasks of one process:

- **dynamics task** (every ``dynamics_step``, runs first at shared times): the rigid
  hub (``spacecraft.Spacecraft``: mass, inertia about its centre of mass, no gravity
  body, Basilisk's default RK4 integrator);
- **flight-software task** (every control period): ``simpleNav`` (no noise: the true
  attitude, rate, position and velocity), ``inertial3D`` (the fixed inertial attitude),
  ``attTrackingError``, ``mrpFeedback`` (no integral term; ``controlLawType = 1``,
  which compensates ``ω × Iω`` as dcsim's ``pd`` does), optionally
  ``hillFrameRelativeControl`` (the position hold, see below), then
  ``extForceTorque``, which reads the commands once per period; the hub applies them
  over every dynamics step of the period (a zero-order hold, as dcsim's world does).

Reaction wheels (optional) replace ``extForceTorque``'s torque: ``rwMotorTorque``
shares ``mrpFeedback``'s torque among the wheels by the minimum-norm inverse (as
dcsim's wheels do), and a ``reactionWheelStateEffector`` of balanced wheels (built by
``simIncludeRW.rwFactory``, type ``custom``) reads those torques once per period, in the
flight-software task after ``rwMotorTorque``, and holds them over the period; the hub
integrates the wheels' speeds with its own state. ``mrpFeedback`` is not given the
wheels' speeds, so its law leaves their momentum out of the gyroscopic term, as
``pd``'s does.

Thrusters (optional, instead of wheels) replace it likewise: ``thrForceMapping``
(``thrForceSign = +1``, all three body axes, its second pass on: the torque shared
again among the thrusters the first pass fired) gives each thruster a force,
``thrFiringRemainder`` (no minimum firing time) the on-time ``T f / F_max``, and a
``thrusterDynamicEffector`` of thrusters built by ``simIncludeThruster.thrusterFactory``
(``Blank_Thruster``, no minimum on-time) reads the on-times once per period, in the
flight-software task, and fires each from the period's start. Two behaviours of these
modules make the thruster loop differ from dcsim's: ``thrFiringRemainder`` commands
nothing at its first two calls (it takes a previous call time of 0 for "no previous
call"), so the thrusters first fire at the third period; and the effector switches a
thruster on or off at the integrator's stage times, so an on-time ending inside a
dynamics step is rounded to the step's RK4 stages (dcsim's PWM gives a partly covered
physics step the covered fraction).

Balanced wheels in Basilisk belong to the hub: its inertia includes theirs, and a
wheel's state is its speed Ω relative to the hub, its momentum about its axis
``Js (Ω + ĝ·ω)``. dcsim's wheels carry that momentum ``h`` (:mod:`dcsim.world.wheels`)
with a base whose inertia leaves out the wheels' inertia about their spin axes. The
same spacecraft is therefore a hub of inertia ``I + Σ Js ĝ ĝᵀ`` here (``I`` dcsim's),
its wheels starting at ``Ω = −ĝ·ω`` (dcsim's start at ``h = 0``); both sides then fly
``I ω̇ = −Σ ĝ u − ω × (I ω + Σ ĝ h)``, ``ḣ = u``.

Position hold: Basilisk's translational feedback module, ``hillFrameRelativeControl``,
is a PD on the position relative to a chief spacecraft in the chief's Hill frame, with
relative-orbit feed-forward. The chief here is the hold point as a constant
navigation message (at ``HOLD_POINT``, moving at ``CHIEF_SPEED`` along +y so that its
Hill frame is defined and equal to the inertial axes), with ``μ`` and the chief's
orbital rate so small that the feed-forward terms vanish (below 1e-12 m/s²) and the
reference velocity cancelling the chief's: the module's law is then
``F = −m (K e + P ė)`` in inertial axes.
"""

from __future__ import annotations

import importlib.util
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcsim.geometry import rotate

HOLD_POINT = (1.0e3, 0.0, 0.0)
"""Where the Basilisk spacecraft starts and holds, inertial frame, m (off the origin
only so that the chief's Hill frame is defined; no gravity acts; near enough that
positions keep 1e-13 m of resolution)."""

CHIEF_SPEED = 1.0e-9
"""Speed of the constant chief message along +y, m/s (its orbital rate, 1e-12 rad/s,
only orients the Hill frame)."""

CHIEF_MU = 1.0e-9
"""Gravitational parameter given to ``hillFrameRelativeControl``, m³/s² (it must be
positive; μ/R³ = 1e-18 s⁻² makes its gravity feed-forward vanish)."""

_NANO = 1_000_000_000


@dataclass(frozen=True)
class WheelSetup:
    """Identical reaction wheels, SI units, body frame.

    Attributes
    ----------
    axes : ndarray (3, N)
        Unit spin axes as columns.
    inertia : float
        Each wheel's moment of inertia about its spin axis, kg·m².
    max_torque : float
        Each wheel's largest motor torque, N·m.
    max_momentum : float
        Each wheel's largest momentum about its axis, N·m·s (Basilisk's speed limit
        ``max_momentum / inertia``).
    """

    axes: np.ndarray
    inertia: float
    max_torque: float
    max_momentum: float


@dataclass(frozen=True)
class ThrusterSetup:
    """Identical thrusters, SI units, body frame.

    Attributes
    ----------
    positions : ndarray (N, 3)
        Where each thruster sits relative to the centre of mass, m.
    directions : ndarray (N, 3)
        The unit direction of each thruster's force on the hub.
    max_thrust : float
        Each thruster's thrust when on, N.
    """

    positions: np.ndarray
    directions: np.ndarray
    max_thrust: float


@dataclass(frozen=True)
class BasiliskSetup:
    """What the Basilisk loop flies, in SI units.

    Attributes
    ----------
    mass : float
        Hub mass, kg.
    inertia : ndarray (3, 3)
        Hub inertia about its centre of mass, body frame, kg·m².
    attitude : ndarray (4,)
        Initial attitude ``[x, y, z, w]``, body to inertial.
    angular_velocity : ndarray (3,)
        Initial angular velocity, inertial frame, rad/s.
    velocity : ndarray (3,)
        Initial velocity, inertial frame, m/s.
    goal_attitude : ndarray (4,)
        The inertial attitude to hold ``[x, y, z, w]``.
    mrp_gains : tuple of float
        ``mrpFeedback``'s K (N·m) and P (N·m·s).
    position_gains : tuple of float or None
        ``hillFrameRelativeControl``'s K (1/s²) and P (1/s), per unit mass, on each
        axis; None flies without position control.
    dynamics_step : float
        Period of the dynamics task, s.
    control_period : float
        Period of the flight-software task, s.
    duration : float
        Simulated time, s (a whole number of control periods).
    wheels : WheelSetup or None
        Reaction wheels giving the torque; None: ``extForceTorque`` gives it.
    thrusters : ThrusterSetup or None
        Thrusters giving the torque (not with wheels); None: ``extForceTorque`` gives it.
    """

    mass: float
    inertia: np.ndarray
    attitude: np.ndarray
    angular_velocity: np.ndarray
    velocity: np.ndarray
    goal_attitude: np.ndarray
    mrp_gains: tuple[float, float]
    position_gains: tuple[float, float] | None
    dynamics_step: float
    control_period: float
    duration: float
    wheels: WheelSetup | None = None
    thrusters: ThrusterSetup | None = None

    @property
    def ideal_torque(self) -> bool:
        """Whether ``extForceTorque`` gives the torque (no wheels, no thrusters)."""
        return self.wheels is None and self.thrusters is None


@dataclass(frozen=True)
class BasiliskFlight:
    """One Basilisk run: its wall time and its record at the control period.

    Attributes
    ----------
    wall : float
        Wall time from building the simulation to its end, s.
    cpu : float
        The process's CPU time over the same span, s.
    times : ndarray (N,)
        Sample times, s.
    attitudes : ndarray (N, 4)
        True attitude ``[x, y, z, w]``, body to inertial.
    positions : ndarray (N, 3)
        True position relative to :data:`HOLD_POINT`, inertial frame, m.
    torques : ndarray (N, 3)
        ``mrpFeedback``'s commanded torque, body frame, N·m.
    wheel_speeds : ndarray (N, wheels)
        Each wheel's momentum about its axis over its inertia, ``Ω + ĝ·ω``, rad/s
        (what dcsim reports as its wheels' speeds); no columns without wheels.
    """

    wall: float
    cpu: float
    times: np.ndarray
    attitudes: np.ndarray
    positions: np.ndarray
    torques: np.ndarray
    wheel_speeds: np.ndarray


def basilisk_missing() -> str | None:
    """Why Basilisk cannot be used here, or None when it is importable."""
    if importlib.util.find_spec("Basilisk") is None:
        return "Basilisk is not installed (pip install 'dcsim[peers]', or pip install bsk)"
    try:
        _modules()
    except Exception as error:  # a broken or incompatible install
        return f"Basilisk does not import: {type(error).__name__}: {error}"
    return None


def mrp_from_quaternion(quaternion: np.ndarray) -> np.ndarray:
    """Modified Rodrigues parameters of the same rotation, the short way round.

    Parameters
    ----------
    quaternion : ndarray (..., 4)
        ``[x, y, z, w]`` (PyBullet's order), body to inertial.

    Returns
    -------
    ndarray (..., 3)
        σ_BN with ``|σ| ≤ 1``.
    """
    q = np.asarray(quaternion, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    q = np.where(q[..., 3:] < 0.0, -q, q)
    return q[..., :3] / (1.0 + q[..., 3:])


def quaternion_from_mrp(sigma: np.ndarray) -> np.ndarray:
    """The unit quaternion ``[x, y, z, w]`` of modified Rodrigues parameters σ_BN (..., 3)."""
    sigma = np.asarray(sigma, dtype=float)
    squared = np.sum(sigma * sigma, axis=-1, keepdims=True)
    return np.concatenate([2.0 * sigma, 1.0 - squared], axis=-1) / (1.0 + squared)


def fly_basilisk(setup: BasiliskSetup) -> BasiliskFlight:
    """Build the Basilisk loop for ``setup``, fly it, and return its record.

    The wall time runs from creating the simulation to the end of its execution (module
    construction, message wiring, recorders, initialisation and the run); importing
    Basilisk is not in it.
    """
    m = _modules()
    began, cpu_began = time.perf_counter(), time.process_time()
    loop = _build(m, setup)
    loop.sim.InitializeSimulation()
    loop.sim.ConfigureStopTime(_nanos(setup.duration))
    loop.sim.ExecuteSimulation()
    wall, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    return BasiliskFlight(
        wall=wall,
        cpu=cpu,
        times=np.asarray(loop.states.times(), dtype=float) / _NANO,
        attitudes=quaternion_from_mrp(np.asarray(loop.states.sigma_BN)),
        positions=np.asarray(loop.states.r_BN_N) - np.asarray(HOLD_POINT),
        torques=np.asarray(loop.torques.torqueRequestBody),
        wheel_speeds=_wheel_speeds(loop, setup.wheels),
    )


def _wheel_speeds(loop: _Loop, wheels: WheelSetup | None) -> np.ndarray:
    """The recorded wheels' ``Ω + ĝ·ω``, rad/s (N, wheels)."""
    if wheels is None:
        return np.zeros((len(loop.states.times()), 0))
    count = wheels.axes.shape[1]
    relative = np.asarray(loop.speeds.wheelSpeeds)[:, :count]
    return relative + np.asarray(loop.states.omega_BN_B) @ wheels.axes


# ---------------------------------------------------------------------- building
@dataclass(frozen=True)
class _Modules:
    """The Basilisk modules the loop is built from (imported once)."""

    SimulationBaseClass: Any
    spacecraft: Any
    extForceTorque: Any
    simpleNav: Any
    inertial3D: Any
    attTrackingError: Any
    mrpFeedback: Any
    hillFrameRelativeControl: Any
    rwMotorTorque: Any
    reactionWheelStateEffector: Any
    simIncludeRW: Any
    thrForceMapping: Any
    thrFiringRemainder: Any
    thrusterDynamicEffector: Any
    simIncludeThruster: Any
    macros: Any
    messaging: Any


_CACHE: list[_Modules] = []


def _modules() -> _Modules:
    if not _CACHE:
        from Basilisk.architecture import messaging
        from Basilisk.fswAlgorithms import (
            attTrackingError,
            hillFrameRelativeControl,
            inertial3D,
            mrpFeedback,
            rwMotorTorque,
            thrFiringRemainder,
            thrForceMapping,
        )
        from Basilisk.simulation import (
            extForceTorque,
            reactionWheelStateEffector,
            simpleNav,
            spacecraft,
            thrusterDynamicEffector,
        )
        from Basilisk.utilities import (
            SimulationBaseClass,
            macros,
            simIncludeRW,
            simIncludeThruster,
        )

        _CACHE.append(
            _Modules(
                SimulationBaseClass,
                spacecraft,
                extForceTorque,
                simpleNav,
                inertial3D,
                attTrackingError,
                mrpFeedback,
                hillFrameRelativeControl,
                rwMotorTorque,
                reactionWheelStateEffector,
                simIncludeRW,
                thrForceMapping,
                thrFiringRemainder,
                thrusterDynamicEffector,
                simIncludeThruster,
                macros,
                messaging,
            )
        )
    return _CACHE[0]


@dataclass
class _Loop:
    """A built simulation, its recorders, and every module and message it uses (SWIG
    objects must stay referenced from Python while the simulation runs)."""

    sim: Any
    states: Any = None
    torques: Any = None
    speeds: Any = None
    parts: list[Any] = field(default_factory=list)

    def add(self, task: str, *modules: Any) -> None:
        """Add ``modules`` to ``task``, in order, and keep them."""
        for module in modules:
            self.sim.AddModelToTask(task, module)
        self.parts.extend(modules)


def _nanos(seconds: float) -> int:
    return round(seconds * _NANO)


def _build(m: _Modules, setup: BasiliskSetup) -> _Loop:
    """The simulation with its two tasks, modules and recorders, not yet initialised."""
    loop = _Loop(m.SimulationBaseClass.SimBaseClass())
    process = loop.sim.CreateNewProcess("loop")
    process.addTask(loop.sim.CreateNewTask("dynamics", _nanos(setup.dynamics_step)), 2)
    process.addTask(loop.sim.CreateNewTask("fsw", _nanos(setup.control_period)), 1)
    hub = _hub(m, setup)
    loop.add("dynamics", hub)
    actuator = None
    if setup.ideal_torque or setup.position_gains is not None:
        actuator = m.extForceTorque.ExtForceTorque()
        actuator.ModelTag = "extForceTorque"
        hub.addDynamicEffector(actuator)
    vehicle = m.messaging.VehicleConfigMsgPayload()
    vehicle.massSC = setup.mass
    vehicle.ISCPntB_B = _hub_inertia(setup).ravel().tolist()
    vehicle_msg = m.messaging.VehicleConfigMsg().write(vehicle)
    loop.parts.append(vehicle_msg)
    navigation = m.simpleNav.SimpleNav()
    navigation.ModelTag = "simpleNav"
    navigation.scStateInMsg.subscribeTo(hub.scStateOutMsg)
    loop.add("fsw", navigation)
    control = _attitude_loop(m, loop, setup, navigation, vehicle_msg)
    if setup.wheels is not None:
        _wheel_loop(m, loop, setup, hub, control)
    elif setup.thrusters is not None:
        _thruster_loop(m, loop, setup.thrusters, hub, control, vehicle_msg)
    elif actuator is not None:
        actuator.cmdTorqueInMsg.subscribeTo(control.cmdTorqueOutMsg)
    if setup.position_gains is not None and actuator is not None:
        hold = _position_loop(m, loop, setup.position_gains, navigation, vehicle_msg)
        actuator.cmdForceInertialInMsg.subscribeTo(hold.forceOutMsg)
    if actuator is not None:
        loop.add("fsw", actuator)
    loop.states = hub.scStateOutMsg.recorder(_nanos(setup.control_period))
    loop.torques = control.cmdTorqueOutMsg.recorder(_nanos(setup.control_period))
    loop.add("fsw", loop.states, loop.torques)
    return loop


def _hub_inertia(setup: BasiliskSetup) -> np.ndarray:
    """The hub's inertia about its centre of mass, body frame, kg·m²: the setup's, plus
    the wheels' about their spin axes (``Σ Js ĝ ĝᵀ``, see the module's notes)."""
    inertia = np.asarray(setup.inertia, dtype=float)
    if setup.wheels is None:
        return inertia
    axes = setup.wheels.axes
    return inertia + setup.wheels.inertia * (axes @ axes.T)


def _hub(m: _Modules, setup: BasiliskSetup) -> Any:
    """The rigid spacecraft hub at its initial state."""
    hub = m.spacecraft.Spacecraft()
    hub.ModelTag = "hub"
    hub.hub.mHub = setup.mass
    hub.hub.IHubPntBc_B = _hub_inertia(setup).tolist()
    hub.hub.r_CN_NInit = [[v] for v in HOLD_POINT]
    hub.hub.v_CN_NInit = [[float(v)] for v in setup.velocity]
    hub.hub.sigma_BNInit = [[float(v)] for v in mrp_from_quaternion(setup.attitude)]
    hub.hub.omega_BN_BInit = [[float(v)] for v in _initial_body_rate(setup)]
    return hub


def _initial_body_rate(setup: BasiliskSetup) -> np.ndarray:
    """The initial angular velocity in body axes, rad/s."""
    return rotate(_conjugate(setup.attitude), setup.angular_velocity)


def _wheel_loop(m: _Modules, loop: _Loop, setup: BasiliskSetup, hub: Any, control: Any) -> None:
    """rwMotorTorque → reactionWheelStateEffector in the flight-software task, the wheels
    on ``hub``, their speeds recorded."""
    wheels = setup.wheels
    assert wheels is not None
    factory = m.simIncludeRW.rwFactory()
    rpm = m.macros.RPM  # rad/s in one rpm: the factory takes speeds in rpm
    for axis, rate in zip(wheels.axes.T, wheels.axes.T @ _initial_body_rate(setup), strict=True):
        factory.create(
            "custom",
            axis.tolist(),
            Js=float(wheels.inertia),
            u_max=float(wheels.max_torque),
            Omega_max=float(wheels.max_momentum / wheels.inertia / rpm),
            Omega=float(-rate / rpm),  # zero momentum about the axis, as dcsim's wheels
        )
    effector = m.reactionWheelStateEffector.ReactionWheelStateEffector()
    factory.addToSpacecraft("reactionWheels", effector, hub)
    parameters = factory.getConfigMessage()
    torques = m.rwMotorTorque.rwMotorTorque()
    torques.ModelTag = "rwMotorTorque"
    torques.controlAxes_B = np.eye(3).ravel().tolist()
    torques.vehControlInMsg.subscribeTo(control.cmdTorqueOutMsg)
    torques.rwParamsInMsg.subscribeTo(parameters)
    effector.rwMotorCmdInMsg.subscribeTo(torques.rwMotorTorqueOutMsg)
    loop.parts.extend([factory, parameters])
    loop.add("fsw", torques, effector)
    loop.speeds = effector.rwSpeedOutMsg.recorder(_nanos(setup.control_period))
    loop.add("fsw", loop.speeds)


def _thruster_loop(
    m: _Modules, loop: _Loop, thrusters: ThrusterSetup, hub: Any, control: Any, vehicle_msg: Any
) -> None:
    """thrForceMapping → thrFiringRemainder → thrusterDynamicEffector in the
    flight-software task, the thrusters on ``hub``."""
    factory = m.simIncludeThruster.thrusterFactory()
    for position, direction in zip(thrusters.positions, thrusters.directions, strict=True):
        factory.create(
            "Blank_Thruster",
            position.tolist(),
            np.asarray(direction, dtype=float),
            MaxThrust=float(thrusters.max_thrust),
            MinOnTime=0.0,
        )
    effector = m.thrusterDynamicEffector.ThrusterDynamicEffector()
    factory.addToSpacecraft("thrusters", effector, hub)
    parameters = factory.getConfigMessage()
    mapping = m.thrForceMapping.thrForceMapping()
    mapping.ModelTag = "thrForceMapping"
    mapping.controlAxes_B = np.eye(3).ravel().tolist()
    mapping.thrForceSign = 1  # thrusters push only
    mapping.use2ndLoop = 1
    mapping.cmdTorqueInMsg.subscribeTo(control.cmdTorqueOutMsg)
    mapping.thrConfigInMsg.subscribeTo(parameters)
    mapping.vehConfigInMsg.subscribeTo(vehicle_msg)
    firing = m.thrFiringRemainder.thrFiringRemainder()
    firing.ModelTag = "thrFiringRemainder"
    firing.thrMinFireTime = 0.0
    firing.baseThrustState = 0  # on-pulsing
    firing.thrConfInMsg.subscribeTo(parameters)
    firing.thrForceInMsg.subscribeTo(mapping.thrForceCmdOutMsg)
    effector.cmdsInMsg.subscribeTo(firing.onTimeOutMsg)
    loop.parts.extend([factory, parameters])
    loop.add("fsw", mapping, firing, effector)


def _attitude_loop(
    m: _Modules, loop: _Loop, setup: BasiliskSetup, navigation: Any, vehicle_msg: Any
) -> Any:
    """inertial3D → attTrackingError → mrpFeedback in the flight-software task."""
    guidance = m.inertial3D.inertial3D()
    guidance.ModelTag = "inertial3D"
    guidance.sigma_R0N = mrp_from_quaternion(setup.goal_attitude).tolist()
    error = m.attTrackingError.attTrackingError()
    error.ModelTag = "attTrackingError"
    error.attNavInMsg.subscribeTo(navigation.attOutMsg)
    error.attRefInMsg.subscribeTo(guidance.attRefOutMsg)
    control = m.mrpFeedback.mrpFeedback()
    control.ModelTag = "mrpFeedback"
    control.K, control.P = setup.mrp_gains
    control.Ki = -1.0  # no integral term
    control.controlLawType = 1  # compensate ω × Iω with the body rate
    control.guidInMsg.subscribeTo(error.attGuidOutMsg)
    control.vehConfigInMsg.subscribeTo(vehicle_msg)
    loop.add("fsw", guidance, error, control)
    return control


def _position_loop(
    m: _Modules, loop: _Loop, gains: tuple[float, float], navigation: Any, vehicle_msg: Any
) -> Any:
    """hillFrameRelativeControl about a constant chief at the hold point, with the
    setup's ``position_gains`` K (1/s²) and P (1/s)."""
    chief = m.messaging.NavTransMsgPayload()
    chief.r_BN_N = list(HOLD_POINT)
    chief.v_BN_N = [0.0, CHIEF_SPEED, 0.0]
    chief_msg = m.messaging.NavTransMsg().write(chief)
    k, p = gains
    hold = m.hillFrameRelativeControl.HillFrameRelativeControl()
    hold.ModelTag = "hillFrameRelativeControl"
    hold.chiefTransInMsg.subscribeTo(chief_msg)
    hold.deputyTransInMsg.subscribeTo(navigation.transOutMsg)
    hold.deputyVehicleConfigInMsg.subscribeTo(vehicle_msg)
    hold.setMu(CHIEF_MU)
    hold.setK(np.diag([k, k, k]).ravel().tolist())
    hold.setP(np.diag([p, p, p]).ravel().tolist())
    hold.setReferencePosition([0.0, 0.0, 0.0])
    hold.setReferenceVelocity([0.0, -CHIEF_SPEED, 0.0])  # at rest in the inertial frame
    loop.parts.append(chief_msg)
    loop.add("fsw", hold)
    return hold


def _conjugate(quaternion: np.ndarray) -> np.ndarray:
    q = np.asarray(quaternion, dtype=float)
    return np.concatenate([-q[:3], q[3:]])
