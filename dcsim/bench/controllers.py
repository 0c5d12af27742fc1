"""``dcsim bench controllers``: controllers crossing a crowded debris field.

Every seed draws a fresh field of moving obstacles (:func:`crowded_obstacles`; seed 0 is
the one written in ``scenarios/crowded_field.yaml``) and flies the crowded-field mission
with each controller under each sensing profile (``ideal``: the obstacles' exact tracks;
``realistic``: the tracks the tracker makes from the object sensor's detections); the
world's seed is the same number, so every controller meets the same field and the same
sensor noise under a profile. A run records its collisions (the scenario
does not stop at the first), the least surface gap to any obstacle, the delta-v and
the mission time. The runs are cases on the campaign engine (:mod:`dcsim.campaign`):
a local Dask cluster, or an existing one by address.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from dcsim.bench.figures import pyplot, save
from dcsim.campaign.engine import ClusterOptions, TaskOutcome, dask_client, run_tasks
from dcsim.errors import DcsimError
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

FIELD_COUNT = 60
"""Obstacles in the crowded field."""
FIELD_BOX = ((-15.0, 15.0), (15.0, 65.0), (-15.0, 15.0))
"""Where obstacles start (x radial, y along-track, z normal), m."""
FIELD_SPEED_SIGMA = 0.03
"""Standard deviation of an obstacle's initial velocity per axis, m/s."""
FIRST_ID = 100


def crowded_obstacles(seed: int, count: int = FIELD_COUNT) -> list[dict]:
    """Obstacles of the crowded field for ``seed``, as scenario entries (Clohessy–Wiltshire)."""
    rng = np.random.default_rng(seed)
    low, high = np.array(FIELD_BOX).T
    positions = rng.uniform(low, high, (count, 3))
    velocities = rng.normal(0.0, FIELD_SPEED_SIGMA, (count, 3))
    radii = rng.uniform(0.8, 1.5, count)
    return [
        {
            "id": FIRST_ID + i,
            "radius": round(float(radii[i]), 2),
            "mass": 50.0,
            "motion": {
                "type": "cw",
                "position": [round(float(x), 2) for x in positions[i]],
                "velocity": [round(float(x), 4) for x in velocities[i]],
            },
        }
        for i in range(count)
    ]


def field_override(seed: int) -> str:
    """The ``--set`` override that puts seed ``seed``'s field in the scenario."""
    return "obstacles=" + yaml.safe_dump(crowded_obstacles(seed), default_flow_style=True).strip()


@dataclass(frozen=True)
class ControllerRun:
    """One controller on one seed of the crowded field under one sensing profile.

    Attributes
    ----------
    controller, sensors : str
        The controller plugin and the sensing profile (``sensors.profile``).
    seed : int
        The field's and the world's seed.
    collisions : int
        Contacts with obstacles counted over the run.
    min_distance : float
        Least surface gap to any obstacle over the run, m (negative: passed into one).
    delta_v : float
        Delta-v spent, m/s.
    mission_time : float
        Simulated time at the end of the run, s.
    delivered, targets : int
        Targets delivered and targets in the mission.
    stopped : str
        Why the mission stopped before its end (a path planner that found no path, a
        stop rule), or "" when the run completed.
    """

    controller: str
    sensors: str
    seed: int
    collisions: int
    min_distance: float
    delta_v: float
    mission_time: float
    delivered: int
    targets: int
    stopped: str = ""


@dataclass(frozen=True)
class ControllerCase:
    """One controller on one seed's field of a scenario under a sensing profile.

    Attributes
    ----------
    scenario : Path
        The crowded-field scenario file.
    controller : str
        The controller plugin, flown with its default parameters.
    seed : int
        The field's and the world's seed.
    overrides : tuple of str
        Further ``KEY.PATH=VALUE`` overrides, applied last.
    sensors : str
        The sensing profile (``sensors.profile``).
    """

    scenario: Path
    controller: str
    seed: int
    overrides: tuple[str, ...] = ()
    sensors: str = "ideal"


def fly(case: ControllerCase) -> ControllerRun:
    """Fly ``case`` (nothing written); its overrides apply after the field, the controller
    and the sensing profile.

    A run the mission or a stop rule stopped early is kept, saying why
    (:attr:`ControllerRun.stopped`): its collisions and closest approach up to the stop
    count, its delta-v and time are those of a shorter flight.

    Raises
    ------
    RuntimeError
        If the run failed (a plugin failed): it has no figures.
    """
    chosen = [
        field_override(case.seed),
        f"controller.plugin={case.controller}",
        "controller.params={}",
        f"sensors.profile={case.sensors}",
    ]
    setup = setup_run(case.scenario, [*chosen, *case.overrides], case.seed)
    summary = Runner(setup, None).run()
    if summary["status"] == "failed":
        raise RuntimeError(
            f"{case.controller} ({case.sensors}) on seed {case.seed}: "
            f"{summary['status']}, {summary['reason']}"
        )
    return ControllerRun(
        case.controller,
        case.sensors,
        case.seed,
        summary["collisions"],
        summary["min_obstacle_distance_m"],
        summary["delta_v_mps"],
        summary["sim_time_s"],
        summary["delivered"],
        summary["targets"],
        "" if summary["status"] == "completed" else summary["reason"],
    )


