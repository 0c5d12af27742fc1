"""The run pictures: axes named after the frame, km for a geocentric field, the
estimation error's envelope, grabs on the timeline; and the outlines of shaped objects.

The pictures are checked on matplotlib's figure objects (labels, tick formatters,
artists), not on pixels.
"""

from __future__ import annotations

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from dcsim.api import Shape, ShapeKind
from dcsim.missions.debris import DebrisMission
from dcsim.missions.debris.plots import timeline_figure, trajectory_figure
from dcsim.registry.discovery import PluginRegistry
from dcsim.report.outlines import outline, wireframe
from dcsim.report.plots import FrameAxes, estimation_figure, motion_figure
from dcsim.run.loop import PLOT_POINTS, Runner
from dcsim.run.recording import SIGMA_COLUMNS, read_telemetry
from dcsim.run.setup import setup_run
from tests.conftest import REPO, SHARES_DEFAULT_RUN

THESIS = REPO / "scenarios" / "thesis_debris_field.yaml"

QUARTER_TURN_Z = [0.0, 0.0, 0.5**0.5, 0.5**0.5]
QUARTER_TURN_X = [0.5**0.5, 0.0, 0.0, 0.5**0.5]


def extent(outline: np.ndarray) -> np.ndarray:
    return np.array([outline.min(axis=0), outline.max(axis=0)])


def test_a_box_footprint_is_its_turned_rectangle():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_Z)
    top = outline(box)
    assert len(top) == 4
    np.testing.assert_allclose(extent(top), [[-2.0, -1.0], [2.0, 1.0]], atol=1e-12)
    eighth = Shape(
        ShapeKind.BOX,
        half_extents=[1.0, 1.0, 1.0],
        orientation=[0.0, 0.0, np.sin(np.pi / 8), np.cos(np.pi / 8)],
    )
    assert np.max(np.linalg.norm(outline(eighth), axis=1)) == pytest.approx(2**0.5)
    np.testing.assert_allclose(extent(outline(eighth)), [[-(2**0.5)] * 2, [2**0.5] * 2])


def test_a_cylinder_footprint_is_a_disc_upright_and_a_rectangle_lying_down():
    upright = outline(Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0))
    np.testing.assert_allclose(np.linalg.norm(upright, axis=1), 0.5)
    lying = outline(Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X))
    np.testing.assert_allclose(extent(lying), [[-0.5, -3.0], [0.5, 3.0]], atol=1e-12)


def test_a_sphere_outline_is_its_circle_in_any_view():
    ball = Shape(ShapeKind.SPHERE, radius=1.5)
    for axes in ((0, 1), (0, 2), (1, 2)):
        np.testing.assert_allclose(np.linalg.norm(outline(ball, axes), axis=1), 1.5)


def test_side_views_project_on_their_own_axes():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_Z)
    np.testing.assert_allclose(extent(outline(box, (0, 2))), [[-2.0, -3.0], [2.0, 3.0]])
    np.testing.assert_allclose(extent(outline(box, (1, 2))), [[-1.0, -3.0], [1.0, 3.0]])


def test_wireframes_lie_on_the_shapes():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0], orientation=QUARTER_TURN_X)
    edges = wireframe(box)
    assert len(edges) == 12
    lengths = sorted(float(np.linalg.norm(e[1] - e[0])) for e in edges)
    np.testing.assert_allclose(lengths, [2.0] * 4 + [4.0] * 4 + [6.0] * 4)
    cylinder = Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X)
    lines = wireframe(cylinder)
    assert len(lines) == 6  # two end circles, four lines along the side
    points = np.vstack(lines)
    np.testing.assert_allclose(np.hypot(points[:, 0], points[:, 2]), 0.5)
    np.testing.assert_allclose(np.sort(np.unique(np.round(points[:, 1], 9))), [-3.0, 3.0])
    ball = np.vstack(wireframe(Shape(ShapeKind.SPHERE, radius=2.0)))
    np.testing.assert_allclose(np.linalg.norm(ball, axis=1), 2.0)


# ---------------------------------------------------------------------- run pictures
@pytest.fixture(scope="module")
def thesis_run(tmp_path_factory):
    """The thesis's geocentric field (r = 150 km) flown for 5 s into a run directory."""
    out = tmp_path_factory.mktemp("thesis") / "run"
    setup = setup_run(THESIS, ["world.duration=5"], registry=PluginRegistry.discover())
    Runner(setup, out).run()
    return setup.scenario, out


def run_files(out):
    """A run directory's telemetry, thinned as for its plots, and its events."""
    telemetry = read_telemetry(out / "telemetry.csv", max_points=PLOT_POINTS)
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    return telemetry, events


@pytest.fixture
def figures():
    """Close every figure a test made."""
    yield
    plt.close("all")


