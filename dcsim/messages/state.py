"""Messages about the robot itself: its state, the belief about it, commands and limits.

Every robot is a base (a rigid body) with an optional chain of joints: a free flyer has
no joints, a manipulator has the joints of its arm. Vectors are read-only float arrays
in the world frame, base quantities at the base's centre of mass; quaternions are
``[x, y, z, w]``; times are scenario seconds. A manipulator's generalised velocity is
ordered ``[v_base, ω_base, θ̇]``.
"""

from __future__ import annotations

import numpy as np

from dcsim.geometry import Vector, length
from dcsim.messages.base import Message, array_field, message
from dcsim.robots.model import RobotModel, check_robot_model

_UNIT_TOLERANCE = 1e-6


@message
class RobotState(Message):
    """The state of a robot's base and joints at one instant.

    Attributes
    ----------
    time : float
        s.
    position : ndarray (3,)
        Base centre of mass, m.
    attitude : ndarray (4,)
        Base attitude, unit quaternion ``[x, y, z, w]`` (body to world).
    velocity : ndarray (3,)
        Base velocity, m/s.
    angular_velocity : ndarray (3,)
        Base angular velocity, world frame, rad/s.
    joint_positions, joint_velocities : ndarray (n,)
        Joint angles (rad) or displacements (m) and their rates; empty for a free flyer.
    """

    time: float = 0.0
    position: Vector = array_field(default=(0.0, 0.0, 0.0))
    attitude: Vector = array_field(shape=(4,), default=(0.0, 0.0, 0.0, 1.0))
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    angular_velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    joint_positions: Vector = array_field(shape=(-1,), default=())
    joint_velocities: Vector = array_field(shape=(-1,), default=())

    def __post_init__(self) -> None:
        super().__post_init__()
        norm = length(self.attitude)
        if abs(norm - 1.0) > _UNIT_TOLERANCE:
            raise ValueError(
                f"{type(self).__name__}.attitude must be a unit quaternion, its norm is {norm:g}"
            )
        if self.joint_positions.shape != self.joint_velocities.shape:
            raise ValueError(
                f"{type(self).__name__} has {len(self.joint_positions)} joint positions "
                f"but {len(self.joint_velocities)} joint velocities"
            )

    @property
    def generalised_velocity(self) -> Vector:
        """``[v_base, ω_base, θ̇]``, shape (6 + n,), SI units."""
        return np.concatenate([self.velocity, self.angular_velocity, self.joint_velocities])

    @property
    def configuration(self) -> Vector:
        """``q = [r_base, quaternion x, y, z, w, θ]``, shape (7 + n,): the configuration a
        manipulator's model takes (base centre of mass in m, joint angles in rad)."""
        return np.concatenate([self.position, self.attitude, self.joint_positions])


@message
class StateEstimate(RobotState):
    """A localiser's belief about the robot: a state with its covariance.

    Attributes
    ----------
    covariance : ndarray (k, k)
        Covariance of the estimated components, in the order position, velocity (m²
        and (m/s)² blocks) for a localiser that estimates the translation only.
    converged : bool
        True once the localiser trusts its estimate (the thesis publishes only then).
    """

    covariance: Vector = array_field(shape=(-1, -1), default=np.eye(6))
    converged: bool = False

    def __post_init__(self) -> None:
        super().__post_init__()
        rows, columns = self.covariance.shape
        if rows != columns:
            raise ValueError(f"StateEstimate.covariance must be square, got {rows}×{columns}")

    def as_state(self, time: float | None = None) -> RobotState:
        """The estimated state alone, at ``time`` (s) if given, else at the estimate's time."""
        return RobotState(
            self.time if time is None else time,
            self.position,
            self.attitude,
            self.velocity,
            self.angular_velocity,
            self.joint_positions,
            self.joint_velocities,
        )


@message
class Prior(Message):
    """The initial belief a localiser is reset with.

    Attributes
    ----------
    position : ndarray (3,)
        Expected position, m.
    position_sigma : float
        Standard deviation of the position about ``position`` per axis, m.
    velocity : ndarray (3,)
        Expected velocity, m/s.
    velocity_sigma : float
        Standard deviation of the velocity per axis, m/s.
    """

    position: Vector = array_field()
    position_sigma: float = 1.0
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    velocity_sigma: float = 0.1


@message
class MotionInput(Message):
    """What the robot was commanded to do over the last interval.

    Attributes
    ----------
    acceleration : ndarray (3,)
        Commanded linear acceleration actually applied (force after limits divided by
        the robot's mass), world frame, m/s².
    """

    acceleration: Vector = array_field(default=(0.0, 0.0, 0.0))


