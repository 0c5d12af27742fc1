"""Every answer a plugin gives is checked where it is given: a wrong type, a wrong shape or
a non-finite number ends the run as ``failed``, naming the plugin, its method and the
time, with the records kept; a plugin that raises leaves its own traceback."""

from __future__ import annotations

import copy
import json
import subprocess
import sys

import numpy as np
import pytest

from dcsim.api import (
    AttitudeReading,
    BeaconRange,
    Command,
    Controller,
    DropVisit,
    NoPath,
    PathPlanner,
    Plan,
    PlanTask,
    PluginParams,
    RateReading,
    StateEstimate,
    TaskPlanner,
    Trajectory,
    quantity,
)
from dcsim.registry import answers
from dcsim.registry.answers import ActuatorCounts, output_problem
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from tests.conftest import REPO
from tests.test_runner import registry_with

BAD_AFTER = 2.0
"""When the misbehaving test plugins start misbehaving, s."""

_NAN3 = np.array([np.nan, 0.0, 0.0])


class WhenParams(PluginParams):
    after: float = quantity(BAD_AFTER, unit="s", ge=0, description="When to misbehave.")
    answer: str = quantity("ndarray", description="What to answer with then (WRONG_ANSWERS).")


WRONG_ANSWERS = {
    "ndarray": np.zeros(3),
    "none": None,
    "nan-force": Command(force=_NAN3),
    "inf-torque": Command(torque=[0.0, np.inf, 0.0]),
    "two-joints": Command(joint_torques=[0.0, 0.0]),
}
"""What :class:`MisbehavingController` answers with, by its ``answer`` parameter."""


class MisbehavingController(Controller):
    """Holds still, then answers with one of :data:`WRONG_ANSWERS`, or raises."""

    name = "misbehaves"
    summary = "Answers wrongly after a while (test)"
    Params = WhenParams

    def reset(self, robot):
        pass

    def command(self, time, estimate, reference, surroundings):
        if time < self.params.after:
            return Command()
        if self.params.answer == "raises":
            _raise()
        return WRONG_ANSWERS[self.params.answer]


def _raise():
    raise ZeroDivisionError("the plugin's own bug")


class NaNPathPlanner(PathPlanner):
    name = "nan-path"
    summary = "A trajectory with a NaN position (test)"

    def plan(self, problem):
        start = problem.start.position
        positions = np.array([start, start + 1.0])
        positions[1, 2] = np.nan
        return Trajectory(
            times=[problem.start.time, problem.start.time + 10],
            positions=positions,
            velocities=np.zeros((2, 3)),
        )


class SilentRefusalPlanner(PathPlanner):
    name = "silent-refusal"
    summary = "Refuses without a reason (test)"

    def plan(self, problem):
        return NoPath(reason="  ")


class InfCostTaskPlanner(TaskPlanner):
    name = "inf-cost"
    summary = "An empty plan with an infinite cost (test)"

    def plan(self, request):
        return Plan(cost=float("inf"))


def fly(tmp_path, overrides, *classes, duration=5.0):
    out = tmp_path / "run"
    setup = setup_run(
        REPO / "scenarios" / "default.yaml",
        [f"world.duration={duration}", *overrides],
        registry=registry_with(*classes),
    )
    runner = Runner(setup, out)
    summary = runner.run()
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    return runner, summary, events, out


@pytest.mark.parametrize(
    ("answer", "said"),
    [
        ("ndarray", "returned ndarray; expected a Command"),
        ("none", "returned NoneType; expected a Command"),
        ("nan-force", "returned non-finite numbers: force [nan, 0.0, 0.0]"),
        ("inf-torque", "returned non-finite numbers: torque [0.0, inf, 0.0]"),
        ("two-joints", "returned 2 joint torques for a robot with 0 joints"),
    ],
)
def test_a_controller_s_wrong_answer_fails_the_run_naming_it(tmp_path, answer, said):
    runner, summary, events, out = fly(
        tmp_path,
        ["controller.plugin=misbehaves", f"controller.params.answer={answer}"],
        MisbehavingController,
    )
    assert summary["status"] == "failed"
    assert summary["reason"].startswith(
        f"controller plugin 'misbehaves' broke its contract in command() at t = {BAD_AFTER:g} s: "
    )
    assert said in summary["reason"]
    failed = events[-1]
    assert failed["event"] == "plugin_failed" and failed["t"] == pytest.approx(BAD_AFTER)
    assert (failed["role"], failed["plugin"], failed["method"]) == (
        "controller",
        "misbehaves",
        "command",
    )
    assert "traceback" not in failed  # it raised nothing: its answer was wrong
    rows = (out / "telemetry.csv").read_text().splitlines()
    assert len(rows) == 1 + 20  # the header, then the ticks at 0.0 ... 1.9 s
    assert json.loads((out / "summary.json").read_text())["status"] == "failed"
    assert any((out / "plots").glob("*.png"))
    assert np.isfinite(summary["delta_v_mps"])  # nothing non-finite reached the world


