"""What a free flyer's environments share: thrust and torque as actions, the estimate,
the goal and the nearest obstacles as observation, and the reward from cost weights.

Actions (``Box(-1, 1)``, float32): the body force along x, y and z of the world frame
(LVLH in an orbit) as fractions of ``robot.max_force``, then the torque as fractions of
``robot.max_torque``; with ``attitude="controller"`` the action is the force alone and
the scenario's controller holds the attitude the mission asks for. A force or torque
longer than its limit is clipped to it by the world, as any controller's is.

Observation (``Box(-inf, inf)``, float32; :attr:`MissionEnv.observation_names`): the
estimate (position m, velocity m/s, attitude quaternion ``[x, y, z, w]``, angular
velocity rad/s, world frame), the goal relative to it (the mission's reference
position and velocity less the estimate's), the share of ``world.duration`` left, then
for each of the ``obstacles`` nearest tracked obstacles (by surface gap, nearest first)
its position and velocity relative to the estimate, its bounding radius and 1 (rows of
zeros where fewer are tracked).

Reward of a step (true state)::

    progress_weight · (d_before − d_after) − (w_dv Δv + w_L ΔL + w_T Δt)
        − speed_weight · max(0, ‖v‖ − v_max) Δt
        + goal_reward on meeting the goal − collision_penalty on a collision

``d`` is the distance (m) to the goal given at the step's start, ``Δv`` the delta-v
spent (m/s), ``ΔL`` the distance flown (m), ``Δt`` the control period (s), ``‖v‖`` the
speed at the step's end and ``v_max`` the scenario's ``robot.max_speed`` (m/s), which
planned flights keep to and nothing else holds an agent to; the
weights are the scenario's path-cost weights (``mission.weights``) unless the
environment is given its own. The shaping term telescopes over an episode to
``progress_weight`` times the distance closed, so it does not change which paths are
best among those that reach the goal (a potential-based shaping).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from dcsim.gym.environment import MissionEnv
from dcsim.messages import Command
from dcsim.run.seeding import component_rng
from dcsim.run.setup import Overrides, ScenarioInput
from dcsim.scenario import Scenario
from dcsim.scenario.model import point_to_cartesian

ATTITUDE_CHOICES = ("agent", "controller")
"""Who gives the torque: the agent (6-D actions) or the scenario's controller (3-D)."""

_ESTIMATE_NAMES = (
    "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps",
    "qx", "qy", "qz", "qw", "wx_radps", "wy_radps", "wz_radps",
)  # fmt: skip
_GOAL_NAMES = (
    "goal_dx_m", "goal_dy_m", "goal_dz_m", "goal_dvx_mps", "goal_dvy_mps", "goal_dvz_mps",
)  # fmt: skip
_OBSTACLE_FIELDS = ("dx_m", "dy_m", "dz_m", "dvx_mps", "dvy_mps", "dvz_mps", "radius_m", "seen")


