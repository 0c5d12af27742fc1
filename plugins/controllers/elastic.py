"""``elastic`` controller: the source thesis's Perpendicular Elastic Force (§5.3).

Every control period the controller computes a desired velocity and tracks it:

1. **Elastic attraction** towards the reference:
   ``V_robot = v_ref + gain (p_ref − p)``, at most the speed limit (the robot's
   MAX_SPEED, or the reference's lower one: the mission's DROP_SPEED on the way to the
   drop point).
2. **Perpendicular repulsion** from every obstacle whose centre is closer than
   ``S = SAFETY_DISTANCE + robot radius + obstacle radius`` (eq. 5.3; SAFETY_DISTANCE
   comes with the surroundings, the robot radius includes any cargo). With ``D`` the
   vector from the obstacle to the robot, the closeness ``C = D′ − D`` (``D′`` along
   ``D`` with norm ``S``) and ``V`` the obstacle's velocity *relative to the collector*,
   the two candidates are ``F⁺ = C × V`` and ``F⁻ = V × C`` (eq. 5.1); the one closer in
   direction to ``V_robot`` — the less disruptive — is taken (eq. 5.2). Its magnitude is
   ``repulsion_gain |C|``: the push grows with how deep the collector is inside the
   safety sphere. Only obstacles the collector is closing on repel: once the two
   separate, pushing on would only cost fuel.
3. ``M = V_robot + Σ F`` (eq. 5.3), at most the speed limit, is published as the
   thesis's Move message (:class:`MoveCommand`: the rotation from the current
   heading onto ``M`` and the speed ``|M|``) and flown by a velocity loop,
   ``F = m (M − v) / response_time`` within the thrust limit.

Where the thesis's formula gives nothing. With the obstacle's own velocity, a static
obstacle never repels, and an obstacle moving along ``D`` (head-on) neither, since
``C × V = 0``. Using the relative velocity fixes the first case for a moving collector.
When ``C`` and ``V`` are (nearly) parallel — head-on, or both at rest — the repulsion
turns, in proportion to ``1 − sin θ`` (θ the angle between ``C`` and ``V``), into a push
that is half radial (straight away from the obstacle) and half sidestep (perpendicular
to ``D``, towards the side ``V_robot`` already leans to, or a fixed side if it leans to
none): a purely radial push would hold the collector in front of an obstacle that sits
on its way, balanced against the attraction, for ever. The same push takes over, in
proportion, when the relative speed falls below ``slow_obstacle_speed``: then ``C × V``
turns with every wobble of the velocity estimate.

Where eq. 5.2 cannot choose. For an obstacle at rest both candidates are perpendicular
to an attraction that points along the collector's path, so the choice falls to noise
and the perpendicular push changes side from one period to the next; on average it
cancels, and what avoids the obstacle is the radial-and-aside share. Keeping the side
taken on entry (a hysteresis) was tried and flew into single obstacles the plain rule
passes, so the thesis's rule stands.

The safety distance must leave room to manoeuvre: the collector needs about
``v² / a`` to turn aside at speed ``v`` and acceleration ``a``; inside that, no
repulsion can avoid contact.

Departures from the thesis, for crowded fields. The repulsion above starts only inside
the safety sphere, a few seconds before contact at the collector's 0.04–0.05 m/s² (three
targets on board: ~2.6 m bounding radius, 115 kg), and does nothing for a collector at
rest that an obstacle creeps into. Two layers are added after eq. 5.3 (each can be switched off);
the attraction, eqs 5.1–5.3 and the Move message stay as they are:

4. **Early dodge** (``lookahead``). For every obstacle, the straight-line closest approach
   of its motion relative to the collector flying ``M``: ``t* = D·V / |V|²`` and the miss
   vector ``m = D − V t*`` (``V`` now relative to ``M``, the velocity about to be flown,
   rather than to the current one, so that a dodge already planned is not planned
   again). An obstacle that comes within ``lookahead`` and misses by less than
   ``S′ = robot radius + obstacle radius + dodge_share · SAFETY_DISTANCE`` adds to ``M``
   the velocity ``(S′ − |m|) / max(t*, dodge_time)`` along ``m``: the push starts as soon
   as a contact is foreseen, is as small as the time left allows, and is zero for an
   obstacle that will pass clear. Its direction is perpendicular to the relative
   velocity, like the thesis's, but turned a right angle about it: ``m`` is along
   ``V × (C × V)``, the part of ``C`` across ``V``, which widens the miss distance at
   first order where ``C × V`` only does at second (``dodge_miss``; off, the dodge takes
   eq. 5.2's candidate and needs ``sqrt(S′² − |m|²)``). A dead-on approach (``|m|`` under
   5 cm) takes eq. 5.2's candidate. Three passes over the obstacles, each against the
   ``M`` the last one left, keep a dodge round one obstacle from flying into the next.
5. **Braking limit and escape** (``brake_fraction``). Towards every obstacle the speed of
   approach may be at most what can still be stopped before the gap to
   ``robot radius + obstacle radius + brake_margin · SAFETY_DISTANCE`` closes, with a
   share ``brake_fraction`` of the thrust-limited acceleration ``a = max_force / mass``
   after the velocity loop's lag ``response_time``: ``v ≤ a (−τ + sqrt(τ² + 2 g / a))``.
   Inside that margin the collector must move away at ``escape_gain`` per metre of
   depth: a collector nearly at rest escapes an obstacle creeping in, straight away
   from it. The limit is enforced by moving ``M`` along each obstacle's ``D`` (three
   passes, so that several obstacles are heeded at once), which leaves the sideways part
   of ``M`` free and so lowers the speed only where a stop might be needed. Where no
   velocity meets every limit (pinched from opposite sides), the obstacle last in the
   track order has its way: a fixed choice, not one that flips with noise.

With both layers on, the collector seldom enters the safety sphere of an obstacle it is
closing on, so the thesis's repulsion mostly stands by as the innermost layer.

Every obstacle is taken as its bounding sphere (``ObjectTrack.radius``), as in the
thesis: for a box or a cylinder (``ObjectTrack.shape``) this is conservative, the
collector keeps clear of the sphere that holds the shape.

When the reference gives an attitude, the shared attitude loop
(:mod:`dcsim_plugins.controllers.attitude`) turns the base towards it; the translation
law above does not depend on it.

The gains are softer than a tracking loop's would be (``gain`` 0.03/s, ``response_time``
4 s): every dodge is followed by a return to the reference, and the velocity loop feeds
the navigation noise into thrust, both at a delta-v cost proportional to them.
``dcsim bench controllers --seeds 50 --controllers elastic,pd --workers 1`` gives
the figures in docs/benchmarks.md.
"""