def test_a_raising_plugin_leaves_its_own_traceback_in_the_event(tmp_path):
    _, summary, events, _ = fly(
        tmp_path,
        ["controller.plugin=misbehaves", "controller.params.answer=raises"],
        MisbehavingController,
    )
    assert summary["reason"] == (
        "controller plugin 'misbehaves' raised in command() at t = 2 s: "
        "ZeroDivisionError: the plugin's own bug"
    )
    failed = events[-1]
    assert failed["error"] == "the plugin's own bug"
    assert failed["traceback"].startswith("Traceback (most recent call last):")
    assert "in _raise" in failed["traceback"]
    assert failed["traceback"].rstrip().endswith("ZeroDivisionError: the plugin's own bug")


@pytest.mark.parametrize(
    ("overrides", "cls", "said"),
    [
        (
            ["path_planner.plugin=nan-path"],
            NaNPathPlanner,
            "path_planner plugin 'nan-path' broke its contract in plan() at t = ",
        ),
        (
            ["path_planner.plugin=silent-refusal"],
            SilentRefusalPlanner,
            "path_planner plugin 'silent-refusal' broke its contract in plan() at t = ",
        ),
        (
            ["task_planner.plugin=inf-cost"],
            InfCostTaskPlanner,
            "task_planner plugin 'inf-cost' broke its contract in plan() at t = ",
        ),
    ],
)
def test_a_planner_s_wrong_answer_fails_the_run_naming_it(tmp_path, overrides, cls, said):
    _, summary, events, _ = fly(tmp_path, overrides, cls, duration=60.0)
    assert summary["status"] == "failed" and summary["reason"].startswith(said), summary["reason"]
    assert events[-1]["event"] == "plugin_failed"


def test_a_localiser_s_non_finite_estimate_is_blamed_on_it(tmp_path):
    from dcsim_plugins.localisers.trilateration import TrilaterationLocaliser

    class NaNLocaliser(TrilaterationLocaliser):
        name = "nan-fix"
        summary = "Trilateration that loses itself after 1 s (test)"

        def estimate(self):
            estimate = super().estimate()
            if estimate.time < 0.95:
                return estimate
            return StateEstimate(time=estimate.time, position=_NAN3, converged=True)

    _, summary, _, _ = fly(tmp_path, ["localiser.plugin=nan-fix"], NaNLocaliser)
    assert summary["reason"].startswith(
        "localiser plugin 'nan-fix' broke its contract in estimate() at t = 1 s: "
        "returned non-finite numbers: position [nan, 0.0, 0.0]"
    )


def test_debug_prints_the_plugin_s_traceback_and_keeps_exit_1(tmp_path):
    """`dcsim --debug run` with a plugin that raises: the plugin's traceback on stderr."""
    package = tmp_path / "raiser_pkg"
    package.mkdir()
    (package / "__init__.py").write_text(
        "from dcsim.api import Command, Controller\n\n\n"
        "class Raiser(Controller):\n"
        "    name = 'raiser'\n"
        "    summary = 'Raises at once (test)'\n\n"
        "    def reset(self, robot):\n"
        "        pass\n\n"
        "    def command(self, time, estimate, reference, surroundings):\n"
        "        return helper_that_fails()\n\n\n"
        "def helper_that_fails():\n"
        "    raise KeyError('no such gain')\n"
    )
    script = (
        "import sys\n"
        "from dcsim.cli import main as module\n"
        "from dcsim.registry.discovery import PluginOrigin, PluginRegistry\n"
        "import raiser_pkg\n"
        "discover = PluginRegistry.discover\n"
        "def with_raiser(*args, **kwargs):\n"
        "    registry = discover(*args, **kwargs)\n"
        "    registry.register_class(raiser_pkg.Raiser, PluginOrigin('t', '0', 't'))\n"
        "    return registry\n"
        "PluginRegistry.discover = staticmethod(with_raiser)\n"
        "module.cli(sys.argv[1:])\n"
    )
    results = {}
    for debug in ([], ["--debug"]):
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                script,
                *debug,
                "run",
                "--out",
                str(tmp_path / f"run{len(debug)}"),
                "--set",
                "controller.plugin=raiser",
                "--set",
                "world.duration=2",
            ],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=120,
        )
        results[bool(debug)] = done
        assert done.returncode == 1, done.stderr
        assert "controller plugin 'raiser' raised in command() at t = 0 s" in done.stdout
    assert "helper_that_fails" in results[True].stderr
    assert "KeyError: 'no such gain'" in results[True].stderr
    assert "Traceback" not in results[False].stderr


