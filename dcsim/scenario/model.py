"""The scenario schema: typed, validated models of every section of a scenario file.

Units are SI unless the key says otherwise; angles are in degrees where the source
thesis uses degrees, with the unit in the key name (``polar_deg``, ``beta_deg_s``).
Unknown keys are errors, and so are NaN and infinite numbers. docs/scenarios.md is
generated from these models.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Annotated, Any, ClassVar, Literal, TypeVar

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Discriminator,
    Field,
    ModelWrapValidatorHandler,
    Tag,
    create_model,
    field_validator,
    model_validator,
)

from dcsim.geometry import Vector, spherical_to_cartesian
from dcsim.messages.planning import ChiefOrbit, FrameDynamics, FrameKind, OrbitModel
from dcsim.messages.sensing import Shape, ShapeKind
from dcsim.motion import (
    STANDARD_GRAVITATIONAL_PARAMETER_EARTH,
    ClohessyWiltshireMotion,
    LinearMotion,
    MotionModel,
    SphericalMotion,
    StaticMotion,
    mean_motion,
)
from dcsim.params import quantity
from dcsim.robots.dh import DHLink, DHRobot, ManipulatorBase

Vec3 = tuple[float, float, float]

PositiveVec3 = tuple[
    Annotated[float, Field(gt=0)], Annotated[float, Field(gt=0)], Annotated[float, Field(gt=0)]
]
"""Three positive numbers (lengths, moments), each > 0."""

MAX_STEPS_PER_CONTROL_PERIOD = 100_000
"""Most physics steps in one control period."""

MAX_PHYSICS_STEPS = 100_000_000
"""Most physics steps in a run (``world.duration / world.physics_step``)."""

MEAN_MOTION_RANGE = (1e-9, 0.1)
"""Least and largest mean motion of the reference orbit, rad/s (periods of 63 s to 200 years)."""

MAX_SEED = 2**31 - 1
"""Largest seed: the range of an FMI Integer, as the FMU's ``seed`` parameter is one."""

LVLH_AXES = ("radial", "along-track", "orbit-normal")
"""Names of the LVLH frame's x, y and z axes (x radial outward, y along-track, z along
the orbit's normal)."""

XYZ_AXES = ("x", "y", "z")
"""Names of the axes of any other frame."""


def frame_axes(frame: str) -> tuple[str, str, str]:
    """The names of world frame ``frame``'s x, y and z axes (``world.frame``'s value)."""
    return LVLH_AXES if frame == "lvlh" else XYZ_AXES


class Section(BaseModel):
    """Base of every scenario section: immutable, unknown keys and non-finite numbers rejected."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class SphericalPoint(Section):
    """A point in the thesis's spherical coordinates."""

    r: float = quantity(unit="m", ge=0, description="Radial distance from the origin.")
    polar_deg: float = quantity(unit="deg", description="Polar angle from +z.")
    azimuth_deg: float = quantity(unit="deg", description="Azimuth from +x towards +y.")


Point = Vec3 | SphericalPoint
"""A point given either as ``[x, y, z]`` (m) or as ``{r, polar_deg, azimuth_deg}``."""


def point_to_cartesian(point: Point) -> Vector:
    """Cartesian position (m) of a scenario point."""
    if isinstance(point, SphericalPoint):
        return spherical_to_cartesian(point.r, point.polar_deg, point.azimuth_deg)
    return np.array(point, dtype=float)


class StaticMotionSpec(Section):
    """An object at rest."""

    type: Literal["static"]
    position: Point = quantity(unit="m", description="Fixed position: [x, y, z] or spherical.")

    def build(self, mean_motion: float) -> MotionModel:
        """The motion model this spec describes."""
        return StaticMotion(point_to_cartesian(self.position))


class CartesianMotionSpec(Section):
    """Force-free straight-line motion from a Cartesian state at t = 0."""

    type: Literal["cartesian"]
    position: Point = quantity(unit="m", description="Position at t = 0.")
    velocity: Vec3 = quantity((0.0, 0.0, 0.0), unit="m/s", description="Constant velocity.")

    def build(self, mean_motion: float) -> MotionModel:
        """The motion model this spec describes."""
        return LinearMotion(point_to_cartesian(self.position), self.velocity)


class SphericalMotionSpec(Section):
    """The thesis's linear spherical model: r, θ, φ advance at v, α, β."""

    type: Literal["spherical"]
    r: float = quantity(unit="m", ge=0, description="Radial distance at t = 0.")
    polar_deg: float = quantity(unit="deg", description="Polar angle θ at t = 0.")
    azimuth_deg: float = quantity(unit="deg", description="Azimuth φ at t = 0.")
    v: float = quantity(0.0, unit="m/s", description="Radial speed.")
    alpha_deg_s: float = quantity(0.0, unit="deg/s", description="Polar rate α.")
    beta_deg_s: float = quantity(0.0, unit="deg/s", description="Azimuthal rate β.")

    def build(self, mean_motion: float) -> MotionModel:
        """The motion model this spec describes."""
        return SphericalMotion(
            self.r, self.polar_deg, self.azimuth_deg, self.v, self.alpha_deg_s, self.beta_deg_s
        )


class CWMotionSpec(Section):
    """Clohessy–Wiltshire relative motion from an LVLH state at t = 0 (frame ``lvlh`` only)."""

    type: Literal["cw"]
    position: Vec3 = quantity(
        unit="m", description="LVLH position at t = 0 (x radial, y along-track)."
    )
    velocity: Vec3 = quantity((0.0, 0.0, 0.0), unit="m/s", description="LVLH velocity at t = 0.")
    bounded: bool = Field(
        False,
        description="Replace the along-track velocity by the drift-free one for the world's "
        "orbit and model (−2 n x under `cw`; the chief's energy under `two-body` and `j2`).",
    )

    def build(self, mean_motion: float) -> MotionModel:
        """The motion model this spec describes (under ``cw``; a ``two-body`` or ``j2``
        world takes only its state at t = 0 and makes a bounded start drift-free in its
        own dynamics)."""
        velocity = self.velocity
        if self.bounded:
            velocity = (velocity[0], -2.0 * mean_motion * self.position[0], velocity[2])
        return ClohessyWiltshireMotion(self.position, velocity, mean_motion)


MotionSpec = Annotated[
    StaticMotionSpec | CartesianMotionSpec | SphericalMotionSpec | CWMotionSpec,
    Field(discriminator="type"),
]
"""A motion, chosen by its ``type`` key: static, cartesian, spherical or cw."""


EARTH_RADIUS = 6_378_137.0
"""Earth's equatorial radius (WGS 84), m."""

EARTH_J2 = 1.08262668e-3
"""Earth's second zonal harmonic J2 (dimensionless)."""

