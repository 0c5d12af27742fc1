"""``q-learning`` path planner: a space manipulator's end-effector path learnt by tabular
Q-learning on a grid of cells (the space manipulator thesis, chapter 5 and §7.3–7.4).

:mod:`cell_environment` builds the thesis's environment for the problem (cells, six
actions, terminal cells for joint limits, singularities and the target out of sight, a
better reward when the base moves little); :mod:`tabular_q` trains the table with the
thesis's ε-greedy rule and temporal-difference update; the greedy path from the start
cell is the answer. The Q-table can be kept in a file (``q_table_file``, ``npz``): it is
loaded when it was trained on the same environment and schedule, else trained and
written. Training draws from the planner's generator, so a seed gives the same table.

The flight follows the cell centres from the start (the end effector's own position:
the lattice is anchored there) to the target's cell, then on to the target itself. The
staircase of centres is first simplified (Ramer–Douglas–Peucker) to the fewest corners
that keep every visited centre within ``smoothing`` cells of the path (0 keeps every
centre), then flown leg by leg, each leg a rest-to-rest minimum-jerk move within the
problem's speed and acceleration limits (:func:`minimum_jerk_legs`): a staircase flown
cell by cell would stop at every cell. "No path" when the target is beyond the arm's
reach, when its cell breaks a constraint, or when the greedy path enters a terminal
cell, comes back to a cell, or does not arrive.

Beside the planner: its bench (:mod:`q_learning_bench`, ``dcsim bench q-learning``,
added through the ``dcsim_register_commands`` hook) and its cell task as a Gymnasium
environment (:mod:`q_learning_gym`).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from dcsim_plugins.path_planners.deadline import OutOfTime
from dcsim_plugins.path_planners.end_effector_line import unreachable
from dcsim_plugins.path_planners.q_learning.cells import (
    CellEnvironment,
    CellRules,
    TooManyCells,
    build_environment,
)
from dcsim_plugins.path_planners.q_learning.tabular_q import (
    Rollout,
    Schedule,
    Training,
    greedy_rollout,
    train,
)

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    PluginError,
    Trajectory,
    hookimpl,
    minimum_jerk_legs,
    quantity,
)

if TYPE_CHECKING:
    import click


class QLearningParams(PathPlannerParams):
    """Parameters of :class:`QLearningPlanner`."""

    cell_size: float = quantity(0.05, unit="m", gt=0, description="Side of a grid cell.")
    margin: int = quantity(
        2, ge=0, le=50, description="Cells added on every side of the box of start and target."
    )
    episodes: int = quantity(2000, ge=1, le=10_000_000, description="Training episodes.")
    max_steps: int = quantity(200, ge=1, description="Most actions in one episode.")
    learning_rate: float = quantity(0.9, gt=0, le=1, description="α of eq. 5.1.")
    discount: float = quantity(0.9, ge=0, le=1, description="γ of eq. 5.1.")
    epsilon_start: float = quantity(
        0.1, ge=0, le=1, description="ε (probability of the greedy action) in the first episode."
    )
    epsilon_end: float = quantity(0.9, ge=0, le=1, description="ε in the last episode.")
    joint_limit_deg: float = quantity(
        90.0,
        unit="deg",
        gt=0,
        le=180,
        description="Joint angle magnitude beyond which a cell is terminal.",
    )
    sight_limit_deg: float = quantity(
        60.0,
        unit="deg",
        gt=0,
        le=180,
        description="Angle between the base's facing side and the "
        "target beyond which a cell is terminal.",
    )
    singular_det: float = quantity(
        1e-3,
        unit="m^6",
        ge=0,
        description="det(J Jᵀ) of the position Jacobian at or below which "
        "a cell is terminal (a singularity).",
    )
    base_ratio: float = quantity(
        0.5,
        gt=0,
        description="Base displacement, as a fraction of the end effector's, above "
        "which a move pays base_penalty.",
    )
    target_reward: float = quantity(100.0, description="Reward for entering the target's cell.")
    terminal_reward: float = quantity(-100.0, description="Reward for entering a terminal cell.")
    step_reward: float = quantity(-1.0, description="Reward of any other move.")
    base_penalty: float = quantity(
        -1.0, description="Added to step_reward where the base moves too much."
    )
    smoothing: float = quantity(
        1.0,
        unit="cells",
        ge=0,
        le=10,
        description="Largest distance of a visited cell's centre from the flown path, in cells.",
    )
    facing_axis: tuple[float, float, float] | None = quantity(
        None,
        description="Base-frame direction of the side that must face the target (give the "
        "reach mission's facing_axis); null: the base axis nearest the target's direction "
        "at the start, as the mission's default.",
    )
    max_cells: int = quantity(
        200_000, ge=1, description="Largest grid; a problem that needs more is refused."
    )
    samples: int = quantity(
        201, ge=2, le=100_000, description="Trajectory samples from start to target."
    )
    q_table_file: str | None = quantity(
        None,
        description="npz file to load the Q-table from (when it was trained on the same "
        "environment and schedule) or to save it to; null: train every time.",
    )


class QLearningPlanner(PathPlanner):
    """Tabular Q-learning of the end effector's path over a grid of cells."""

    name = "q-learning"
    summary = "A manipulator's end-effector path by tabular Q-learning on a cell grid"
    Params = QLearningParams
    params: QLearningParams
    robots = ("manipulator",)

    # ------------------------------------------------------------------ parts
    def rules(self) -> CellRules:
        """The environment's constants from the parameters."""
        p = self.params
        return CellRules(
            cell_size=p.cell_size,
            margin=p.margin,
            joint_limit=np.radians(p.joint_limit_deg),
            sight_limit=np.radians(p.sight_limit_deg),
            singular_det=p.singular_det,
            base_ratio=p.base_ratio,
            target_reward=p.target_reward,
            terminal_reward=p.terminal_reward,
            step_reward=p.step_reward,
            base_penalty=p.base_penalty,
            max_cells=p.max_cells,
            facing_axis=p.facing_axis,
        )

    def schedule(self) -> Schedule:
        """The training constants from the parameters."""
        p = self.params
        return Schedule(
            episodes=p.episodes,
            max_steps=p.max_steps,
            alpha=p.learning_rate,
            gamma=p.discount,
            epsilon_start=p.epsilon_start,
            epsilon_end=p.epsilon_end,
        )

    def environment(self, problem: PathProblem, deadline: float = float("inf")) -> CellEnvironment:
        """The cell environment of ``problem`` (:func:`build_environment`), built by
        ``deadline`` (``time.monotonic()``) or :class:`OutOfTime`."""
        return build_environment(problem, self.rules(), deadline)

    def train(self, environment: CellEnvironment, deadline: float = float("inf")) -> Training:
        """A Q-table trained on ``environment`` with the planner's generator, by
        ``deadline`` (``time.monotonic()``) or :class:`OutOfTime`."""
        starts = np.flatnonzero(~environment.ends)
        return train(
            environment.next_cell,
            environment.reward,
            environment.ends,
            starts,
            self.schedule(),
            self.rng,
            deadline,
        )

    def greedy_path(self, environment: CellEnvironment, q: np.ndarray) -> Rollout:
        """The greedy path of table ``q`` from the environment's start cell."""
        return greedy_rollout(
            q,
            environment.next_cell,
            environment.reward,
            environment.ends,
            environment.target,
            environment.start,
            self.params.discount,
        )

    # ------------------------------------------------------------------ plan
    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Learn (or load) the table and return the greedy end-effector path."""
        refusal = unreachable(problem)
        if refusal is not None:
            return refusal
        deadline = problem.due()
        budget = deadline - time.monotonic()  # the deadline, not time_budget, may govern
        try:
            environment = self.environment(problem, deadline)
            if environment.start == environment.target:  # nothing to learn: one move
                return self._trajectory(problem, environment, [environment.start], {})
            if environment.terminal[environment.target]:
                reason = environment.reasons[environment.target]
                return NoPath(f"the target's cell breaks a constraint: {reason}")
            q, loaded = self._table(environment, deadline)
        except TooManyCells as large:
            return NoPath(str(large))
        except OutOfTime as late:
            return NoPath(
                f"the planning budget of {budget:.3g} s ran out ({late} done): "
                "give it more time, or fewer cells or episodes (a q_table_file trained on this "
                "environment skips the training)"
            )
        rollout = self.greedy_path(environment, q)
        if rollout.outcome != "target":
            return NoPath(_no_path_reason(environment, rollout.cells, rollout.outcome))
        statistics = {
            "cells": float(environment.cells),
            "terminal_cells": float(environment.terminal.sum()),
            "moves": float(len(rollout.cells) - 1),
            "discounted_return": rollout.discounted_return,
            "loaded_q_table": float(loaded),
        }
        return self._trajectory(problem, environment, rollout.cells, statistics)

    def _table(self, environment: CellEnvironment, deadline: float) -> tuple[np.ndarray, bool]:
        """The Q-table: loaded from ``q_table_file`` if it fits, else trained (and saved)."""
        path = None if self.params.q_table_file is None else Path(self.params.q_table_file)
        fingerprint = _fingerprint(environment, self.schedule())
        if path is not None and path.exists():
            try:
                with np.load(path) as saved:
                    if str(saved["fingerprint"]) == fingerprint:
                        return saved["q"], True
            except (OSError, ValueError, KeyError, TypeError) as error:  # TypeError: a .npy
                raise PluginError(f"q-learning: cannot read the Q-table {path}: {error}") from None
        q = self.train(environment, deadline).q
        if path is not None:
            _save(path, q, fingerprint)
        return q, False

    def _trajectory(
        self, problem: PathProblem, environment: CellEnvironment, cells: list[int], statistics
    ) -> Trajectory:
        """The flight along the simplified cell path to the target, leg by leg."""
        points = environment.centres(np.asarray(cells))
        target = np.asarray(problem.goal.position, dtype=float)
        if np.linalg.norm(points[-1] - target) > 1e-9:
            points = np.vstack([points, target])
        points = simplified(points, self.params.smoothing * environment.cell_size)
        times, positions, velocities = minimum_jerk_legs(
            points, problem.max_speed, problem.max_acceleration, self.params.samples
        )
        return Trajectory(
            times=problem.start.time + times,
            positions=positions,
            velocities=velocities,
            length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
            duration=float(times[-1]),
            statistics=statistics,
        )


def simplified(points: np.ndarray, tolerance: float) -> np.ndarray:
    """The fewest of ``points`` (k, 3), ends kept, whose polyline passes within
    ``tolerance`` (m) of every dropped point (Ramer–Douglas–Peucker)."""
    if len(points) < 3:
        return points
    first, last = points[0], points[-1]
    chord = last - first
    offsets = points[1:-1] - first
    span = float(chord @ chord)
    if span > 0.0:
        along = np.clip(offsets @ chord / span, 0.0, 1.0)
        offsets = offsets - along[:, None] * chord
    distances = np.linalg.norm(offsets, axis=1)
    farthest = int(np.argmax(distances)) + 1
    if distances[farthest - 1] <= tolerance:
        return np.vstack([first, last])
    head = simplified(points[: farthest + 1], tolerance)
    return np.vstack([head[:-1], simplified(points[farthest:], tolerance)])


def _no_path_reason(environment: CellEnvironment, cells: list[int], outcome: str) -> str:
    last = cells[-1]
    where = np.array2string(environment.centres(np.array([last]))[0], precision=3)
    if outcome == "terminal":
        return (
            f"the greedy path enters a terminal cell at {where} m after {len(cells) - 1} moves "
            f"({environment.reasons[last]}): train longer or change the grid"
        )
    if outcome == "loop":
        return f"the greedy path comes back to the cell at {where} m: train longer"
    return f"the greedy path does not reach the target within {len(cells) - 1} moves"


def _fingerprint(environment: CellEnvironment, schedule: Schedule) -> str:
    """A digest of what the table was trained on."""
    digest = hashlib.sha256()
    for array in (environment.next_cell, environment.reward, environment.ends):
        digest.update(np.ascontiguousarray(array).tobytes())
    digest.update(repr(schedule).encode())
    return digest.hexdigest()


def _save(path: Path, q: np.ndarray, fingerprint: str) -> None:
    """Write the table atomically (a reader sees the old file or the new)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, name = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".npz")
        with os.fdopen(handle, "wb") as partial:  # one file per writer: no two share it
            np.savez(partial, q=q, fingerprint=np.array(fingerprint))
        Path(name).replace(path)
    except OSError as error:
        raise PluginError(f"q-learning: cannot write the Q-table {path}: {error}") from None


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the Q-learning planner."""
    return [QLearningPlanner]


@hookimpl
def dcsim_register_commands(bench: click.Group) -> None:
    """Add ``dcsim bench q-learning``: the planner against value iteration on its cells."""
    from dcsim_plugins.path_planners.q_learning.bench import command

    bench.add_command(command)
