"""The conformance suite: every built-in plugin passes it, and broken plugins are caught."""

from __future__ import annotations

import dataclasses
import functools
import subprocess
import sys
import time

import numpy as np
import pytest
from dcsim_plugins.controllers.computed_torque import ComputedTorqueController
from dcsim_plugins.controllers.pd import PDController
from dcsim_plugins.localisers.trilateration import TrilaterationLocaliser
from dcsim_plugins.path_planners.straight_line import StraightLinePlanner
from dcsim_plugins.task_planners.nearest import NearestTaskPlanner

from dcsim.api import Command, GoalRegion, NoPath, Plugin, PluginRegistry, ShapeKind
from dcsim.testing import (
    CheckResult,
    ContractViolation,
    ControllerContract,
    check_plugin,
    checks_for,
)
from tests.testing.peeking_plugin import PeekingController

# `fmu` needs an FMU to exist at all; tests/fmu/test_fmu_controller.py runs these checks
# on it with the example PD controller FMU.
BUILTINS = [
    p
    for p in PluginRegistry.discover().plugins()
    if p.origin.distribution == "dcsim" and p.name != "fmu"
]


@pytest.mark.parametrize(
    "plugin, check",
    [(p.cls, c) for p in BUILTINS for c in checks_for(p.kind)],
    ids=[f"{p.kind}:{p.name}::{c.name}" for p in BUILTINS for c in checks_for(p.kind)],
)
def test_builtin_plugins_keep_every_contract(plugin, check):
    check.run(plugin)


def test_every_kind_has_builtins_under_test():
    assert {p.kind for p in BUILTINS} == {
        "sensor",
        "tracker",
        "localiser",
        "task_planner",
        "path_planner",
        "controller",
    }


# ----------------------------------------------------------------- broken plugins


class MutatingLocaliser(TrilaterationLocaliser):
    name = "mutating"
    summary = "Drops the farthest range from the list it is given (test)"

    def update(self, ranges):
        if ranges:
            ranges.pop()
        super().update(ranges)


class NondeterministicPlanner(NearestTaskPlanner):
    name = "nondeterministic"
    summary = "Perturbs its plan with an unseeded generator (test)"

    def plan(self, request):
        plan = super().plan(request)
        return type(plan)(
            plan.tasks, plan.drop_visits, plan.cost + np.random.default_rng().random()
        )


class OverreachingController(PDController):
    name = "overreaching"
    summary = "Asks twice the force limit (test)"

    def command(self, time, estimate, reference, surroundings):
        force = super().command(time, estimate, reference, surroundings).force
        norm = np.linalg.norm(force)
        return Command(force=force / norm * 2 * self.robot.max_force if norm else force)


class SlowPlanner(NearestTaskPlanner):
    name = "slow"
    summary = "Ignores its time budget (test)"

    def plan(self, request):
        time.sleep(request.time_budget + 0.5)
        return super().plan(request)


class FragilePathPlanner(StraightLinePlanner):
    name = "fragile"
    summary = "Raises when there are no obstacles (test)"

    def plan(self, problem):
        if not problem.obstacles:
            raise IndexError("no obstacles to avoid")
        return super().plan(problem)


class LostLocaliser(TrilaterationLocaliser):
    name = "lost"
    summary = "Ignores every range (test)"

    def update(self, ranges):
        return None


class CarelessPathPlanner(StraightLinePlanner):
    name = "careless"
    summary = "Flies straight even through obstacles (test)"

    def plan(self, problem):
        return super().plan(dataclasses.replace(problem, obstacles=()))


class AbruptPathPlanner(StraightLinePlanner):
    name = "abrupt"
    summary = "Accelerates at three times the limit (test)"

    def plan(self, problem):
        return super().plan(
            dataclasses.replace(problem, max_acceleration=3 * problem.max_acceleration)
        )


class HurriedPathPlanner(StraightLinePlanner):
    name = "hurried"
    summary = "Flies at twice the speed limit (test)"

    def plan(self, problem):
        return super().plan(dataclasses.replace(problem, max_speed=2 * problem.max_speed))


class CasualArrivalPlanner(StraightLinePlanner):
    name = "casual"
    summary = "Ignores the goal's time, attitude and velocity (test)"

    def plan(self, problem):
        goal = GoalRegion(position=problem.goal.position, tolerance=problem.goal.tolerance)
        return super().plan(dataclasses.replace(problem, goal=goal))


class ShortcutPathPlanner(StraightLinePlanner):
    name = "shortcut"
    summary = "Flies into the box it should avoid (test)"

    def plan(self, problem):
        box = next((o for o in problem.obstacles if o.shape.kind is ShapeKind.BOX), None)
        if box is None:
            return super().plan(problem)
        goal = dataclasses.replace(problem.goal, position=box.position)
        return super().plan(dataclasses.replace(problem, goal=goal, obstacles=()))


class StartBlindPathPlanner(StraightLinePlanner):
    name = "start-blind"
    summary = "Ignores the obstacle it starts in (test)"

    def plan(self, problem):
        start = problem.start.position
        clear = tuple(o for o in problem.obstacles if np.linalg.norm(o.position - start) > o.radius)
        return super().plan(dataclasses.replace(problem, obstacles=clear))