class FreeFlyerEnv(MissionEnv):
    """A free flyer's mission as an environment (see the module for its spaces and reward).

    Parameters
    ----------
    scenario, overrides
        As for :class:`MissionEnv`.
    obstacles : int
        How many of the nearest tracked obstacles the observation shows.
    attitude : {"agent", "controller"}
        Who gives the torque.
    start_spread : float
        Half-width (m) of a box about the scenario's initial position from which each
        episode's start is drawn, uniformly, by the episode's seed; 0: the scenario's.
    cost_weights : tuple of 3 floats, optional
        ``(w_dv, w_L, w_T)`` in s/m, 1/m and 1/s; the mission's own if None.
    speed_weight : float
        Weight of the speed-limit term (1/m): reward taken away per m/s above
        ``robot.max_speed`` per second.
    **options
        ``goal_reward``, ``collision_penalty``, ``progress_weight``, ``registry``: as
        for :class:`MissionEnv`.
    """

    def __init__(
        self,
        scenario: ScenarioInput = None,
        overrides: Overrides = (),
        *,
        obstacles: int = 4,
        attitude: str = "agent",
        start_spread: float = 0.0,
        cost_weights: Sequence[float] | None = None,
        speed_weight: float = 10.0,
        **options: Any,
    ) -> None:
        if attitude not in ATTITUDE_CHOICES:
            choices = ", ".join(ATTITUDE_CHOICES)
            raise ValueError(f"attitude must be one of {choices}, not {attitude!r}")
        if obstacles < 0 or start_spread < 0 or speed_weight < 0:
            raise ValueError("obstacles, start_spread and speed_weight must not be negative")
        self.obstacle_count = int(obstacles)
        self.attitude = attitude
        self.start_spread = float(start_spread)
        self.speed_weight = float(speed_weight)
        super().__init__(scenario, overrides, **options)
        self.cost_weights = (
            self._mission_weights() if cost_weights is None else np.asarray(cost_weights, float)
        )
        robot = self.scenario.robot
        self._force_limit = float(robot.max_force)
        self._speed_limit = float(robot.max_speed)
        self._torque_limit = float(robot.max_torque)

    # ------------------------------------------------------------------ spaces
    def _observation_names(self) -> list[str]:
        obstacles = [
            f"obstacle{k}_{field}"
            for k in range(1, self.obstacle_count + 1)
            for field in _OBSTACLE_FIELDS
        ]
        return [*_ESTIMATE_NAMES, *_GOAL_NAMES, "time_left", *self._mission_names(), *obstacles]

    def _action_names(self) -> list[str]:
        force = [f"f{axis} (× robot.max_force)" for axis in "xyz"]
        torque = [f"t{axis} (× robot.max_torque)" for axis in "xyz"]
        return force if self.attitude == "controller" else [*force, *torque]

    def _command(self, action: np.ndarray) -> Command | Mapping[str, np.ndarray]:
        force = action[:3] * self._force_limit
        if self.attitude == "controller":
            return {"force": force}
        return Command(force=force, torque=action[3:6] * self._torque_limit)

    def _observation(self) -> np.ndarray:
        runner = self.runner
        assert runner is not None and runner.estimate is not None
        estimate, reference = runner.estimate, runner.reference
        assert reference is not None  # every decided period has one
        goal_velocity = np.zeros(3) if reference.velocity is None else reference.velocity
        parts: list[Any] = [
            estimate.position,
            estimate.velocity,
            estimate.attitude,
            estimate.angular_velocity,
            reference.position - estimate.position,
            goal_velocity - estimate.velocity,
            [self._time_left()],
            self._mission_observation(),
            self._obstacle_rows(estimate.position, estimate.velocity).ravel(),
        ]
        return np.concatenate(parts).astype(np.float32)

    def _obstacle_rows(self, position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """One row per observed obstacle slot (see the module), nearest first."""
        rows = np.zeros((self.obstacle_count, len(_OBSTACLE_FIELDS)))
        runner = self.runner
        assert runner is not None
        tracks = () if runner.surroundings is None else runner.surroundings.obstacles
        if not tracks or not self.obstacle_count:
            return rows
        positions = np.array([track.position for track in tracks])
        velocities = np.array([track.velocity for track in tracks])
        radii = np.array([track.radius for track in tracks])
        offsets = positions - position
        gaps = np.linalg.norm(offsets, axis=1) - radii
        chosen = np.argsort(gaps, kind="stable")[: self.obstacle_count]  # nearest first
        count = len(chosen)
        rows[:count, 0:3] = offsets[chosen]
        rows[:count, 3:6] = velocities[chosen] - velocity
        rows[:count, 6] = radii[chosen]
        rows[:count, 7] = 1.0
        return rows

    # ------------------------------------------------------------------ reward
    def _progress_state(self) -> dict[str, Any]:
        runner = self.runner
        assert runner is not None and runner.reference is not None and runner.world is not None
        position = np.array(runner.outputs["position"])
        goal = np.array(runner.reference.position)
        return {
            "goal": goal,
            "distance": float(np.linalg.norm(position - goal)),
            "position": position,
            "delta_v": float(runner.world.delta_v),
            **self._mission_counts(),
        }

    def _reward(self, before: Mapping[str, Any], action: np.ndarray) -> float:
        runner = self.runner
        assert runner is not None and runner.world is not None
        position = runner.outputs["position"]
        distance = float(np.linalg.norm(position - before["goal"]))
        spent = np.array(
            [
                runner.world.delta_v - before["delta_v"],
                float(np.linalg.norm(position - before["position"])),
                self.scenario.world.control_period,
            ]
        )
        progress = self.progress_weight * (before["distance"] - distance)
        speed = float(np.linalg.norm(runner.outputs["velocity"]))
        over = self.speed_weight * max(0.0, speed - self._speed_limit) * spent[2]
        return progress - float(self.cost_weights @ spent) - over

    # ------------------------------------------------------------------ episodes
    def _episode_scenario(self, seed: int) -> Scenario:
        scenario = super()._episode_scenario(seed)
        if self.start_spread == 0:
            return scenario
        robot = scenario.robot
        start = point_to_cartesian(robot.initial.position)
        offset = component_rng(seed, "gym-start").uniform(-1.0, 1.0, 3) * self.start_spread
        initial = robot.initial.model_copy(update={"position": tuple((start + offset).tolist())})
        return scenario.model_copy(update={"robot": robot.model_copy(update={"initial": initial})})

    # ------------------------------------------------------------------ per mission
    def _mission_weights(self) -> np.ndarray:
        """The mission's own cost weights ``(w_dv, w_L, w_T)``."""
        raise NotImplementedError

    def _mission_names(self) -> Sequence[str]:
        """Names of the mission's own observation entries (after ``time_left``)."""
        return ()

    def _mission_observation(self) -> np.ndarray:
        """The mission's own observation entries."""
        return np.zeros(0)

    def _mission_counts(self) -> dict[str, Any]:
        """Counts the mission's event rewards compare across a step."""
        return {}
