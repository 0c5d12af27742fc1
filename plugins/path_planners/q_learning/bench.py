"""``dcsim bench q-learning``: the Q-learning planner against the exact answers of its
own cell environment (the space manipulator thesis, §7.3–7.4).

The problems are the reach of a manipulator scenario (default
``scenarios/space_manipulator_reach.yaml``): its robot and start, its target, its
speed and acceleration limits. The bench lives with its planner and uses it directly:
``planner.environment(problem)`` gives the cell environment, ``planner.train(env)`` a
trained table with the planner's generator, ``planner.plan(problem)`` the whole answer.
Exact answers on the same environment come from ``dcsim.api.optimal_values``,
``reachable_cells`` and ``working_cells``. The plugin adds the command to ``dcsim
bench`` through the ``dcsim_register_commands`` hook, as a third party's package would.

- **Working cells** (Table 7.3): for each (α, γ) and number of episodes, over seeds, the
  share of the cells from which the target can be reached at all whose greedy path gets
  there (100 % is the ceiling).
- **Cumulative reward** (Figs 7.2–7.3): each episode's summed reward, per (α, γ).
- **Environment size** (Fig. 7.4): cells against the time to build the environment and
  to train, as the grid's margin grows.
- **Application** (Figs 7.5–7.13): the greedy paths from the scenario's start and from a
  second start, their discounted return against the optimum, and the arm's state along
  them (joint angles, det(J Jᵀ), the target's angle from the base's facing side, the
  base's displacement against half the end effector's).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import click
import numpy as np
from dcsim_plugins.path_planners.q_learning.planner import QLearningPlanner

from dcsim.api import (
    PathProblem,
    Trajectory,
    comma_numbers,
    load_reach_problem,
    optimal_values,
    pyplot,
    reachable_cells,
    save_figure,
    working_cells,
)

THESIS_SETTINGS = ((0.9, 0.9), (0.5, 0.8), (0.2, 0.5))
"""The (α, γ) pairs of the thesis's Table 7.3."""

SECOND_START = (1.2, 0.9, -1.1)
"""The end effector's second start of the thesis's §7.4, m."""

Progress = Callable[[str], None]


def _planner(params: dict[str, Any], seed: int) -> QLearningPlanner:
    return QLearningPlanner(params, np.random.default_rng(seed))


# --------------------------------------------------------------------- working cells
@dataclass(frozen=True)
class WorkingRow:
    """Working cells of one (α, γ, episodes) over seeds.

    Attributes
    ----------
    alpha, gamma : float
    episodes : int
    working : ndarray (seeds,)
        Share of the reachable cells whose greedy path arrives, %.
    training_seconds : ndarray (seeds,)
        Wall time of each training, s.
    greedy_gap : ndarray (seeds,)
        ``100 (V* − G) / |V*|`` % of the greedy return ``G`` from the start (NaN when the
        greedy path from the start does not arrive).
    """

    alpha: float
    gamma: float
    episodes: int
    working: np.ndarray
    training_seconds: np.ndarray
    greedy_gap: np.ndarray


def working_table(
    problem: PathProblem,
    episodes: Sequence[int],
    seeds: int,
    settings: Sequence[tuple[float, float]] = THESIS_SETTINGS,
    progress: Progress | None = None,
) -> tuple[list[WorkingRow], int, int]:
    """Table 7.3 and more: working cells per setting and episodes, over ``seeds`` seeds.

    Returns
    -------
    rows : list of WorkingRow
    reachable, cells : int
        Cells from which the target can be reached at all; cells that do not end an
        episode.
    """
    environment = _planner({}, 0).environment(problem)
    reach = reachable_cells(environment.next_cell, environment.ends, environment.target)
    rows = []
    for alpha, gamma in settings:
        optimum = optimal_values(environment.next_cell, environment.reward, environment.ends, gamma)
        for count in episodes:
            working, seconds, gaps = [], [], []
            for seed in range(seeds):
                planner = _planner(
                    {"learning_rate": alpha, "discount": gamma, "episodes": count}, seed
                )
                began = time.perf_counter()
                q = planner.train(environment).q
                seconds.append(time.perf_counter() - began)
                works = working_cells(
                    q, environment.next_cell, environment.ends, environment.target
                )
                working.append(100.0 * (works & reach).sum() / max(reach.sum(), 1))
                gaps.append(_gap(planner.greedy_path(environment, q), optimum[environment.start]))
            rows.append(
                WorkingRow(
                    alpha, gamma, count, np.array(working), np.array(seconds), np.array(gaps)
                )
            )
            if progress is not None:
                progress(f"α = {alpha}, γ = {gamma}, {count} episodes: {np.mean(working):.1f} %")
    return rows, int(reach.sum()), int((~environment.ends).sum())