class SlowPathPlanner(StraightLinePlanner):
    name = "slow-path"
    summary = "Overruns short time budgets (test)"

    def plan(self, problem):
        if problem.time_budget < 0.5:
            time.sleep(problem.time_budget + 0.5)
        return super().plan(problem)


class MarginBlindPathPlanner(StraightLinePlanner):
    name = "margin-blind"
    summary = "Keeps the robot's radius from obstacles but not the problem's margin (test)"

    def plan(self, problem):
        return super().plan(dataclasses.replace(problem, safety_margin=0.0))


class DeadlineBlindPathPlanner(StraightLinePlanner):
    name = "deadline-blind"
    summary = "Takes a second when its time budget is long, whatever the deadline (test)"

    def plan(self, problem):
        if problem.time_budget > 5.0:
            time.sleep(1.0)
        return super().plan(problem)


class StillnessPathPlanner(StraightLinePlanner):
    name = "stillness"
    summary = "Plans among static obstacles only, and says so (test)"
    handles_moving_obstacles = False

    def plan(self, problem):
        moving = [o.id for o in problem.obstacles if np.any(o.predict(problem.start.time + 1.0)[1])]
        if moving:
            return NoPath(f"obstacles {moving} are moving")
        return super().plan(problem)


class BoastfulPathPlanner(StraightLinePlanner):
    name = "boastful"
    summary = "Declares it handles static obstacles only, then plans among moving ones (test)"
    handles_moving_obstacles = False


class NaNController(PDController):
    name = "nan-force"
    summary = "Commands a NaN force from the start (test)"

    def command(self, time, estimate, reference, surroundings):
        return Command(force=[np.nan, 0.0, 0.0])


class LateInfController(PDController):
    name = "late-inf"
    summary = "Commands like PD, then an infinite torque after 50 s (test)"

    def command(self, time, estimate, reference, surroundings):
        command = super().command(time, estimate, reference, surroundings)
        if time > 50.0:
            return Command(force=command.force, torque=[0.0, 0.0, np.inf])
        return command


class LateNaNArmController(ComputedTorqueController):
    name = "late-nan-arm"
    summary = "Computed torque, then NaN joint torques after 5 s (test)"

    def command(self, time, estimate, reference, surroundings):
        command = super().command(time, estimate, reference, surroundings)
        if time > 5.0:
            return Command(joint_torques=np.full(command.joint_torques.shape, np.nan))
        return command


# SlowPlanner's checks sleep through its budgets for some 15 s: the tests reading them
# share one pass, in one pytest-xdist worker.
SHARES_SLOW_CHECKS = pytest.mark.xdist_group("slow-planner-checks")


@functools.cache
def results_of(plugin: type) -> dict[str, CheckResult]:
    """Every check's result on ``plugin``, by check name (one pass per test process)."""
    return {r.check: r for r in check_plugin(plugin)}


@pytest.mark.parametrize(
    "plugin, failing",
    [
        (MutatingLocaliser, {"does_not_mutate_inputs"}),
        (NondeterministicPlanner, {"deterministic"}),
        (OverreachingController, {"commands_within_limits"}),
        pytest.param(SlowPlanner, {"honours_time_budget"}, marks=SHARES_SLOW_CHECKS),
        (FragilePathPlanner, {"handles_empty_inputs"}),
        (LostLocaliser, {"converges"}),
        (CarelessPathPlanner, {"answers_no_path"}),
        (AbruptPathPlanner, {"respects_acceleration_limit"}),
        (HurriedPathPlanner, {"respects_limits"}),
        (CasualArrivalPlanner, {"reaches_the_goal"}),
        (ShortcutPathPlanner, {"collision_free"}),
        (StartBlindPathPlanner, {"answers_no_path"}),
        (SlowPathPlanner, {"honours_time_budget"}),
        (MarginBlindPathPlanner, {"keeps_safety_margin"}),
        (DeadlineBlindPathPlanner, {"honours_deadline"}),
        (BoastfulPathPlanner, {"declares_obstacle_motion"}),
        (PeekingController, {"uses_only_the_public_api"}),
        (
            NaNController,
            {
                "commands_within_limits",
                "rests_at_the_reference",
                "stabilises_a_double_integrator",
                "outputs_well_formed",
            },
        ),
        (LateInfController, {"stabilises_a_double_integrator"}),
        (LateNaNArmController, {"converges_on_a_manipulator"}),
    ],
    ids=lambda value: getattr(value, "name", None) or "-".join(sorted(value)),
)
def test_broken_plugins_are_reported_by_the_right_check(plugin, failing):
    results = results_of(plugin)
    failed = {name for name, r in results.items() if not r.passed}
    assert failing <= failed, results
    for name in failing:
        message = results[name].message
        assert f"plugin '{plugin.name}' breaks '{name}'" in message and "contract: " in message


