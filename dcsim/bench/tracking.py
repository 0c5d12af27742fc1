"""``dcsim bench tracking``: the tracker's consistency in the closed loop.

A scenario is flown under the ``realistic`` sensing profile, so the tracks the mission,
the planners and the controller see are the tracker's, made from the object sensor's
detections and the localiser's estimate. Each control tick, every track the tracker
hands the mission is compared with the true state of its object (the world's object
field, read and never changed):

- the position error ``e = p_track - p_true`` (m) and its normalised estimation error
  squared (NEES) ``ε = eᵀ P_pp⁻¹ e``, with ``P_pp`` the track's position covariance
  (m²). For a consistent tracker ε is chi-square with 3 degrees of freedom: its mean
  is 3 and it stays within the 3σ bound ``χ²₃(0.9973) = 14.16`` in 99.73 % of
  track-ticks;
- the same for the velocity error (m/s) with the velocity covariance;
- the root-mean-square position and velocity errors over the track-ticks;
- the position NEES with the localiser's error taken out, ``e - (x_est - x_true)``
  with ``x_est`` the robot position the tracker was given and ``x_true`` the true one:
  what the tracker's own filtering contributes. Detections are relative to the robot,
  so the localiser's error enters every track; the tracker adds its covariance to each
  detection's as if it were white, while it is common to all objects and slowly
  varying, and the difference between the two NEES shows what that costs.

Only tracks of free objects are compared: a track of an object just grabbed lives on
for the tracker's ``lose_after`` without detections, predicted as if the object still
drifted, and the mission no longer looks at it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from dcsim.errors import DcsimError
from dcsim.messages import Detection, ObjectTrack, StateEstimate
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import Tracker
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

BOUND_PROBABILITY = 0.9973
"""Probability inside the 3σ bound of a Gaussian error (3 degrees of freedom)."""
BOUND = float(chi2.ppf(BOUND_PROBABILITY, 3))
"""The 3σ bound on a 3-dof NEES, ``χ²₃(0.9973)`` (≈ 14.16)."""


@dataclass(frozen=True)
class TrackingRun:
    """The track-ticks of one run: every live track of a free object at every tick.

    Attributes
    ----------
    scenario : str
        The scenario file's name.
    seed : int
        The world's seed.
    ticks : int
        Control ticks flown.
    position_nees, velocity_nees : ndarray (K,)
        NEES of each track-tick's position and velocity error (dimensionless).
    relative_nees : ndarray (K,)
        NEES of each track-tick's position error less the localiser's error then.
    position_error : ndarray (K,)
        Norm of each track-tick's position error, m.
    velocity_error : ndarray (K,)
        Norm of each track-tick's velocity error, m/s.
    """

    scenario: str
    seed: int
    ticks: int
    position_nees: np.ndarray
    velocity_nees: np.ndarray
    relative_nees: np.ndarray
    position_error: np.ndarray
    velocity_error: np.ndarray


class _Comparison:
    """Compares the tracks a run's tracker answers with the run's true object states.

    Parameters
    ----------
    runner : Runner
        The run; its world is read at each of the tracker's answers.
    """

    def __init__(self, runner: Runner) -> None:
        self.runner = runner
        self.ticks = 0
        self.parts: list[np.ndarray] = []

    def watch(self, tracker: Tracker) -> None:
        """Compare every answer of ``tracker.update`` as it is made (answers unchanged)."""
        update = tracker.update

        def compared(
            time: float, detections: Sequence[Detection], robot: StateEstimate
        ) -> tuple[ObjectTrack, ...]:
            tracks = update(time, detections, robot)
            self.add(tracks, robot)
            return tracks

        setattr(tracker, "update", compared)  # noqa: B010 - an instance's own attribute

    def add(self, tracks: Sequence[ObjectTrack], robot: StateEstimate) -> None:
        """Errors and NEES (5, K) of the ``tracks`` of free objects, against the truth now,
        made from detections relative to the robot's estimate ``robot``."""
        self.ticks += 1
        world = self.runner.world
        assert world is not None  # the tracker is first asked once the world is built
        field = world.field
        rows = np.array([field.index[track.id] for track in tracks], dtype=int)
        free = field.free_mask()[rows]
        if not free.any():
            return
        kept = [track for track, keep in zip(tracks, free.tolist(), strict=True) if keep]
        positions, velocities = field.free_states(world.time)
        states = np.array([np.concatenate([t.position, t.velocity]) for t in kept])
        covariances = np.array([t.covariance for t in kept])
        errors = states - np.hstack([positions, velocities])[rows[free]]
        localiser_error = robot.position - world.base_state()[0]
        self.parts.append(
            np.stack(
                [
                    _nees(errors[:, :3], covariances[:, :3, :3]),
                    _nees(errors[:, 3:], covariances[:, 3:, 3:]),
                    _nees(errors[:, :3] - localiser_error, covariances[:, :3, :3]),
                    np.linalg.norm(errors[:, :3], axis=1),
                    np.linalg.norm(errors[:, 3:], axis=1),
                ]
            )
        )


