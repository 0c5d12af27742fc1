"""The hardware panels under every free flyer mission's timeline: attitude error, reaction
wheels' momenta and thrusters' duty cycles, there when the telemetry has them.

Checked on matplotlib's figure objects (titles, lines, the duty cycles' mesh), not on
pixels, from real runs of the shipped ``default_hardware`` scenario and of runs without
the hardware.
"""

from __future__ import annotations

import json
import textwrap

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml
from matplotlib.collections import QuadMesh

from dcsim.missions.debris import DebrisMission
from dcsim.missions.debris.plots import timeline_figure as debris_timeline
from dcsim.missions.hold.plots import timeline_figure as hold_timeline
from dcsim.missions.transfer import TransferMission
from dcsim.missions.transfer.plots import timeline_figure as transfer_timeline
from dcsim.registry.discovery import PluginRegistry
from dcsim.report.hardware import hardware_panels
from dcsim.run.loop import PLOT_POINTS, Runner
from dcsim.run.recording import read_telemetry
from dcsim.run.setup import setup_run
from tests.conftest import REPO

HARDWARE = REPO / "scenarios" / "default_hardware.yaml"
ERROR_TITLE = "Attitude error: angle to the reference's attitude"
WHEEL_TITLE = "Reaction wheels: momentum about each spin axis"
DUTY_TITLE = "Thrusters: duty cycle (fraction of each control period)"
THRUSTER_LABELS = [
    f"{i} {axis}"
    for i, axis in enumerate(
        ["+x", "+x", "-x", "-x", "+y", "+y", "-y", "-y", "+z", "+z", "-z", "-z"], 1
    )
]


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


def fly(out, scenario, registry, *overrides):
    """Run ``scenario`` into ``out``; its resolved scenario, plot telemetry and events."""
    setup = setup_run(scenario, list(overrides), registry=registry)
    Runner(setup, out).run()
    telemetry = read_telemetry(out / "telemetry.csv", max_points=PLOT_POINTS)
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    return setup.scenario, telemetry, events


@pytest.fixture(scope="module")
def hardware_run(tmp_path_factory, registry):
    """default_hardware's first 30 s: twelve thrusters fire, four wheels spin."""
    return fly(tmp_path_factory.mktemp("hardware") / "run", HARDWARE, registry, "world.duration=30")


@pytest.fixture(scope="module")
def ideal_run(tmp_path_factory, registry):
    """The default scenario's first 10 s: ideal force and torque, the attitude held."""
    return fly(tmp_path_factory.mktemp("ideal") / "run", None, registry, "world.duration=10")


@pytest.fixture
def figures():
    """Close every figure a test made."""
    yield
    plt.close("all")


def panel(figure, title):
    (axis,) = [axis for axis in figure.axes if axis.get_title() == title]
    return axis


def check_hardware_panels(figure, scenario, telemetry):
    """The last three panels are the hardware's, drawn from ``telemetry``."""
    titles = [axis.get_title() for axis in figure.axes if axis.get_title()]
    assert titles[-3:] == [ERROR_TITLE, WHEEL_TITLE, DUTY_TITLE]
    error = panel(figure, ERROR_TITLE).get_lines()[0]  # then a transfer's mode changes
    np.testing.assert_allclose(error.get_ydata(), np.degrees(telemetry["attitude_error"]))
    wheels = panel(figure, WHEEL_TITLE)
    lines = wheels.get_lines()
    named = [line for line in lines if line.get_label().startswith("wheel")]
    assert [line.get_label() for line in named] == [f"wheel {i}" for i in range(1, 5)]
    for i, line in enumerate(named, 1):
        np.testing.assert_array_equal(line.get_ydata(), telemetry[f"wheel_h_{i}"])
    dashed = sorted(
        float(line.get_ydata()[0])
        for line in lines
        if line.get_linestyle() == "--" and len(line.get_ydata())  # not the legend's sample
    )
    limit = scenario.robot.actuators.reaction_wheels[0].max_momentum
    assert dashed[0] == -limit and dashed[-1] == limit and limit == 4.0
    duty = panel(figure, DUTY_TITLE)
    (mesh,) = [c for c in duty.collections if isinstance(c, QuadMesh)]
    expected = np.column_stack([telemetry[f"duty_{i}"] for i in range(1, 13)]).T
    shown = np.ma.filled(mesh.get_array(), 0.0).reshape(expected.shape)
    np.testing.assert_allclose(shown, expected)
    assert expected.max() > 0.05  # thrusters fired
    assert [t.get_text() for t in duty.get_yticklabels()] == THRUSTER_LABELS
    assert figure.axes[len(titles) - 1].get_xlabel() == "time [s]"