def bench_controllers(
    scenario: Path,
    controllers: Sequence[str],
    seeds: Iterable[int],
    overrides: Sequence[str] = (),
    cluster: ClusterOptions | None = None,
    progress: Callable[[str], None] = print,
    sensors: Sequence[str] = ("ideal",),
) -> list[ControllerRun]:
    """Fly every controller under every sensing profile on the fields of ``seeds`` as
    cases on a Dask cluster.

    Parameters
    ----------
    scenario : Path
        The crowded-field scenario file.
    controllers : sequence of str
        Controller plugins, each flown with its default parameters.
    seeds : iterable of int
        The fields' (and worlds') seeds.
    overrides : sequence of str
        ``KEY.PATH=VALUE`` overrides applied to every run after the bench's own.
    cluster : ClusterOptions or None
        Where the cases run; None: a local cluster.
    progress : callable
        Told a line per finished run.
    sensors : sequence of str
        Sensing profiles (``sensors.profile``) every controller flies under.

    Returns
    -------
    list of ControllerRun
        Seed by seed, the profiles in the order given, in each the controllers in the
        order given.

    Raises
    ------
    DcsimError
        At the first run that failed (the others are cancelled).
    """
    cases = [
        ControllerCase(scenario, controller, seed, tuple(overrides), profile)
        for seed in seeds
        for profile in sensors
        for controller in controllers
    ]
    runs: dict[int, ControllerRun] = {}

    def record(outcome: TaskOutcome) -> None:
        if outcome.error is not None:
            raise DcsimError(f"bench controllers: {outcome.error}")
        run = runs[outcome.index] = outcome.value
        progress(
            f"{run.controller} ({run.sensors}) seed {run.seed}: {run.collisions} collisions, "
            f"closest {run.min_distance:.2f} m, delta-v {run.delta_v:.2f} m/s"
            + (f"; stopped: {run.stopped}" if run.stopped else "")
        )

    with dask_client(cluster or ClusterOptions()) as client:
        run_tasks(client, fly, dict(enumerate(cases)), record, name="dcsim-bench-controllers")
    return [runs[index] for index in range(len(cases))]


def _series(runs: list[ControllerRun]) -> dict[tuple[str, str], list[ControllerRun]]:
    """The runs of each controller and sensing profile, controller by controller."""
    controllers = list(dict.fromkeys(r.controller for r in runs))
    keys = sorted(
        dict.fromkeys((r.controller, r.sensors) for r in runs),
        key=lambda key: controllers.index(key[0]),
    )
    return {key: [r for r in runs if (r.controller, r.sensors) == key] for key in keys}


def markdown_table(runs: list[ControllerRun]) -> str:
    """Per controller and sensing profile: collisions, closest approach, delta-v and
    mission time over the seeds."""
    lines = [
        "| controller | sensors | seeds | runs with a collision | collisions "
        "| closest gap min / median [m] | delta-v median (p95) [m/s] "
        "| mission time median [s] | all delivered | stopped early |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for (name, profile), mine in _series(runs).items():
        gaps = np.array([r.min_distance for r in mine])
        dv = np.array([r.delta_v for r in mine])
        lines.append(
            f"| {name} | {profile} | {len(mine)} | {sum(r.collisions > 0 for r in mine)} | "
            f"{sum(r.collisions for r in mine)} | {gaps.min():.2f} / {np.median(gaps):.2f} | "
            f"{np.median(dv):.2f} ({np.percentile(dv, 95):.2f}) | "
            f"{np.median([r.mission_time for r in mine]):.0f} | "
            f"{sum(r.delivered == r.targets for r in mine)} / {len(mine)} | "
            f"{sum(bool(r.stopped) for r in mine)} |"
        )
    return "\n".join(lines)


def plot(runs: list[ControllerRun], safety_distance: float, path: Path) -> None:
    """Distribution of the closest approach per controller and sensing profile, with the
    safety distance (m); runs stopped early (before crossing the field) are left out and
    counted in the legend."""
    plt = pyplot()

    series = _series(runs)
    figure, axis = plt.subplots(figsize=(8, 4.5))
    data = [[r.min_distance for r in mine if not r.stopped] for mine in series.values()]
    flown = [values for values in data if values] or [[safety_distance]]
    bins = np.linspace(min(min(d) for d in flown), max(max(d) for d in flown), 30)
    for (name, profile), values, mine in zip(series, data, series.values(), strict=True):
        left_out = len(mine) - len(values)
        label = f"{name}, {profile} ({len(values)} seeds"
        label += f"; {left_out} stopped early left out)" if left_out else ")"
        axis.hist(values, bins=bins, alpha=0.5, histtype="stepfilled", label=label)
    axis.axvline(safety_distance, color="k", ls="--", label="safety distance")
    axis.axvline(0.0, color="r", lw=1, label="contact")
    axis.set(
        xlabel="closest surface gap to any obstacle over the run [m]",
        ylabel="runs",
        title="Crowded field: closest approach per run",
    )
    axis.legend()
    axis.grid(alpha=0.3)
    save(figure, path)