@SHARES_SLOW_CHECKS
def test_messages_say_what_the_plugin_did():
    results = results_of(OverreachingController)
    assert "asks 10.000 N" in results["commands_within_limits"].message
    assert "the limits are 5.0 N" in results["commands_within_limits"].message
    slow = results_of(SlowPlanner)["honours_time_budget"].message
    assert "with a budget of 0.3 s" in slow


def test_non_finite_commands_are_named_with_their_time():
    late = results_of(LateInfController)["stabilises_a_double_integrator"].message
    assert "returned non-finite numbers: torque [0.0, 0.0, inf]" in late
    assert "on the double integrator at t = 50.1 s" in late
    arm = results_of(LateNaNArmController)["converges_on_a_manipulator"].message
    assert "returned non-finite numbers: joint_torques" in arm
    assert "on a manipulator near its reference at t = 5.01 s" in arm


def test_path_planner_messages_say_what_the_plugin_did():
    abrupt = {r.check: r for r in check_plugin(AbruptPathPlanner)}
    assert "accelerates at 0.075 m/s²" in abrupt["respects_acceleration_limit"].message
    assert "the limit is 0.025 m/s²" in abrupt["respects_acceleration_limit"].message
    casual = {r.check: r for r in check_plugin(CasualArrivalPlanner)}
    assert "on the arrival problem it ends at t = " in casual["reaches_the_goal"].message
    shortcut = {r.check: r for r in check_plugin(ShortcutPathPlanner)}
    assert "overlaps obstacle 4 by " in shortcut["collision_free"].message
    blind = {r.check: r for r in check_plugin(StartBlindPathPlanner)}
    assert "for a start inside obstacle 9" in blind["answers_no_path"].message
    margin = results_of(MarginBlindPathPlanner)["keeps_safety_margin"].message
    assert "on the margin problem it comes 0.500 m from obstacle 1" in margin
    assert "inside the problem's safety_margin of 1 m" in margin
    late = results_of(DeadlineBlindPathPlanner)["honours_deadline"].message
    assert "s after the problem's deadline (its time_budget of 30 s" in late
    hurried = {r.check: r for r in check_plugin(HurriedPathPlanner)}
    assert "exceeds 0.5 m/s" in hurried["respects_limits"].message


def test_a_static_only_planner_is_checked_on_still_obstacles_and_on_its_refusal():
    results = results_of(StillnessPathPlanner)
    # this test module itself imports more of dcsim than dcsim.api
    failed = {name for name, r in results.items() if not r.passed}
    assert failed == {"uses_only_the_public_api"}, results
    boastful = results_of(BoastfulPathPlanner)["declares_obstacle_motion"].message
    assert "answered a trajectory ending at" in boastful
    assert "whose obstacles move" in boastful


def test_a_class_that_is_no_plugin_fails_only_the_metadata_check():
    (result,) = check_plugin(int)
    assert result.check == "declares_metadata" and not result.passed
    assert "is not a plugin class" in result.message


class ControllerByNameOnly(Plugin):
    """Says it is a controller, but derives from no kind's class."""

    kind = "controller"
    name = "by-name-only"
    summary = "A controller by its kind attribute alone."


def test_a_check_run_alone_names_a_class_not_derived_from_its_kind():
    (check,) = [c for c in checks_for("controller") if c.name == "stabilises_a_double_integrator"]
    with pytest.raises(ContractViolation, match="does not derive from Controller"):
        check.run(ControllerByNameOnly)


class TestSubclassingTheContractRunsEveryCheck(ControllerContract):
    plugin = PDController


def test_contract_classes_get_one_test_per_check():
    names = {n for n in dir(TestSubclassingTheContractRunsEveryCheck) if n.startswith("test_")}
    assert names == {f"test_{c.name}" for c in checks_for("controller")}


def test_pytest_option_runs_the_suite_against_an_installed_plugin(tmp_path):
    command = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "--dcsim-plugin"]
    passing = subprocess.run(
        [*command, "controller:pd"], cwd=tmp_path, capture_output=True, text=True
    )
    assert passing.returncode == 0, passing.stdout
    assert f"{len(checks_for('controller', PDController))} passed" in passing.stdout
    unknown = subprocess.run(
        [*command, "controller:nope"], cwd=tmp_path, capture_output=True, text=True
    )
    assert unknown.returncode != 0 and "no controller plugin named 'nope'" in unknown.stdout


def test_docs_list_every_check_and_every_hook():
    import inspect

    from dcsim.registry import hookspecs
    from dcsim.report.docgen import block
    from dcsim.testing.reference import BEGIN, END, render_checks
    from tests.conftest import REPO

    text = (REPO / "docs" / "plugins.md").read_text()
    assert block(text, BEGIN, END) == render_checks(), "docs/plugins.md is stale: run `make docs`"
    specs = [
        name
        for name, function in inspect.getmembers(hookspecs, inspect.isfunction)
        if hasattr(function, "dcsim_spec")
    ]
    assert len(specs) == 6
    for name in specs:
        assert f"### {name}\n" in text, f"hook {name} has no entry in docs/plugins.md"
