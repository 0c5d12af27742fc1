"""`dcsim bench gym` measures every vector and count it is given, and a step against a tick."""

from __future__ import annotations

import json
import math

import pytest

from dcsim.bench import gym as bench

TRANSFER = "dcsim/Transfer-v0"


@pytest.fixture(scope="module")
def result() -> bench.GymBenchResult:
    # 80 periods: the transfer's run collides at its 66th tick (path_planner=null, pd
    # straight at the goal), so the run side starts a second run within each repeat.
    return bench.bench_gym(
        [TRANSFER], counts=[1, 2], vectors=["async", "sync"], steps=3, periods=80, repeats=2
    )


def test_every_vector_and_count_is_measured_once(result):
    measured = [(row.env_id, row.vector, row.envs) for row in result.throughput]
    assert measured == [
        (TRANSFER, "async", 1),
        (TRANSFER, "async", 2),
        (TRANSFER, "sync", 1),
        (TRANSFER, "sync", 2),
    ]
    assert [row.env_steps for row in result.throughput] == [3, 6, 3, 6]
    assert all(0 <= row.episodes_ended <= row.env_steps for row in result.throughput)
    rates = [row.steps_per_second for row in result.throughput]
    assert all(math.isfinite(rate) and rate > 0 for rate in rates)


@pytest.mark.parametrize("vector", bench.VECTOR_KINDS)
def test_episodes_that_end_while_timed_are_counted(vector):
    # Two control periods to a run: every copy's episode is truncated at its second
    # step, and its third is its reset.
    row = bench.throughput(TRANSFER, vector, 2, steps=3, overrides=["world.duration=0.2"])
    assert row.episodes_ended == 2


def test_the_step_cost_has_every_repeat_of_both_sides(result):
    (cost,) = result.costs
    assert cost.env_id == TRANSFER and cost.periods == 80
    assert len(cost.env) == len(cost.run) == 2
    times = [*cost.env, *cost.run, cost.ratio]
    assert all(math.isfinite(t) and t > 0 for t in times)
    assert cost.met == (cost.ratio <= bench.RATIO_TARGET)


def test_the_tables_json_and_plot_hold_every_measurement(result, tmp_path):
    tables = bench.markdown_tables(result)
    assert tables.count(f"| {TRANSFER} | ") == 5  # four vectors and counts, one step cost
    assert f"{TRANSFER}: an environment step costs" in bench.verdict(result)
    data = json.loads(json.dumps(result.as_json()))
    assert len(data["throughput"]) == 4 and len(data["step_cost"]) == 1
    assert data["step_cost"][0]["target"] == bench.RATIO_TARGET
    bench.plot(result, tmp_path / "gym.png")
    assert (tmp_path / "gym.png").stat().st_size > 0


@pytest.mark.parametrize(("env_step", "met"), [(1.2e-3, True), (1.21e-3, False)])
def test_the_target_is_a_step_of_at_most_1_2_ticks(env_step, met):
    cost = bench.StepCost(TRANSFER, 10, env=[env_step] * 3, run=[1e-3, 1e-3, 5e-3])
    assert cost.met is met
    table = bench.markdown_tables(bench.GymBenchResult([], [cost]))
    assert table.rstrip().endswith("| met |" if met else "| not met |")
    assert ("NOT MET" in bench.verdict(bench.GymBenchResult([], [cost]))) is not met