DEFAULT_ORBIT_RADIUS = 6_778_137.0
"""The default orbit's radius: 400 km above :data:`EARTH_RADIUS`, m."""

OrbitModelName = Literal["cw", "two-body", "j2"]
"""How bodies move relative to the chief: linearised (Clohessy–Wiltshire), exact
two-body, or exact two-body with Earth's J2."""


class OrbitSpec(Section):
    """The chief's orbit, whose LVLH frame is the world frame, and the relative dynamics.

    The frame is the chief's local-vertical local-horizontal frame at every instant: x
    along the chief's position, z along its orbital angular momentum, y = z × x (along
    track for a circular orbit). Under ``cw`` the orbit is circular and the relative
    motion linearised; under ``two-body`` and ``j2`` every body moves under the exact
    relative dynamics (J2 perturbs the chief too).
    """

    model: OrbitModelName = Field(
        "cw",
        description="Relative dynamics: `cw` (Clohessy–Wiltshire, circular orbit only), "
        "`two-body` (exact Keplerian) or `j2` (exact, with Earth's J2 on every body).",
    )
    radius: float | None = quantity(
        None,
        unit="m",
        gt=0,
        description="Semi-major axis (a circular orbit's radius); "
        f"{DEFAULT_ORBIT_RADIUS:,.0f} m (400 km up) when neither it nor altitude is given.",
    )
    altitude: float | None = quantity(
        None,
        unit="m",
        gt=0,
        description="Altitude of a circular orbit above earth_radius, instead of radius.",
    )
    eccentricity: float = quantity(
        0.0, ge=0, lt=1, description="Eccentricity (0 for `cw`, which is circular)."
    )
    inclination: float = quantity(51.6, unit="deg", ge=0, le=180, description="Inclination.")
    raan: float = quantity(
        0.0, unit="deg", ge=0, lt=360, description="Right ascension of the ascending node."
    )
    argument_of_perigee: float = quantity(
        0.0, unit="deg", ge=0, lt=360, description="Argument of perigee."
    )
    true_anomaly: float = quantity(
        0.0, unit="deg", ge=0, lt=360, description="The chief's true anomaly at t = 0."
    )
    mu: float = quantity(
        STANDARD_GRAVITATIONAL_PARAMETER_EARTH,
        unit="m^3/s^2",
        gt=0,
        description="Gravitational parameter of the central body.",
    )
    j2: float = quantity(
        EARTH_J2, ge=0, description="Second zonal harmonic of the central body (model `j2`)."
    )
    earth_radius: float = quantity(
        EARTH_RADIUS,
        unit="m",
        gt=0,
        description="Equatorial radius of the central body (J2's reference radius).",
    )
    cw_tolerance: float = quantity(
        0.1,
        unit="m",
        gt=0,
        description="Under `cw`: the linearisation error (estimated as 3 ρ² n t / a from "
        "the largest separation ρ and the time t flown) above which the run says that "
        "CW no longer holds.",
    )

    @property
    def semi_major_axis(self) -> float:
        """The orbit's semi-major axis, m (from ``radius``, ``altitude`` or the default)."""
        if self.radius is not None:
            return self.radius
        if self.altitude is not None:
            return self.earth_radius + self.altitude
        return DEFAULT_ORBIT_RADIUS

    @property
    def mean_motion(self) -> float:
        """Mean motion of the orbit, rad/s."""
        return mean_motion(self.semi_major_axis, self.mu)

    def chief_orbit(self) -> ChiefOrbit:
        """The orbit as a :class:`~dcsim.messages.ChiefOrbit`: SI units, angles in rad."""
        return ChiefOrbit(
            OrbitModel(self.model),
            self.semi_major_axis,
            self.eccentricity,
            math.radians(self.inclination),
            math.radians(self.raan),
            math.radians(self.argument_of_perigee),
            math.radians(self.true_anomaly),
            self.mu,
            self.j2,
            self.earth_radius,
        )


class WorldSpec(Section):
    """Frame, time steps and seed."""

    frame: Literal["lvlh", "geocentric"] = Field(
        "lvlh",
        description="lvlh: relative motion in the LVLH frame of world.orbit (its model: "
        "Clohessy–Wiltshire, two-body or j2); "
        "geocentric: the debris collector thesis's force-free spherical world.",
    )
    orbit: OrbitSpec = Field(
        default_factory=OrbitSpec,
        description="The chief's orbit and the relative dynamics (lvlh only); its mean "
        "motion is between "
        f"{MEAN_MOTION_RANGE[0]:g} and {MEAN_MOTION_RANGE[1]:g} rad/s.",
    )
    physics_step: float = quantity(
        0.01, unit="s", gt=0, le=1, description="Fixed physics time step."
    )
    control_period: float = quantity(
        0.1,
        unit="s",
        gt=0,
        description="Control period; a whole number of physics steps, at most "
        f"{MAX_STEPS_PER_CONTROL_PERIOD:,}.",
    )
    duration: float = quantity(
        600.0,
        unit="s",
        gt=0,
        description="Simulated time after which the run ends; at most "
        f"{MAX_PHYSICS_STEPS:,} physics steps.",
    )
    seed: int = quantity(
        0,
        ge=0,
        le=MAX_SEED,
        description="Seed of every random number in the run (it fits an FMU Integer).",
    )


class InitialStateSpec(Section):
    """The collector's state at t = 0."""

    position: Point = quantity(
        (0.0, 0.0, 0.0), unit="m", description="Position: [x, y, z] or spherical."
    )
    velocity: Vec3 = quantity((0.0, 0.0, 0.0), unit="m/s", description="Velocity.")
    attitude: tuple[float, float, float, float] = quantity(
        (0.0, 0.0, 0.0, 1.0), description="Attitude quaternion [x, y, z, w]."
    )
    angular_velocity: Vec3 = quantity(
        (0.0, 0.0, 0.0), unit="rad/s", description="Angular velocity."
    )
    position_sigma: float = quantity(
        1.0,
        unit="m",
        gt=0,
        description="Uncertainty of the position the localiser is told at start (per axis).",
    )
    velocity_sigma: float = quantity(
        0.05,
        unit="m/s",
        gt=0,
        description="Uncertainty of the velocity the localiser is told at start (per axis).",
    )


class RobotBaseSection(Section):
    """What every robot's base has: a type, a wet mass, thrusters fed by its propellant,
    a torque and a speed limit, and an object sensor. Each robot type's section derives
    from it (and states its own type, mass and propellant)."""

    type: str = Field(description="The robot type.")
    mass: float = quantity(unit="kg", gt=0, description="Mass, propellant included.")
    propellant_mass: float = quantity(0.0, unit="kg", ge=0, description="Usable propellant.")
    max_force: float = quantity(10.0, unit="N", gt=0, description="Largest thrust magnitude.")
    max_torque: float = quantity(
        1.0, unit="N*m", gt=0, description="Largest torque magnitude on the base."
    )
    max_speed: float = quantity(
        1.0, unit="m/s", gt=0, description="Speed guidance must not exceed."
    )
    specific_impulse: float = quantity(
        220.0, unit="s", gt=0, description="Thruster specific impulse."
    )
    sensor_range: float = quantity(
        200.0, unit="m", gt=0, description="Objects farther away are not tracked."
    )