def labels(axis) -> list[str]:
    names = [axis.get_xlabel(), axis.get_ylabel()]
    return names + [axis.get_zlabel()] if hasattr(axis, "get_zlabel") else names


def test_a_debris_run_draws_its_four_pictures(thesis_run):
    _, out = thesis_run
    names = {p.name for p in (out / "plots").iterdir()}
    assert names == {"trajectory.png", "timeline.png", "motion.png", "estimation.png"}
    assert all(p.stat().st_size > 10_000 for p in (out / "plots").iterdir())


@SHARES_DEFAULT_RUN
def test_lvlh_axes_are_radial_along_track_and_orbit_normal(default_run, figures):
    runner, _, out = default_run
    telemetry, events = run_files(out)
    figure = trajectory_figure(runner.scenario, telemetry, events)
    ax3d, in_plane, out_of_plane = figure.axes
    assert labels(ax3d) == ["radial [m]", "along-track [m]", "orbit-normal [m]"]
    assert labels(in_plane) == ["along-track [m]", "radial [m]"]  # V-bar across, R-bar up
    assert labels(out_of_plane) == ["along-track [m]", "orbit-normal [m]"]
    thrust = motion_figure(runner.scenario, telemetry).axes[1]
    assert [t.get_text() for t in thrust.get_legend().get_texts()] == [
        "radial",
        "along-track",
        "orbit-normal",
        "|F|",
    ]


@SHARES_DEFAULT_RUN
def test_true_and_estimated_paths_are_drawn_apart_and_named(default_run, figures):
    runner, _, out = default_run
    telemetry, events = run_files(out)
    figure = trajectory_figure(runner.scenario, telemetry, events)
    legend = {
        t.get_text(): h
        for t, h in zip(
            figure.legends[0].get_texts(), figure.legends[0].legend_handles, strict=True
        )
    }
    true, estimated = legend["collector, true"], legend["collector, estimated"]
    assert (true.get_color(), true.get_linestyle()) != (
        estimated.get_color(),
        estimated.get_linestyle(),
    )
    assert not any(axis.get_legend() for axis in figure.axes)  # the legend is outside


def test_a_geocentric_field_far_from_the_origin_is_ticked_in_km(thesis_run, figures):
    scenario, out = thesis_run
    telemetry, events = run_files(out)
    figure = trajectory_figure(scenario, telemetry, events)
    ax3d, top, side = figure.axes
    assert labels(ax3d) == ["x [km]", "y [km]", "z [km]"]
    assert labels(top) == ["x [km]", "y [km]"] and labels(side) == ["x [km]", "z [km]"]
    for axis in (ax3d.xaxis, ax3d.zaxis, top.yaxis, side.xaxis):
        assert axis.get_major_formatter()(150_500.0, 0) == "150.5"
    near = FrameAxes.of(scenario, np.array([[9_000.0, -9_000.0, 0.0]]))
    assert near.unit == "m" and near.label(2) == "z [m]"


@SHARES_DEFAULT_RUN
def test_the_error_panels_have_the_3_sigma_envelope_of_the_reported_covariance(
    default_run, figures
):
    runner, _, out = default_run
    telemetry, _ = run_files(out)
    figure = estimation_figure(runner.scenario, telemetry)
    for axis, column in zip(figure.axes[:3], SIGMA_COLUMNS, strict=True):
        (envelope,) = [c for c in axis.collections if isinstance(c, PolyCollection)]
        heights = np.concatenate([path.vertices[:, 1] for path in envelope.get_paths()])
        largest = 3.0 * telemetry[column].max()
        assert largest > 0
        assert heights.max() == pytest.approx(largest) and heights.min() == pytest.approx(-largest)
    assert [axis.get_ylabel() for axis in figure.axes[:3]] == [
        "radial [m]",
        "along-track [m]",
        "orbit-normal [m]",
    ]


@SHARES_DEFAULT_RUN
def test_the_timeline_marks_every_grab_on_the_grab_level(default_run, figures):
    runner, _, out = default_run
    telemetry, events = run_files(out)
    modes = DebrisMission.modes
    figure = timeline_figure(runner.scenario, telemetry, events, modes, 2.5)
    (grabs,) = [line for line in figure.axes[0].get_lines() if line.get_label() == "grab"]
    expected = [e["t"] for e in events if e["event"] == "grab" and e["success"]]
    assert len(expected) == 4
    np.testing.assert_array_equal(grabs.get_xdata(), expected)
    assert set(grabs.get_ydata()) == {modes.index("GRAB")}
    assert "GRAB" not in set(telemetry["mode"])  # which is why the events are marked
    titles = [axis.get_title() for axis in figure.axes]
    assert titles[1:3] == ["Propellant used", "Delta-v used"]  # separate panels