def _nees(errors: np.ndarray, covariances: np.ndarray) -> np.ndarray:
    """``eᵀ P⁻¹ e`` of each error (K, 3) with its covariance (K, 3, 3)."""
    return np.einsum("ki,ki->k", errors, np.linalg.solve(covariances, errors[..., None])[..., 0])


def track_consistency(
    scenario: Path,
    seed: int,
    duration: float | None = None,
    overrides: Sequence[str] = (),
    registry: PluginRegistry | None = None,
) -> TrackingRun:
    """Fly ``scenario`` under realistic sensing and compare its tracks with the truth.

    Parameters
    ----------
    scenario : Path
        A scenario file.
    seed : int
        The world's seed (``world.seed``).
    duration : float or None
        Simulated time at most, s; None: the scenario's ``world.duration``.
    overrides : sequence of str
        ``KEY.PATH=VALUE`` overrides applied after ``sensors.profile=realistic``.
    registry : PluginRegistry or None
        Where the plugins come from; discovered if None.

    Returns
    -------
    TrackingRun
        Every track-tick's errors and NEES.

    Raises
    ------
    DcsimError
        If the run has no tracker (an override took the object sensor's model away)
        or did not complete.
    """
    chosen = ["sensors.profile=realistic", *overrides]
    if duration is not None:
        chosen.append(f"world.duration={duration}")
    setup = setup_run(scenario, chosen, seed, registry)
    tracker = setup.plugins.get("tracker")
    if not isinstance(tracker, Tracker):
        raise DcsimError(
            f"{scenario.name}: no tracker runs (sensors.objects has no model): "
            "give the object sensor a model to measure its tracks"
        )
    runner = Runner(setup, None, keep_rows=False, plots=False)
    comparison = _Comparison(runner)
    comparison.watch(tracker)
    summary = runner.run()
    if summary["status"] == "failed":
        raise DcsimError(f"{scenario.name} seed {seed}: the run failed: {summary['reason']}")
    values = np.hstack(comparison.parts) if comparison.parts else np.zeros((5, 0))
    return TrackingRun(scenario.name, seed, comparison.ticks, *values)


def bench_tracking(
    scenarios: Sequence[Path],
    seeds: Iterable[int],
    duration: float | None = None,
    overrides: Sequence[str] = (),
    progress: Callable[[str], None] = print,
) -> list[TrackingRun]:
    """:func:`track_consistency` of every scenario on every seed, one run after another.

    Returns
    -------
    list of TrackingRun
        Scenario by scenario, seed by seed.
    """
    registry = PluginRegistry.discover()
    runs = []
    seeds = list(seeds)
    for scenario in scenarios:
        for seed in seeds:
            run = track_consistency(scenario, seed, duration, overrides, registry)
            progress(
                f"{run.scenario} seed {run.seed}: {run.position_nees.size} track-ticks, "
                f"{_inside(run.position_nees):.2%} inside the 3-sigma bound"
            )
            runs.append(run)
    return runs


def _inside(nees: np.ndarray) -> float:
    """Fraction of NEES values within :data:`BOUND` (1 when there are none)."""
    return float(np.mean(nees <= BOUND)) if nees.size else 1.0


def markdown_table(runs: list[TrackingRun]) -> str:
    """Per scenario over its seeds: track-ticks, mean NEES and the fraction inside the 3σ
    bound (position and velocity; the worst seed's position fraction), RMS errors (m,
    m/s), and the position NEES with the localiser's error taken out."""
    lines = [
        "| scenario | seeds | ticks | track-ticks | position NEES mean | inside 3σ "
        "| worst seed inside 3σ | velocity NEES mean | velocity inside 3σ "
        "| RMS position error [m] | RMS velocity error [m/s] "
        "| localiser's error out: NEES mean | inside 3σ |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name in dict.fromkeys(run.scenario for run in runs):
        mine = [run for run in runs if run.scenario == name]
        position, velocity, relative, position_error, velocity_error = (
            np.concatenate([getattr(run, part) for run in mine])
            for part in (
                "position_nees",
                "velocity_nees",
                "relative_nees",
                "position_error",
                "velocity_error",
            )
        )
        lines.append(
            f"| {name} | {len(mine)} | {sum(r.ticks for r in mine)} | {position.size} | "
            f"{_mean(position, 2)} | {_inside(position):.2%} | "
            f"{min(_inside(r.position_nees) for r in mine):.2%} | "
            f"{_mean(velocity, 2)} | {_inside(velocity):.2%} | "
            f"{_mean(position_error**2, 3, np.sqrt)} | {_mean(velocity_error**2, 4, np.sqrt)} | "
            f"{_mean(relative, 2)} | {_inside(relative):.2%} |"
        )
    return "\n".join(lines)


def _mean(values: np.ndarray, digits: int, then: Callable[[float], float] = float) -> str:
    """``then`` of the mean of ``values`` with ``digits`` decimals, or "–" if empty."""
    return f"{then(float(np.mean(values))):.{digits}f}" if values.size else "–"
