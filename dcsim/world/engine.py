"""The world as a steppable system: the robot's dynamics, collisions, state and outputs.

One PyBullet DIRECT client per world, zero gravity, a fixed physics step; every call
passes the client id, so several worlds live side by side in one process. The world
composes its pieces:

- :mod:`~dcsim.world.robot_body`: the robot, one of two body types behind one
  interface — :mod:`~dcsim.world.free_flyer` (a rigid body) and
  :mod:`~dcsim.world.manipulator` (a floating-base arm);
- :mod:`~dcsim.world.bodies`: the PyBullet bodies of the objects;
- :mod:`~dcsim.world.environment`: Clohessy–Wiltshire forces and the propellant;
- :mod:`~dcsim.world.sensors`: beacon ranges, object tracks, attitude and rate;
- :mod:`~dcsim.world.payload`: objects held by the robot (a mission attaches them);
- :mod:`~dcsim.world.objects`: the targets and obstacles and their motion;
- :mod:`~dcsim.world.actuators`: the base's thrusters and reaction wheels;
- :mod:`~dcsim.world.capture_rig`: a manipulator's gripper and a tumbling body it may
  grasp (:mod:`~dcsim.world.gripper`, :mod:`~dcsim.world.tumbling_body`), with contact.

- **Robot**: its base is driven by thrust and torque: ideal (thrust clipped to
  ``max_force`` and to the propellant left, torque to ``max_torque``, using none), or
  what the base's thrusters and reaction wheels deliver
  (:mod:`~dcsim.world.actuators`; a free flyer's and a manipulator's base alike); a
  manipulator's joints by joint torques. The base's
  mass is updated once per control period.
- **Objects**: targets and obstacles, spheres, boxes or cylinders of fixed orientation,
  follow their motion models exactly while free.
- **Collisions**: every physics step, the robot and what it carries against every
  free object that the control period's broad phase (swept bounding spheres) found
  within reach, from PyBullet's closest-point queries on the true shapes. A collision
  is reported once, when contact starts. Contacts are detected, not resolved: bodies
  pass through each other.
"""

from __future__ import annotations

import dataclasses
import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcsim.geometry import clip_norm, combined_inertia, length, row_lengths
from dcsim.messages import (
    BeaconRange,
    MotionInput,
    ObjectTrack,
    Observations,
    RobotSpec,
    RobotState,
)
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario.model import ManipulatorSection, RobotSection, Scenario
from dcsim.world.actuators import Actuators, ThrustProfile
from dcsim.world.bodies import ObjectBodies, surface_gap
from dcsim.world.capture_rig import CaptureRig
from dcsim.world.environment import (
    Propellant,
    apply_cw_force,
    apply_cw_force_on_link,
    cw_acceleration,
)
from dcsim.world.free_flyer import FreeFlyerBody
from dcsim.world.manipulator import ManipulatorBody
from dcsim.world.objects import ObjectField, ObjectStatus, build_objects
from dcsim.world.orbit.chief import relative_dynamics
from dcsim.world.orbit.forces import ExactOrbitalForces
from dcsim.world.payload import Payload
from dcsim.world.pybullet_client import connect_direct, pb
from dcsim.world.robot_body import RobotBody
from dcsim.world.sensors import Sensing, build_sensor_models
from dcsim.world.vector3 import turn

_BROAD_PHASE_SLACK = 1e-3  # m added to the swept reach of each control period


def _build_capture_rig(scenario: Scenario, client: int, robot: RobotBody) -> CaptureRig | None:
    """The gripper and the tumbling body, when the robot has one and the mission the other."""
    target = scenario.mission.tumbling_body()
    gripper = getattr(scenario.robot, "gripper", None)
    if target is None or gripper is None or not isinstance(robot, ManipulatorBody):
        return None
    return CaptureRig(client, robot, gripper, target, scenario.world.physics_step)


def _build_robot_body(client: int, robot: RobotSection | ManipulatorSection) -> RobotBody:
    """The body type of the scenario's robot, created at its initial state."""
    if isinstance(robot, ManipulatorSection):
        return ManipulatorBody(client, robot)
    return FreeFlyerBody(client, robot)


