"""Every bench ends cleanly at the least values its options allow.

Each ``dcsim bench`` command runs in this process with every count at its least
allowed value (one run, one instance, zero of what may be zero) and every budget and
duration at its least or a tiny allowed value, its plot written where it has one.
Where a bench at those values still runs long, the case says so and shortens it with
an option it has. ``world``, ``manipulator`` and ``localisers`` run at their least
values in tests/test_cli.py, ``capture`` in tests/bench/test_capture_bench.py; ``task-planners`` has fixed problem sizes (5 to 15
targets) that take a minute even at one instance, so its functions run here on the
smallest size with the command's least counts.
"""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from dcsim.bench.task_planners import (
    compare_strategies,
    gap_table,
    optimality_gaps,
    plot_gaps,
    plot_strategies,
    strategy_table,
)
from dcsim.cli.main import cli
from tests.conftest import REPO

SCENARIOS = REPO / "scenarios"

SMALLEST = {
    "soak": ["--ticks", "100", "--samples", "10", "--fmu-cycles", "0", "--plot", "{tmp}/soak.png"],
    "fmu": ["--duration", "1", "--repeats", "1"],
    # Every plan out of time at once.
    "grid-search": ["--scenario", str(SCENARIOS / "station_inspection.yaml"), "--budget", "1e-9"],
    # One setting of the colony; the least budget leaves the plan without a trajectory.
    "ant-colony": [
        *("--layouts", "1", "--deltas", "0", "--cross-sections", "line"),
        *("--variants", "defaults", "--budget", "1e-6", "--plot", "{tmp}/ant.png"),
    ],
    # One cheap planner on one problem: every registered planner takes minutes.
    "path-planners": [
        *("--planners", "straight-line", "--problems", "static-spheres", "--runs", "1"),
        *("--no-memory", "--plot", "{tmp}/paths.png"),
    ],
    # One exact model, one case, a hundredth of an orbit; no missions flown.
    "dynamics": [
        *("--models", "two-body", "--separations", "100", "--axes", "x"),
        *("--eccentricities", "0", "--orbits", "0.01", "--no-planners"),
        *("--plot", "{tmp}/dynamics.png"),
    ],
    "campaign": ["--cases", "1", "--workers", "1", "--duration", "0.01", "--out", "{tmp}/cases"],
    # One controller under one profile; the crowded field's whole crossing takes 35 s,
    # 10 s of it do here.
    "controllers": [
        *("--seeds", "1", "--controllers", "pd", "--sensors", "realistic"),
        *("--workers", "1", "--worker-deaths", "1"),
        *("--set", "world.duration=10", "--plot", "{tmp}/gaps.png"),
    ],
    # One environment, one copy in one vector kind, one step and one period.
    "gym": [
        *("--envs", "dcsim/Transfer-v0", "--counts", "1", "--vector", "sync"),
        *("--steps", "1", "--periods", "1", "--repeats", "1", "--out", "{tmp}/gym"),
    ],
    # One seed of the default and the crowded-field scenarios, a second of each.
    "tracking": ["--seeds", "1", "--duration", "1"],
    # About 9 s whatever the options: the thesis's two application cases are flown.
    "q-learning": [
        *("--scenario", str(SCENARIOS / "space_manipulator_reach.yaml"), "--episodes", "1"),
        *("--seeds", "1", "--margins", "0", "--size-episodes", "1"),
    ],
}


@pytest.mark.parametrize("bench", list(SMALLEST))
def test_a_bench_at_its_smallest_options_prints_its_tables(bench, tmp_path):
    options = [option.format(tmp=tmp_path) for option in SMALLEST[bench]]
    result = CliRunner().invoke(cli, ["bench", bench, *options])
    assert result.exception is None, result.output
    assert result.exit_code == 0 and "|---" in result.stdout
    for written in (option for option in options if option.startswith(str(tmp_path))):
        assert (tmp_path / written).exists(), written


def test_task_planners_at_their_smallest_counts(tmp_path):
    def quiet(line: str) -> None:
        pass

    gaps = optimality_gaps((5,), (5,), 1, 0, 10.0, 2500.0, quiet)
    table = gap_table(gaps)
    assert "| moving (grid optimum) | 5 | ga | 0 | – | – | – | – | – |" in table
    assert "| stationary | 5 | nearest | 1 |" in table
    strategies = compare_strategies((5,), 1, 2, 1, quiet)
    assert strategy_table(strategies, 2).count("\n| 5 |") == 4
    plot_gaps(gaps, tmp_path / "gaps.png")
    plot_strategies(strategies, tmp_path / "strategies.png")
    assert (tmp_path / "gaps.png").exists() and (tmp_path / "strategies.png").exists()
