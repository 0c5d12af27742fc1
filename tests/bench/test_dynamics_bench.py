"""``dcsim bench dynamics``: the drift comparison with the inertial reference, the
refused case, the thrust's step comparison and a mission flown under j2."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.bench import dynamics
from dcsim.bench.dynamics import DriftCase
from dcsim.errors import PlanOutlastsRunWarning
from dcsim.registry.discovery import PluginRegistry
from dcsim.world.orbit.chief import orbit_period
from tests.conftest import REPO


@pytest.mark.parametrize("model", ["two-body", "j2"])
def test_an_exact_world_drifts_as_the_inertial_reference_says(model):
    result = dynamics.drift_error(DriftCase(model, 0.01, 1000.0, "x"), orbits=0.02)
    assert result.simulated == pytest.approx(111.1, abs=0.1)  # 0.02 of 5553 s
    assert result.worst_error < 1e-6  # measured 1e-8 to 1e-7
    assert result.target == 0.01 and result.met


def test_a_drift_free_start_is_what_the_reference_gets():
    case = DriftCase("j2", 0.0, 10_000.0, "x")
    orbit = dynamics.drift_scenario(case, 1.0).world.orbit
    velocity = dynamics.drift_free_velocity(orbit, case.start)
    times = np.array([orbit_period(orbit)])  # a whole orbit: back where it started
    stays = dynamics.reference_positions(case, orbit, velocity, times)[-1]
    at_rest = dynamics.reference_positions(case, orbit, np.zeros(3), times)[-1]
    assert np.linalg.norm(stays - case.start) < 500  # measured 181 m (J2), 20 km ellipse
    assert np.linalg.norm(at_rest - case.start) > 100_000  # drifts 6π x along track


def test_cw_is_held_to_the_two_body_reference_and_its_bound():
    result = dynamics.drift_error(DriftCase("cw", 0.0, 10_000.0, "y"), orbits=0.05)
    assert result.case.reference_model == "two-body" and result.target is None
    # the linearisation's along-track error stays below 3 ρ² n t / a (13.9 m after a
    # twentieth of an orbit; it reaches the bound after a whole one, docs/benchmarks.md)
    assert 1.0 < result.worst_error < result.cw_estimate  # measured 1.107 m


def test_cw_on_an_eccentric_orbit_is_skipped_with_the_rules_reason():
    result = dynamics.drift_error(DriftCase("cw", 0.01, 100.0, "z"), orbits=0.01)
    assert result.worst_error is None and "circular" in result.skipped
    assert "skipped: the scenario rules refuse it" in dynamics.drift_table([result])
    assert "skipped cw on the orbit of e = 0.01 (1 case)" in dynamics.verdict([result])


def test_thrust_separates_the_two_physics_steps():
    cost = dynamics.thrust_cost(orbits=0.01)
    assert cost.without_thrust < 1e-6 < cost.with_thrust < 1e-2


def test_a_transfer_flown_under_j2_reports_its_plan_and_miss():
    with pytest.warns(PlanOutlastsRunWarning):  # the run stops 20 s into the plan
        flight = dynamics.fly_mission(
            REPO / "scenarios/station_inspection.yaml",
            "multi-burn",
            ["path_planner.plugin=multi-burn", "world.duration=20"],
            "j2",
            PluginRegistry.discover(),
        )
    assert flight.model == "j2" and flight.plans == 1 and flight.planned_delta_v > 0
    assert flight.miss == pytest.approx(23.6, abs=0.3)  # 24.0 m at the start
    assert not flight.goal_met and flight.collisions == 0
    assert "| station_inspection.yaml | multi-burn | j2 |" in dynamics.flights_table([flight])
