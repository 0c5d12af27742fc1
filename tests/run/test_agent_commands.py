"""Flying a run by commands given to ``advance`` (an agent's, a replay's) instead of the
controller's, and missions flown without a path planner (``path_planner: null``)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from dcsim.api import Command, close_run, open_run, run
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from tests.conftest import REPO

DEBRIS = ["world.duration=130"]  # grabs its first target at 124 s: the pd holds attitude after
FFSR = REPO / "scenarios" / "ffsr_obstacles.yaml"


def test_a_run_flown_by_the_commands_a_pd_run_gave_reproduces_that_run():
    runner = open_run(overrides=DEBRIS)
    commands = []
    while not runner.ended:
        commands.append(runner.outputs["command"])
        runner.advance()
    flown = close_run(runner)
    replay = open_run(overrides=DEBRIS)
    for command in commands:
        assert not replay.ended
        replay.advance(command=command)
    assert replay.ended
    replayed = close_run(replay)
    assert flown.summary["collisions"] == 0 and any(e["event"] == "grab" for e in flown.events)
    pd.testing.assert_frame_equal(replayed.telemetry, flown.telemetry, check_exact=True)
    assert replayed.events == flown.events


def test_forces_read_back_from_telemetry_with_the_controller_holding_attitude_reproduce_it():
    flown = run(overrides=DEBRIS)
    forces = flown.telemetry[["fx_N", "fy_N", "fz_N"]].to_numpy()
    replay = open_run(overrides=DEBRIS)
    for force in forces[:-1]:  # the last row's command is never flown
        replay.advance(command={"force": force})
    replayed = close_run(replay)
    pd.testing.assert_frame_equal(replayed.telemetry, flown.telemetry, check_exact=True)


def test_the_agents_command_is_flown_and_recorded_in_place_of_the_controllers():
    runner = open_run(FFSR, ["path_planner=null", "world.duration=5"])
    push = np.array([0.0, 0.0, 0.4])
    while not runner.ended:
        runner.advance(command=Command(force=push))
    result = close_run(runner)
    recorded = result.telemetry[["fx_N", "fy_N", "fz_N"]].to_numpy()
    assert np.array_equal(recorded[:-1], np.tile(push, (len(recorded) - 1, 1)))
    # 0.4 N on 5 kg for 5 s, less the propellant burnt: about 0.4 m/s along z
    assert result.telemetry["vz_mps"].iloc[-1] == pytest.approx(0.4, rel=0.01)
    assert abs(result.telemetry["vx_mps"].iloc[-1]) < 1e-9


def test_a_command_that_is_not_one_is_refused_before_anything_is_flown():
    runner = open_run(FFSR, ["path_planner=null", "world.duration=5"])
    with pytest.raises(ValueError, match="has no field thrust"):
        runner.advance(command={"thrust": [1.0, 0.0, 0.0]})
    with pytest.raises(ValueError, match="non-finite"):
        runner.advance(command=Command(force=np.array([np.nan, 0.0, 0.0])))
    with pytest.raises(ValueError, match="joint torques"):
        runner.advance(command={"joint_torques": [1.0, 2.0]})
    with pytest.raises(ValueError, match="not a Command"):
        runner.advance(command={"force": [1.0, 2.0]})
    assert runner.world.time == 0.0
    runner.advance(command={"force": [0.1, 0.0, 0.0]})
    assert runner.world.time == pytest.approx(0.1)
    close_run(runner)


def test_a_transfer_without_a_path_planner_flies_at_its_goal():
    result = run(FFSR, ["path_planner=null", "obstacles=[]"])
    assert result.summary["reason"] == "goal reached"
    assert "path_planner" not in result.summary["plugins"]
    assert not any(e["event"] == "path" for e in result.events)


def test_a_debris_mission_without_a_path_planner_still_plans_its_tasks_and_grabs():
    result = run(overrides=["path_planner=null", "world.duration=120"])
    events = [e["event"] for e in result.events]
    assert "plan" in events and "grab" in events and "path" not in events
    assert "path_planner" not in result.summary["plugins"]


def test_a_controller_asked_on_demand_flies_the_same_run_and_is_not_asked_for_whole_commands():
    flown = run(overrides=DEBRIS)
    setup = setup_run(None, DEBRIS)
    runner = Runner(setup, controller_on_demand=True)
    runner.open()
    while not runner.ended:
        runner.advance()
    on_demand = close_run(runner)
    command_columns = ["fx_N", "fy_N", "fz_N"]
    # the same run; its last row records no command, as none is flown after it
    pd.testing.assert_frame_equal(
        on_demand.telemetry.drop(columns=command_columns),
        flown.telemetry.drop(columns=command_columns),
        check_exact=True,
    )
    assert (
        (
            on_demand.telemetry[command_columns].iloc[:-1]
            == flown.telemetry[command_columns].iloc[:-1]
        )
        .all()
        .all()
    )
    assert not on_demand.telemetry[command_columns].iloc[-1].any()
    assert "controller" in on_demand.summary["wall_time_by_phase_s"]

    whole = Command(force=np.array([0.1, 0.0, 0.0]))
    every_field = {name: getattr(whole, name) for name in Command.__dataclass_fields__}
    for command, asked in ((whole, False), (every_field, False), ({"force": whole.force}, True)):
        agent = Runner(
            setup_run(FFSR, ["path_planner=null", "world.duration=3"]), controller_on_demand=True
        )
        agent.open()
        assert agent.outputs["command"] is None  # not asked yet
        while not agent.ended:
            agent.advance(command=command)
        phases = close_run(agent).summary["wall_time_by_phase_s"]
        assert ("controller" in phases) == asked and "agent" in phases