def _gap(rollout: Any, optimum: float) -> float:
    """``100 (V* − G) / |V*|`` % of a greedy path's return ``G``; NaN if it fails."""
    if rollout.outcome != "target":
        return float("nan")
    gap = 100.0 * (optimum - rollout.discounted_return) / abs(optimum)
    return 0.0 if abs(gap) < 1e-9 else gap  # equal returns, summed in another order


# --------------------------------------------------------------------- reward curves
def reward_curves(
    problem: PathProblem,
    episodes: int,
    settings: Sequence[tuple[float, float]] = THESIS_SETTINGS,
    seed: int = 0,
) -> dict[tuple[float, float], np.ndarray]:
    """The summed reward of every training episode (Figs 7.2–7.3), per (α, γ)."""
    environment = _planner({}, seed).environment(problem)
    curves = {}
    for alpha, gamma in settings:
        planner = _planner({"learning_rate": alpha, "discount": gamma, "episodes": episodes}, seed)
        curves[(alpha, gamma)] = planner.train(environment).returns
    return curves


# --------------------------------------------------------------------- environment size
@dataclass(frozen=True)
class SizeRow:
    """Cost of one environment size (Fig. 7.4).

    Attributes
    ----------
    margin, cells, terminal : int
        The grid's margin (cells), its cells and its terminal cells.
    environment_seconds, training_seconds : float
        Wall time to build the environment and to train it, s.
    working : float
        Share of the reachable cells that work after training, %.
    """

    margin: int
    cells: int
    terminal: int
    environment_seconds: float
    training_seconds: float
    working: float


def size_sweep(
    problem: PathProblem, margins: Sequence[int], episodes: int, progress: Progress | None = None
) -> list[SizeRow]:
    """Build and train the environment for every margin with ``episodes`` episodes."""
    rows = []
    for margin in margins:
        planner = _planner({"margin": margin, "episodes": episodes}, 0)
        began = time.perf_counter()
        environment = planner.environment(problem)
        built = time.perf_counter()
        q = planner.train(environment).q
        trained = time.perf_counter()
        reach = reachable_cells(environment.next_cell, environment.ends, environment.target)
        works = working_cells(q, environment.next_cell, environment.ends, environment.target)
        rows.append(
            SizeRow(
                margin=margin,
                cells=environment.cells,
                terminal=int(environment.terminal.sum()),
                environment_seconds=built - began,
                training_seconds=trained - built,
                working=100.0 * (works & reach).sum() / max(reach.sum(), 1),
            )
        )
        if progress is not None:
            progress(f"margin {margin}: {environment.cells} cells, {trained - began:.2f} s")
    return rows


# --------------------------------------------------------------------- application
@dataclass(frozen=True)
class Application:
    """The planner's answer from one start, and the arm along its cell path.

    Attributes
    ----------
    start : ndarray (3,)
        The end effector's start, m.
    trajectory : Trajectory or None
        The planner's answer (None with ``reason`` when it found no path).
    reason : str
    cells : ndarray (k,) of int
        The greedy cell path.
    centres, joints, det_jjt, sight, base_displacement, ee_displacement : ndarray
        Along the cell path: centres (m), joint angles (rad), det(J Jᵀ) (m⁶), the target's
        angle from the base's facing side (rad), the base's and the end effector's
        displacement from the start (m).
    greedy_gap : float
        The greedy return's gap to the optimum, %.
    plan_seconds : float
        Wall time of the whole plan, s.
    """

    start: np.ndarray
    trajectory: Trajectory | None
    reason: str
    cells: np.ndarray
    centres: np.ndarray
    joints: np.ndarray
    det_jjt: np.ndarray
    sight: np.ndarray
    base_displacement: np.ndarray
    ee_displacement: np.ndarray
    greedy_gap: float
    plan_seconds: float


def application(problem: PathProblem, seed: int = 0) -> Application:
    """Plan ``problem`` with the planner's defaults and describe the path's cells."""
    planner = _planner({}, seed)
    began = time.perf_counter()
    answer = planner.plan(problem)
    seconds = time.perf_counter() - began
    environment = _planner({}, seed).environment(problem)
    replay = _planner({}, seed)
    q = replay.train(environment).q
    rollout = replay.greedy_path(environment, q)
    optimum = optimal_values(
        environment.next_cell, environment.reward, environment.ends, replay.params.discount
    )[environment.start]
    cells = np.asarray(rollout.cells)
    centres = environment.centres(cells)
    bases = environment.base_positions[cells]
    trajectory = answer if isinstance(answer, Trajectory) else None
    return Application(
        start=centres[0],
        trajectory=trajectory,
        reason="" if trajectory is not None else answer.reason,
        cells=cells,
        centres=centres,
        joints=environment.joints[cells],
        det_jjt=environment.det_jjt[cells],
        sight=environment.sight[cells],
        base_displacement=np.linalg.norm(bases - bases[0], axis=1),
        ee_displacement=np.linalg.norm(centres - centres[0], axis=1),
        greedy_gap=_gap(rollout, optimum),
        plan_seconds=seconds,
    )