def _rigid(moments: tuple[float, float, float]) -> tuple[float, float, float]:
    if any(2.0 * m > sum(moments) * (1.0 + 1e-12) for m in moments):
        raise ValueError("each principal moment must be at most the sum of the other two")
    return moments


Moments = Annotated[PositiveVec3, AfterValidator(_rigid)]
"""Principal moments of inertia of a rigid body: positive, each at most the sum of the others."""


def _no_tensor(value: Any) -> Any:
    if isinstance(value, list | tuple) and any(isinstance(row, list | tuple) for row in value):
        raise ValueError(
            "a full inertia tensor is not supported: give the three principal moments "
            "[Ixx, Iyy, Izz] along body axes that are the principal axes"
        )
    return value


def _nonzero_axis(axis: Vec3) -> Vec3:
    if sum(a * a for a in axis) < 1e-12:
        raise ValueError("the axis must not be zero")
    return axis


class WheelSpec(Section):
    """One reaction wheel: its spin axis in the body frame and its limits."""

    axis: Annotated[Vec3, AfterValidator(_nonzero_axis)] = quantity(
        description="Spin axis [x, y, z] in the body frame (normalised; not zero)."
    )
    inertia: float = quantity(
        unit="kg*m^2",
        gt=0,
        description="The wheel's moment of inertia about its spin axis; it gives the "
        "wheel's spin rate (momentum / inertia). The base's `inertia` includes the wheels' "
        "mass but not this: a wheel's momentum about its axis is counted apart.",
    )
    max_torque: float = quantity(unit="N*m", gt=0, description="Largest wheel torque magnitude.")
    max_momentum: float = quantity(
        unit="N*m*s",
        gt=0,
        description="Largest angular momentum magnitude about the spin axis; a wheel there "
        "gives no more torque in that direction (saturated).",
    )


def _spanning(wheels: list[WheelSpec]) -> list[WheelSpec]:
    axes = wheel_axes(wheels)
    singular = np.linalg.svd(axes, compute_uv=False)
    if singular[-1] < 1e-6 * singular[0]:
        raise ValueError("the wheels' axes must span three dimensions (no common plane)")
    return wheels


def wheel_axes(wheels: list[WheelSpec]) -> Vector:
    """The wheels' unit spin axes as the columns of a (3, N) matrix, body frame."""
    axes = np.array([wheel.axis for wheel in wheels], dtype=float).T
    return axes / np.linalg.norm(axes, axis=0)


class ThrusterSpec(Section):
    """One thruster: where it sits on the base, which way it pushes, its limits."""

    position: Vec3 = quantity(
        unit="m",
        description="Position [x, y, z] in the body frame, from the base's centre of mass.",
    )
    direction: Annotated[Vec3, AfterValidator(_nonzero_axis)] = quantity(
        description="Direction [x, y, z] of the force on the base, body frame (normalised; "
        "the plume leaves the other way)."
    )
    max_thrust: float = quantity(unit="N", gt=0, description="Thrust when on.")
    min_impulse_bit: float = quantity(
        0.0,
        unit="N*s",
        ge=0,
        description="Smallest impulse of one firing: shorter on-times are rounded to 0 or to "
        "it (docs/architecture.md, World).",
    )
    specific_impulse: float | None = quantity(
        None, unit="s", gt=0, description="Specific impulse; null: `robot.specific_impulse`."
    )


class UnloadingSpec(Section):
    """Momentum unloading: thrusters take the reaction wheels' momentum out.

    Unloading starts when a wheel's momentum passes ``start_fraction`` of its limit and
    stops when every wheel is below ``stop_fraction``; meanwhile the thrusters give the
    torque ``-H / time_constant`` (``H`` the wheels' momentum, body frame) and the wheels
    the rest of the commanded torque, so the base feels what was commanded while the
    wheels' momentum decays.
    """

    start_fraction: float = quantity(
        0.8, gt=0, le=1, description="Momentum fraction of any wheel that starts unloading."
    )
    stop_fraction: float = quantity(
        0.1, ge=0, lt=1, description="Momentum fraction every wheel is below when it stops."
    )
    time_constant: float = quantity(
        30.0, unit="s", gt=0, description="Time constant of the wheels' momentum decay."
    )

    @model_validator(mode="after")
    def _ordered(self) -> UnloadingSpec:
        if self.stop_fraction >= self.start_fraction:
            raise ValueError("stop_fraction must be below start_fraction")
        return self


_AXIS_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")


ThrusterKey = tuple[tuple[Vec3, Vec3, float], ...]
"""Each thruster's position, direction and maximum thrust: what its geometry depends on."""


def thruster_matrices(thrusters: list[ThrusterSpec]) -> tuple[Vector, Vector]:
    """Force (N) and torque (N·m) of each thruster at full thrust, body frame: the
    columns of two (3, N) matrices."""
    return _matrices(_thruster_key(thrusters))


def _thruster_key(thrusters: list[ThrusterSpec]) -> ThrusterKey:
    return tuple((t.position, t.direction, t.max_thrust) for t in thrusters)


def _matrices(thrusters: ThrusterKey) -> tuple[Vector, Vector]:
    positions = np.array([p for p, _, _ in thrusters], dtype=float)
    directions = np.array([d for _, d, _ in thrusters], dtype=float)
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    thrust = np.array([f for _, _, f in thrusters])
    return (directions * thrust[:, None]).T, (np.cross(positions, directions) * thrust[:, None]).T


def axis_capacities(produced: Vector, held: Vector) -> Vector:
    """The largest output along each body axis, +x, -x, +y, -y, +z, -z, that thrusts
    between zero and full give while the other output stays zero (a linear programme
    per axis; 0 where none).

    Parameters
    ----------
    produced : ndarray (3, N)
        What each thruster gives at full thrust of the output asked for (force or torque).
    held : ndarray (3, N)
        What each gives of the output held at zero.
    """
    from scipy.optimize import linprog  # imported here: only validation needs it

    n = produced.shape[1]
    capacities = []
    for axis in np.vstack([np.eye(3), -np.eye(3)])[[0, 3, 1, 4, 2, 5]]:
        # variables: duty cycles u (N) and the magnitude s; maximise s
        equality = np.block([[produced, -axis[:, None]], [held, np.zeros((3, 1))]])
        result = linprog(
            np.r_[np.zeros(n), -1.0],
            A_eq=equality,
            b_eq=np.zeros(6),
            bounds=[(0.0, 1.0)] * n + [(0.0, None)],
            method="highs",
        )
        capacities.append(float(result.x[-1]) if result.status == 0 else 0.0)
    return np.array(capacities)