def test_the_output_check_passes_good_answers():
    assert output_problem("controller", "command", Command(), ActuatorCounts()) is None
    two = Command(joint_torques=[1, 2])
    assert output_problem("controller", "command", two, ActuatorCounts(joints=2)) is None
    none_given = Command()
    assert output_problem("controller", "command", none_given, ActuatorCounts(joints=6)) is None
    assert output_problem("path_planner", "plan", NoPath(reason="boxed in")) is None
    assert output_problem("localiser", "update", None) is None  # answers nothing
    trajectory = Trajectory(times=[0, 1], positions=np.zeros((2, 3)), velocities=np.zeros((2, 3)))
    assert output_problem("path_planner", "plan", trajectory) is None
    still = Trajectory(times=[0, 0], positions=np.zeros((2, 3)), velocities=np.zeros((2, 3)))
    assert "times do not increase" in output_problem("path_planner", "plan", still)


def _spoiled(message, bad):
    """Copies of ``message`` with each number it holds made ``bad`` in turn (an array's
    last element), those of the messages in its tuples included, as a plugin could
    hand them back: the fields set as they are, past any check."""
    for name in message.__dataclass_fields__:
        value = getattr(message, name)
        if isinstance(value, tuple):
            for index, item in enumerate(value):
                for worse in _spoiled(item, bad):
                    yield _with(message, name, (*value[:index], worse, *value[index + 1 :]))
        elif isinstance(value, np.ndarray) and value.size:
            array = value.copy()
            array.flat[-1] = bad
            yield _with(message, name, array)
        elif isinstance(value, float):
            yield _with(message, name, bad)


def _with(message, name, value):
    changed = copy.copy(message)
    object.__setattr__(changed, name, value)
    return changed


GOOD_ANSWERS = [
    StateEstimate(
        1.5,
        [1.0, 2.0, 3.0],
        joint_positions=[0.1, 0.2],
        joint_velocities=[0.0, 0.3],
        covariance=np.eye(6),
    ),
    Command(force=[1.0, 0.0, 0.0], joint_torques=[0.5], wheel_torques=[0.1, 0.2]),
    Trajectory(times=[0, 1], positions=np.ones((2, 3)), velocities=np.zeros((2, 3))),
    Plan(
        tasks=(PlanTask(3, 10.0, [1.0, 2.0, 3.0]), PlanTask(4, 20.0, [4.0, 5.0, 6.0])),
        drop_visits=(DropVisit(1, 30.0, [0.0, 0.0, 1.0]),),
        cost=12.0,
    ),
    AttitudeReading(2.0, [0.0, 0.0, 0.0, 1.0], sigma=[1e-4, 1e-4, 1e-4]),
    RateReading(2.0, [0.0, 0.1, 0.0], sigma=1e-5),
    BeaconRange(2, [100.0, 0.0, 0.0], range=50.0, sigma=0.05),
]


@pytest.mark.parametrize("good", GOOD_ANSWERS, ids=lambda m: type(m).__name__)
def test_the_quick_finite_test_agrees_with_the_exact_walk(good):
    assert answers._non_finite(good) is None and answers._first_non_finite(good) is None
    spoiled = [*_spoiled(good, np.nan), *_spoiled(good, np.inf), *_spoiled(good, -np.inf)]
    assert len(spoiled) >= 9  # every number of every message, three ways
    for bad in spoiled:
        said = answers._non_finite(bad)
        assert said is not None and said.startswith("returned non-finite numbers: ")
        assert said == answers._first_non_finite(bad)
    for huge in _spoiled(good, 1e300):  # finite, though their squares overflow
        assert answers._non_finite(huge) is None


def test_a_huge_finite_command_is_still_checked_for_its_actuators():
    huge = Command(force=[1e300, 0.0, 0.0], joint_torques=[1e300, 1.0])
    assert output_problem("controller", "command", huge, ActuatorCounts(joints=2)) is None
    said = output_problem("controller", "command", huge, ActuatorCounts(joints=3))
    assert said == "returned 2 joint torques for a robot with 3 joints"