def test_the_debris_timeline_shows_the_attitude_error_wheels_and_thrusters(hardware_run, figures):
    scenario, telemetry, events = hardware_run
    figure = debris_timeline(scenario, telemetry, events, DebrisMission.modes, 0.5)
    check_hardware_panels(figure, scenario, telemetry)
    assert len([a for a in figure.axes if a.get_title()]) == 4 + 3


def test_a_run_without_wheels_or_thrusters_keeps_its_panels_and_gains_the_attitude_error(
    ideal_run, figures
):
    scenario, telemetry, events = ideal_run
    assert not any(name.startswith(("wheel_h_", "duty_")) for name in telemetry)
    figure = debris_timeline(scenario, telemetry, events, DebrisMission.modes, 0.5)
    titles = [axis.get_title() for axis in figure.axes]
    assert titles[1:3] == ["Propellant used", "Delta-v used"]
    assert titles[4:] == [ERROR_TITLE]  # the attitude is held, by ideal torque
    assert figure.get_size_inches()[1] == pytest.approx(10.0 + 2.2)
    free = {**telemetry, "attitude_error": np.full(len(telemetry["time"]), np.nan)}
    assert hardware_panels(free, scenario) == []  # a reference that never held an attitude
    figure = debris_timeline(scenario, free, events, DebrisMission.modes, 0.5)
    assert len(figure.axes) == 4 and figure.get_size_inches()[1] == pytest.approx(10.0)


def test_without_the_scenario_the_panels_draw_the_telemetry_alone(hardware_run, figures):
    scenario, telemetry, _ = hardware_run
    figure, axes = plt.subplots(3, 1)
    for axis, draw in zip(axes, hardware_panels(telemetry), strict=True):
        draw(axis)
    assert not [line for line in axes[1].get_lines() if line.get_linestyle() == "--"]
    assert [line.get_label() for line in axes[1].get_lines()] == [f"wheel {i}" for i in range(1, 5)]
    assert [t.get_text() for t in axes[2].get_yticklabels()] == [str(i) for i in range(1, 13)]


@pytest.mark.filterwarnings("ignore:the plan made at t = 0.0 s ends")  # flown 20 s of 120
def test_the_transfer_timeline_shows_them_too(tmp_path, registry, figures):
    station = yaml.safe_load((REPO / "scenarios" / "station_inspection.yaml").read_text())
    hardware = yaml.safe_load(HARDWARE.read_text())
    for key in ("max_force", "max_torque"):  # the thrusters' and wheels' instead
        del station["robot"][key]
    station["robot"]["actuators"] = hardware["robot"]["actuators"]
    path = tmp_path / "station.yaml"
    path.write_text(yaml.safe_dump(station))
    scenario, telemetry, events = fly(
        tmp_path / "run",
        path,
        registry,
        "world.duration=20",
        "mission.goal.position=[1.8288,3.9624,0.0]",
    )
    figure = transfer_timeline(scenario, telemetry, events, TransferMission.modes, 0.5)
    check_hardware_panels(figure, scenario, telemetry)
    assert len([a for a in figure.axes if a.get_title()]) == 7 + 3


HOLD = """\
    name: hold-on-hardware
    world: {{frame: lvlh, orbit: {{radius: 6778137.0}}, duration: 20}}
    robot:
      mass: 100.0
      radius: 0.5
      inertia: [8.77, 9.42, 10.02]
      actuators: {actuators}
      initial: {{velocity: [0.01, 0, 0], angular_velocity: [0, 0, 0.02]}}
    mission: {{type: hold}}
"""


def test_a_hold_run_draws_a_timeline_with_the_hardware(tmp_path, registry, figures):
    actuators = yaml.safe_load(HARDWARE.read_text())["robot"]["actuators"]
    path = tmp_path / "hold.yaml"
    flow = yaml.safe_dump(actuators, default_flow_style=True, width=10_000).strip()
    path.write_text(textwrap.dedent(HOLD.format(actuators=flow)))
    scenario, telemetry, _ = fly(tmp_path / "run", path, registry)
    names = sorted(p.name for p in (tmp_path / "run" / "plots").iterdir())
    assert names == ["estimation.png", "motion.png", "timeline.png"]
    figure = hold_timeline(scenario, telemetry)
    check_hardware_panels(figure, scenario, telemetry)
    assert panel(figure, "Distance from the held position")
