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
   thesis's Move message (:class:`dcsim.api.MoveCommand`: the rotation from the current
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
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    Command,
    Controller,
    LocationEstimate,
    MoveCommand,
    PluginParams,
    Reference,
    RobotSpec,
    Surroundings,
    clip_norm,
    hookimpl,
    quantity,
    quaternion_between,
    unit,
)

_PARALLEL = 1e-9  # |C| |V| (m²/s) below which C × V is taken to vanish


class ElasticParams(PluginParams):
    """Parameters of :class:`ElasticController`."""

    gain: float = quantity(
        0.1, unit="1/s", gt=0, description="Elastic attraction: velocity per metre of error."
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
        2.0, unit="s", gt=0, description="Time constant of the velocity-tracking loop."
    )


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
    plus = np.cross(closeness, relative_velocity)
    minus = np.cross(relative_velocity, closeness)
    take_plus = _cosine(plus, attraction) >= _cosine(minus, attraction)
    return plus, minus, np.where(take_plus[:, None], plus, minus)


def _cosine(vectors: np.ndarray, reference: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(vectors, axis=1) * np.linalg.norm(reference)
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
    depth = np.linalg.norm(closeness, axis=1)
    radial = closeness / np.maximum(depth, 1e-12)[:, None]
    speed = np.linalg.norm(relative_velocity, axis=1)
    size = np.linalg.norm(chosen, axis=1)
    sine = np.divide(size, depth * speed, out=np.zeros(len(depth)), where=depth * speed > _PARALLEL)
    if speed_scale > 0:
        sine *= np.minimum(speed / speed_scale, 1.0)
    perpendicular = chosen / np.maximum(size, 1e-300)[:, None]
    fallback = radial + _sidestep(radial, attraction)
    fallback /= np.linalg.norm(fallback, axis=1)[:, None]
    direction = sine[:, None] * perpendicular + (1.0 - sine)[:, None] * fallback
    return gain * depth[:, None] * direction


def _sidestep(radial: np.ndarray, attraction: np.ndarray) -> np.ndarray:
    """Unit directions perpendicular to each ``radial`` row, on the side ``attraction`` leans to."""
    lean = attraction - (radial @ attraction)[:, None] * radial
    axis = np.eye(3)[np.argmin(np.abs(radial), axis=1)]
    fixed = np.cross(radial, axis)
    side = np.where(np.linalg.norm(lean, axis=1)[:, None] > 1e-9, lean, fixed)
    return side / np.linalg.norm(side, axis=1)[:, None]


class ElasticController(Controller):
    """Perpendicular Elastic Force collision avoidance with a velocity-tracking loop."""

    name = "elastic"
    summary = "Perpendicular elastic-force collision avoidance, velocity tracking (thesis §5.3)"
    Params = ElasticParams
    params: ElasticParams

    def reset(self, robot: RobotSpec) -> None:
        """Remember the robot's limits, mass and size (called again after a grab or release)."""
        self.robot = robot

    def move(
        self,
        time: float,
        estimate: LocationEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> MoveCommand:
        """The thesis's Move message for this instant: rotation from the heading, and speed."""
        return self._move(time, estimate, reference, surroundings)[0]

    def command(
        self,
        time: float,
        estimate: LocationEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Force that flies the Move message's velocity; no torque."""
        move, heading = self._move(time, estimate, reference, surroundings)
        return move.to_command(
            heading,
            estimate.velocity,
            self.robot.mass,
            self.robot.max_force,
            self.params.response_time,
        )

    def _move(
        self,
        time: float,
        estimate: LocationEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> tuple[MoveCommand, np.ndarray]:
        """The Move message and the heading it rotates."""
        desired = self.desired_velocity(time, estimate, reference, surroundings)
        speed = float(np.linalg.norm(desired))
        if np.linalg.norm(estimate.velocity) > 1e-6:
            heading = unit(estimate.velocity)
        else:  # at rest: the heading is taken to be the way it is about to go
            heading = unit(desired) if speed > 0 else np.array([1.0, 0.0, 0.0])
        target = desired if speed > 0 else heading
        return MoveCommand(rotation=quaternion_between(heading, target), speed=speed), heading

    def desired_velocity(
        self,
        time: float,
        estimate: LocationEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> np.ndarray:
        """``M`` of eq. 5.3: attraction plus the repulsions, within the speed limit, m/s."""
        limit = min(self.robot.max_speed, reference.max_speed)
        error = reference.position - estimate.position
        attraction = clip_norm(reference.velocity + self.params.gain * error, limit)
        if not surroundings.obstacles:
            return attraction
        closeness, relative = self._inside(time, estimate, surroundings)
        chosen = perpendicular_repulsion(closeness, relative, attraction)[2]
        push = repulsion(
            closeness,
            relative,
            attraction,
            self.params.repulsion_gain,
            chosen,
            self.params.slow_obstacle_speed,
        )
        return clip_norm(attraction + push.sum(axis=0), limit)

    def _inside(
        self, time: float, estimate: LocationEstimate, surroundings: Surroundings
    ) -> tuple[np.ndarray, np.ndarray]:
        """Closeness ``D′ − D`` and relative velocity of the obstacles that repel.

        An obstacle repels while the collector is inside its safety sphere and the two
        are closing; once they separate, pushing on would only cost fuel.
        """
        obstacles = surroundings.obstacles
        states = [  # tracks stamped now need no prediction (the usual case)
            (track.position, track.velocity) if track.time == time else track.predict(time)
            for track in obstacles
        ]
        centres = np.array([p for p, _ in states])
        relative = np.array([v for _, v in states]) - estimate.velocity
        radii = np.array([track.radius for track in obstacles])
        away = estimate.position - centres  # D
        distance = np.linalg.norm(away, axis=1)
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
