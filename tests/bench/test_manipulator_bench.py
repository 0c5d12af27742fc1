"""`dcsim bench manipulator` times every implementation it has and judges the 10× target."""

from __future__ import annotations

import pytest

from dcsim.bench import manipulator as bench
from tests.conftest import REPO

QUANTITIES = set(bench.QUANTITIES)


@pytest.fixture(scope="module")
def result() -> bench.ManipulatorBenchResult:
    return bench.bench_manipulator(states=2, repeats=1, number=1)


def test_every_implementation_is_timed_on_what_it_computes(result):
    assert set(result.seconds[bench.OURS]) == QUANTITIES
    assert set(result.seconds[bench.BULLET]) == QUANTITIES - {
        "coriolis matrix",
        "mass and coriolis",
    }
    assert set(result.seconds[bench.PINOCCHIO]) == QUANTITIES - {"mass and coriolis"}
    assert all(t > 0 for times in result.seconds.values() for t in times.values())


def test_the_references_agree_with_the_model(result):
    assert len(result.agreement) == 6
    assert max(result.agreement.values()) <= 1e-9


def test_the_table_gives_every_call_and_the_verdict(result):
    table = bench.markdown_table(result)
    labels = [line.split("|")[1].strip() for line in table.splitlines()[2:] if line.startswith("|")]
    assert labels == [*bench.QUANTITIES.values(), "M + C, two calls"]
    ratio = result.target_ratio
    assert ratio > 0
    holds = "yes" if ratio <= bench.TARGET else "no"
    assert f"M + C within 10× of Pinocchio: {holds}" in table


def test_without_pinocchio_its_column_is_empty_and_the_target_not_judged(monkeypatch):
    monkeypatch.setattr(bench, "pin", None)
    lines = []
    result = bench.bench_manipulator(states=1, repeats=1, number=1, progress=lines.append)
    assert bench.PINOCCHIO not in result.seconds and result.target_ratio is None
    assert "Pinocchio is not installed" in lines[-1]
    table = bench.markdown_table(result)
    assert "| M | " in table and "not judged (Pinocchio is not installed)" in table


def test_a_scenario_is_run_for_its_real_time_factor():
    path = REPO / "scenarios" / "space_manipulator_reach.yaml"
    speed = bench.scenario_speed(path, ["world.duration=0.2"])
    assert speed.name == "space-manipulator-reach"
    assert speed.sim_time == pytest.approx(0.2) and speed.real_time_factor > 0
    assert set(speed.phases) == set(bench.PHASES) and speed.phases["controller"] > 0
    assert "real-time factor" in bench.scenario_line(speed)
