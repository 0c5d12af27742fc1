"""The PyBullet world: collector dynamics, object motion, sensors, services, collisions.

One PyBullet DIRECT client per world, zero gravity, a fixed physics step; every call
passes the client id, so several worlds live side by side in one process.

- **Collector**: a rigid sphere driven by thrust (clipped to ``max_force`` and to the
  propellant left) and torque (clipped to ``max_torque``, from reaction wheels: no
  propellant). Propellant use is ``|F| dt / (Isp g0)``; delta-v accumulates
  ``|F| dt / m`` with ``m`` the mass of the collector and what it carries. The body's
  mass is updated once per control period.
- **Objects**: targets and obstacles follow their motion models exactly while free.
  They are static collision spheres that are moved to their model position only when
  a query needs them, so a large field costs little.
- **Frame**: in ``lvlh`` the collector (and what it carries) feels the
  Clohessy–Wiltshire accelerations ``(3n²x + 2nẏ, −2nẋ, −n²z)`` as external forces;
  ``geocentric`` is force-free, as in the source thesis.
- **Collisions**: every physics step, the collector and what it carries against every
  free object that the control period's broad phase found within reach, from
  PyBullet's closest-point queries. A collision is reported once, when contact starts.
  Contacts are detected, not resolved: bodies pass through each other.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from dcsim.geometry import clip_norm
from dcsim.messages import (
    BeaconRange,
    DropPoint,
    MotionInput,
    ObjectKind,
    ObjectTrack,
    Observations,
    RobotSpec,
)
from dcsim.scenario.model import Scenario, point_to_cartesian
from dcsim.world.objects import ObjectField, ObjectStatus, SpaceObject
from dcsim.world.pybullet_client import connect_direct, pb

STANDARD_GRAVITY = 9.80665
"""g0 used with the specific impulse, m/s²."""

_CONSTRAINT_FORCE = 1e9  # N; a grabbed target must not slip
_BROAD_PHASE_SLACK = 1e-3  # m added to the swept reach of each control period


@dataclass
class WorldInputs:
    """The world's inputs for the coming control period.

    Attributes
    ----------
    force : ndarray (3,)
        Commanded thrust, world frame, N (clipped to the limits).
    torque : ndarray (3,)
        Commanded torque, world frame, N·m (clipped to the limit).
    disturbance_force : ndarray (3,)
        External force on the collector, N (not clipped, uses no propellant).
    disturbance_torque : ndarray (3,)
        External torque on the collector, N·m.
    """

    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    disturbance_force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    disturbance_torque: np.ndarray = field(default_factory=lambda: np.zeros(3))


@dataclass(frozen=True)
class CollisionEvent:
    """Contact starting between the collector (or a carried target) and an object.

    Attributes
    ----------
    time : float
        s.
    object_id : int
        The object hit.
    body : str
        ``"collector"`` or ``"target <id>"`` for a carried target.
    penetration : float
        Depth of the overlap when detected, m.
    """

    time: float
    object_id: int
    body: str
    penetration: float


@dataclass(frozen=True)
class GrabResult:
    """Outcome of :meth:`World.grab`: success, and why not."""

    success: bool
    target_id: int
    reason: str
    gap: float


@dataclass(frozen=True)
class ReleaseResult:
    """Outcome of :meth:`World.release`: the targets delivered, and why none if so."""

    delivered: tuple[int, ...]
    reason: str


def build_objects(scenario: Scenario) -> list[SpaceObject]:
    """The scenario's targets and obstacles as world objects (targets first)."""
    n = scenario.mean_motion
    return [
        SpaceObject(spec.id, kind, spec.radius, spec.mass, spec.motion.build(n))
        for kind, specs in (
            (ObjectKind.TARGET, scenario.targets),
            (ObjectKind.OBSTACLE, scenario.obstacles),
        )
        for spec in specs
    ]


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
        The world's generator (sensor noise).

    Attributes
    ----------
    time : float
        Simulated time, s (a whole number of physics steps).
    inputs : WorldInputs
        Inputs applied over the next :meth:`step`.
    fuel_used, delta_v : float
        Propellant used (kg) and delta-v accumulated (m/s).
    collisions : list of CollisionEvent
        Every collision so far.
    robot_changes : int
        How many times the robot's mass or shape changed by a grab or a release (its
        :meth:`robot_spec` is then new).
    """

    def __init__(self, scenario: Scenario, rng: np.random.Generator) -> None:
        self.scenario = scenario
        self.physics_step = scenario.world.physics_step
        self.steps_per_control = round(scenario.world.control_period / self.physics_step)
        self.control_period = self.steps_per_control * self.physics_step
        self._rng = rng
        self._steps = 0
        robot = scenario.robot
        self.robot = robot
        self.dry_mass = robot.mass - robot.propellant_mass
        self.propellant = robot.propellant_mass
        self.fuel_used = 0.0
        self.delta_v = 0.0
        self.collisions: list[CollisionEvent] = []
        self.inputs = WorldInputs()
        self._mean_motion = scenario.mean_motion if scenario.world.frame == "lvlh" else None
        self.beacons = np.array(
            [point_to_cartesian(p) for p in scenario.beacons.positions]
        ).reshape(-1, 3)
        self.drop_point = DropPoint(
            scenario.drop_point.build(scenario.mean_motion), scenario.drop_point.tolerance
        )
        self.field = ObjectField(build_objects(scenario))
        self._client = connect_direct()
        # A world dropped without close() (an FMU reset does that) still disconnects.
        self._disconnect = weakref.finalize(self, pb.disconnect, physicsClientId=self._client)
        self._state_cache: tuple[int, tuple[np.ndarray, ...]] | None = None
        pb.setTimeStep(self.physics_step, physicsClientId=self._client)
        self.collector = self._create_collector()
        self._bodies = [self._create_object_body(i) for i in range(len(self.field))]
        self._carried: dict[int, tuple[int, int]] = {}  # object index -> (body, constraint)
        self._protrusion = 0.0  # m, see cargo_protrusion
        self.robot_changes = 0
        self._contacts: set[tuple[int, int]] = set()
        self._candidates = np.zeros(0, dtype=int)
        self._period_mass = self.assembly_mass()
        self._body_mass = robot.mass
        self._last_acceleration = np.zeros(3)

    # ------------------------------------------------------------------ bodies
    def _sphere(self, radius: float, mass: float, position: np.ndarray, maximal: bool) -> int:
        shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=radius, physicsClientId=self._client)
        body = pb.createMultiBody(
            baseMass=mass,
            baseCollisionShapeIndex=shape,
            basePosition=position.tolist(),
            useMaximalCoordinates=maximal,
            physicsClientId=self._client,
        )
        pb.setCollisionFilterGroupMask(body, -1, 0, 0, physicsClientId=self._client)
        if mass > 0:
            pb.changeDynamics(
                body, -1, linearDamping=0, angularDamping=0, physicsClientId=self._client
            )
        return body

    def _create_collector(self) -> int:
        initial = self.robot.initial
        body = self._sphere(
            self.robot.radius, self.robot.mass, point_to_cartesian(initial.position), False
        )
        attitude = np.asarray(initial.attitude) / np.linalg.norm(initial.attitude)
        pb.resetBasePositionAndOrientation(
            body,
            point_to_cartesian(initial.position).tolist(),
            attitude.tolist(),
            physicsClientId=self._client,
        )
        pb.resetBaseVelocity(
            body,
            list(initial.velocity),
            list(initial.angular_velocity),
            physicsClientId=self._client,
        )
        return body

    def _create_object_body(self, index: int) -> int:
        obj = self.field.objects[index]
        position = self.field.free_states(0.0)[0][index]
        return self._sphere(obj.radius, 0.0, position, True)

    def _place(self, index: int) -> None:
        """Move a free object's static body to its model position now."""
        position = self.field.objects[index].motion.state_at(self.time)[0]
        pb.resetBasePositionAndOrientation(
            self._bodies[index], position.tolist(), [0, 0, 0, 1], physicsClientId=self._client
        )

    # ------------------------------------------------------------------ state
    @property
    def client(self) -> int:
        """The PyBullet client id, for tools that query PyBullet directly."""
        return self._client

    @property
    def time(self) -> float:
        """Simulated time, s."""
        return self._steps * self.physics_step

    def collector_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """True ``(position, velocity, attitude [x, y, z, w], angular velocity)``.

        Read from PyBullet once per physics step; sensors, outputs and the broad phase of
        one tick share the reading.
        """
        if self._state_cache is None or self._state_cache[0] != self._steps:
            position, attitude = pb.getBasePositionAndOrientation(
                self.collector, physicsClientId=self._client
            )
            velocity, angular = pb.getBaseVelocity(self.collector, physicsClientId=self._client)
            state = tuple(np.array(v) for v in (position, velocity, attitude, angular))
            for array in state:
                array.setflags(write=False)
            self._state_cache = (self._steps, state)
        return self._state_cache[1]

    def collector_mass(self) -> float:
        """Collector mass, propellant included, kg."""
        return self.dry_mass + self.propellant

    def assembly_mass(self) -> float:
        """Mass of the collector and every target it carries, kg."""
        carried = sum(self.field.objects[i].mass for i in self._carried)
        return self.collector_mass() + carried

    def robot_spec(self) -> RobotSpec:
        """The collector's current mass, inertia, limits and bounding radius (cargo included).

        The inertia is the collector body's own, as PyBullet holds it, about its centre
        of mass in the body frame.
        """
        r = self.robot
        inertia = pb.getDynamicsInfo(self.collector, -1, physicsClientId=self._client)[2]
        return RobotSpec(
            mass=self.assembly_mass(),
            inertia=np.diag(inertia),
            radius=r.radius + self.cargo_protrusion(),
            max_force=r.max_force,
            max_torque=r.max_torque,
            max_speed=r.max_speed,
        )

    def carried_ids(self) -> list[int]:
        """Ids of the targets on board."""
        return [self.field.objects[i].id for i in self._carried]

    def object_states(self) -> tuple[np.ndarray, np.ndarray]:
        """True positions and velocities (N, 3) of all objects; carried ones from physics."""
        positions, velocities = (a.copy() for a in self.field.free_states(self.time))
        for index, (body, _) in self._carried.items():
            p, _ = pb.getBasePositionAndOrientation(body, physicsClientId=self._client)
            v, _ = pb.getBaseVelocity(body, physicsClientId=self._client)
            positions[index], velocities[index] = p, v
        return positions, velocities

    def nearest_obstacle_distance(self) -> float:
        """Smallest surface gap between the collector (and cargo) and a free obstacle, m."""
        mask = self.field.free_mask() & ~self.field.is_target
        if not mask.any():
            return float("inf")
        positions = self.field.free_states(self.time)[0][mask]
        radii = self.field.radii[mask]
        gaps = [
            np.linalg.norm(positions - centre, axis=1) - radii - radius
            for centre, radius in self._assembly_spheres()
        ]
        return float(np.min(gaps))

    def cargo_protrusion(self) -> float:
        """How far carried targets reach beyond the collector's surface, m (0 if none).

        Cargo is held rigidly, so this changes only at a grab or a release.
        """
        return self._protrusion

    def _measure_protrusion(self) -> float:
        (centre, radius), *cargo = self._assembly_spheres()
        return max((np.linalg.norm(c - centre) + r - radius for c, r in cargo), default=0.0)

    def _assembly_spheres(self) -> list[tuple[np.ndarray, float]]:
        spheres = [(self.collector_state()[0], self.robot.radius)]
        for index, (body, _) in self._carried.items():
            p, _ = pb.getBasePositionAndOrientation(body, physicsClientId=self._client)
            spheres.append((np.array(p), self.field.objects[index].radius))
        return spheres

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
            "mean_motion": self._mean_motion or 0.0,
        }

    def outputs(self) -> dict[str, object]:
        """Named outputs of the world as a system (true state and bookkeeping)."""
        position, velocity, attitude, angular = self.collector_state()
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
            "carried": len(self._carried),
            "captured": self.field.count(ObjectStatus.CARRIED)
            + self.field.count(ObjectStatus.DELIVERED),
            "delivered": self.field.count(ObjectStatus.DELIVERED),
            "collisions": len(self.collisions),
            "nearest_obstacle_distance": self.nearest_obstacle_distance(),
        }

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
        torque = clip_norm(self.inputs.torque, self.robot.max_torque)
        self._period_mass = self.assembly_mass()
        self._update_broad_phase(force)
        disturbance = tuple(float(f) for f in self.inputs.disturbance_force)
        total_torque = tuple(
            float(q) for q in torque + np.asarray(self.inputs.disturbance_torque, dtype=float)
        )
        started: list[CollisionEvent] = []
        for thrust in self._burn_schedule(force):
            self._physics_step(thrust, disturbance, total_torque)
            if len(self._candidates):
                started += self._detect_collisions()
        self._set_body_mass(self.collector_mass())
        self.collisions += started
        return started

    def _set_body_mass(self, mass: float) -> None:
        pb.changeDynamics(self.collector, -1, mass=mass, physicsClientId=self._client)
        self._body_mass = mass

    def _burn_schedule(self, force: np.ndarray) -> list[tuple[float, float, float]]:
        """Thrust of each physics step of the coming period, with propellant bookkeeping.

        The commanded force is held over the period until the propellant runs out.
        """
        steps, dt = self.steps_per_control, self.physics_step
        magnitude = float(np.linalg.norm(force))
        per_step = magnitude * dt / (self.robot.specific_impulse * STANDARD_GRAVITY)
        fractions = np.zeros(steps)
        if per_step > 0:
            fractions = np.clip(
                (self.propellant - per_step * np.arange(steps)) / per_step, 0.0, 1.0
            )
        used = per_step * float(fractions.sum())
        self.propellant = max(self.propellant - used, 0.0)
        self.fuel_used += used
        self.delta_v += magnitude * dt * float(fractions.sum()) / self._period_mass
        self._last_acceleration = force * (fractions.mean() / self._period_mass)
        return [tuple(float(f) for f in force * k) for k in fractions]

    def _physics_step(
        self,
        thrust: tuple[float, float, float],
        disturbance: tuple[float, float, float],
        torque: tuple[float, float, float],
    ) -> None:
        client, body = self._client, self.collector
        position, _ = pb.getBasePositionAndOrientation(body, physicsClientId=client)
        fx, fy, fz = (thrust[k] + disturbance[k] for k in range(3))
        if self._mean_motion is not None:
            velocity, _ = pb.getBaseVelocity(body, physicsClientId=client)
            ax, ay, az = self._cw_acceleration(position, velocity)
            fx, fy, fz = (
                fx + self._body_mass * ax,
                fy + self._body_mass * ay,
                fz + self._body_mass * az,
            )
            for index, (cargo, _) in self._carried.items():
                p, _ = pb.getBasePositionAndOrientation(cargo, physicsClientId=client)
                v, _ = pb.getBaseVelocity(cargo, physicsClientId=client)
                m = self.field.objects[index].mass
                cx, cy, cz = self._cw_acceleration(p, v)
                pb.applyExternalForce(
                    cargo, -1, (m * cx, m * cy, m * cz), p, pb.WORLD_FRAME, physicsClientId=client
                )
        pb.applyExternalForce(
            body, -1, (fx, fy, fz), position, pb.WORLD_FRAME, physicsClientId=client
        )
        if torque != (0.0, 0.0, 0.0):
            pb.applyExternalTorque(body, -1, torque, pb.WORLD_FRAME, physicsClientId=client)
        pb.stepSimulation(physicsClientId=client)
        self._steps += 1

    def _cw_acceleration(
        self, position: Sequence[float], velocity: Sequence[float]
    ) -> tuple[float, float, float]:
        """Clohessy–Wiltshire acceleration at an LVLH state, m/s²."""
        n = self._mean_motion
        return (
            3.0 * n * n * position[0] + 2.0 * n * velocity[1],
            -2.0 * n * velocity[0],
            -n * n * position[2],
        )

    def _update_broad_phase(self, force: np.ndarray) -> None:
        """Find the free objects that could touch the assembly in the coming period."""
        free = np.flatnonzero(self.field.free_mask())
        if free.size == 0:
            self._candidates = free
            return
        period = self.control_period
        position, velocity, _, _ = self.collector_state()
        spheres = self._assembly_spheres()
        reach = max(np.linalg.norm(c - position) + r for c, r in spheres)
        push = np.linalg.norm(force) + np.linalg.norm(self.inputs.disturbance_force)
        accel = push / self._period_mass
        if self._mean_motion is not None:
            accel += 2 * float(np.linalg.norm(self._cw_acceleration(position, velocity)))
        sweep = np.linalg.norm(velocity) * period + accel * period**2
        now = self.field.free_states(self.time)[0][free]
        later = self.field.free_states((self._steps + self.steps_per_control) * self.physics_step)[
            0
        ][free]
        moves = np.linalg.norm(later - now, axis=1)
        gaps = np.linalg.norm(now - position, axis=1) - reach - self.field.radii[free]
        self._candidates = free[gaps <= 1.5 * (moves + sweep) + _BROAD_PHASE_SLACK]

    def _detect_collisions(self) -> list[CollisionEvent]:
        started = []
        carriers = [(self.collector, "collector", -1)] + [
            (body, f"target {self.field.objects[i].id}", i)
            for i, (body, _) in self._carried.items()
        ]
        for index in self._candidates:
            if self.field.status[index] != ObjectStatus.FREE:
                continue
            self._place(index)
            for body, label, key in carriers:
                points = pb.getClosestPoints(
                    body, self._bodies[index], 0.0, physicsClientId=self._client
                )
                depth = -min((pt[8] for pt in points), default=0.0)
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
    def beacon_ranges(self) -> list[BeaconRange]:
        """Noisy ranges to the nearest beacons within range (the thesis's Beacon topic)."""
        if len(self.beacons) == 0:
            return []
        settings = self.scenario.beacons
        distances = np.linalg.norm(self.beacons - self.collector_state()[0], axis=1)
        order = np.argsort(distances, kind="stable")
        if settings.max_range is not None:
            order = order[distances[order] <= settings.max_range]
        order = order[: settings.report_nearest]
        noise = (
            self._rng.normal(0.0, settings.noise_sigma, len(order)) if settings.noise_sigma else 0.0
        )
        measured = distances[order] + noise
        return [
            BeaconRange(int(i), self.beacons[i], float(r), settings.noise_sigma)
            for i, r in zip(order, np.atleast_1d(measured), strict=True)
        ]

    def object_tracks(self) -> list[ObjectTrack]:
        """Tracks of the free objects within sensor range (the thesis's Objects topic)."""
        positions, velocities = self.field.free_states(self.time)
        if len(positions) == 0:
            return []
        distances = np.linalg.norm(positions - self.collector_state()[0], axis=1)
        visible = np.flatnonzero(self.field.free_mask() & (distances <= self.robot.sensor_range))
        return [
            ObjectTrack(
                id=obj.id,
                kind=obj.kind,
                time=self.time,
                position=positions[i],
                velocity=velocities[i],
                mass=obj.mass,
                radius=obj.radius,
                motion=obj.motion,
            )
            for i in visible
            for obj in (self.field.objects[i],)
        ]

    def observations(self) -> Observations:
        """Every sensor's reading now: beacon ranges, object tracks, attitude and rate.

        The star tracker and the gyros are noise-free.
        """
        _, _, attitude, angular_velocity = self.collector_state()
        return Observations(
            time=self.time,
            ranges=tuple(self.beacon_ranges()),
            tracks=tuple(self.object_tracks()),
            attitude=attitude,
            angular_velocity=angular_velocity,
        )

    def motion_input(self) -> MotionInput:
        """Mean thrust acceleration applied over the last control period."""
        return MotionInput(acceleration=self._last_acceleration)

    # ------------------------------------------------------------------ services
    def grab(self, target_id: int) -> GrabResult:
        """Try to grab target ``target_id`` (the thesis's Grab service).

        Succeeds when the target is free, the collector has room, and the gap between
        the two surfaces is at most ``robot.grab_distance``. The target is then attached
        by a fixed constraint and moves with the collector.
        """
        index = self.field.index.get(target_id)
        if index is None or not self.field.is_target[index]:
            return GrabResult(False, target_id, "no such target", float("nan"))
        if self.field.status[index] != ObjectStatus.FREE:
            return GrabResult(False, target_id, "target is not free", float("nan"))
        if len(self._carried) >= self.robot.capacity:
            return GrabResult(
                False, target_id, f"capacity {self.robot.capacity} reached", float("nan")
            )
        self._place(index)
        reach = self.robot.grab_distance
        points = pb.getClosestPoints(
            self.collector, self._bodies[index], reach + 1.0, physicsClientId=self._client
        )
        gap = min((pt[8] for pt in points), default=float("inf"))
        if gap > reach:
            return GrabResult(
                False, target_id, f"out of reach: gap {gap:.3f} m > {reach:g} m", float(gap)
            )
        self._attach(index)
        return GrabResult(True, target_id, "grabbed", float(gap))

    def _attach(self, index: int) -> None:
        obj = self.field.objects[index]
        position, velocity = (a.copy() for a in obj.motion.state_at(self.time))
        pb.removeBody(self._bodies[index], physicsClientId=self._client)
        body = self._sphere(obj.radius, obj.mass, position, False)
        pb.resetBaseVelocity(body, velocity.tolist(), [0, 0, 0], physicsClientId=self._client)
        c_position, _, c_attitude, _ = self.collector_state()
        inverse = pb.invertTransform(c_position.tolist(), c_attitude.tolist())
        local_position, local_attitude = pb.multiplyTransforms(
            inverse[0], inverse[1], position.tolist(), [0, 0, 0, 1]
        )
        constraint = pb.createConstraint(
            self.collector,
            -1,
            body,
            -1,
            pb.JOINT_FIXED,
            [0, 0, 0],
            parentFramePosition=local_position,
            childFramePosition=[0, 0, 0],
            parentFrameOrientation=local_attitude,
            physicsClientId=self._client,
        )
        pb.changeConstraint(constraint, maxForce=_CONSTRAINT_FORCE, physicsClientId=self._client)
        self._carried[index] = (body, constraint)
        self._protrusion = self._measure_protrusion()
        self.robot_changes += 1
        self._bodies[index] = body
        self.field.status[index] = ObjectStatus.CARRIED
        self._contacts = {pair for pair in self._contacts if pair[0] != index}

    def release(self) -> ReleaseResult:
        """Release every carried target if the collector is at the drop point.

        Released targets count as delivered and leave the world.
        """
        if not self._carried:
            return ReleaseResult((), "nothing carried")
        distance = float(
            np.linalg.norm(self.collector_state()[0] - self.drop_point.state_at(self.time)[0])
        )
        if distance > self.drop_point.tolerance:
            return ReleaseResult(
                (),
                f"{distance:.3f} m from the drop point (tolerance {self.drop_point.tolerance:g} m)",
            )
        delivered = []
        for index, (body, constraint) in self._carried.items():
            pb.removeConstraint(constraint, physicsClientId=self._client)
            pb.removeBody(body, physicsClientId=self._client)
            self.field.status[index] = ObjectStatus.DELIVERED
            delivered.append(self.field.objects[index].id)
        self._carried.clear()
        self._protrusion = 0.0
        self.robot_changes += 1
        pb.changeDynamics(
            self.collector, -1, mass=self.collector_mass(), physicsClientId=self._client
        )
        return ReleaseResult(tuple(delivered), "delivered")

    # ------------------------------------------------------------------ lifetime
    def close(self) -> None:
        """Disconnect from PyBullet; the world cannot be used afterwards."""
        if self._client is not None:
            self._disconnect()
            self._client = None

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