def thruster_capacities(thrusters: list[ThrusterSpec]) -> tuple[Vector, Vector]:
    """The largest force (N) along, and torque (N·m) about, each body axis direction
    (+x, -x, +y, -y, +z, -z) the thrusters give with the other held at zero
    (:func:`axis_capacities`), each (6,), read-only (a layout's are computed once)."""
    return _capacities(_thruster_key(thrusters))


@functools.lru_cache(maxsize=32)
def _capacities(thrusters: ThrusterKey) -> tuple[Vector, Vector]:
    forces, torques = _matrices(thrusters)
    capacities = axis_capacities(forces, torques), axis_capacities(torques, forces)
    for array in capacities:
        array.setflags(write=False)
    return capacities


def _thrusters_push_every_way(thrusters: list[ThrusterSpec]) -> list[ThrusterSpec]:
    missing = []
    force_capacities, torque_capacities = thruster_capacities(thrusters)
    for what, capacities in (("force", force_capacities), ("torque", torque_capacities)):
        weak = [name for name, c in zip(_AXIS_NAMES, capacities, strict=True) if c <= 1e-9]
        if weak:
            missing.append(f"no {what} along {', '.join(weak)}")
    if missing:
        raise ValueError(
            "the thrusters must give a force along every body axis without a torque, and "
            f"a torque about every axis without a force; they give {'; '.join(missing)}"
        )
    return thrusters


class ActuatorsSpec(Section):
    """A robot base's actuators: thrusters, reaction wheels, both or neither (ideal).

    Without ``thrusters`` the commanded force is applied as it is (world frame, clipped
    to ``robot.max_force``); without ``reaction_wheels`` the commanded torque likewise,
    or by the thrusters when there are thrusters. With both, the thrusters give the
    force and unload the wheels, and the wheels the torque (docs/architecture.md, World).
    """

    thrusters: (
        Annotated[
            list[ThrusterSpec], Field(min_length=1), AfterValidator(_thrusters_push_every_way)
        ]
        | None
    ) = Field(
        None,
        description="Thrusters fixed to the base, giving a force along and a torque about "
        "every body axis; null: ideal thrust.",
    )
    reaction_wheels: (
        Annotated[list[WheelSpec], Field(min_length=3), AfterValidator(_spanning)] | None
    ) = Field(
        None,
        description="Reaction wheels, at least three, their axes spanning three dimensions; "
        "null: ideal torque (or the thrusters').",
    )
    unloading: UnloadingSpec = Field(
        default_factory=UnloadingSpec,
        description="When thrusters unload the wheels (used when both are given).",
    )

    @model_validator(mode="before")
    @classmethod
    def _no_type(cls, data: Any) -> Any:
        if isinstance(data, dict) and "type" in data:
            raise ValueError(
                "robot.actuators takes no `type`: list `reaction_wheels: [...]` and/or "
                "`thrusters: [...]` (neither: ideal force and torque)"
            )
        return data

    @property
    def ideal(self) -> bool:
        """Whether both force and torque are ideal (no thrusters, no wheels)."""
        return self.thrusters is None and self.reaction_wheels is None

    def torque_limit(self) -> float | None:
        """The largest torque magnitude, N·m, the attitude actuators deliver exactly about
        every body axis (the wheels' in every direction); None when torque is ideal.

        The wheels' minimum-norm allocation gives wheel ``i`` the torque ``(A⁺ t)_i`` for a
        body torque ``t``; it stays within ``max_torque_i`` for every direction of ``t``
        while ``|t| ≤ max_torque_i / |row i of A⁺|``. The smallest of these bounds the
        weakest direction. Thrusters alone: the smallest of their torques along the six
        body axis directions with zero force.
        """
        if self.reaction_wheels is not None:
            rows = np.linalg.norm(np.linalg.pinv(wheel_axes(self.reaction_wheels)), axis=1)
            limits = np.array([wheel.max_torque for wheel in self.reaction_wheels]) / rows
            return float(limits.min())
        if self.thrusters is not None:
            return float(thruster_capacities(self.thrusters)[1].min())
        return None

    def force_limit(self) -> float | None:
        """The largest force, N, the thrusters give along every body axis with zero torque
        (the smallest of the six axis directions' linear programmes); None when ideal."""
        if self.thrusters is None:
            return None
        return float(thruster_capacities(self.thrusters)[0].min())


class ActuatedRobotSection(RobotBaseSection):
    """A robot base with thrusters and reaction wheels (``actuators``), or ideal force
    and torque: what the free flyer and the manipulator's base share."""

    actuators: ActuatorsSpec = Field(
        default_factory=ActuatorsSpec,
        description="Thrusters and reaction wheels on the base; absent, ideal force and "
        "torque. With them, `max_force` and `max_torque` are theirs when left out (the "
        "largest given along every body axis); given, they must not exceed them.",
    )

    @model_validator(mode="wrap")
    @classmethod
    def _actuator_limits(cls, data: Any, handler: ModelWrapValidatorHandler[Any]) -> Any:
        """Fill in ``max_force`` and ``max_torque`` from the actuators when not given."""
        robot = handler(data)
        limits = {
            "max_force": robot.actuators.force_limit(),
            "max_torque": robot.actuators.torque_limit(),
        }
        update = {
            key: limit
            for key, limit in limits.items()
            if limit is not None and key not in robot.model_fields_set
        }
        return robot.model_copy(update=update) if update else robot


class RobotSection(ActuatedRobotSection):
    """The robot: a free flyer (the debris collector) with mass, limits, sensors, grabber."""

    type: Literal["free-flyer"] = Field(
        "free-flyer", description="The robot type: `free-flyer`, a rigid body with thrusters."
    )
    mass: float = quantity(100.0, unit="kg", gt=0, description="Initial mass, propellant included.")
    propellant_mass: float = quantity(
        10.0, unit="kg", ge=0, description="Usable propellant (part of mass)."
    )
    radius: float = quantity(1.0, unit="m", gt=0, description="Radius of the bounding sphere.")
    grab_distance: float = quantity(
        2.0, unit="m", gt=0, description="Largest centre distance at which a grab succeeds."
    )
    capacity: int = quantity(2, ge=1, description="Targets carried at once.")
    inertia: Annotated[Moments | None, BeforeValidator(_no_tensor)] = quantity(
        None,
        unit="kg*m^2",
        description="Principal moments of inertia [Ixx, Iyy, Izz] about the centre of mass, "
        "along the body axes, at the initial mass `mass`; each at most the sum of the "
        "other two. They scale with the mass as propellant burns (as a uniform body's "
        "would). A full 3x3 tensor is refused: turn the body axes to the principal axes. "
        "null: a uniform sphere's of `radius`, 2/5 m r^2.",
    )
    initial: InitialStateSpec = Field(
        default_factory=InitialStateSpec, description="State at t = 0."
    )