@dataclass
class WorldInputs:
    """The world's inputs for the coming control period.

    Attributes
    ----------
    force : ndarray (3,)
        Commanded thrust, world frame, N (clipped to the limits).
    torque : ndarray (3,)
        Commanded torque, world frame, N·m (clipped to the limit; with reaction wheels,
        turned into body axes at the period's start and shared among the wheels).
    disturbance_force : ndarray (3,)
        External force on the robot's base, N (not clipped, uses no propellant).
    disturbance_torque : ndarray (3,)
        External torque on the robot's base, N·m.
    joint_torques : ndarray (n,)
        Commanded joint torques of a manipulator, N·m (clipped to the limits); empty
        for none (and for a free flyer, which has no joints).
    thruster_on_times : ndarray (N,)
        Each thruster's on-time from the period's start, s; empty: allocate ``force``
        (:class:`~dcsim.messages.Command`).
    wheel_torques : ndarray (N,)
        Each reaction wheel's torque, N·m; empty: allocate ``torque``.
    """

    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    disturbance_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    disturbance_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    joint_torques: np.ndarray = field(default_factory=lambda: np.zeros(0))
    thruster_on_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    wheel_torques: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class CollisionEvent:
    """Contact starting between the robot (or a carried target) and an object.

    Attributes
    ----------
    time : float
        s.
    object_id : int
        The object hit.
    body : str
        ``"collector"`` for the robot or ``"target <id>"`` for a carried target.
    penetration : float
        Depth of the overlap when detected, m.
    """

    time: float
    object_id: int
    body: str
    penetration: float


def _build_actuators(
    robot: RobotSection | ManipulatorSection, control_period: float, physics_step: float
) -> Actuators | None:
    """The base's thrusters and reaction wheels, or None when both are ideal."""
    if robot.actuators.ideal:
        return None
    return Actuators(robot.actuators, robot.specific_impulse, control_period, physics_step)


