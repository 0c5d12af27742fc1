"""Free motion in the planning frame and plans made of impulsive burns.

Not a plugin itself; the burn planners of this package (``grid-astar``, ``multi-burn``)
share it.

:class:`FreeMotion`
    The state transition of the frame's free motion: straight lines in an inertial
    frame, the Clohessy–Wiltshire closed form in a local-vertical/local-horizontal frame
    (x radial, y along-track, z orbit normal; ẍ = 3n²x + 2nẏ, ÿ = −2nẋ, z̈ = −n²z).
    Over a duration τ the state moves as ``[r; v] ← Φ(τ) [r; v]`` with the 3 × 3 blocks
    ``Φ_rr, Φ_rv, Φ_vr, Φ_vv``. Everything is vectorised over leading axes.
Single burn (:meth:`FreeMotion.single_burn`)
    The velocity that carries the robot from ``r_A`` to ``r_B`` in τ,
    ``v_A⁺ = Φ_rv⁻¹ (r_B − Φ_rr r_A)``, and the velocity it arrives with,
    ``v_B⁻ = Φ_vr r_A + Φ_vv v_A⁺``. ``Φ_rv`` is singular at τ = 0 and, about a circular
    orbit, at nτ = π (the orbit-normal motion cannot be changed in half an orbit), so
    durations stay below :attr:`FreeMotion.longest_duration`.
Two burns (:meth:`FreeMotion.two_burn_delta_v`)
    The delta-v of the direct transfer from a state to a goal state in a given time: the
    burn at the start onto the single-burn arc, and the burn at the goal onto the goal's
    velocity.
:class:`BurnPlan`
    Waypoints joined by single-burn arcs: the burns, swept samples for collision checks,
    and the :class:`dcsim.api.Trajectory` that realises each impulsive burn with finite
    thrust (:meth:`BurnPlan.trajectory`).
:class:`SpeedLimits`
    The limits a burn planner keeps: the least and largest mean speed of a leg and the
    largest single burn, unset ones scaled from the problem's speed limit with the
    paper's Table 2 ratios.
Swept samples (:func:`swept_arcs`)
    Samples along free arcs close enough that a collision check at them, with the
    robot's sphere grown by the margin returned, covers the whole arc.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from dcsim.api import FrameDynamics, FrameKind, Trajectory

PAPER_SPEEDS = (0.09, 0.19, 0.2)
"""The paper's least speed, largest speed and largest single delta-v, ft/s (Table 2)."""
_BURN_SAMPLES = 5
"""Trajectory samples across each finite burn (its position is quadratic in time)."""
_NO_ARC = 1e3
"""Residual of the burn fit where the burns would leave a leg no time."""
_SHORTEST_BURN = 1e-3
"""Duration given to a burn when the acceleration is unlimited, s."""