@message
class Reference(Message):
    """What a controller should track at one instant.

    Attributes
    ----------
    time : float
        s.
    position, velocity : ndarray (3,)
        Reference base state, m and m/s.
    acceleration : ndarray (3,)
        Feed-forward linear acceleration, m/s².
    attitude : ndarray (4,) or None
        Reference attitude ``[x, y, z, w]``; None leaves the attitude free (no torque
        is asked for it).
    angular_velocity, angular_acceleration : ndarray (3,)
        Reference angular velocity (rad/s) and feed-forward angular acceleration
        (rad/s²), world frame; used with ``attitude``.
    joint_positions, joint_velocities, joint_accelerations : ndarray (n,)
        Joint references and feed-forward; empty when no joint is tracked.
    max_speed : float
        Speed not to exceed, m/s (``inf``: the robot's own limit applies); the debris
        mission lowers it on the way to the drop point (the thesis's DROP_SPEED).
    max_angular_rate : float
        Angular rate not to exceed, rad/s (``inf``: the robot's own limit applies).
    """

    time: float
    position: Vector = array_field()
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    acceleration: Vector = array_field(default=(0.0, 0.0, 0.0))
    attitude: Vector | None = array_field(shape=(4,), default=None, optional=True)
    angular_velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    angular_acceleration: Vector = array_field(default=(0.0, 0.0, 0.0))
    joint_positions: Vector = array_field(shape=(-1,), default=())
    joint_velocities: Vector = array_field(shape=(-1,), default=())
    joint_accelerations: Vector = array_field(shape=(-1,), default=())
    max_speed: float = float("inf")
    max_angular_rate: float = float("inf")


@message
class Command(Message):
    """What the actuators apply over one control period.

    Attributes
    ----------
    force : ndarray (3,)
        Thrust on the base, world frame, N (with thrusters, allocated to them).
    torque : ndarray (3,)
        Torque on the base, world frame, N·m (with reaction wheels or thrusters,
        allocated to them).
    joint_torques : ndarray (n,)
        Joint torques (N·m) or forces (N); empty for a free flyer.
    thruster_on_times : ndarray (N,)
        Each thruster's firing time from the control period's start, s, in the order
        of ``robot.actuators.thrusters``; given, it replaces the allocation of ``force``
        (and of ``torque`` without wheels). Empty: allocate.
    wheel_torques : ndarray (N,)
        Each reaction wheel's torque about its spin axis, N·m (the base receives the
        reaction), in the order of ``robot.actuators.reaction_wheels``; given, it
        replaces the allocation of ``torque``. Empty: allocate.
    """

    force: Vector = array_field(default=(0.0, 0.0, 0.0))
    torque: Vector = array_field(default=(0.0, 0.0, 0.0))
    joint_torques: Vector = array_field(shape=(-1,), default=())
    thruster_on_times: Vector = array_field(shape=(-1,), default=())
    wheel_torques: Vector = array_field(shape=(-1,), default=())


@message
class RobotSpec(Message):
    """The robot's physical properties and limits, as planners and controllers need them.

    Attributes
    ----------
    mass : float
        Current mass of the base and anything it carries, kg.
    inertia : ndarray (3, 3)
        Inertia tensor about the centre of mass of the base and any cargo it holds
        (each object a uniform solid of its shape), body axes, kg·m²; a manipulator's
        arm is in ``model``.
    radius : float
        Radius of a sphere about the base's centre that holds it and any cargo, m.
    max_force : float
        Largest thrust magnitude, N.
    max_torque : float
        Largest base torque magnitude, N·m. With reaction wheels
        (``robot.actuators``), at most the largest they deliver exactly in every
        direction (the weakest direction of their minimum-norm allocation); larger
        commands are clipped wheel by wheel, and a wheel at its momentum limit gives
        less. With thrusters and no wheels, at most their torque about the weakest body
        axis.
    max_speed : float
        Speed the robot must not exceed, m/s.
    max_angular_rate : float
        Angular rate the base must not exceed, rad/s (``inf``: no limit).
    joint_position_limits : ndarray (n, 2)
        Lower and upper limit of each joint, rad or m; no rows for a free flyer.
    joint_torque_limits : ndarray (n,)
        Largest torque (N·m) or force (N) of each joint.
    thruster_forces, thruster_torques : ndarray (3, N)
        Each thruster's force (N) and torque about the centre of mass (N·m) at full
        thrust, body frame, as columns in the order of ``robot.actuators.thrusters``; no
        columns without thrusters. A command's on-time ``t_i`` over a control period
        ``T`` gives the mean force ``Σ (t_i / T) thruster_forces[:, i]``.
    wheel_axes : ndarray (3, N)
        Each reaction wheel's unit spin axis, body frame, as columns; no columns without
        wheels. A wheel torque ``τ_i`` gives the base ``-τ_i wheel_axes[:, i]``.
    model : RobotModel or None
        The robot's model for model-based plugins (for a manipulator its
        :class:`~dcsim.robots.manipulator.ManipulatorModel`: kinematics, ``det(J Jᵀ)``,
        mass and Coriolis matrices); None for a free flyer.
    held_mass : float
        Mass of a body a manipulator's end effector holds rigidly (a captured target),
        kg; 0 when it holds none. It is part of ``mass`` but not of ``model``.

    Raises
    ------
    TypeError
        If ``model`` is neither None nor a :class:`~dcsim.robots.model.RobotModel`.
    """

    mass: float
    inertia: Vector = array_field(shape=(3, 3))
    radius: float = 0.0
    max_force: float = 0.0
    max_torque: float = 0.0
    max_speed: float = 0.0
    max_angular_rate: float = float("inf")
    joint_position_limits: Vector = array_field(shape=(-1, 2), default=np.zeros((0, 2)))
    joint_torque_limits: Vector = array_field(shape=(-1,), default=())
    thruster_forces: Vector = array_field(shape=(3, -1), default=np.zeros((3, 0)))
    thruster_torques: Vector = array_field(shape=(3, -1), default=np.zeros((3, 0)))
    wheel_axes: Vector = array_field(shape=(3, -1), default=np.zeros((3, 0)))
    model: RobotModel | None = None
    held_mass: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_robot_model("RobotSpec.model", self.model)