# --------------------------------------------------------------------- reports
def markdown(
    rows: Sequence[WorkingRow],
    reachable: int,
    cells: int,
    sizes: Sequence[SizeRow],
    applications: Sequence[Application],
) -> str:
    """The bench's tables for docs/benchmarks.md."""
    lines = [
        f"Working cells (% of the {reachable} cells of {cells} from which the target can be "
        "reached; mean, min–max over seeds), training time and the greedy return's gap to "
        "the optimum from the start:",
        "",
        "| α | γ | episodes | working cells % | training s | greedy gap % |",
        "|---|---|---|---|---|---|",
    ]
    for row in rows:
        gap = np.nanmax(row.greedy_gap) if np.isfinite(row.greedy_gap).any() else float("nan")
        failed = int(np.isnan(row.greedy_gap).sum())
        lines.append(
            f"| {row.alpha} | {row.gamma} | {row.episodes} | {row.working.mean():.1f} "
            f"({row.working.min():.1f}–{row.working.max():.1f}) | "
            f"{row.training_seconds.mean():.2f} | {gap:.2f}"
            + (f" ({failed} greedy paths from the start failed)" if failed else "")
            + " |"
        )
    lines += [
        "",
        "| margin | cells | terminal cells | environment s | training s | working cells % |",
        "|---|---|---|---|---|---|",
    ]
    for size in sizes:
        lines.append(
            f"| {size.margin} | {size.cells} | {size.terminal} | {size.environment_seconds:.2f} "
            f"| {size.training_seconds:.2f} | {size.working:.1f} |"
        )
    lines += [
        "",
        "| start [m] | moves | path s | greedy gap % | plan s | joints max ° | min det(J Jᵀ) "
        "| max sight ° | base / end effector |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for case in applications:
        duration = "no path" if case.trajectory is None else f"{case.trajectory.duration:.2f}"
        ratio = np.max(case.base_displacement[1:] / case.ee_displacement[1:], initial=0.0)
        lines.append(
            f"| {np.round(case.start, 3).tolist()} | {len(case.cells) - 1} | {duration} | "
            f"{case.greedy_gap:.2f} | {case.plan_seconds:.2f} | "
            f"{np.degrees(np.abs(case.joints)).max():.1f} | {case.det_jjt.min():.3g} | "
            f"{np.degrees(case.sight).max():.1f} | {ratio:.3f} |"
        )
    return "\n".join(lines)


def plot_curves(curves: dict[tuple[float, float], np.ndarray], path: Path) -> None:
    """Figs 7.2–7.3: the summed reward per episode for each (α, γ), with a running mean."""
    plt = pyplot()
    figure, axes = plt.subplots(1, len(curves), figsize=(5 * len(curves), 4), sharey=True)
    for axis, ((alpha, gamma), returns) in zip(np.atleast_1d(axes), curves.items(), strict=True):
        window = max(len(returns) // 40, 1)
        running = np.convolve(returns, np.ones(window) / window, mode="valid")
        axis.plot(returns, lw=0.4, color="0.6", label="episode")
        axis.plot(
            np.arange(window - 1, len(returns)), running, color="tab:blue", label="running mean"
        )
        axis.set(title=f"α = {alpha}, γ = {gamma}", xlabel="episode")
        axis.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("summed reward")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    save_figure(figure, path)


def plot_sizes(sizes: Sequence[SizeRow], path: Path) -> None:
    """Fig. 7.4: build and training time against the number of cells."""
    plt = pyplot()
    figure, axis = plt.subplots(figsize=(6, 4))
    cells = [s.cells for s in sizes]
    axis.plot(cells, [s.environment_seconds for s in sizes], "o-", label="environment")
    axis.plot(cells, [s.training_seconds for s in sizes], "s-", label="training")
    axis.set(xlabel="cells", ylabel="wall time [s]", title="Cost against environment size")
    axis.grid(alpha=0.3)
    axis.legend()
    save_figure(figure, path)


def plot_application(case: Application, target: np.ndarray, path: Path) -> None:
    """Figs 7.5–7.10 (and 7.11–7.13): the path and the arm's state along its cells."""
    plt = pyplot()
    figure = plt.figure(figsize=(13, 8))
    axis = figure.add_subplot(2, 3, 1, projection="3d")
    axis.plot(*case.centres.T, "o-", ms=3, color="tab:blue", label="greedy cells")
    if case.trajectory is not None:
        axis.plot(*case.trajectory.positions.T, color="k", lw=1.0, label="flown path")
    axis.scatter(*case.start, color="tab:blue", s=40)
    axis.scatter(*target, color="tab:green", s=40)
    axis.set(xlabel="x [m]", ylabel="y [m]", zlabel="z [m]", title="End-effector path")
    axis.legend(fontsize=7)
    moves = np.arange(len(case.cells))
    panels = [
        (np.degrees(case.joints), "joint angles [deg]", (-90.0, 90.0)),
        (case.det_jjt, "det(J Jᵀ) [m⁶]", None),
        (np.degrees(case.sight), "target's angle from the facing side [deg]", (60.0,)),
    ]
    for k, (values, label, limits) in enumerate(panels, start=2):
        ax = figure.add_subplot(2, 3, k)
        ax.plot(moves, values, "o-", ms=3)
        for limit in limits or ():
            ax.axhline(limit, color="k", ls="--", lw=0.8)
        ax.set(xlabel="move", ylabel=label)
        ax.grid(alpha=0.3)
    ax = figure.add_subplot(2, 3, 5)
    ax.plot(moves, case.base_displacement, "o-", ms=3, color="tab:red", label="base")
    ax.plot(moves, 0.5 * case.ee_displacement, "o-", ms=3, label="half the end effector's")
    ax.set(xlabel="move", ylabel="displacement [m]")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    figure.suptitle(f"q-learning from {np.round(case.start, 3).tolist()} m")
    save_figure(figure, path)


def run_applications(scenario: str | Path, seed: int = 0) -> list[Application]:
    """The two application cases of §7.4: the scenario's start and :data:`SECOND_START`."""
    return [
        application(load_reach_problem(scenario), seed),
        application(load_reach_problem(scenario, SECOND_START), seed),
    ]


# --------------------------------------------------------------------- command
@click.command("q-learning", short_help="The q-learning planner against value iteration.")
@click.option(
    "--scenario",
    default="scenarios/space_manipulator_reach.yaml",
    show_default=True,
    help="A reach scenario: its robot, start, target and limits.",
)
@click.option(
    "--episodes",
    default="500,1000,2000",
    show_default=True,
    help="Comma-separated training lengths of the working-cells table.",
)
@click.option("--seeds", type=click.IntRange(1, 1000), default=5, show_default=True)
@click.option(
    "--margins",
    default="1,2,3,4,5,6",
    show_default=True,
    help="Comma-separated grid margins (cells) of the environment-size sweep.",
)
@click.option(
    "--size-episodes",
    type=click.IntRange(1),
    default=2000,
    show_default=True,
    help="Training episodes of the environment-size sweep and the reward curves.",
)
@click.option(
    "--figures",
    "figures_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Write q_learning_rewards.png, q_learning_sizes.png and the two application "
    "cases' q_learning_start_a.png and q_learning_start_b.png here.",
)
def command(
    scenario: str,
    episodes: str,
    seeds: int,
    margins: str,
    size_episodes: int,
    figures_dir: Path | None,
) -> None:
    """The q-learning planner against the exact answers of its cell environment.

    The thesis's Table 7.3 (working cells for its three (α, γ) at equal episodes, as a
    share of the cells from which the target can be reached at all), the greedy return's
    gap to the optimum that value iteration finds, the cumulative reward per episode
    (Figs 7.2-7.3), build and training time against the environment's size (Fig. 7.4),
    and the two application cases of §7.4 with the arm's state along their paths (Figs
    7.5-7.13). Prints Markdown tables for docs/benchmarks.md; progress goes to stderr.
    """
    counts = [int(v) for v in comma_numbers(episodes, "--episodes")]
    widths = [int(v) for v in comma_numbers(margins, "--margins")]
    progress = lambda line: click.echo(line, err=True)  # noqa: E731
    problem = load_reach_problem(scenario)
    rows, reachable, cells = working_table(problem, counts, seeds, progress=progress)
    sizes = size_sweep(problem, widths, size_episodes, progress=progress)
    cases = run_applications(scenario)
    click.echo(markdown(rows, reachable, cells, sizes, cases))
    if figures_dir is not None:
        figures_dir.mkdir(parents=True, exist_ok=True)
        plot_curves(reward_curves(problem, size_episodes), figures_dir / "q_learning_rewards.png")
        plot_sizes(sizes, figures_dir / "q_learning_sizes.png")
        target = problem.goal.position  # the reach mission's goal is about its target
        for case, name in zip(cases, ("start_a", "start_b"), strict=True):
            plot_application(case, target, figures_dir / f"q_learning_{name}.png")
        click.echo(f"\nfigures in {figures_dir}")