@dataclass(frozen=True)
class FreeMotion:
    """The planning frame's free motion.

    Parameters
    ----------
    mean_motion : float
        Mean motion ``n`` of the circular reference orbit, rad/s; 0 for an inertial
        frame (force-free straight lines).
    """

    mean_motion: float = 0.0

    @classmethod
    def of(cls, frame: FrameDynamics) -> FreeMotion:
        """The free motion of a path problem's frame."""
        if frame.kind is FrameKind.CLOHESSY_WILTSHIRE:
            return cls(float(frame.mean_motion))
        return cls(0.0)

    @property
    def longest_duration(self) -> float:
        """Longest duration a single burn may span, s: 0.9 π / n (``inf`` when inertial)."""
        return math.inf if self.mean_motion == 0 else 0.9 * math.pi / self.mean_motion

    def blocks(self, durations: np.ndarray) -> tuple[np.ndarray, ...]:
        """The blocks ``Φ_rr, Φ_rv, Φ_vr, Φ_vv`` of the state transition over each duration.

        Parameters
        ----------
        durations : array_like
            Durations τ, s, any shape ``S``.

        Returns
        -------
        tuple of four ndarrays, shape ``S + (3, 3)``
            Position from position (-), position from velocity (s), velocity from position
            (1/s) and velocity from velocity (-).
        """
        tau = np.asarray(durations, dtype=float)
        shape = tau.shape + (3, 3)
        rr, rv, vr, vv = (np.zeros(shape) for _ in range(4))
        n = self.mean_motion
        if n == 0:
            eye = np.eye(3)
            rr[...] = eye
            rv[...] = tau[..., None, None] * eye
            vv[...] = eye
            return rr, rv, vr, vv
        nt = n * tau
        s, c = np.sin(nt), np.cos(nt)
        rr[..., 0, 0], rr[..., 1, 0], rr[..., 1, 1], rr[..., 2, 2] = 4 - 3 * c, 6 * (s - nt), 1, c
        rv[..., 0, 0], rv[..., 0, 1] = s / n, 2 * (1 - c) / n
        rv[..., 1, 0], rv[..., 1, 1], rv[..., 2, 2] = -2 * (1 - c) / n, (4 * s - 3 * nt) / n, s / n
        vr[..., 0, 0], vr[..., 1, 0], vr[..., 2, 2] = 3 * n * s, -6 * n * (1 - c), -n * s
        vv[..., 0, 0], vv[..., 0, 1], vv[..., 1, 0] = c, 2 * s, -2 * s
        vv[..., 1, 1], vv[..., 2, 2] = 4 * c - 3, c
        return rr, rv, vr, vv

    def propagate(
        self, position: np.ndarray, velocity: np.ndarray, durations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The free state after each duration.

        Parameters
        ----------
        position, velocity : ndarray (..., 3)
            Initial state, m and m/s.
        durations : ndarray (...)
            Durations, s; broadcast with the states' leading axes.

        Returns
        -------
        position, velocity : ndarray (..., 3)
            m and m/s.
        """
        rr, rv, vr, vv = self.blocks(durations)
        r, v = np.asarray(position, dtype=float), np.asarray(velocity, dtype=float)
        return _apply(rr, r) + _apply(rv, v), _apply(vr, r) + _apply(vv, v)

    def single_burn(
        self, start: np.ndarray, end: np.ndarray, durations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Departure and arrival velocities of the free arc from ``start`` to ``end``.

        Parameters
        ----------
        start, end : ndarray (..., 3)
            End points, m.
        durations : ndarray (...)
            Flight times, s: positive and below :attr:`longest_duration`.

        Returns
        -------
        departure, arrival : ndarray (..., 3)
            Velocity just after the burn at ``start`` and on arrival at ``end``, m/s.
        """
        rr, rv, vr, vv = self.blocks(durations)
        r_a = np.asarray(start, dtype=float)
        departure = np.linalg.solve(rv, (np.asarray(end, dtype=float) - _apply(rr, r_a))[..., None])
        departure = departure[..., 0]
        return departure, _apply(vr, r_a) + _apply(vv, departure)

    def two_burn_delta_v(
        self,
        position: np.ndarray,
        velocity: np.ndarray,
        goal_position: np.ndarray,
        goal_velocity: np.ndarray,
        durations: np.ndarray,
    ) -> np.ndarray:
        """Delta-v of the direct two-burn transfer to a goal state, m/s.

        Parameters
        ----------
        position, velocity : ndarray (..., 3)
            Where the transfer starts, m and m/s.
        goal_position, goal_velocity : ndarray (3,) or (..., 3)
            The state to arrive in, m and m/s.
        durations : ndarray (...)
            Transfer times, s (positive, below :attr:`longest_duration`).

        Returns
        -------
        ndarray (...)
            ``|v_A⁺ − v| + |v_goal − v_B⁻|``, m/s.
        """
        departure, arrival = self.single_burn(position, goal_position, durations)
        first = np.linalg.norm(departure - velocity, axis=-1)
        return first + np.linalg.norm(np.asarray(goal_velocity) - arrival, axis=-1)


@dataclass(frozen=True)
class SpeedLimits:
    """The limits of a burn plan's legs and burns.

    Attributes
    ----------
    min_speed, max_speed : float
        Least and largest mean speed of a leg (chord over duration), m/s.
    max_burn : float
        Largest single delta-v, m/s.
    """

    min_speed: float
    max_speed: float
    max_burn: float

    @classmethod
    def derive(
        cls, min_speed: float | None, max_burn: float | None, max_speed: float
    ) -> SpeedLimits:
        """The limits with unset values scaled from the speed limit by the paper's Table 2.

        Parameters
        ----------
        min_speed : float or None
            Least mean speed, m/s (None: ``0.09/0.19 max_speed``).
        max_burn : float or None
            Largest single delta-v, m/s (None: ``0.2/0.19 max_speed``).
        max_speed : float
            The problem's speed limit, m/s.
        """
        least, most, burn = PAPER_SPEEDS
        return cls(
            min_speed if min_speed is not None else least / most * max_speed,
            max_speed,
            max_burn if max_burn is not None else burn / most * max_speed,
        )


def swept_arcs(
    motion: FreeMotion,
    origins: np.ndarray,
    departures: np.ndarray,
    durations: np.ndarray,
    robot_speed: float,
    obstacle_speed: float,
    spacing: float,
    most_samples: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples along free arcs for a swept collision check.

    Every arc gets the same number of samples, enough that robot and obstacle close by
    at most ``spacing`` between two samples of the longest arc (``most_samples`` at
    most). Checking the robot's sphere grown by the returned margin at the samples
    covers the arc between them: the margin is half the largest step of the robot
    between two samples plus half the obstacles' largest step.

    Parameters
    ----------
    motion : FreeMotion
        The frame's free motion.
    origins, departures : ndarray (..., 3)
        Where each arc starts (m) and its velocity after the burn there (m/s),
        broadcast together.
    durations : ndarray (...)
        Flight time of each arc, s.
    robot_speed, obstacle_speed : float
        Largest speeds of the robot and of any obstacle, m/s.
    spacing : float
        Largest closing of robot and obstacle between two samples, m.
    most_samples : int, optional
        Cap on the samples per arc (the margins grow to match).

    Returns
    -------
    elapsed : ndarray (..., s)
        Time of each sample since the arc's start, s.
    points : ndarray (..., s, 3)
        Positions, m.
    margins : ndarray (...)
        Growth of the robot's sphere on each arc, m.
    """
    durations = np.asarray(durations, dtype=float)
    count = int(np.ceil((robot_speed + obstacle_speed) * durations.max() / spacing)) + 1
    if most_samples is not None:
        count = min(count, most_samples)
    fractions = np.linspace(0.0, 1.0, max(count, 2))
    elapsed = durations[..., None] * fractions
    points, _ = motion.propagate(
        np.asarray(origins, dtype=float)[..., None, :], departures[..., None, :], elapsed
    )
    hops = np.linalg.norm(np.diff(points, axis=-2), axis=-1).max(axis=-1)
    obstacle_hop = obstacle_speed * durations / (len(fractions) - 1)
    return elapsed, points, 0.5 * (hops + obstacle_hop)


def _apply(matrices: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``matrices @ vectors`` over broadcast leading axes, (..., 3)."""
    return np.einsum("...ij,...j->...i", matrices, vectors)


@dataclass(frozen=True)
class BurnPlan:
    """Waypoints joined by free arcs, an impulsive burn at each.

    Parameters
    ----------
    motion : FreeMotion
        The frame's free motion.
    times : ndarray (k + 1,)
        Waypoint times, s, strictly increasing; the first is the start.
    positions : ndarray (k + 1, 3)
        Waypoints, m; the first is the start, the last the goal.
    start_velocity, goal_velocity : ndarray (3,)
        Velocity before the first burn and after the last, m/s.
    """

    motion: FreeMotion
    times: np.ndarray
    positions: np.ndarray
    start_velocity: np.ndarray
    goal_velocity: np.ndarray

    @property
    def legs(self) -> tuple[np.ndarray, np.ndarray]:
        """Departure and arrival velocity of each leg, (k, 3) m/s each."""
        return self.motion.single_burn(self.positions[:-1], self.positions[1:], np.diff(self.times))

    def burns(self) -> np.ndarray:
        """The k + 1 velocity changes, (k + 1, 3) m/s: onto each leg, then onto the goal's."""
        departure, arrival = self.legs
        before = np.vstack([self.start_velocity, arrival])
        after = np.vstack([departure, self.goal_velocity])
        return after - before

    @property
    def delta_v(self) -> float:
        """Total delta-v, m/s."""
        return float(np.linalg.norm(self.burns(), axis=1).sum())

    def sweep(self, samples_per_leg: int) -> tuple[np.ndarray, np.ndarray]:
        """Positions along every arc at evenly spaced times (ends included).

        Returns
        -------
        times : ndarray (k, samples_per_leg)
            s.
        positions : ndarray (k, samples_per_leg, 3)
            m.
        """
        departure, _ = self.legs
        fractions = np.linspace(0.0, 1.0, samples_per_leg)
        elapsed = np.diff(self.times)[:, None] * fractions
        points, _ = self.motion.propagate(
            self.positions[:-1, None, :], departure[:, None, :], elapsed
        )
        return self.times[:-1, None] + elapsed, points

    def realised_legs(
        self, max_acceleration: float
    ) -> list[tuple[float, np.ndarray, float, np.ndarray]]:
        """The coasting arcs of the plan flown with finite burns at ``max_acceleration``.

        Interior burns are centred on their waypoint's time: in a force-free frame that
        joins the planned arcs exactly (about an orbit, up to the free motion's pull over
        the burn). The first burn starts at the start time and the last ends at the
        arrival time, so the first arc starts where the first burn ends and the last arc
        ends where the last burn starts. Both arcs are solved again together with the two
        burns' durations and end points (scipy's Levenberg–Marquardt ``root``): each burn
        lasts what its velocity change needs at the limit, and its end lies where
        constant thrust takes the robot.

        Returns
        -------
        list of (start time s, start position m, end time s, end position m)
            One per leg.
        """
        k = len(self.times) - 1
        inner = [(float(self.times[i]), self.positions[i]) for i in range(k + 1)]

        def arcs(unknowns: np.ndarray) -> tuple[list, list]:
            """Arc end points for the burn spans ``unknowns[:2]`` (s) and the first arc's
            start and last arc's end ``unknowns[2:5]``, ``unknowns[5:]`` (m)."""
            starts, ends = list(inner[:-1]), list(inner[1:])
            starts[0] = (inner[0][0] + unknowns[0], unknowns[2:5])
            ends[-1] = (inner[-1][0] - unknowns[1], unknowns[5:8])
            return starts, ends

        def mismatch(unknowns: np.ndarray) -> np.ndarray:
            starts, ends = arcs(unknowns)
            if any(b <= a for (a, _), (b, _) in zip(starts, ends, strict=True)):
                return np.full(8, _NO_ARC)  # burns longer than a leg: far from a solution
            departure, arrival = self._solve(starts, ends)
            first, last = departure[0], arrival[-1]
            spans = [
                _span(first - self.start_velocity, max_acceleration),
                _span(self.goal_velocity - last, max_acceleration),
            ]
            start = inner[0][1] + 0.5 * unknowns[0] * (self.start_velocity + first)
            end = inner[-1][1] - 0.5 * unknowns[1] * (last + self.goal_velocity)
            return np.concatenate([spans - unknowns[:2], start - unknowns[2:5], end - unknowns[5:]])

        departure, arrival = self._solve(inner[:-1], inner[1:])
        guess = np.concatenate([[0.0, 0.0], inner[0][1], inner[-1][1]])
        guess -= mismatch(guess)  # the impulsive burns' spans and the points they give
        solution = optimize.root(mismatch, guess, method="lm", options={"xtol": 1e-14}).x
        if np.abs(mismatch(solution)).max() > 1e-9:
            raise ValueError(
                "a leg is shorter than the burns at its ends (no fit for the first and last)"
            )
        starts, ends = arcs(solution)
        return [(a, p, b, q) for (a, p), (b, q) in zip(starts, ends, strict=True)]

    def _solve(
        self, starts: list[tuple[float, np.ndarray]], ends: list[tuple[float, np.ndarray]]
    ) -> tuple[np.ndarray, np.ndarray]:
        """Departure and arrival velocities of arcs between the given timed points."""
        durations = np.array([b - a for (a, _), (b, _) in zip(starts, ends, strict=True)])
        if np.any(durations <= 0):
            raise ValueError("a leg is shorter than the burns at its ends")
        return self.motion.single_burn(
            np.array([p for _, p in starts]), np.array([q for _, q in ends]), durations
        )

    def trajectory(
        self,
        max_acceleration: float,
        mass: float | None,
        sample_step: float,
        statistics: dict[str, float] | None = None,
    ) -> Trajectory:
        """The plan as a reference, each burn flown at constant thrust (:meth:`realised_legs`).

        Parameters
        ----------
        max_acceleration : float
            Thrust acceleration of the burns, m/s² (``inf``: 1 ms burns).
        mass : float or None
            Robot mass, kg, for the feed-forward forces (None: no forces given).
        sample_step : float
            Largest time between samples on the arcs, s.
        statistics : dict, optional
            The planner's figures, passed on.

        Returns
        -------
        Trajectory
            Positions and velocities on the arcs and across the burns; attitude left
            free; forces (N) when ``mass`` is given; ``delta_v`` the burns as flown.

        Raises
        ------
        ValueError
            If burns overlap (a leg shorter than the burns at its ends).
        """
        legs = self.realised_legs(max_acceleration)
        begins = np.array([a for a, _, _, _ in legs])
        ends = np.array([b for _, _, b, _ in legs])
        origins = np.array([p for _, p, _, _ in legs])
        departure, arrival = self._solve(
            [(a, p) for a, p, _, _ in legs], [(b, q) for _, _, b, q in legs]
        )
        k = len(legs)
        ramps = [
            _ramp(self.positions[0], self.start_velocity, departure[0], self.times[0], begins[0])
        ]
        for i in range(1, k):
            span = _span(departure[i] - arrival[i - 1], max_acceleration)
            start = self.times[i] - 0.5 * span
            position, before = self.motion.propagate(
                origins[i - 1], departure[i - 1], start - begins[i - 1]
            )
            # the ramp starts from the arc's velocity half a burn early, not its arrival
            span = _span(departure[i] - before, max_acceleration)
            ramps.append(_ramp(position, before, departure[i], start, start + span))
        last = legs[-1][3]
        ramps.append(_ramp(last, arrival[-1], self.goal_velocity, ends[-1], self.times[-1]))
        pieces = [ramps[0]]
        for i in range(k):
            pieces.append(
                self._coast(
                    origins[i],
                    departure[i],
                    begins[i],
                    ramps[i][0][-1],
                    ramps[i + 1][0][0],
                    sample_step,
                )
            )
            pieces.append(ramps[i + 1])
        times = np.concatenate([p[0] for p in pieces])
        if np.any(np.diff(times) <= 0):
            raise ValueError("burns overlap: a leg is shorter than the burns at its ends")
        positions = np.vstack([p[1] for p in pieces])
        accelerations = np.vstack([p[3] for p in pieces])[:-1]
        sizes = [float(np.linalg.norm(r[2][-1] - r[2][0])) for r in ramps]
        return Trajectory(
            times=times,
            positions=positions,
            velocities=np.vstack([p[2] for p in pieces]),
            forces=None if mass is None else mass * accelerations,
            delta_v=float(sum(sizes)),
            length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
            duration=float(times[-1] - times[0]),
            statistics=dict(statistics or {}),
        )

    def _coast(
        self,
        origin: np.ndarray,
        velocity: np.ndarray,
        epoch: float,
        after: float,
        before: float,
        sample_step: float,
    ) -> tuple[np.ndarray, ...]:
        """Samples of the free arc leaving ``origin`` at ``epoch`` (s) with ``velocity``,
        strictly between ``after`` and ``before`` (s), at most ``sample_step`` apart; each
        row's acceleration (zero) holds until the next sample."""
        count = max(int(np.ceil((before - after) / sample_step)), 1)
        times = after + (before - after) * np.arange(1, count) / count
        positions, velocities = self.motion.propagate(origin, velocity, times - epoch)
        return times, positions, velocities, np.zeros((len(times), 3))


def _span(burn: np.ndarray, max_acceleration: float) -> float:
    """Duration of a constant-thrust burn, s."""
    return max(float(np.linalg.norm(burn)) / max_acceleration, _SHORTEST_BURN)


def _ramp(
    origin: np.ndarray, before: np.ndarray, after: np.ndarray, start: float, end: float
) -> tuple[np.ndarray, ...]:
    """Samples of a constant-thrust burn from ``origin`` (m) taking the velocity from
    ``before`` to ``after`` (m/s) between ``start`` and ``end`` (s): times, positions,
    velocities and each row's acceleration (the last row's holds until the next piece:
    zero, a coast follows)."""
    since = np.linspace(0.0, end - start, _BURN_SAMPLES)
    acceleration = (after - before) / (end - start)
    positions = origin + np.outer(since, before) + 0.5 * np.outer(since**2, acceleration)
    rows = np.vstack([np.tile(acceleration, (_BURN_SAMPLES - 1, 1)), np.zeros((1, 3))])
    return start + since, positions, before + np.outer(since, acceleration), rows
