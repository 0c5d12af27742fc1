"""The typed contract of a robot's model: what model-based plugins may ask of it.

``RobotSpec.model`` and ``PathProblem.model`` hold a :class:`RobotModel` (for a
manipulator, :class:`~dcsim.robots.manipulator.ManipulatorModel`) or None (a free
flyer). The protocol lists exactly what the built-in model-based plugins call: the
computed-torque controllers take ``M(q)`` and ``C(q, q̇)``, the end-effector planners
take forward and inverse kinematics, ``det(J Jᵀ)`` and the arm's reach. A plugin
relies on these members alone; the messages check a model against the protocol when
they are built (:func:`check_robot_model`).

States follow the manipulator's conventions: ``q`` (7 + n,) is the base's centre of
mass (m), its attitude quaternion ``[x, y, z, w]`` and the joint angles (rad);
``q̇`` (6 + n,) is ``[v_base, ω_base, θ̇]`` (m/s, rad/s), world frame.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from dcsim.robots.manipulator import ForwardKinematics, InverseKinematicsResult

IKBase = Literal["held", "floating", "centre-of-mass"]
"""What moves in an inverse kinematics solution besides the joints (see
:meth:`RobotModel.inverse_kinematics`)."""


@runtime_checkable
class RobotModel(Protocol):
    """A robot's kinematic and dynamic model, as model-based plugins use it.

    ``isinstance(model, RobotModel)`` checks that every member is there (not their
    signatures); a type checker checks the signatures.
    """

    @property
    def n_joints(self) -> int:
        """Number of joints ``n``."""
        ...

    @property
    def reach(self) -> float:
        """Largest distance from the first joint's axis origin to the end effector, m."""
        ...

    def forward_kinematics(self, q: ArrayLike) -> ForwardKinematics:
        """Every joint frame and the end effector of state ``q`` (7 + n,), world frame."""
        ...

    def inverse_kinematics(
        self,
        target: ArrayLike,
        q0: ArrayLike,
        base: IKBase = "held",
        damping: float = 0.0,
        tolerance: float = 1e-10,
        max_iterations: int = 100,
        singular_tolerance: float = 1e-12,
    ) -> InverseKinematicsResult:
        """A state (7 + n,) from seed ``q0`` that puts the end effector at ``target`` (m,
        world frame) within ``tolerance`` (m), never raising on failure."""
        ...

    def det_jjt(self, q: ArrayLike, position_only: bool = False) -> float:
        """``det(J Jᵀ)`` of the arm's joint columns at state ``q``: zero at a kinematic
        singularity (m⁶ with ``position_only``)."""
        ...

    def dynamics(self, q: ArrayLike, qd: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``M(q)`` and ``C(q, q̇)``, each (6 + n, 6 + n), in the order of ``q̇``."""
        ...


_CONFORMING: set[type] = set()
"""Classes whose instances were found to be robot models."""


def check_robot_model(owner: str, model: object) -> None:
    """Raise unless ``model`` is None or satisfies :class:`RobotModel`.

    Parameters
    ----------
    owner : str
        What holds the model, for the message (e.g. ``"RobotSpec.model"``).
    model : object
        The model to check.

    Raises
    ------
    TypeError
        Naming the members ``model`` lacks.
    """
    if model is None or type(model) in _CONFORMING:
        return
    if isinstance(model, RobotModel):
        _CONFORMING.add(type(model))  # checked once per class: robot specs are made every tick
        return
    members = [name for name in vars(RobotModel) if not name.startswith("_")]
    missing = [name for name in members if not hasattr(model, name)]
    raise TypeError(
        f"{owner} must be None or a dcsim.api.RobotModel; {type(model).__name__} lacks "
        f"{', '.join(missing)}"
    )