class World:
    """A steppable PyBullet world built from a scenario.

    As a system it has named inputs (:class:`WorldInputs`: force, torque and the
    disturbance force and torque, set before each :meth:`step` of one control period),
    named outputs (:meth:`outputs`) and parameters (:meth:`parameters`); it is usable
    without the runner.

    Parameters
    ----------
    scenario : Scenario
        The validated scenario.
    rng : numpy.random.Generator
        The world's generator (beacon range noise; the other sensor models draw from
        their own, :func:`~dcsim.world.sensors.build_sensor_models`).
    registry : PluginRegistry, optional
        Where the scenario's sensor models are found; the installed packages' (found
        once per process) if None.

    Attributes
    ----------
    time : float
        Simulated time, s (a whole number of physics steps).
    inputs : WorldInputs
        Inputs applied over the next :meth:`step`.
    field : ObjectField
        The targets and obstacles.
    collisions : list of CollisionEvent
        Every collision so far.
    robot_id : int
        The robot's PyBullet body id (its base is link -1).
    actuators : Actuators or None
        The base's thrusters and reaction wheels (``robot.actuators``); None when
        force and torque are ideal.
    wheels : ReactionWheels or None
        The base's reaction wheels; None for ideal (or thrusters') torque.
    capture : CaptureRig or None
        The manipulator's gripper and the mission's tumbling body; None unless the robot
        has a gripper and the mission a tumbling body.
    """

    def __init__(
        self,
        scenario: Scenario,
        rng: np.random.Generator,
        registry: PluginRegistry | None = None,
    ) -> None:
        self.scenario = scenario
        self.physics_step = scenario.world.physics_step
        self.steps_per_control = round(scenario.world.control_period / self.physics_step)
        self.control_period = self.steps_per_control * self.physics_step
        self._steps = 0
        robot = scenario.robot
        self.robot = robot
        self.dry_mass = robot.mass - robot.propellant_mass
        self._propellant = Propellant(
            robot.propellant_mass, robot.specific_impulse, self.physics_step, self.steps_per_control
        )
        self.collisions: list[CollisionEvent] = []
        self.inputs = WorldInputs()
        orbit, lvlh = scenario.world.orbit, scenario.world.frame == "lvlh"
        self._mean_motion = scenario.mean_motion if lvlh and orbit.model == "cw" else None
        dynamics = relative_dynamics(orbit) if lvlh and orbit.model != "cw" else None
        self.field = ObjectField(build_objects(scenario, dynamics))
        self._client = connect_direct()
        # A world dropped without close() (an FMU reset does that) still disconnects.
        self._disconnect = weakref.finalize(self, pb.disconnect, physicsClientId=self._client)
        self._state_cache: (
            tuple[int, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] | None
        ) = None
        self._cargo_cache: tuple[tuple[int, int], list[tuple[np.ndarray, float]]] | None = None
        self._kinds_cache: tuple[int, tuple[np.ndarray, np.ndarray]] | None = None
        pb.setTimeStep(self.physics_step, physicsClientId=self._client)
        self._robot = _build_robot_body(self._client, robot)
        self.actuators = _build_actuators(robot, self.control_period, self.physics_step)
        self.wheels = None if self.actuators is None else self.actuators.wheels
        self._links_mass = sum(mass for _, mass in self._robot.links)
        self.robot_id = self._robot.body
        self._joint_torques = np.zeros(0)
        self._bodies = ObjectBodies(self._client, self.field)
        self.capture = _build_capture_rig(scenario, self._client, self._robot)
        self.sensing = Sensing(
            self.field,
            build_sensor_models(scenario, rng, registry),
            beacons=scenario.beacons,
            sensor_range=robot.sensor_range,
            control_period=scenario.world.control_period,
            initial=robot.initial,
            capture=self.capture,
        )
        self._payload = Payload(self._client, self.robot_id, robot.radius, self.field, self._bodies)
        self._contacts: set[tuple[int, int]] = set()
        self._candidates = np.zeros(0, dtype=int)
        self._period_mass = self.assembly_mass()
        self._body_mass = robot.mass
        self._exact_forces: ExactOrbitalForces | None = None
        if dynamics is not None:
            self._exact_forces = ExactOrbitalForces(
                self._client, dynamics, self.physics_step, self.steps_per_control
            )
            self._exact_forces.stagger_velocity(self.robot_id, self.physics_step)

    # ------------------------------------------------------------------ state
    @property
    def client(self) -> int:
        """The PyBullet client id, for tools that query PyBullet directly."""
        return self._client

    @property
    def time(self) -> float:
        """Simulated time, s."""
        return self._steps * self.physics_step

    @property
    def beacons(self) -> np.ndarray:
        """Beacon positions (B, 3), world frame, m."""
        return self.sensing.beacons

    @property
    def propellant(self) -> float:
        """Propellant left, kg."""
        return self._propellant.remaining

    @property
    def fuel_used(self) -> float:
        """Propellant used so far, kg."""
        return self._propellant.used

    @property
    def delta_v(self) -> float:
        """Delta-v accumulated, m/s."""
        return self._propellant.delta_v

    @property
    def robot_changes(self) -> int:
        """How many times the robot's mass or shape changed by an object attached or removed
        (a capture's latch included).

        Its :meth:`robot_spec` is new after each change.
        """
        latched = int(self.capture is not None and self.capture.latched)
        return self._payload.changes + latched

    def base_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """True ``(position, velocity, attitude [x, y, z, w], angular velocity)`` of the
        robot's base, world frame.

        Read from PyBullet once per physics step; sensors, outputs and the broad phase of
        one tick share the reading.
        """
        if self._state_cache is None or self._state_cache[0] != self._steps:
            position, attitude = pb.getBasePositionAndOrientation(
                self.robot_id, physicsClientId=self._client
            )
            velocity, angular = pb.getBaseVelocity(self.robot_id, physicsClientId=self._client)
            state = (np.array(position), np.array(velocity), np.array(attitude), np.array(angular))
            for array in state:
                array.setflags(write=False)
            self._state_cache = (self._steps, state)
        return self._state_cache[1]

    def base_mass(self) -> float:
        """Mass of the robot's base, propellant included, kg."""
        return self.dry_mass + self.propellant

    def assembly_mass(self) -> float:
        """Mass of the robot (a manipulator's arm included) and every object it carries,
        kg."""
        return self.base_mass() + self._payload.mass + self._links_mass + self._held_mass()

    def _held_mass(self) -> float:
        """Mass of the tumbling body the gripper's latch holds, kg (0 if none)."""
        rig = self.capture
        return rig.target.mass if rig is not None and rig.latched else 0.0

    @property
    def robot_body(self) -> RobotBody:
        """The robot's body: a free flyer's sphere or a manipulator's multibody."""
        return self._robot

    def joint_state(self) -> tuple[np.ndarray, np.ndarray]:
        """True joint angles (rad) and rates (rad/s), (n,) each; empty for a free flyer."""
        return self._robot.joint_state()

    def robot_state(self) -> RobotState:
        """The true state: base (centre of mass, world frame) and joints."""
        position, velocity, attitude, angular = self.base_state()
        angles, rates = self.joint_state()
        return RobotState(
            time=self.time,
            position=position,
            velocity=velocity,
            attitude=attitude,
            angular_velocity=angular,
            joint_positions=angles,
            joint_velocities=rates,
        )

    def end_effector(self) -> np.ndarray:
        """True end-effector position of a manipulator (origin of DH frame n), world frame, m.

        Raises
        ------
        ValueError
            For a free flyer, which has no arm.
        """
        return self._robot.end_effector(self.robot_state().configuration)

    def robot_spec(self) -> RobotSpec:
        """The robot's current mass (cargo included), inertia, limits and bounding radius
        (grown by the cargo's protrusion); a manipulator's joint limits and model.

        The inertia is about the centre of mass of the base and its cargo, along the body
        axes: the base's own as PyBullet holds it, plus each object held as a uniform
        solid of its shape, by the parallel-axis theorem.
        """
        spec = self._robot.spec(self.assembly_mass(), self.base_mass(), self.cargo_protrusion())
        if self.actuators is not None:
            spec = self._with_actuators(spec)
        if self._held_mass():
            spec = dataclasses.replace(spec, held_mass=self._held_mass())
        if not self._payload.held:
            return spec
        position, _, attitude, _ = self.base_state()
        rotation = np.reshape(pb.getMatrixFromQuaternion(attitude.tolist()), (3, 3))
        base = (self.base_mass(), position, rotation @ spec.inertia @ rotation.T)
        _, inertia = combined_inertia([base, *self._payload.parts()])
        return dataclasses.replace(spec, inertia=rotation.T @ inertia @ rotation)

    def _with_actuators(self, spec: RobotSpec) -> RobotSpec:
        """``spec`` with the thrusters' and wheels' geometry."""
        assert self.actuators is not None
        thrusters, wheels = self.actuators.thrusters, self.wheels
        if thrusters is not None:
            spec = dataclasses.replace(
                spec, thruster_forces=thrusters.forces, thruster_torques=thrusters.torques
            )
        if wheels is not None:
            spec = dataclasses.replace(spec, wheel_axes=wheels.axes)
        return spec

    def carried_ids(self) -> list[int]:
        """Ids of the targets on board."""
        return [self.field.objects[i].id for i in self._payload.held]

    def object_states(self) -> tuple[np.ndarray, np.ndarray]:
        """True positions and velocities (N, 3) of all objects; carried ones from physics."""
        positions, velocities = (a.copy() for a in self.field.free_states(self.time))
        for index, (body, _) in self._payload.held.items():
            p, _ = pb.getBasePositionAndOrientation(body, physicsClientId=self._client)
            v, _ = pb.getBaseVelocity(body, physicsClientId=self._client)
            positions[index], velocities[index] = p, v
        return positions, velocities

    def nearest_obstacle_distance(self) -> float:
        """Smallest surface gap between the robot (and cargo) and a free obstacle, m.

        Pairs of spheres are measured from their centres and radii, all at once. A pair
        with a box or a cylinder is measured by PyBullet's closest points, only if its
        bounding spheres are nearer than the nearest gap found so far.
        """
        obstacles, radii, spheres = self.field.free_obstacles()
        if not obstacles.size:
            return float("inf")
        positions = self.field.free_states(self.time)[0][obstacles]
        if not self._payload.held and spheres.all():  # the robot alone, every pair exact
            gaps = row_lengths(positions - self.base_state()[0]) - radii - self.robot.radius
            return float(gaps.min())
        centres = np.array([centre for centre, _ in self._assembly_spheres()])
        part_radii, is_sphere = self._assembly_kinds()
        distances = row_lengths(positions - centres[:, None])  # (parts, obstacles)
        bounds = distances - radii - part_radii[:, None]
        if spheres.all() and is_sphere.all():  # every pair exact: sphere to sphere
            return float(bounds.min())
        exact = np.outer(is_sphere, spheres)
        nearest = float(np.min(bounds, where=exact, initial=np.inf))
        return self._nearest_shaped_gap(nearest, bounds, distances, ~exact, obstacles)

    def _nearest_shaped_gap(
        self,
        nearest: float,
        bounds: np.ndarray,
        distances: np.ndarray,
        pending: np.ndarray,
        obstacles: np.ndarray,
    ) -> float:
        """``nearest`` lowered by the true gaps of the ``pending`` (part, obstacle) pairs, m.

        ``bounds`` are the pairs' bounding-sphere gaps (lower bounds of the true ones),
        ``distances`` their centre distances (upper bounds: each shape holds its centre),
        both (P, K); ``obstacles`` the field indices of the K obstacles. Pairs are
        measured nearest bound first, until no bound is below the nearest gap, each
        only as far as the nearest gap (a farther one cannot lower it).
        """
        parts, columns = np.nonzero(pending)
        order = np.argsort(bounds[parts, columns], kind="stable")
        carriers = [self.robot_id, *(body for body, _ in self._payload.held.values())]
        for part, column in zip(parts[order], columns[order], strict=True):
            if bounds[part, column] >= nearest:
                break
            body = self._bodies.place(obstacles[column], self.time)
            within = max(0.0, min(nearest, distances[part, column]))
            nearest = min(nearest, surface_gap(self._client, carriers[part], body, within))
        return nearest

    def cargo_protrusion(self) -> float:
        """How far carried objects reach beyond the robot's bounding sphere, m (0 if none).

        Cargo is held rigidly, so this changes only when an object is attached or removed.
        """
        return self._payload.protrusion

    def _assembly_spheres(self) -> list[tuple[np.ndarray, float]]:
        """Centre and bounding radius of the robot, then of each object it carries."""
        return [(self.base_state()[0], self.robot.radius), *self._cargo_spheres()]

    def _cargo_spheres(self) -> list[tuple[np.ndarray, float]]:
        """Centre (m, world frame, read-only) and bounding radius (m) of each object
        carried, read from PyBullet once per physics step and payload."""
        key = (self._steps, self._payload.changes)
        if self._cargo_cache is None or self._cargo_cache[0] != key:
            spheres = self._payload.spheres()
            for centre, _ in spheres:
                centre.setflags(write=False)
            self._cargo_cache = (key, spheres)
        return self._cargo_cache[1]

    def _assembly_reach(self, position: np.ndarray) -> float:
        """How far the assembly's bounding spheres reach from ``position``, the base's
        centre (m): the robot's radius, or a carried object's farther reach."""
        reaches = (length(c - position) + r for c, r in self._cargo_spheres())
        return max([self.robot.radius, *reaches])

    def _assembly_kinds(self) -> tuple[np.ndarray, np.ndarray]:
        """The bounding radius (m) of each part of :meth:`_assembly_spheres` and whether
        it is a sphere (the robot's part is its bounding sphere), kept until the payload
        changes."""
        changes = self._payload.changes
        if self._kinds_cache is None or self._kinds_cache[0] != changes:
            held = list(self._payload.held)
            radii = np.array([self.robot.radius, *self.field.radii[held]])
            spheres = np.array([True, *self.field.is_sphere[held]])
            self._kinds_cache = (changes, (radii, spheres))
        return self._kinds_cache[1]

    def parameters(self) -> dict[str, float]:
        """Named scalar parameters of the world as a system (fixed for its lifetime)."""
        r = self.robot
        return {
            "physics_step": self.physics_step,
            "control_period": self.control_period,
            "robot.mass": r.mass,
            "robot.propellant_mass": r.propellant_mass,
            "robot.radius": r.radius,
            "robot.max_force": r.max_force,
            "robot.max_torque": r.max_torque,
            "robot.specific_impulse": r.specific_impulse,
            "robot.sensor_range": r.sensor_range,
            "robot.grab_distance": r.grab_distance,
            "robot.capacity": float(r.capacity),
            "mean_motion": self.scenario.mean_motion
            if self.scenario.world.frame == "lvlh"
            else 0.0,
        }

    def outputs(self) -> dict[str, Any]:
        """Named outputs of the world as a system (true state and bookkeeping)."""
        position, velocity, attitude, angular = self.base_state()
        return {
            "time": self.time,
            "position": position,
            "velocity": velocity,
            "attitude": attitude,
            "angular_velocity": angular,
            "mass": self.assembly_mass(),
            "propellant": self.propellant,
            "fuel_used": self.fuel_used,
            "delta_v": self.delta_v,
            "carried": len(self._payload.held),
            "captured": self.field.count(ObjectStatus.CARRIED)
            + self.field.count(ObjectStatus.REMOVED),
            "delivered": self.field.count(ObjectStatus.REMOVED),
            "collisions": len(self.collisions),
            "nearest_obstacle_distance": self.nearest_obstacle_distance(),
            **self._hardware_outputs(),
        }

    def _hardware_outputs(self) -> dict[str, Any]:
        """The reaction wheels' momenta (N·m·s), spin rates (rad/s) and the torque they
        gave the base over the last physics step (body frame, N·m); each thruster's duty
        cycle over the last control period (a fraction) and whether the thrusters are
        unloading the wheels; none of these without the hardware."""
        outputs: dict[str, Any] = {}
        if self.wheels is not None:
            outputs["wheel_momentum"] = self.wheels.momentum.copy()
            outputs["wheel_speed"] = self.wheels.speeds
            outputs["wheel_torque"] = self.wheels.delivered()
        if self.actuators is not None and self.actuators.thrusters is not None:
            outputs["thruster_duty"] = self.actuators.duty.copy()
            outputs["unloading"] = self.actuators.unloading
        return outputs

    @property
    def attitude_fuel_used(self) -> float:
        """Propellant burnt for attitude so far, kg: with thrusters, what each period's
        firing burnt beyond the allocation of its mean force alone
        (:mod:`~dcsim.world.actuators`); 0 with ideal thrust."""
        return 0.0 if self.actuators is None else self.actuators.attitude_propellant

    # ------------------------------------------------------------------ stepping
    def step(self, inputs: WorldInputs | None = None) -> list[CollisionEvent]:
        """Advance one control period with ``inputs`` (or the current :attr:`inputs`).

        Returns
        -------
        list of CollisionEvent
            Collisions that started during the period.
        """
        if inputs is not None:
            self.inputs = inputs
        force = clip_norm(self.inputs.force, self.robot.max_force)
        self._period_mass = self.assembly_mass()
        self._joint_torques = self._robot.clip_joint_torques(self.inputs.joint_torques)
        if self._exact_forces is not None:
            self._linearise_orbital_forces()
        self._update_broad_phase(force)
        disturbance = tuple(np.asarray(self.inputs.disturbance_force, dtype=float).tolist())
        other_torque = np.asarray(self.inputs.disturbance_torque, dtype=float)
        if self.actuators is not None and self.actuators.thrusters is not None:
            profile = self._fire_thrusters(force)
            torque = tuple(other_torque.tolist())
            started = self._fly_period(None, disturbance, torque, profile)
        else:
            torque = tuple((self._torque_on_base() + other_torque).tolist())
            thrusts = self._propellant.burn(force, self._period_mass)
            started = self._fly_period(thrusts, disturbance, torque)
        self._set_body_mass(self.base_mass())
        self.collisions += started
        return started

    def _rotation(self) -> np.ndarray:
        """The base's body-to-world rotation matrix now."""
        return np.reshape(pb.getMatrixFromQuaternion(self.base_state()[2].tolist()), (3, 3))

    def _torque_on_base(self) -> np.ndarray:
        """The commanded torque clipped to ``max_torque``, world frame, N·m; with reaction
        wheels, zero: the wheels take the command (in body axes, each wheel clipped to its
        limits) and the base gets their reaction step by step."""
        if self.actuators is None:
            return clip_norm(self.inputs.torque, self.robot.max_torque)
        torque = np.asarray(self.inputs.torque, dtype=float)
        wheel_torques = np.asarray(self.inputs.wheel_torques, dtype=float)
        self.actuators.command_wheels(self.time, self._rotation(), torque, wheel_torques, None)
        return np.zeros(3)

    def _fire_thrusters(self, force: np.ndarray) -> ThrustProfile:
        """The thrusters' firing over the coming period (and the wheels' command, with
        wheels), propellant booked."""
        assert self.actuators is not None
        rotation = self._rotation()
        torque = np.asarray(self.inputs.torque, dtype=float)
        if self.wheels is None:  # the thrusters give it
            torque = clip_norm(torque, self.robot.max_torque)
        profile = self.actuators.fire(
            self.time,
            rotation,
            force,
            torque,
            np.asarray(self.inputs.thruster_on_times, dtype=float),
            self._propellant,
            self._period_mass,
            rotation.T @ self._centre_offset(),
        )
        if self.wheels is not None:
            wheel_torques = np.asarray(self.inputs.wheel_torques, dtype=float)
            self.actuators.command_wheels(self.time, rotation, torque, wheel_torques, profile)
        return profile

    def _centre_offset(self) -> np.ndarray:
        """The centre of mass of the base and its cargo less the base's, world frame, m."""
        if not self._payload.held:
            return np.zeros(3)
        position = self.base_state()[0]
        parts = [(self.base_mass(), position, np.zeros((3, 3))), *self._payload.parts()]
        return combined_inertia(parts)[0] - position

    def _linearise_orbital_forces(self) -> None:
        """Expand the exact orbital acceleration of every body of the robot (base, cargo,
        arm links) about its state at the coming period's start."""
        assert self._exact_forces is not None
        position, velocity, _, _ = self.base_state()
        held = self._payload.held.items()
        parts = [(c, -1, self.field.objects[i].mass) for i, (c, _) in held]
        parts += [(self.robot_id, link, mass) for link, mass in self._robot.links]
        self._exact_forces.begin_period(self.time, (position, velocity), parts)

    def _set_body_mass(self, mass: float) -> None:
        """Give the robot's base ``mass``, kg (the orbital force on it uses it)."""
        self._robot.set_base_mass(mass)
        self._body_mass = mass

    def _fly_period(
        self,
        thrusts: list[tuple[float, float, float]] | None,
        disturbance: tuple[float, ...],
        torque: tuple[float, ...],
        profile: ThrustProfile | None = None,
    ) -> list[CollisionEvent]:
        """The control period's physics steps: thrust, disturbance and orbital forces on
        the assembly (and the arm's joint torques), the broad phase's candidates checked
        for contact after each step. What cannot change within the period is read once.

        ``thrusts`` gives each step's ideal thrust (world frame, N); with thrusters it is
        None and ``profile`` gives each step's body force and torque instead, turned by
        that step's attitude. ``torque`` is the torque on the base besides the
        thrusters' and the wheels' (world frame, N·m)."""
        client, body, mass, n = self._client, self.robot_id, self._body_mass, self._mean_motion
        get_pose, get_velocity = pb.getBasePositionAndOrientation, pb.getBaseVelocity
        apply_force, step = pb.applyExternalForce, pb.stepSimulation
        cargo = [(c, self.field.objects[i].mass) for i, (c, _) in self._payload.held.items()]
        robot, links, joints = self._robot, self._robot.links, self._robot.n_joints > 0
        exact, dt = self._exact_forces, self.physics_step
        parts = exact is not None and exact.has_parts
        wheels, actuators = self.wheels, self.actuators
        if profile is not None:  # each step's body force and torque, as plain floats
            body_forces, body_torques = profile.forces.tolist(), profile.torques.tolist()
        if wheels is not None:  # the base's mass, and so its inertia, is set per period
            ix, iy, iz = pb.getDynamicsInfo(body, -1, physicsClientId=client)[2]
            moments = (ix, iy, iz)
        apply_torque = torque != (0.0, 0.0, 0.0) or profile is not None
        check_contacts = len(self._candidates) > 0
        rig = self.capture
        if rig is not None:
            rig.begin_period()
        # each step reads the base's state once: the rotation for the thrusters' and the
        # wheels' body-frame torques, the velocity for the orbital force and the wheels
        turns = profile is not None or wheels is not None
        moves = n is not None or exact is not None or wheels is not None
        dx, dy, dz = disturbance
        started: list[CollisionEvent] = []
        for k in range(self.steps_per_control):
            position, attitude = get_pose(body, client)
            if turns:
                rotation = pb.getMatrixFromQuaternion(attitude)
            if moves:
                velocity, angular = get_velocity(body, client)
            if thrusts is not None:
                tx, ty, tz = thrusts[k]
                step_torque = torque
            else:
                tx, ty, tz = turn(rotation, body_forces[k])
                qx, qy, qz = turn(rotation, body_torques[k])
                step_torque = (qx + torque[0], qy + torque[1], qz + torque[2])
            fx, fy, fz = tx + dx, ty + dy, tz + dz
            if n is not None:
                ax, ay, az = cw_acceleration(n, position, velocity)
                fx, fy, fz = fx + mass * ax, fy + mass * ay, fz + mass * az
                for carried, carried_mass in cargo:
                    apply_cw_force(client, carried, carried_mass, n)
                for link, link_mass in links:
                    apply_cw_force_on_link(client, body, link, link_mass, n)
            elif exact is not None:
                ax, ay, az = exact.base_acceleration(k * dt, body, position, velocity)
                fx, fy, fz = fx + mass * ax, fy + mass * ay, fz + mass * az
                if parts:
                    exact.apply_to_parts(k * dt)
            if joints:
                robot.apply_joint_torques(self._joint_torques)
            apply_force(body, -1, (fx, fy, fz), position, pb.WORLD_FRAME, client)
            if wheels is not None:
                self._apply_wheel_torque(rotation, angular, moments, step_torque)
            elif apply_torque:
                pb.applyExternalTorque(body, -1, step_torque, pb.WORLD_FRAME, client)
            step(client)
            self._steps += 1
            if actuators is not None and wheels is not None:
                actuators.note_saturations(self.time)
            if check_contacts:
                started += self._detect_collisions()
            if rig is not None:
                rig.after_step()
        return started

    def _apply_wheel_torque(
        self,
        rotation: tuple[float, ...],
        angular_velocity: tuple[float, ...],
        moments: tuple[float, float, float],
        disturbance: tuple[float, ...],
    ) -> None:
        """Step the reaction wheels and put their reaction, with ``disturbance`` (world
        frame, N·m), on the base for the coming physics step; ``rotation`` is the base's
        body-to-world rotation now (nine floats, row by row), ``angular_velocity`` its
        angular velocity (world frame, rad/s), ``moments`` its principal moments of
        inertia (kg·m²)."""
        assert self.wheels is not None
        client, body = self._client, self.robot_id
        wx, wy, wz = angular_velocity
        dx, dy, dz = disturbance
        rx, ry, rz = self.wheels.step(
            rotation, (wx, wy, wz), moments, (dx, dy, dz), self.physics_step
        )
        pb.applyExternalTorque(body, -1, (rx + dx, ry + dy, rz + dz), pb.WORLD_FRAME, client)

    def _update_broad_phase(self, force: np.ndarray) -> None:
        """Find the free objects that could touch the assembly in the coming period."""
        field = self.field
        free = field.free_indices()
        if free.size == 0:
            self._candidates = free
            return
        period = self.control_period
        position, velocity, _, _ = self.base_state()
        push = length(force) + length(self.inputs.disturbance_force)
        accel = push / self._period_mass
        if self._mean_motion is not None:
            accel += 2 * length(cw_acceleration(self._mean_motion, position, velocity))
        elif self._exact_forces is not None:
            accel += 2 * length(np.array(self._exact_forces.base.base))
        sweep = length(velocity) * period + accel * period**2
        now = field.free_states(self.time)[0]
        later = field.free_states((self._steps + self.steps_per_control) * self.physics_step)[0]
        radii = field.radii
        if free.size < len(field):
            now, later, radii = now[free], later[free], radii[free]
        moves = row_lengths(later - now)
        gaps = row_lengths(now - position) - self._assembly_reach(position) - radii
        self._candidates = free[gaps <= 1.5 * (moves + sweep) + _BROAD_PHASE_SLACK]

    def _detect_collisions(self) -> list[CollisionEvent]:
        started = []
        carriers = [(self.robot_id, "collector", -1)] + [
            (body, f"target {self.field.objects[i].id}", i)
            for i, (body, _) in self._payload.held.items()
        ]
        for index in self._candidates:
            if self.field.status[index] != ObjectStatus.FREE:
                continue
            body = self._bodies.place(index, self.time)
            for carrier, label, key in carriers:
                depth = -surface_gap(self._client, carrier, body, 0.0)
                pair = (int(index), key)
                if depth > 0 and pair not in self._contacts:
                    self._contacts.add(pair)
                    started.append(
                        CollisionEvent(self.time, self.field.objects[index].id, label, depth)
                    )
                elif depth <= 0:
                    self._contacts.discard(pair)
        return started

    # ------------------------------------------------------------------ sensors
    def beacon_ranges(self) -> tuple[BeaconRange, ...]:
        """The beacon range sensor's reading now (the thesis's Beacon topic)."""
        position, velocity, attitude, angular_velocity = self.base_state()
        truth = self.sensing.truth(self.time, position, velocity, attitude, angular_velocity)
        return self.sensing.beacon_ranges(truth)

    def object_tracks(self) -> list[ObjectTrack]:
        """Exact tracks of the free objects within sensor range (the thesis's Objects
        topic), whatever the sensors: what ideal object sensing reports."""
        return self.sensing.object_tracks(self.time, self.base_state()[0])

    def observations(self) -> Observations:
        """Every sensor's reading now (:class:`~dcsim.world.sensors.Sensing`): beacon
        ranges, object tracks or detections, attitude and rate, joint encoders."""
        position, velocity, attitude, angular_velocity = self.base_state()
        observed = self.sensing.observations(
            self.time, position, velocity, attitude, angular_velocity
        )
        if not self._robot.n_joints:
            return observed
        angles, rates = self._robot.joint_state()  # noise-free encoders
        return dataclasses.replace(observed, joint_positions=angles, joint_velocities=rates)

    def motion_input(self) -> MotionInput:
        """Mean thrust acceleration applied over the last control period."""
        return MotionInput(acceleration=self._propellant.last_acceleration)

    # ------------------------------------------------------------------ payload
    def surface_gap(self, object_id: int, within: float) -> float:
        """Gap between the robot's base and free object ``object_id``, m.

        Parameters
        ----------
        object_id : int
            The object's id.
        within : float
            Largest gap looked for, m.

        Returns
        -------
        float
            The gap (negative when they overlap), or ``inf`` beyond ``within``.
        """
        body = self._bodies.place(self.field.index[object_id], self.time)
        return surface_gap(self._client, self.robot_id, body, within)

    def attach(self, object_id: int) -> None:
        """Hold free object ``object_id`` rigidly where it is now, fixed to the robot's base.

        It joins the robot's assembly: its mass, its orbital force and its collisions.
        """
        position, _, attitude, _ = self.base_state()
        index = self.field.index[object_id]
        self._payload.attach(index, self.time, position, attitude)
        self._contacts = {pair for pair in self._contacts if pair[0] != index}

    def remove_payload(self) -> tuple[int, ...]:
        """Take every object the robot holds out of the world (status removed).

        Returns
        -------
        tuple of int
            Ids of the objects removed.
        """
        removed = self._payload.remove_all()
        self._robot.set_base_mass(self.base_mass())
        return removed

    # ------------------------------------------------------------------ lifetime
    def close(self) -> None:
        """Disconnect from PyBullet; the world cannot be used afterwards."""
        if self._disconnect.alive:
            self._disconnect()

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