from __future__ import annotations

import numpy as np
from dcsim_plugins.controllers.attitude import AttitudeLoop, attitude_bandwidth, attitude_damping

from dcsim.api import (
    Command,
    Controller,
    Message,
    PluginParams,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    array_field,
    clip_norm,
    cross,
    hookimpl,
    length,
    message,
    quantity,
    quaternion_between,
    rotate,
    row_lengths,
    unit,
)

_PARALLEL = 1e-9  # |C| |V| (m²/s) below which C × V is taken to vanish
_DODGE_PASSES = 3  # passes over the obstacles when adding the dodges
_BRAKE_PASSES = 3  # passes over the obstacles when enforcing the braking limit
_DEAD_ON = 0.05  # m: predicted miss below which the dodge takes eq. 5.2's candidate


@message
class MoveCommand(Message):
    """The thesis's Move message: turn the heading by a rotation, then fly at a speed.

    Attributes
    ----------
    rotation : ndarray (4,)
        Unit quaternion ``[x, y, z, w]`` taking the current heading onto the commanded
        direction of flight.
    speed : float
        Commanded speed along that direction, m/s.
    """

    rotation: np.ndarray = array_field(shape=(4,))
    speed: float = 0.0

    def desired_velocity(self, heading: np.ndarray) -> np.ndarray:
        """The commanded velocity (m/s) for a collector whose heading is ``heading``."""
        return self.speed * unit(rotate(self.rotation, unit(heading)))

    def to_command(
        self,
        heading: np.ndarray,
        velocity: np.ndarray,
        mass: float,
        max_force: float,
        response_time: float,
    ) -> Command:
        """Convert to the force that reaches the commanded velocity.

        Parameters
        ----------
        heading : array_like (3,)
            Current heading (direction the rotation starts from).
        velocity : array_like (3,)
            Current velocity, m/s.
        mass : float
            Current mass, kg.
        max_force : float
            Thrust limit, N; the force is scaled down to it.
        response_time : float
            Time constant of the velocity loop, s.

        Returns
        -------
        Command
            ``F = m (v_cmd − v) / response_time``, limited to ``max_force``; no torque.
        """
        force = mass * (self.desired_velocity(heading) - np.asarray(velocity)) / response_time
        return Command(force=clip_norm(force, max_force))