def robot_hardware(
    robot: RobotSection | ManipulatorSection,
) -> tuple[list[ThrusterSpec], list[WheelSpec]]:
    """The thrusters and the reaction wheels of a scenario's robot's base, in the
    scenario's order (none for ideal force and torque)."""
    return list(robot.actuators.thrusters or ()), list(robot.actuators.reaction_wheels or ())


def _ordered(limits: tuple[float, float]) -> tuple[float, float]:
    if not limits[0] <= limits[1]:
        raise ValueError("give [lower, upper], lower at most upper")
    return limits


Limits = Annotated[tuple[float, float], AfterValidator(_ordered)]
"""A lower and an upper limit."""


class ManipulatorInitialSpec(InitialStateSpec):
    """The manipulator's state at t = 0: its base's (as a free flyer's) and its joints'."""

    joint_angles_deg: list[float] | None = quantity(
        None,
        unit="deg",
        description="Joint angles, one per link of `links`; null: all zero.",
    )
    joint_rates_deg_s: list[float] | None = quantity(
        None,
        unit="deg/s",
        description="Joint rates, one per link of `links`; null: all zero.",
    )


class DHLinkSpec(Section):
    """One row of the arm's Denavit–Hartenberg table: a revolute joint and the link it moves.

    The link's centre of mass is the midpoint of its DH segment and its principal axes
    are those of DH frame i (x along the link); see docs/architecture.md.
    """

    a: float = quantity(unit="m", description="Link length along x_i.")
    alpha_deg: float = quantity(unit="deg", description="Link twist about x_i.")
    d: float = quantity(0.0, unit="m", description="Link offset along z_(i-1).")
    theta_offset_deg: float = quantity(
        0.0, unit="deg", description="DH angle θ_i when the joint angle is zero."
    )
    mass: float = quantity(unit="kg", gt=0, description="Link mass.")
    inertia: Moments = quantity(
        unit="kg*m^2",
        description="Principal moments of inertia about the link's centre of mass, along "
        "the axes of DH frame i; each at most the sum of the other two.",
    )
    position_limits_deg: Limits | None = quantity(
        None, unit="deg", description="Lower and upper joint angle; null: unlimited."
    )
    torque_limit: float | None = quantity(
        None, unit="N*m", gt=0, description="Largest joint torque magnitude; null: unlimited."
    )

    def build(self) -> DHLink:
        """The link in SI units (radians)."""
        lower, upper = self.position_limits_deg or (-math.inf, math.inf)
        return DHLink(
            a=self.a,
            alpha=math.radians(self.alpha_deg),
            d=self.d,
            mass=self.mass,
            inertia=np.array(self.inertia),
            theta_offset=math.radians(self.theta_offset_deg),
            joint_limits=(math.radians(lower), math.radians(upper)),
            torque_limit=math.inf if self.torque_limit is None else self.torque_limit,
        )


class GripperSpec(Section):
    """A two-pad gripper at the arm's end effector: a palm and two pads that close on a
    grapple bar with PyBullet contact and friction (docs/architecture.md, Capture).

    The palm's back face sits on DH frame n; the pads' centres are ``reach`` ahead of it
    along x_n and close towards each other along y_n, so a bar held between them lies
    along z_n.
    """

    palm_mass: float = quantity(2.0, unit="kg", gt=0, description="Mass of the palm.")
    palm_size: PositiveVec3 = quantity(
        (0.05, 0.24, 0.10),
        unit="m",
        description="Edge lengths of the palm's box along x_n, y_n and z_n.",
    )
    pad_mass: float = quantity(0.5, unit="kg", gt=0, description="Mass of each pad.")
    pad_size: PositiveVec3 = quantity(
        (0.08, 0.02, 0.08),
        unit="m",
        description="Edge lengths of each pad's box along x_n, y_n (its thickness) and z_n.",
    )
    reach: float = quantity(
        0.15, unit="m", gt=0, description="Distance from DH frame n to the pads' centres along x_n."
    )
    opening: float = quantity(0.16, unit="m", gt=0, description="Gap between the pads when open.")
    closing_time: float = quantity(
        1.0, unit="s", gt=0, description="Time the pads take from open to touching."
    )
    grip_force: float = quantity(
        150.0, unit="N", gt=0, description="Largest force each pad's drive pushes with."
    )
    friction: float = quantity(
        0.8, unit="1", gt=0, description="Coefficient of friction between pad and bar."
    )
    force_limit: float = quantity(
        1500.0,
        unit="N",
        gt=0,
        description="Largest contact or latch force the gripper is built to take; a run "
        "records whether it was exceeded.",
    )

    @model_validator(mode="after")
    def _pads_fit(self) -> GripperSpec:
        if self.reach <= 0.5 * self.palm_size[0] + 0.5 * self.pad_size[0]:
            raise ValueError("`reach` must put the pads ahead of the palm's front face")
        if self.opening + 2.0 * self.pad_size[1] > self.palm_size[1] + 1e-12:
            raise ValueError("the open pads must fit within the palm's width (`palm_size[1]`)")
        return self


