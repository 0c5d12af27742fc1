"""The exact orbital forces on the robot's PyBullet bodies in a ``two-body`` or ``j2`` world.

At the start of each control period the relative acceleration of every body the robot
is made of (its base, each carried object, each arm link) is expanded about that body's
state (:meth:`~dcsim.world.orbit.relative.RelativeDynamics.linearised`); every physics
step of the period then applies ``mass × acceleration`` at the body's centre of mass,
from its state at that step.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dcsim.world.orbit.frame import LvlhFrame
from dcsim.world.orbit.relative import AffineAcceleration, RelativeDynamics
from dcsim.world.pybullet_client import pb

Force = tuple[float, float, float]

FRAME_BLOCK = 128
"""Control periods whose frames are computed together."""


class ExactOrbitalForces:
    """Orbital forces on the robot's bodies, one linearisation per control period.

    Parameters
    ----------
    client : int
        PyBullet client id.
    dynamics : RelativeDynamics
        The chief's frame and the relative acceleration.
    physics_step : float
        s.
    steps_per_control : int
        Physics steps in a control period.
    """

    def __init__(
        self,
        client: int,
        dynamics: RelativeDynamics,
        physics_step: float,
        steps_per_control: int,
    ) -> None:
        self._client = client
        self.dynamics = dynamics
        self._step = physics_step
        self._steps_per_control = steps_per_control
        self._period = steps_per_control * physics_step
        self._frames: dict[int, LvlhFrame] = {}
        self._base: AffineAcceleration | None = None
        self._parts: list[tuple[int, int, float, AffineAcceleration]] = []
        self._previous: dict[tuple[int, int], tuple[float, ...]] = {}

    def _frame(self, period: int) -> LvlhFrame:
        """The frame at the start of control period ``period``; frames are computed
        :data:`FRAME_BLOCK` periods at a time, at the world's own clock
        (``steps × physics_step``)."""
        frame = self._frames.get(period)
        if frame is None:
            indices = range(period, period + FRAME_BLOCK)
            steps = np.array(indices) * self._steps_per_control
            frames = self.dynamics.frames(steps * self._step)
            self._frames = dict(zip(indices, frames, strict=True))
            frame = self._frames[period]
        return frame

    def stagger_velocity(self, body: int, physics_step: float) -> None:
        """Start the base's velocity half a physics step back: ``v₀ − a₀ Δt/2``.

        PyBullet's semi-implicit Euler step, ``v ← v + a Δt`` then ``x ← x + v Δt``, is
        the leapfrog scheme with the velocity taken half a step late; started from
        ``v₀`` instead of ``v(−Δt/2)`` it carries a velocity error of ``a₀ Δt/2`` for
        good, which a relative orbit turns into a position error growing with it. Started
        staggered, positions are second-order accurate.
        """
        position, velocity = self._state(body, -1)
        frame = self._frame(0)
        acceleration = self.dynamics.acceleration(
            frame, np.array([position]), np.array([velocity])
        )[0]
        angular = pb.getBaseVelocity(body, physicsClientId=self._client)[1]
        staggered = np.asarray(velocity) - 0.5 * physics_step * acceleration
        pb.resetBaseVelocity(body, staggered.tolist(), angular, physicsClientId=self._client)
        self._previous[(body, -1)] = tuple((staggered - physics_step * acceleration).tolist())

    def begin_period(
        self,
        t: float,
        base_state: tuple[np.ndarray, np.ndarray],
        parts: Sequence[tuple[int, int, float]],
    ) -> None:
        """Linearise every body's acceleration for the period starting at ``t`` (s).

        Parameters
        ----------
        t : float
            The period's start, s.
        base_state : (ndarray, ndarray)
            The base's position and velocity now, LVLH, m and m/s.
        parts : sequence of (int, int, float)
            The other bodies: body id, link index (-1 for a body's base) and mass (kg).
        """
        states = [base_state, *(self._state(b, link) for b, link, _ in parts)]
        rho = np.array([p for p, _ in states], dtype=float)
        rho_dot = np.array([v for _, v in states], dtype=float)
        period = round(t / self._period)
        fields = self.dynamics.linearised(
            self._frame(period), self._frame(period + 1), self._period, rho, rho_dot
        )
        self._base = fields[0]
        self._parts = [(b, link, m, f) for (b, link, m), f in zip(parts, fields[1:], strict=True)]

    def _state(self, body: int, link: int) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Position and velocity of a body's base (link -1) or a link's centre of mass."""
        client = self._client
        if link < 0:
            return (
                pb.getBasePositionAndOrientation(body, physicsClientId=client)[0],
                pb.getBaseVelocity(body, physicsClientId=client)[0],
            )
        state = pb.getLinkState(body, link, computeLinkVelocity=1, physicsClientId=client)
        return state[0], state[6]

    @property
    def base(self) -> AffineAcceleration:
        """The base's linearised acceleration this period."""
        assert self._base is not None, "begin_period first"
        return self._base

    def _on_step(self, key: tuple[int, int], velocity: tuple[float, ...]) -> tuple[float, ...]:
        """The velocity at the step's start, from PyBullet's, which is half a step late.

        The last step's change is extrapolated by half a step:
        ``v(t) ≈ v_PyBullet + (v_PyBullet − v_previous)/2`` (second order). Without it
        the Coriolis term would act on a velocity ``a Δt/2`` out, a first-order error.
        """
        u, v, w = self._previous.get(key, velocity)
        self._previous[key] = velocity
        x, y, z = velocity
        return (1.5 * x - 0.5 * u, 1.5 * y - 0.5 * v, 1.5 * z - 0.5 * w)

    def base_acceleration(
        self, tau: float, body: int, position: tuple[float, ...], velocity: tuple[float, ...]
    ) -> tuple[float, float, float]:
        """The base's orbital acceleration (m/s², LVLH) for the next physics step,
        ``tau`` (s) into the period, from PyBullet's reading of its state."""
        return self.base.at(tau, position, self._on_step((body, -1), velocity))

    @property
    def has_parts(self) -> bool:
        """Whether the robot has bodies besides its base this period (cargo, links)."""
        return bool(self._parts)

    def apply_to_parts(self, tau: float) -> None:
        """Apply each part's orbital force for the next physics step, ``tau`` (s) into
        the period, at its centre of mass (world frame)."""
        client = self._client
        for body, link, mass, field in self._parts:
            position, velocity = self._state(body, link)
            ax, ay, az = field.at(tau, position, self._on_step((body, link), velocity))
            pb.applyExternalForce(
                body, link, (mass * ax, mass * ay, mass * az), position, pb.WORLD_FRAME, client
            )