class ElasticParams(PluginParams):
    """Parameters of :class:`ElasticController`."""

    gain: float = quantity(
        0.03, unit="1/s", gt=0, description="Elastic attraction: velocity per metre of error."
    )
    repulsion_gain: float = quantity(
        0.5,
        unit="1/s",
        gt=0,
        description="Repulsion: velocity per metre the collector is inside an obstacle's "
        "safety sphere.",
    )
    slow_obstacle_speed: float = quantity(
        0.05,
        unit="m/s",
        ge=0,
        description="Relative speed below which the push turns from perpendicular to "
        "radial-and-aside in proportion.",
    )
    response_time: float = quantity(
        4.0, unit="s", gt=0, description="Time constant of the velocity-tracking loop."
    )
    lookahead: float = quantity(
        60.0,
        unit="s",
        ge=0,
        description="Horizon of the early dodge: obstacles whose closest approach to the "
        "planned velocity comes within this time and inside the safety sphere are dodged "
        "perpendicular to the relative velocity (0: off).",
    )
    dodge_time: float = quantity(
        4.0,
        unit="s",
        gt=0,
        description="Least time over which a dodge is spread (caps its velocity).",
    )
    dodge_share: float = quantity(
        1.0,
        ge=0,
        description="Share of the safety distance the early dodge aims to clear.",
    )
    dodge_miss: bool = quantity(
        True,
        description="Dodge along the predicted miss vector (True) or along eq 5.2's "
        "perpendicular candidate (False).",
    )
    brake_fraction: float = quantity(
        0.5,
        ge=0,
        le=1,
        description="Share of the thrust-limited acceleration the braking limit may assume "
        "(0: no braking limit).",
    )
    brake_margin: float = quantity(
        0.5,
        ge=0,
        description="Gap kept by the braking limit, as a share of the safety distance.",
    )
    escape_gain: float = quantity(
        0.2, unit="1/s", ge=0, description="Escape speed per metre inside the braking margin."
    )
    attitude_bandwidth: float = attitude_bandwidth()
    attitude_damping: float = attitude_damping()