class ManipulatorSection(ActuatedRobotSection):
    """The robot: a space manipulator, a satellite base carrying an arm of revolute joints.

    The base flies as a free flyer does (thrust from propellant, torque from reaction
    wheels); the arm is described by its DH table (docs/architecture.md, Robots).
    """

    type: Literal["manipulator"] = Field(
        description="The robot type: `manipulator`, a base with a DH arm."
    )
    mass: float = quantity(unit="kg", gt=0, description="Base mass, propellant included.")
    propellant_mass: float = quantity(
        0.0, unit="kg", ge=0, description="Usable propellant (part of the base's mass)."
    )
    inertia: Moments = quantity(
        unit="kg*m^2",
        description="Principal moments of inertia of the base about its centre of mass, "
        "along its axes; each at most the sum of the other two.",
    )
    size: PositiveVec3 = quantity(
        (1.0, 1.0, 1.0), unit="m", description="Edge lengths of the base's box (centred)."
    )
    mount: Vec3 = quantity(
        (0.0, 0.0, 0.0),
        unit="m",
        description="r_q: the first joint's frame (DH frame 0) from the base's centre of "
        "mass, base frame; frame 0 has the base's axes.",
    )
    links: list[DHLinkSpec] = Field(
        min_length=1, description="The DH table, one row per joint, from the base outwards."
    )
    initial: ManipulatorInitialSpec = Field(
        default_factory=ManipulatorInitialSpec, description="State at t = 0."
    )
    gripper: GripperSpec | None = Field(
        None, description="A gripper at the end effector; null: a bare end effector."
    )

    grab_distance: ClassVar[float] = 0.0
    """A manipulator grabs nothing through the world's grab service."""
    capacity: ClassVar[int] = 0

    @property
    def radius(self) -> float:
        """Radius of a sphere about the base's centre of mass holding base and arm, m."""
        reach = float(np.hypot([k.a for k in self.links], [k.d for k in self.links]).sum())
        half_diagonal = 0.5 * float(np.linalg.norm(self.size))
        return max(half_diagonal, float(np.linalg.norm(self.mount)) + reach)

    def dh_robot(self) -> DHRobot:
        """The robot's DH description in SI units (radians)."""
        base = ManipulatorBase(
            mass=self.mass,
            inertia=np.array(self.inertia),
            size=np.array(self.size),
            mount=np.array(self.mount),
        )
        return DHRobot(base=base, links=tuple(link.build() for link in self.links))

    def initial_joints(self) -> tuple[Vector, Vector]:
        """Initial joint angles (rad) and rates (rad/s) (zero where not given).

        Raises
        ------
        ValueError
            If a list does not have one value per link (the loader reports it first).
        """
        n = len(self.links)
        for values in (self.initial.joint_angles_deg, self.initial.joint_rates_deg_s):
            if values is not None and len(values) != n:
                raise ValueError(f"{len(values)} initial joint values for {n} links")
        angles, rates = self.initial.joint_angles_deg, self.initial.joint_rates_deg_s
        return (
            np.radians(np.zeros(n) if angles is None else np.asarray(angles, dtype=float)),
            np.radians(np.zeros(n) if rates is None else np.asarray(rates, dtype=float)),
        )


def _robot_type(data: Any) -> str | None:
    """The tag of a robot section: its ``type`` (``free-flyer`` when absent)."""
    if isinstance(data, dict):
        value = data.get("type", "free-flyer")
        return value if isinstance(value, str) else None
    return getattr(data, "type", "free-flyer")  # not a section: the default's error says so


AnyRobotSection = Annotated[
    Annotated[RobotSection, Tag("free-flyer")] | Annotated[ManipulatorSection, Tag("manipulator")],
    Discriminator(
        _robot_type,
        custom_error_type="robot_type",
        custom_error_message="robot.type must be `free-flyer` or `manipulator`",
    ),
]
"""The robot section, chosen by its ``type`` key (``free-flyer`` when absent)."""


