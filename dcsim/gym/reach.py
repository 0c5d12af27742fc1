"""``dcsim/Reach-v0``: drive a space manipulator's joints to bring its end effector to a target.

The reach mission flies without its path planner: the arm holds its start until the
agent's joint torques move it, and the mission declares arrival when the end effector
is within ``mission.tolerance`` of ``mission.target``. The base floats free (no force
or torque on it) unless ``base="controller"``, when the scenario's controller holds
it as the mission asks.

Actions (``Box(-1, 1)``, float32): each joint's torque as a fraction of its link's
``torque_limit``. Observation (float32): the joint angles (rad) and rates (rad/s), the
end effector less the target (m, world frame), the base's position less its start
(m), velocity (m/s), attitude quaternion ``[x, y, z, w]`` and angular velocity
(rad/s), and the share of ``world.duration`` left — all from the estimate.

Reward of a step (true state)::

    progress_weight · (d_before − d_after) − effort_weight · mean((τ / τ_max)²) · Δt
        + goal_reward on arrival − collision_penalty on a collision

``d`` is the end effector's distance to the target (m) and ``Δt`` the control period
(s). The episode terminates on arrival or a collision and is truncated at
``world.duration``. Without a scenario the packaged ``space_manipulator_reach.yaml``
is flown (its 1 mm tolerance is the thesis's; ``overrides=["mission.tolerance=0.02"]``
gives an agent a reachable first goal).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from dcsim.gym.environment import MissionEnv
from dcsim.messages import Command, RobotState
from dcsim.missions.reach.settings import ReachMissionSection
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.run.setup import Overrides, ScenarioInput
from dcsim.scenario.model import ManipulatorSection

BASE_CHOICES = ("free", "controller")
"""Who acts on the base: nobody (free floating) or the scenario's controller."""


class ReachEnv(MissionEnv):
    """A reach scenario as an environment (see the module).

    Parameters
    ----------
    scenario, overrides
        As for :class:`MissionEnv`.
    base : {"free", "controller"}
        Whether the base floats free or the scenario's controller holds it.
    effort_weight : float
        Weight of the effort term of the reward (1/s).
    **options
        ``goal_reward``, ``collision_penalty``, ``progress_weight``, ``registry``: as
        for :class:`MissionEnv`.
    """

    mission_type = "reach"
    default_scenario = "space_manipulator_reach.yaml"

    def __init__(
        self,
        scenario: ScenarioInput = None,
        overrides: Overrides = (),
        *,
        base: str = "free",
        effort_weight: float = 0.0,
        **options: Any,
    ) -> None:
        if base not in BASE_CHOICES:
            raise ValueError(f"base must be one of {', '.join(BASE_CHOICES)}, not {base!r}")
        self.base = base
        self.effort_weight = float(effort_weight)
        super().__init__(scenario, overrides, **options)
        robot = self.scenario.robot
        assert isinstance(robot, ManipulatorSection)  # the reach mission flies only manipulators
        limits = [link.torque_limit for link in robot.links]
        if any(limit is None for limit in limits):
            raise ValueError(
                "Reach-v0 scales its actions to each link's torque_limit: give every link one"
            )
        self._torque_limits = np.array(limits, dtype=float)
        self.target = np.array(self.scenario.mission_as(ReachMissionSection).target, dtype=float)

    # ------------------------------------------------------------------ spaces
    def _joint_count(self) -> int:
        robot = self.scenario.robot
        assert isinstance(robot, ManipulatorSection)
        return len(robot.links)

    def _observation_names(self) -> list[str]:
        joints = range(1, self._joint_count() + 1)
        return [
            *(f"q{j}_rad" for j in joints),
            *(f"dq{j}_radps" for j in joints),
            "ee_dx_m", "ee_dy_m", "ee_dz_m",
            "base_dx_m", "base_dy_m", "base_dz_m",
            "base_vx_mps", "base_vy_mps", "base_vz_mps",
            "qx", "qy", "qz", "qw", "wx_radps", "wy_radps", "wz_radps",
            "time_left",
        ]  # fmt: skip

    def _action_names(self) -> list[str]:
        joints = range(1, self._joint_count() + 1)
        return [f"tau{j} (× links[{j - 1}].torque_limit)" for j in joints]

    def _command(self, action: np.ndarray) -> Command | Mapping[str, np.ndarray]:
        torques = action * self._torque_limits
        if self.base == "controller":
            return {"joint_torques": torques}
        return Command(joint_torques=torques)

    def _observation(self) -> np.ndarray:
        runner = self.runner
        assert runner is not None and runner.estimate is not None and runner.mission is not None
        estimate = runner.estimate
        parts = [
            estimate.joint_positions,
            estimate.joint_velocities,
            self._end_effector(estimate.as_state()) - self.target,
            estimate.position - self.start_state.position,
            estimate.velocity,
            estimate.attitude,
            estimate.angular_velocity,
            [self._time_left()],
        ]
        return np.concatenate(parts).astype(np.float32)

    # ------------------------------------------------------------------ reward
    def _start_episode(self) -> None:
        """Keep the arm's model (its kinematics do not change with the propellant
        burnt) and the end effector's true distance to the target."""
        runner = self.runner
        assert runner is not None and runner.world is not None
        model = runner.world.robot_spec().model
        assert isinstance(model, ManipulatorModel)  # the reach mission flies manipulators
        self._arm = model
        self._distance = self._true_distance()

    def _progress_state(self) -> dict[str, Any]:
        return {"distance": self._distance}

    def _reward(self, before: Mapping[str, Any], action: np.ndarray) -> float:
        self._distance = self._true_distance()
        progress = self.progress_weight * (before["distance"] - self._distance)
        effort = self.effort_weight * float(np.mean(action**2)) * self.scenario.world.control_period
        return progress - effort

    # ------------------------------------------------------------------ geometry
    def _end_effector(self, state: RobotState) -> np.ndarray:
        return self._arm.forward_kinematics(state.configuration).end_effector

    def _true_distance(self) -> float:
        runner = self.runner
        assert runner is not None and runner.world is not None
        return float(np.linalg.norm(self._end_effector(runner.world.robot_state()) - self.target))