def perpendicular_repulsion(
    closeness: np.ndarray, relative_velocity: np.ndarray, attraction: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The thesis's two candidate repulsions and the chosen one, per obstacle (eqs 5.1–5.2).

    Parameters
    ----------
    closeness : ndarray (K, 3)
        ``D′ − D`` per obstacle, m.
    relative_velocity : ndarray (K, 3)
        Each obstacle's velocity relative to the collector, m/s.
    attraction : ndarray (3,)
        The elastic attraction ``V_robot``, m/s.

    Returns
    -------
    plus, minus, chosen : ndarray (K, 3)
        ``C × V``, ``V × C`` and, per row, whichever makes the larger cosine with
        ``attraction`` (``plus`` on a tie).
    """
    plus = cross(closeness, relative_velocity)
    minus = cross(relative_velocity, closeness)
    take_plus = _cosine(plus, attraction) >= _cosine(minus, attraction)
    return plus, minus, np.where(take_plus[:, None], plus, minus)


def _cosine(vectors: np.ndarray, reference: np.ndarray) -> np.ndarray:
    norms = row_lengths(vectors) * length(reference)
    return np.divide(vectors @ reference, norms, out=np.zeros(len(vectors)), where=norms > 0)


def repulsion(
    closeness: np.ndarray,
    relative_velocity: np.ndarray,
    attraction: np.ndarray,
    gain: float,
    chosen: np.ndarray,
    speed_scale: float = 0.0,
) -> np.ndarray:
    """Repulsive velocity per obstacle inside its safety sphere, m/s (see the module docs).

    Parameters
    ----------
    closeness, relative_velocity : ndarray (K, 3)
        ``D′ − D`` (m) and the obstacle's velocity relative to the collector (m/s).
    attraction : ndarray (3,)
        ``V_robot``, m/s.
    gain : float
        Velocity per metre of closeness, 1/s.
    chosen : ndarray (K, 3)
        The perpendicular candidate eq. 5.2 chose (:func:`perpendicular_repulsion`).
    speed_scale : float
        Relative speed, m/s, below which the perpendicular share fades in proportion
        (a slow obstacle's ``C × V`` turns with every wobble of the velocity estimate).

    Returns
    -------
    ndarray (K, 3)
    """
    depth = row_lengths(closeness)
    radial = closeness / np.maximum(depth, 1e-12)[:, None]
    speed = row_lengths(relative_velocity)
    size = row_lengths(chosen)
    sine = np.divide(size, depth * speed, out=np.zeros(len(depth)), where=depth * speed > _PARALLEL)
    if speed_scale > 0:
        sine *= np.minimum(speed / speed_scale, 1.0)
    perpendicular = chosen / np.maximum(size, 1e-300)[:, None]
    fallback = radial + _sidestep(radial, attraction)
    fallback /= row_lengths(fallback)[:, None]
    direction = sine[:, None] * perpendicular + (1.0 - sine)[:, None] * fallback
    return gain * depth[:, None] * direction


def _sidestep(radial: np.ndarray, attraction: np.ndarray) -> np.ndarray:
    """Unit directions perpendicular to each ``radial`` row, on the side ``attraction`` leans to."""
    lean = attraction - (radial @ attraction)[:, None] * radial
    axis = np.eye(3)[np.argmin(np.abs(radial), axis=1)]
    fixed = cross(radial, axis)
    side = np.where(row_lengths(lean)[:, None] > 1e-9, lean, fixed)
    return side / row_lengths(side)[:, None]


def _states(time: float, surroundings: Surroundings) -> tuple[np.ndarray, ...]:
    """Obstacles' centres (K, 3), velocities (K, 3) and radii (K,) at ``time``."""
    obstacles = surroundings.obstacles
    states = [  # tracks stamped now need no prediction (the usual case)
        (track.position, track.velocity) if track.time == time else track.predict(time)
        for track in obstacles
    ]
    centres = np.array([p for p, _ in states])
    velocities = np.array([v for _, v in states])
    return centres, velocities, np.array([track.radius for track in obstacles])


def early_dodge(
    away: np.ndarray,
    velocities: np.ndarray,
    sphere: np.ndarray,
    planned: np.ndarray,
    limit: float,
    lookahead: float,
    dodge_time: float,
    along_miss: bool = True,
    passes: int = _DODGE_PASSES,
) -> np.ndarray:
    """The planned velocity with a dodge for every foreseen contact (departure 4), m/s.

    Parameters
    ----------
    away : ndarray (K, 3)
        ``D``, from each obstacle's centre to the collector's, m.
    velocities : ndarray (K, 3)
        Obstacles' velocities, m/s.
    sphere : ndarray (K,)
        Centre distance each closest approach must keep, m.
    planned : ndarray (3,)
        ``M`` before the dodge, m/s.
    limit : float
        Speed limit, m/s.
    lookahead, dodge_time : float
        Horizon of the prediction and least time a dodge is spread over, s.
    along_miss : bool
        Dodge along the miss vector (else along eq. 5.2's perpendicular candidate).
    passes : int
        Passes over the obstacles, each against the velocity the last one left.

    Returns
    -------
    ndarray (3,)
    """
    closing = limit + row_lengths(velocities)  # fastest closing speed, m/s
    near = row_lengths(away) < sphere + closing * lookahead
    away, velocities, sphere = away[near], velocities[near], sphere[near]
    planned = np.asarray(planned, dtype=float)
    for _ in range(passes):
        relative = velocities - planned  # obstacle relative to the planned velocity
        squared = np.einsum("ij,ij->i", relative, relative)
        t_star = np.einsum("ij,ij->i", away, relative) / np.maximum(squared, 1e-12)
        miss = away - relative * t_star[:, None]
        missed_by = row_lengths(miss)
        threat = (squared > 1e-8) & (t_star > 0) & (t_star < lookahead) & (missed_by < sphere)
        if not threat.any():
            break
        total = np.zeros(3)
        for i in np.flatnonzero(threat):
            if along_miss and missed_by[i] > _DEAD_ON:
                direction = miss[i] / missed_by[i]
                needed = sphere[i] - missed_by[i]
            else:
                closeness = unit(away[i]) * max(sphere[i] - length(away[i]), 1e-3)
                chosen = perpendicular_repulsion(closeness[None], relative[i][None], planned)[2]
                if length(chosen) < 1e-12:
                    chosen = _sidestep(unit(away[i])[None], planned)
                direction = unit(chosen[0])
                needed = np.sqrt(max(sphere[i] ** 2 - missed_by[i] ** 2, 0.0))
            total += direction * needed / max(t_star[i], dodge_time)
        planned = clip_norm(planned + total, limit)
    return planned


def braking_limit(
    away: np.ndarray,
    velocities: np.ndarray,
    keep: np.ndarray,
    planned: np.ndarray,
    limit: float,
    acceleration: float,
    lag: float,
    escape_gain: float,
) -> np.ndarray:
    """The planned velocity with every approach slow enough to stop in time (departure 5).

    Parameters
    ----------
    away : ndarray (K, 3)
        ``D``, from each obstacle's centre to the collector's, m.
    velocities : ndarray (K, 3)
        Obstacles' velocities, m/s.
    keep : ndarray (K,)
        Centre distance to stop at, m.
    planned : ndarray (3,)
        ``M`` before the limit, m/s.
    limit : float
        Speed limit, m/s.
    acceleration, lag : float
        Braking acceleration assumed (m/s²) and the reaction lag before it (s).
    escape_gain : float
        Speed away per metre inside ``keep``, 1/s.

    Returns
    -------
    ndarray (3,)
    """
    distance = row_lengths(away)
    gap = distance - keep
    normal = away / np.maximum(distance, 1e-12)[:, None]
    stoppable = acceleration * (-lag + np.sqrt(lag**2 + 2.0 * np.maximum(gap, 0.0) / acceleration))
    allowed = np.where(gap > 0, stoppable, escape_gain * gap)  # approach speed, m/s
    closing = limit + row_lengths(velocities)  # fastest closing speed, m/s
    watch = np.flatnonzero(gap < closing**2 / (2.0 * acceleration) + closing * lag)
    planned = np.asarray(planned, dtype=float)
    for _ in range(_BRAKE_PASSES):
        for i in watch:
            receding = (planned - velocities[i]) @ normal[i]
            if receding < -allowed[i]:
                planned = planned + normal[i] * (-allowed[i] - receding)
    return clip_norm(planned, limit)


class ElasticController(Controller):
    """Perpendicular Elastic Force collision avoidance with a velocity-tracking loop."""

    name = "elastic"
    summary = "Perpendicular elastic-force collision avoidance, velocity tracking (thesis §5.3)"
    Params = ElasticParams
    params: ElasticParams

    def reset(self, robot: RobotSpec) -> None:
        """Remember the robot's limits, mass and size (called again after a grab or release)."""
        self.robot = robot
        self.attitude_loop = AttitudeLoop(
            self.params.attitude_bandwidth, self.params.attitude_damping
        )

    def move(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> MoveCommand:
        """The thesis's Move message for this instant: rotation from the heading, and speed."""
        return self._move(time, estimate, reference, surroundings)[0]

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Force that flies the Move message's velocity; torque towards the reference's
        attitude, if it gives one."""
        move, heading = self._move(time, estimate, reference, surroundings)
        command = move.to_command(
            heading,
            estimate.velocity,
            self.robot.mass,
            self.robot.max_force,
            self.params.response_time,
        )
        if reference.attitude is None:
            return command
        torque = self.attitude_loop.torque(self.robot, estimate, reference)
        return Command(force=command.force, torque=torque)

    def _move(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> tuple[MoveCommand, np.ndarray]:
        """The Move message and the heading it rotates."""
        desired = self.desired_velocity(time, estimate, reference, surroundings)
        speed = length(desired)
        if length(estimate.velocity) > 1e-6:
            heading = unit(estimate.velocity)
        else:  # at rest: the heading is taken to be the way it is about to go
            heading = unit(desired) if speed > 0 else np.array([1.0, 0.0, 0.0])
        target = desired if speed > 0 else heading
        return MoveCommand(rotation=quaternion_between(heading, target), speed=speed), heading

    def desired_velocity(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> np.ndarray:
        """``M``: eq. 5.3's attraction plus repulsions, then the early dodge and the braking
        limit (departures 4 and 5), within the speed limit, m/s."""
        limit = min(self.robot.max_speed, reference.max_speed)
        error = reference.position - estimate.position
        attraction = clip_norm(reference.velocity + self.params.gain * error, limit)
        if not surroundings.obstacles:
            return attraction
        centres, velocities, radii = _states(time, surroundings)
        away = estimate.position - centres  # D
        closeness, relative = self._inside(
            away, velocities - estimate.velocity, radii, surroundings
        )
        chosen = perpendicular_repulsion(closeness, relative, attraction)[2]
        push = repulsion(
            closeness,
            relative,
            attraction,
            self.params.repulsion_gain,
            chosen,
            self.params.slow_obstacle_speed,
        )
        desired = clip_norm(attraction + push.sum(axis=0), limit)
        return self._dodge_and_brake(away, velocities, radii, surroundings, desired, limit)

    def _dodge_and_brake(
        self,
        away: np.ndarray,
        velocities: np.ndarray,
        radii: np.ndarray,
        surroundings: Surroundings,
        desired: np.ndarray,
        limit: float,
    ) -> np.ndarray:
        """``M`` after the early dodge and the braking limit (departures 4 and 5), m/s.

        ``away`` is ``D`` (K, 3), m; ``velocities`` the obstacles' (K, 3), m/s; ``radii``
        theirs (K,), m.
        """
        p = self.params
        margin = self.robot.radius + radii
        if p.lookahead > 0:
            sphere = margin + p.dodge_share * surroundings.safety_distance
            desired = early_dodge(
                away, velocities, sphere, desired, limit, p.lookahead, p.dodge_time, p.dodge_miss
            )
        if p.brake_fraction > 0:
            desired = braking_limit(
                away,
                velocities,
                margin + p.brake_margin * surroundings.safety_distance,
                desired,
                limit,
                p.brake_fraction * self.robot.max_force / self.robot.mass,
                p.response_time,
                p.escape_gain,
            )
        return desired

    def _inside(
        self,
        away: np.ndarray,
        relative: np.ndarray,
        radii: np.ndarray,
        surroundings: Surroundings,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Closeness ``D′ − D`` and relative velocity of the obstacles that repel.

        ``away`` is ``D`` (K, 3), m; ``relative`` the obstacles' velocities relative to
        the collector (K, 3), m/s; ``radii`` theirs (K,), m. An obstacle repels while the
        collector is inside its safety sphere and the two are closing; once they
        separate, pushing on would only cost fuel.
        """
        distance = row_lengths(away)
        sphere = surroundings.safety_distance + self.robot.radius + radii
        closing = np.einsum("ij,ij->i", away, relative) > 0
        repel = (distance < sphere) & closing
        direction = away[repel] / np.maximum(distance[repel], 1e-12)[:, None]
        closeness = direction * (sphere - distance)[repel][:, None]
        return closeness, relative[repel]


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the elastic controller."""
    return [ElasticController]