def _nonzero(quaternion: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    if sum(q * q for q in quaternion) < 1e-12:
        raise ValueError("the quaternion must not be zero")
    return quaternion


Quaternion = Annotated[tuple[float, float, float, float], AfterValidator(_nonzero)]
"""A rotation ``[x, y, z, w]``, any non-zero length (normalised where used)."""


def _unit(quaternion: Quaternion) -> Vector:
    q = np.array(quaternion, dtype=float)
    return q / np.linalg.norm(q)


def _orientation() -> Any:
    return quantity(
        (0.0, 0.0, 0.0, 1.0),
        description="Body-to-world rotation [x, y, z, w], fixed while the object moves "
        "(normalised; not zero).",
    )


class SphereShapeSpec(Section):
    """A sphere centred on the object's position."""

    type: Literal["sphere"]
    radius: float = quantity(unit="m", gt=0, description="Radius.")

    def build(self) -> Shape:
        """The shape this spec describes."""
        return Shape(ShapeKind.SPHERE, radius=self.radius)


class BoxShapeSpec(Section):
    """A box centred on the object's position, its body axes turned by `orientation`."""

    type: Literal["box"]
    half_extents: PositiveVec3 = quantity(
        unit="m", description="Half side lengths along the body x, y and z axes (each > 0)."
    )
    orientation: Quaternion = _orientation()

    def build(self) -> Shape:
        """The shape this spec describes."""
        return Shape(
            ShapeKind.BOX,
            half_extents=np.array(self.half_extents),
            orientation=_unit(self.orientation),
        )


class CylinderShapeSpec(Section):
    """A cylinder centred on the object's position, its axis the body z axis."""

    type: Literal["cylinder"]
    radius: float = quantity(unit="m", gt=0, description="Radius.")
    height: float = quantity(unit="m", gt=0, description="Full length along the body z axis.")
    orientation: Quaternion = _orientation()

    def build(self) -> Shape:
        """The shape this spec describes."""
        return Shape(
            ShapeKind.CYLINDER,
            radius=self.radius,
            height=self.height,
            orientation=_unit(self.orientation),
        )


ShapeSpec = Annotated[
    SphereShapeSpec | BoxShapeSpec | CylinderShapeSpec, Field(discriminator="type")
]
"""A collision shape, chosen by its ``type`` key: sphere, box or cylinder."""


class SpaceObjectSpec(Section):
    """A target or an obstacle.

    Without a ``shape`` the object is a sphere of ``radius``. With one, ``radius`` is the
    shape's bounding radius: it is filled in when omitted, and given anyway it must
    agree (a scenario written back out states both).
    """

    id: int = quantity(ge=0, description="Unique id among targets and obstacles.")
    radius: float = quantity(
        1.0,
        unit="m",
        gt=0,
        description="Radius of the sphere when there is no `shape`; with a `shape`, its "
        "bounding radius (leave it out: it is computed).",
    )
    mass: float = quantity(10.0, unit="kg", gt=0, description="Mass.")
    motion: MotionSpec = Field(description="How the object moves until grabbed.")
    shape: ShapeSpec | None = Field(
        None, description="Collision shape: sphere, box or cylinder; null for a sphere of `radius`."
    )

    @model_validator(mode="wrap")
    @classmethod
    def _bounding_radius(cls, data: Any, handler: ModelWrapValidatorHandler[Any]) -> Any:
        """Fill in ``radius`` from the shape when it is not given."""
        spec = handler(data)
        if spec.shape is not None and "radius" not in spec.model_fields_set:
            return spec.model_copy(update={"radius": spec.shape.build().bounding_radius})
        return spec

    def build_shape(self) -> Shape:
        """The object's collision shape (a sphere of ``radius`` when none is given)."""
        if self.shape is None:
            return Shape(ShapeKind.SPHERE, radius=self.radius)
        return self.shape.build()


def _inertia_tensor(value: Any) -> Any:
    """Three principal moments, or a symmetric 3x3 tensor, checked as a rigid body's."""
    if not all(isinstance(row, list | tuple) for row in value):
        return _rigid(value)
    matrix = np.array(value, dtype=float)
    if not np.allclose(matrix, matrix.T, rtol=1e-9, atol=0.0):
        raise ValueError("the inertia tensor must be symmetric")
    moments = np.linalg.eigvalsh(matrix)
    if moments[0] <= 0.0:
        raise ValueError("the inertia tensor must be positive definite")
    _rigid((float(moments[0]), float(moments[1]), float(moments[2])))
    return value


InertiaSpec = Annotated[PositiveVec3 | tuple[Vec3, Vec3, Vec3], AfterValidator(_inertia_tensor)]
"""A rigid body's inertia about its centre of mass: principal moments along its body axes,
or a full symmetric tensor in its body axes, kg·m²."""


class FixtureSpec(Section):
    """A grapple fixture: a bar on a target's body that a gripper closes on.

    The bar is a cylinder centred on ``position`` along ``bar_axis``; a gripper comes to
    it from outside along ``approach_axis`` (pointing out of the body), so the gripper's
    x_n points along ``-approach_axis`` and its z_n along ``bar_axis`` when it holds it.
    """

    position: Vec3 = quantity(unit="m", description="Bar centre, body frame.")
    approach_axis: Annotated[Vec3, AfterValidator(_nonzero_axis)] = quantity(
        description="Direction, body frame, from which the gripper comes (out of the body)."
    )
    bar_axis: Annotated[Vec3, AfterValidator(_nonzero_axis)] = quantity(
        description="The bar's long axis, body frame; at right angles to `approach_axis`."
    )
    radius: float = quantity(0.02, unit="m", gt=0, description="Bar radius.")
    length: float = quantity(0.2, unit="m", gt=0, description="Bar length.")

    @model_validator(mode="after")
    def _square(self) -> FixtureSpec:
        approach, bar = np.array(self.approach_axis), np.array(self.bar_axis)
        cosine = abs(approach @ bar) / (np.linalg.norm(approach) * np.linalg.norm(bar))
        if cosine > 1e-6:
            raise ValueError("`bar_axis` must be at right angles to `approach_axis`")
        return self


class TumblingBodySpec(Section):
    """A free rigid body that tumbles torque-free until something holds it (a capture
    target): its shape, mass, inertia, initial state and grapple fixture."""

    id: int = quantity(1, ge=0, description="Id of the body in tracks and events.")
    shape: BoxShapeSpec | CylinderShapeSpec = Field(
        discriminator="type",
        description="Collision shape (box or cylinder), centred on the centre of mass, "
        "along the body axes (its `orientation` must be the identity: turn the body "
        "with `attitude`).",
    )
    mass: float = quantity(unit="kg", gt=0, description="Mass.")
    inertia: InertiaSpec | None = quantity(
        None,
        unit="kg*m^2",
        description="Inertia about the centre of mass in body axes: three principal moments "
        "or a full tensor; null: a uniform solid of `shape`.",
    )
    position: Vec3 = quantity(unit="m", description="Centre of mass at t = 0, world frame.")
    velocity: Vec3 = quantity(
        (0.0, 0.0, 0.0), unit="m/s", description="Velocity, world frame (constant while free)."
    )
    attitude: Quaternion = quantity(
        (0.0, 0.0, 0.0, 1.0), description="Body-to-world rotation [x, y, z, w] at t = 0."
    )
    angular_velocity_deg_s: Vec3 = quantity(
        (0.0, 0.0, 0.0), unit="deg/s", description="Angular velocity at t = 0, body axes."
    )
    fixture: FixtureSpec = Field(description="The grapple fixture.")

    @field_validator("shape")
    @classmethod
    def _unturned(cls, shape: BoxShapeSpec | CylinderShapeSpec) -> BoxShapeSpec | CylinderShapeSpec:
        if not np.allclose(_unit(shape.orientation), (0.0, 0.0, 0.0, 1.0), atol=1e-12):
            raise ValueError(
                "a tumbling body's shape lies along its body axes: turn it with `attitude`"
            )
        return shape

    def inertia_tensor(self) -> Vector:
        """The inertia tensor (3, 3) about the centre of mass, body axes, kg·m²."""
        if self.inertia is None:
            return np.diag(self.shape.build().moments_of_inertia(self.mass))
        matrix = np.array(self.inertia, dtype=float)
        return matrix if matrix.ndim == 2 else np.diag(matrix)

    def unit_attitude(self) -> Vector:
        """``attitude`` normalised, [x, y, z, w]."""
        return _unit(self.attitude)


class BeaconsSection(Section):
    """Fixed localisation beacons and their range sensor."""

    positions: list[Point] = Field(
        default_factory=list, description="Beacon positions: [x, y, z] or spherical."
    )
    max_range: float | None = quantity(
        None, unit="m", gt=0, description="Beacons farther away give no range; null for unlimited."
    )
    noise_sigma: float = quantity(
        0.1, unit="m", ge=0, description="Standard deviation of the range noise."
    )
    report_nearest: int = quantity(
        3, ge=1, description="Ranges reported per step (the nearest beacons)."
    )


class PluginChoice(Section):
    """Which plugin fills a role, and its parameters."""

    plugin: str = Field(description="Registered plugin name (see `dcsim plugins`).")
    params: dict[str, Any] = Field(
        default_factory=dict, description="Plugin parameters (see the plugin's docs)."
    )


class SensorChoice(Section):
    """Which sensor model a sensor has, and its parameters."""

    model: str = Field(description="Registered sensor model name (see `dcsim plugins sensor`).")
    params: dict[str, Any] = Field(
        default_factory=dict, description="The model's parameters (see its docs)."
    )


SensingProfile = Literal["ideal", "realistic"]


class SensorsSection(Section):
    """The robot's sensors: each one's model, from the profile unless given here.

    A sensor given here replaces its profile's model (keeping the profile's parameters
    it does not set when the model is the same).

    Under the ``ideal`` profile (the default) the beacon ranges have white noise
    (``beacons.noise_sigma``) and nothing else, and the star tracker, the gyros and the
    object sensor report the truth (no model: the tracks are exact and no tracker runs).
    Under ``realistic`` each sensor has the model and the numbers of
    :data:`dcsim.scenario.sensors.REALISTIC` (their sources are named there and in
    docs/sensors.md).
    """

    profile: SensingProfile = Field(
        "ideal",
        description="`ideal` (white-noise beacon ranges, everything else exact) or "
        "`realistic` (docs/sensors.md).",
    )
    beacon_ranges: SensorChoice | None = Field(
        None, description="The beacon range sensor's model; null for the profile's."
    )
    star_tracker: SensorChoice | None = Field(
        None, description="The star tracker's model; null for the profile's."
    )
    gyros: SensorChoice | None = Field(
        None, description="The gyros' model; null for the profile's."
    )
    objects: SensorChoice | None = Field(
        None, description="The object sensor's model (lidar, camera); null for the profile's."
    )


class MissionSettings(Section):
    """Base of every mission type's section: ``type`` selects the mission.

    A mission's package declares its section as a subclass, with ``type`` a ``Literal``
    of its own name. ``role_defaults`` replaces the scenario's default plugin choice of
    a role for this mission; ``None`` makes the role optional (absent unless the file
    names a plugin). ``rules`` are the mission's checks across keys, run with the
    schema's (:data:`dcsim.scenario.loader.Rule`: each takes the scenario's
    :class:`~dcsim.scenario.loader.ScenarioValues` and gives ``(key path, message)``
    pairs).
    """

    role_defaults: ClassVar[dict[str, PluginChoice | None]] = {}
    rules: ClassVar[tuple[Callable[..., list[tuple[tuple[str | int, ...], str]]], ...]] = ()
    targets_key: ClassVar[str | None] = None
    """The section's key holding the targets the mission puts into the world (a list of
    objects, checked as the obstacles are); None when the mission has none."""
    body_key: ClassVar[str | None] = None
    """The section's key holding the one tumbling body the mission puts into the world
    (its id shares the objects' id space); None when the mission has none."""
    moved_keys: ClassVar[dict[tuple[str, ...], tuple[str, ...]]] = {}
    """Keys the mission's scenarios once had elsewhere, by old key path: a file that
    still has one is refused with an error naming the new place."""

    type: str = Field(
        "debris",
        description="The mission type: a built-in one (`debris`, `transfer`, `reach`, "
        "`hold`) or one an installed package adds.",
    )

    def target_specs(self) -> list[SpaceObjectSpec]:
        """The objects the mission puts into the world as its targets, beside the
        scenario's obstacles: its field named by :attr:`targets_key` (none without one)."""
        return [] if self.targets_key is None else list(getattr(self, self.targets_key))

    def tumbling_body(self) -> TumblingBodySpec | None:
        """The free rigid body with contact the mission puts into the world (a capture
        target): its field named by :attr:`body_key` (None without one)."""
        return None if self.body_key is None else getattr(self, self.body_key)


class StopSection(Section):
    """When a run ends before ``world.duration``."""

    on_collision: bool = Field(True, description="End the run at the first collision.")
    max_wall_time: float | None = quantity(
        None,
        unit="s",
        gt=0,
        description="End the run after this much wall-clock time; null for no limit.",
    )


SettingsT = TypeVar("SettingsT", bound=MissionSettings)


class Scenario(Section):
    """A complete scenario: world, robot, obstacles, sensors, plugins, mission, stop rules."""

    name: str = Field("unnamed", description="Short name of the scenario.")
    description: str = Field("", description="What the scenario shows.")
    world: WorldSpec = Field(default_factory=WorldSpec, description="Frame, steps and seed.")
    robot: AnyRobotSection = Field(
        default_factory=RobotSection,
        description="The robot; `type` selects it (default `free-flyer`).",
    )
    obstacles: list[SpaceObjectSpec] = Field(default_factory=list, description="Objects to avoid.")
    beacons: BeaconsSection = Field(
        default_factory=BeaconsSection, description="Localisation beacons."
    )
    localiser: PluginChoice = Field(
        default_factory=lambda: PluginChoice(plugin="trilateration"),
        description="Localiser plugin.",
    )
    task_planner: PluginChoice = Field(
        default_factory=lambda: PluginChoice(plugin="nearest"), description="Task planner plugin."
    )
    path_planner: PluginChoice = Field(
        default_factory=lambda: PluginChoice(plugin="straight-line"),
        description="Path planner plugin.",
    )
    controller: PluginChoice = Field(
        default_factory=lambda: PluginChoice(plugin="pd"), description="Controller plugin."
    )
    sensors: SensorsSection = Field(
        default_factory=SensorsSection,
        description="Sensor models: a profile (`ideal` or `realistic`) and any sensor's own.",
    )
    tracker: PluginChoice = Field(
        default_factory=lambda: PluginChoice(plugin="kalman"),
        description="Tracker plugin: turns the object sensor's detections into tracks "
        "(used when `sensors` has an object sensor model).",
    )
    mission: MissionSettings = Field(
        default_factory=MissionSettings,
        description="The mission and its settings; `type` selects it (default `debris`).",
    )
    stop: StopSection = Field(default_factory=StopSection, description="Stop rules.")

    def mission_as(self, settings: type[SettingsT]) -> SettingsT:
        """The ``mission`` section as the settings class of the mission that reads it.

        Parameters
        ----------
        settings : type of MissionSettings
            The mission's settings class (its ``Settings``).

        Raises
        ------
        TypeError
            If the section is not of that class (the scenario was not validated with
            its mission's model, :func:`scenario_model`).
        """
        if not isinstance(self.mission, settings):
            raise TypeError(
                f"the scenario's mission section is a {type(self.mission).__name__}, "
                f"not the {settings.__name__} its mission reads"
            )
        return self.mission

    @property
    def mean_motion(self) -> float:
        """Mean motion of the reference orbit, rad/s (used by ``cw`` motions)."""
        return self.world.orbit.mean_motion

    @property
    def frame_dynamics(self) -> FrameDynamics:
        """The free dynamics of the world's frame, as path planners are told them."""
        if self.world.frame != "lvlh":
            return FrameDynamics(FrameKind.INERTIAL)
        orbit = self.world.orbit
        if orbit.model == "cw":
            return FrameDynamics(FrameKind.CLOHESSY_WILTSHIRE, self.mean_motion)
        chief = orbit.chief_orbit()
        return FrameDynamics(FrameKind.CLOHESSY_WILTSHIRE, self.mean_motion, chief)


@functools.cache
def scenario_model(settings: type[MissionSettings]) -> type[Scenario]:
    """The scenario model whose ``mission`` section is ``settings``.

    :class:`Scenario` is generic in its mission; a scenario is validated with the model
    of its mission's section (the loader picks it by ``mission.type``).

    Parameters
    ----------
    settings : type of MissionSettings
        A mission type's section; its ``role_defaults`` replace the roles' default
        plugins. A section whose every key has a default is the scenario's default
        when the file has no ``mission``.
    """
    roles: dict[str, Any] = {
        role: (
            PluginChoice | None,
            Field(
                default, description=f"{role.replace('_', ' ').capitalize()} plugin; null: none."
            ),
        )
        for role, default in settings.role_defaults.items()
    }
    description = Scenario.model_fields["mission"].description
    if any(field.is_required() for field in settings.model_fields.values()):
        mission = Field(description=description)
    else:
        mission = Field(default_factory=settings, description=description)
    return create_model(
        "Scenario",
        __base__=Scenario,
        __doc__=Scenario.__doc__,
        mission=(settings, mission),
        **roles,
    )
