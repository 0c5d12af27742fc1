"""Denavit–Hartenberg description of a space manipulator: a rigid base carrying a serial
arm of revolute joints.

Convention (the source thesis's eq. 3.2, standard DH): frame ``i`` follows from frame
``i − 1`` by a rotation ``θ_i`` about ``z_{i−1}``, a translation ``d_i`` along
``z_{i−1}``, a translation ``a_i`` along the new ``x`` and a rotation ``α_i`` about it.
Joint ``i`` therefore turns about ``z_{i−1}`` through the origin of frame ``i − 1``, and
link ``i`` (the body that joint ``i`` moves) carries frame ``i``.

What the thesis leaves open is fixed here:

- frame 0 sits at ``r_q`` (base frame, from the base's centre of mass) with the base's
  axes;
- link ``i``'s centre of mass is the midpoint of its DH segment, from the origin of frame
  ``i − 1`` to the origin of frame ``i``;
- link ``i``'s principal axes of inertia are those of frame ``i`` (``x`` along the link);
- the end effector is the origin of frame ``n`` (with the axes of frame ``n``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

Vector = NDArray[np.float64]


def _check_moments(moments: Vector, owner: str) -> None:
    """Principal moments of a rigid body: positive, and each at most the sum of the other
    two (PyBullet drops an inertia that breaks this)."""
    if np.any(moments <= 0.0) or np.any(2.0 * moments > moments.sum() * (1.0 + 1e-12)):
        raise ValueError(
            f"{owner} principal moments of inertia must be positive and each at most the sum "
            f"of the other two, got {moments.tolist()}"
        )


def _vector(values: ArrayLike, size: int, name: str) -> Vector:
    array = np.array(values, dtype=float).reshape(-1)
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be {size} finite numbers, got {values!r}")
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class DHLink:
    """One link of the arm and the revolute joint that moves it.

    Attributes
    ----------
    a : float
        Link length: distance along ``x_i`` between the ``z_{i−1}`` and ``z_i`` axes, m.
    alpha : float
        Link twist: angle from ``z_{i−1}`` to ``z_i`` about ``x_i``, rad.
    d : float
        Link offset: coordinate of the origin of frame ``i`` along ``z_{i−1}``, m.
    mass : float
        Link mass, kg (> 0).
    inertia : ndarray (3,)
        Principal moments of inertia about the link's centre of mass along the axes of
        frame ``i`` (``x`` along the link), kg·m².
    theta_offset : float
        DH angle ``θ_i`` when the joint angle is zero, rad: ``θ_i = q_i + theta_offset``.
    joint_limits : tuple of float
        Lower and upper joint angle, rad (``±inf``: unlimited).
    torque_limit : float
        Largest joint torque magnitude, N·m (``inf``: unlimited).
    """

    a: float
    alpha: float
    d: float
    mass: float
    inertia: Vector
    theta_offset: float = 0.0
    joint_limits: tuple[float, float] = (-math.inf, math.inf)
    torque_limit: float = math.inf

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia", _vector(self.inertia, 3, "inertia"))
        if not self.mass > 0.0:
            raise ValueError(f"link mass must be positive, got {self.mass}")
        _check_moments(self.inertia, "link")
        lower, upper = self.joint_limits
        if not lower <= upper:
            raise ValueError(f"joint limits must be (lower, upper), got {self.joint_limits}")
        if not self.torque_limit > 0.0:
            raise ValueError(f"torque limit must be positive, got {self.torque_limit}")


@dataclass(frozen=True)
class ManipulatorBase:
    """The rigid base (the satellite) that carries the arm.

    Attributes
    ----------
    mass : float
        Base mass, kg.
    inertia : ndarray (3,)
        Principal moments of inertia about the base's centre of mass along the base's
        axes, kg·m².
    size : ndarray (3,)
        Edge lengths of the base's box, centred on its centre of mass, m.
    mount : ndarray (3,)
        ``r_q``: the origin of DH frame 0 (the first joint's frame) from the base's centre
        of mass, base frame, m. Frame 0 has the base's axes.
    """

    mass: float
    inertia: Vector
    size: Vector = field(default_factory=lambda: np.ones(3))
    mount: Vector = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia", _vector(self.inertia, 3, "base inertia"))
        object.__setattr__(self, "size", _vector(self.size, 3, "base size"))
        object.__setattr__(self, "mount", _vector(self.mount, 3, "base mount"))
        if not self.mass > 0.0 or np.any(self.size <= 0.0):
            raise ValueError("base mass and size must be positive")
        _check_moments(self.inertia, "base")


@dataclass(frozen=True)
class DHRobot:
    """A space manipulator: its base and the DH table of its arm.

    Attributes
    ----------
    base : ManipulatorBase
        The base.
    links : tuple of DHLink
        The arm's links, from the base outwards (at least one).
    name : str
        Robot name (the URDF's ``robot`` name).
    """

    base: ManipulatorBase
    links: tuple[DHLink, ...]
    name: str = "manipulator"

    def __post_init__(self) -> None:
        object.__setattr__(self, "links", tuple(self.links))
        if not self.links:
            raise ValueError("a manipulator needs at least one link")

    @property
    def n_joints(self) -> int:
        """Number of joints (and links) of the arm."""
        return len(self.links)

    def column(self, name: str) -> Vector:
        """One attribute of every link as an array, e.g. ``column("a")`` (n,)."""
        return np.array([getattr(link, name) for link in self.links], dtype=float)

    @property
    def reach(self) -> float:
        """Largest distance of the end effector from the first joint's origin, m (the sum
        of the DH segments' lengths ``√(a² + d²)``)."""
        return float(np.hypot(self.column("a"), self.column("d")).sum())


def thesis_manipulator() -> DHRobot:
    """The source thesis's robot (its Tables 7.1–7.2 and eq. 7.1).

    A 1 m cube base of 1000 kg (166.67 kg·m² about each axis) carrying a 3 m, six-joint
    arm: ``a = 0.7, 0.4, 0.4, 0.4, 0.4, 0.7`` m, ``α = π/2, 0, π/2, π/2, 0, 0``, ``d = 0``,
    link masses 20, 15, 15, 15, 15, 20 kg, first joint at ``r_q = (0.5, 0, 0)`` m. The
    thesis gives no joint or torque limits: they are unlimited here.

    Returns
    -------
    DHRobot
    """
    half_pi = 0.5 * math.pi
    table = [
        (0.7, half_pi, 20.0, (0.2, 1.87, 1.87)),
        (0.4, 0.0, 15.0, (0.1, 1.25, 1.25)),
        (0.4, half_pi, 15.0, (0.1, 1.25, 1.25)),
        (0.4, half_pi, 15.0, (0.1, 1.25, 1.25)),
        (0.4, 0.0, 15.0, (0.1, 1.25, 1.25)),
        (0.7, 0.0, 20.0, (0.2, 1.87, 1.87)),
    ]
    links = tuple(
        DHLink(a=a, alpha=alpha, d=0.0, mass=mass, inertia=np.array(inertia))
        for a, alpha, mass, inertia in table
    )
    base = ManipulatorBase(
        mass=1000.0,
        inertia=np.array((166.67, 166.67, 166.67)),
        size=np.array((1.0, 1.0, 1.0)),
        mount=np.array((0.5, 0.0, 0.0)),
    )
    return DHRobot(base=base, links=links, name="thesis_manipulator")
