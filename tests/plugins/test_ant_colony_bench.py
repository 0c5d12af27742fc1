"""``dcsim bench ant-colony``: the colony scored against the DP optimum of its own graph."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from dcsim_plugins.path_planners.ant_colony import bench
from dcsim_plugins.path_planners.ant_colony.planner import AntColonyPlanner

from dcsim.api import layered_optimum, load_bench_problem
from dcsim.cli.main import cli
from tests.conftest import REPO

PNG = b"\x89PNG\r\n\x1a\n"
SETTINGS = bench.settings(["line"], [2.0], ["defaults", "paper"])


@pytest.fixture(scope="module")
def layouts():
    return [load_bench_problem(f"static-spheres:{seed}") for seed in range(2)]


@pytest.fixture(scope="module")
def runs(layouts):
    lines = []  # a generous budget: a busy machine must not cut the whole plan's colony
    runs = bench.bench_ant_colony(layouts, SETTINGS, budget=30.0, progress=lines.append)
    return runs, lines


def test_every_run_is_a_real_colony_scored_on_a_graph_rebuilt_here(layouts, runs):
    runs, progress = runs
    assert [(r.problem, r.setting) for r in runs] == [
        (layout.name, setting) for layout in layouts for setting in SETTINGS
    ]
    assert len(progress) == 2 and progress[-1].startswith("[2/2] static-spheres-1: ")
    assert "ETA" in progress[0]
    for run in runs:
        assert run.scored and run.answered, (run.reason, run.plan_reason)
        seed = [layout.name for layout in layouts].index(run.problem)
        assert run.seed == seed
        planner = AntColonyPlanner(run.setting.params(), np.random.default_rng(seed))
        graph = planner.candidate_graph(layouts[seed].problem)
        assert layered_optimum(graph.lengths, graph.node_cost).cost == run.optimum
        again = planner.colony(graph)  # the same generator: the same colony
        assert again.cost == run.cost and again.cycles == run.cycles
        assert run.history[-1] == run.cost and len(run.history) == run.cycles
        assert 1 <= run.found_at <= run.cycles and run.history[run.found_at - 1] == run.cost
        assert graph.costs(run.path[None])[0] == pytest.approx(run.cost)
        # the whole plan ran the same colony (the budget did not cut it short)
        assert run.plan_cycles == run.cycles and not run.cut_by_budget
        assert run.trajectory is not None and run.trajectory.statistics["best_cost"] == run.cost
        for seconds in (run.graph_seconds, run.colony_seconds, run.dp_seconds, run.plan_seconds):
            assert 0 < seconds < 10


def test_the_optimum_is_never_above_the_colony_and_gaps_are_not_negative(runs):
    runs, _ = runs
    for run in runs:
        assert run.optimum <= run.cost * (1 + 1e-12)
        assert run.gap >= 0
        assert run.gap == pytest.approx(max(0.0, 100 * (run.cost / run.optimum - 1)), abs=1e-9)
    paper = [r.gap for r in runs if r.setting.variant == "paper"]
    assert max(paper) > 0  # the paper's literal colony stops above the optimum here


def test_rounding_below_the_optimum_is_clipped_but_a_real_shortfall_is_kept():
    assert bench.gap_percent(100.0 - 1e-12, 100.0) == 0.0
    assert bench.gap_percent(101.0, 100.0) == pytest.approx(1.0)
    assert bench.gap_percent(99.0, 100.0) == pytest.approx(-1.0)


def test_the_tables_hold_the_statistics_of_the_runs(runs):
    runs, _ = runs
    quality, timing, targets = (
        bench.quality_table(runs),
        bench.time_table(runs),
        bench.target_table(runs),
    )
    for setting in SETTINGS:
        mine = [r for r in runs if r.setting == setting]
        gaps = np.array([r.gap for r in mine])
        row = next(line for line in quality.splitlines() if f"| {setting.variant} |" in line)
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[3] == "2/2"
        assert cells[4] == f"{np.median(gaps):,.2f}" and cells[6] == f"{gaps.max():,.2f}"
        assert cells[8] == f"{np.median([r.cycles for r in mine]):,.0f}"
        assert cells[-1] == "2/2 (100 %)"
        row = next(line for line in timing.splitlines() if f"| {setting.variant} |" in line)
        cells = [c.strip() for c in row.strip("|").split("|")]
        plan = np.array([r.plan_seconds for r in mine]) * 1e3
        assert cells[7] == f"{np.median(plan):,.1f}" and cells[9] == f"{plan.max():,.1f}"
        row = next(line for line in targets.splitlines() if f"| {setting.variant} |" in line)
        verdict = "yes" if np.median(gaps) <= bench.TARGET_MEDIAN_GAP else "NO"
        assert f"| {verdict} ({np.median(gaps):.2f} %) |" in row


def test_the_command_prints_the_tables_and_writes_the_figures(tmp_path):
    figure, plot = tmp_path / "img" / "fig2.png", tmp_path / "gaps.png"
    result = CliRunner().invoke(
        cli,
        [
            "bench",
            "ant-colony",
            "--layouts",
            "1",
            "--cross-sections",
            "line",
            "--deltas",
            "2,6",
            "--variants",
            "defaults",
            "--params",
            "max_cycles=40",
            "--figure",
            str(figure),
            "--figure-scenario",
            str(REPO / "scenarios" / "ffsr_obstacles.yaml"),
            "--plot",
            str(plot),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "ant-colony on 1 problems (static-spheres:0)" in result.stdout
    assert "max_cycles=40" in result.stdout
    assert "| line | 6 | defaults | 1/1 |" in result.stdout
    assert "ffsr_obstacles (the paper's Fig. 2)" in result.stdout
    assert "Targets met" in result.stdout
    assert "[1/1] static-spheres-0: " in result.stderr
    convergence = tmp_path / "img" / "fig2_convergence.png"
    for path in (figure, convergence, plot):
        data = path.read_bytes()
        assert data.startswith(PNG) and len(data) > 10_000, path


@pytest.mark.parametrize(
    "options, message",
    [
        (["--deltas", "two"], "--deltas: expected numbers"),
        (["--deltas", "nan"], "δ must be a finite number"),
        (["--cross-sections", "cube"], "unknown cross-section 'cube'"),
        (["--variants", "paper,fast"], "unknown variant 'fast'"),
        (["--layouts", "0"], "--layouts must be at least 1"),
        (["--layouts", "2", "--problems", "shapes:1"], "not both"),
        (["--params", "ants=0"], "invalid parameters for plugin 'ant-colony'"),
        (["--params", "colour=red"], "colour: unknown key"),
        (["--params", "ants"], "'ants' in 'ant-colony:ants' is not key=value"),
        (["--problems", "mars:1"], "'mars:1' is neither a problem family"),
        (["--budget", "0"], "--budget must be a positive"),
    ],
)
def test_bad_options_are_errors_without_a_traceback(options, message):
    result = CliRunner().invoke(cli, ["bench", "ant-colony", *options])
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error: ") or "\nerror: " in result.stderr
    assert message in result.stderr
    assert "Traceback" not in result.output and isinstance(result.exception, SystemExit)
    assert "[1/" not in result.stderr  # refused before any run


def test_the_convergence_figure_sits_beside_the_paths_figure(tmp_path):
    assert bench.convergence_path(tmp_path / "a.png") == tmp_path / "a_convergence.png"
    assert bench.convergence_path(tmp_path / "b") == tmp_path / "b_convergence.png"


def test_a_whole_plan_cut_short_by_its_budget_is_counted(layouts):
    setting = SETTINGS[0]
    unhurried = bench.run_setting(layouts[0], setting, 0)
    # a third of what the whole plan took here: the cut holds however fast the machine,
    # and the candidate graph (about an eighth of the plan) is still built in time
    run = bench.run_setting(layouts[0], setting, 0, budget=unhurried.plan_seconds / 3)
    assert run.scored and run.cycles > 1  # the measured colony has no deadline
    assert run.plan_cycles < run.cycles and run.cut_by_budget
    row = next(line for line in bench.time_table([run]).splitlines() if "| line |" in line)
    assert row.endswith("| 1 |")
