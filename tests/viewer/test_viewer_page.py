"""The run viewer's page: written by the command line, self-contained, and shown in Chromium.

The browser tests open the page written by ``dcsim run --view`` in Debian's Chromium,
driven by Playwright (never a browser of Playwright's own). Without Chromium they are
skipped, saying so (``.ci/run`` installs it).
"""

from __future__ import annotations

import io
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from dcsim.report.viewer.page import PAGE_NAME

CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
EIGHTH_TURN_Z = [0.0, 0.0, float(np.sin(np.pi / 8)), float(np.cos(np.pi / 8))]
LOAD_TIMEOUT_MS = 120_000  # plotly.js alone takes seconds to start on a loaded two-core machine


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """The default scenario's first 20 s, run with ``dcsim run --view``."""
    import subprocess

    from tests.conftest import DCSIM

    out = tmp_path_factory.mktemp("viewed") / "run"
    done = subprocess.run(
        [str(DCSIM), "run", "--out", str(out), "--set", "world.duration=20", "--view"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert f"view in {out / PAGE_NAME}" in done.stdout
    return out


def test_run_view_writes_a_self_contained_page_of_a_few_megabytes(run_dir):
    page = (run_dir / PAGE_NAME).read_text(encoding="utf-8")
    assert 3e6 < len(page) < 8e6
    assert not re.search(r"<(script|link|img)[^>]*(src|href)=", page)
    assert "{{" not in page.replace("{{{", "")[:2000]
    assert '<script type="application/json" id="dcsim-scene">' in page
    assert "plotly.js v" in page
    assert "<title>default: debris mission, free-flyer</title>" in page


def test_view_rewrites_the_page_and_refuses_what_is_not_a_run_directory(
    dcsim_cli, run_dir, tmp_path
):
    page = tmp_path / "page.html"
    result = dcsim_cli("view", str(run_dir), "--out", str(page), "--max-frames", "50")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"wrote {page} (") and result.stdout.rstrip().endswith("MB)")
    assert page.stat().st_size > 3e6
    for folder, message in (
        (tmp_path / "missing", "is not a run directory: no such folder"),
        (tmp_path, "is not a run directory: it has no scenario.yaml"),
    ):
        result = dcsim_cli("view", str(folder))
        assert result.returncode == 2
        assert result.stderr.startswith("error: ") and message in result.stderr
        assert "Traceback" not in result.stderr


# ---------------------------------------------------------------- in Chromium


def chromium() -> str:
    """Debian's Chromium, or skip the test saying it is missing."""
    path = shutil.which("chromium") or (
        "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None
    )
    if path is None:
        pytest.skip(
            "Chromium is not installed (apt-get install chromium; .ci/run does): "
            "the run viewer's page was not opened in a browser"
        )
    return path


@pytest.fixture(scope="module")
def browser():
    executable = chromium()
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="playwright is not installed (pip install -e '.[test]')"
    )
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


class Visit:
    """The page open in a tab, with every script error and network request it made."""

    def __init__(self, browser, page_path: Path) -> None:
        self.tab = browser.new_page(viewport={"width": 1280, "height": 800})
        self.errors: list[str] = []
        self.requests: list[str] = []
        self.tab.on("pageerror", lambda error: self.errors.append(f"page error: {error}"))
        self.tab.on(
            "console",
            lambda message: message.type == "error" and self.errors.append(message.text),
        )
        self.tab.on("request", lambda request: self.requests.append(request.url))
        self.tab.goto(page_path.as_uri(), timeout=LOAD_TIMEOUT_MS)
        self.tab.wait_for_function(
            "window.dcsimView && window.dcsimView.ready", timeout=LOAD_TIMEOUT_MS
        )

    def show(self, fraction: float) -> int:
        """Move the slider to ``fraction`` of the run as a person would; the frame shown."""
        frames = self.tab.evaluate("window.dcsimView.frames")
        frame = round(fraction * (frames - 1))
        self.tab.locator("#slider").fill(str(frame))
        self.tab.wait_for_function(f"window.dcsimView.frame() === {frame}")  # drawn
        return frame

    def plot_pixels(self) -> np.ndarray:
        from PIL import Image

        png = self.tab.locator("#plot").screenshot()
        return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)

    def readout(self, label: str) -> str:
        return self.tab.evaluate(
            """label => [...document.querySelectorAll('#readouts tr')]
                .find(row => row.cells[0].textContent === label).cells[1].textContent""",
            label,
        )


@pytest.fixture(scope="module")
def visit(browser, run_dir):
    visit = Visit(browser, run_dir / PAGE_NAME)
    yield visit
    visit.tab.close()


def test_the_page_renders_without_script_errors_or_network(visit):
    visit.show(0.5)
    assert visit.errors == []
    assert all(url.startswith("file:") for url in visit.requests), visit.requests


def test_the_page_draws_the_robot_objects_plan_beacons_and_drop_point(visit):
    names = visit.tab.evaluate("document.getElementById('plot').data.map(t => t.name)")
    for name in ("robot", "robot path", "targets", "obstacles", "beacons", "plan", "body x axis"):
        assert name in names
    assert "drop point (tolerance)" in names
    robot_vertices = visit.tab.evaluate(
        "document.getElementById('plot').data.find(t => t.name === 'robot').x.length"
    )
    assert robot_vertices > 100
    labels = visit.tab.evaluate(
        "document.getElementById('plot').data.find(t => t.name === 'targets labels').text"
    )
    assert labels == ["T1", "T2", "T3", "T4"]


def test_the_axes_are_named_after_the_frame(visit):
    titles = visit.tab.evaluate(
        "['xaxis', 'yaxis', 'zaxis'].map(a => "
        "document.getElementById('plot').layout.scene[a].title.text)"
    )
    assert titles == ["radial [m]", "along-track [m]", "orbit-normal [m]"]  # default: LVLH


@pytest.fixture(scope="module")
def reach_visit(browser, tmp_path_factory):
    """The reach scenario's first 2 s, run with ``dcsim run --view`` and open in a tab."""
    import subprocess

    from tests.conftest import DCSIM, REPO

    out = tmp_path_factory.mktemp("viewed") / "reach"
    scenario = REPO / "scenarios" / "space_manipulator_reach.yaml"
    done = subprocess.run(
        [str(DCSIM), "run", str(scenario), "--out", str(out), "--set", "world.duration=2"]
        + ["--view"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    visit = Visit(browser, out / PAGE_NAME)
    yield visit
    visit.tab.close()


def test_the_reach_target_draws_as_a_cross(reach_visit):
    """Its marker is a glyph every font has: not a box standing for a missing one."""
    reach_visit.tab.evaluate(
        """() => {
            const plot = document.getElementById('plot');
            const others = plot.data.map((_, i) => i)
                .filter(i => plot.data[i].name !== 'reach target');
            return Plotly.update(plot, {visible: false}, {showlegend: false}, others);
        }"""
    )
    pixels = reach_visit.plot_pixels()
    green = pixels[..., 1] - np.maximum(pixels[..., 0], pixels[..., 2]) > 50
    rows, columns = np.nonzero(green)
    assert 8 <= np.ptp(rows) <= 40 and 8 <= np.ptp(columns) <= 40, (np.ptp(rows), np.ptp(columns))
    middle_row = green[(rows.min() + rows.max()) // 2, columns.min() : columns.max() + 1]
    middle_column = green[rows.min() : rows.max() + 1, (columns.min() + columns.max()) // 2]
    assert middle_row.mean() > 0.8 and middle_column.mean() > 0.8  # the two bars of a "+"
    assert reach_visit.errors == []


def test_the_slider_moves_the_scene_and_the_readouts(visit):
    visit.show(0.0)
    early, early_time = visit.plot_pixels(), visit.readout("time")
    visit.show(1.0)
    late, late_time = visit.plot_pixels(), visit.readout("time")
    assert (early_time, late_time) == ("0.00 s", "20.00 s")
    changed = np.any(np.abs(early - late) > 30, axis=2)
    assert changed.mean() > 0.001  # the robot, its path and the targets moved
    assert visit.readout("mode") and visit.readout("speed").endswith(" m/s")
    assert visit.errors == []


def test_following_the_robot_puts_it_in_the_middle_of_the_picture(visit):
    visit.tab.select_option("#view", "follow")
    visit.show(1.0)
    pixels = visit.plot_pixels()
    height, width, _ = pixels.shape
    middle = pixels[height // 2 - 10 : height // 2 + 10, width // 2 - 10 : width // 2 + 10]
    red, green, blue = (middle[..., k].mean() for k in range(3))
    assert blue > red + 40 and blue > green + 20, (red, green, blue)  # the robot's blue body
    visit.tab.select_option("#view", "work")
    assert visit.errors == []


def test_play_runs_the_frames_and_pause_stops_them(visit):
    visit.show(0.0)
    visit.tab.select_option("#speed", "2")  # the 20 s run in 10 s
    visit.tab.click("#play")
    assert visit.tab.inner_text("#play") == "pause"
    visit.tab.wait_for_function("window.dcsimView.frame() > 10", timeout=60_000)
    visit.tab.click("#play")
    assert visit.tab.inner_text("#play") == "play"
    visit.tab.wait_for_timeout(1000)  # a frame asked for before the pause may still be drawn
    stopped = visit.tab.evaluate("window.dcsimView.frame()")
    visit.tab.wait_for_timeout(1000)
    assert visit.tab.evaluate("window.dcsimView.frame()") == stopped < 200
    assert visit.errors == []


def test_without_plotly_the_page_is_refused_saying_how_to_install_it(monkeypatch, run_dir):
    from dcsim.report.viewer import ViewError, write_view

    monkeypatch.setitem(sys.modules, "plotly.offline", None)  # import fails
    with pytest.raises(ViewError, match="needs the plotly package: pip install plotly"):
        write_view(run_dir)


@pytest.fixture(scope="module")
def hardware_visit(browser, tmp_path_factory):
    """default_hardware's first 30 s, the base turned 45° about z from the start (so the
    plumes turn with it), run with ``dcsim run --view`` and open in a tab."""
    import subprocess

    from tests.conftest import DCSIM, REPO

    out = tmp_path_factory.mktemp("viewed") / "hardware"
    scenario = REPO / "scenarios" / "default_hardware.yaml"
    done = subprocess.run(
        [str(DCSIM), "run", str(scenario), "--out", str(out), "--set", "world.duration=30"]
        + ["--set", f"robot.initial.attitude={EIGHTH_TURN_Z}", "--view"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    visit = Visit(browser, out / PAGE_NAME)
    yield visit
    visit.tab.close()


def plume_pixels(visit) -> int:
    """Pixels of the plumes' amber with every other trace hidden."""
    visit.tab.evaluate(
        """() => {
            const plot = document.getElementById('plot');
            const others = plot.data.map((_, i) => i)
                .filter(i => plot.data[i].name !== 'thruster plumes');
            return Plotly.restyle(plot, {visible: false}, others);
        }"""
    )
    pixels = visit.plot_pixels()
    red, green, blue = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return int(np.sum((red > 200) & (np.abs(green - 166) < 40) & (blue < 80)))


def test_firing_thrusters_draw_plumes_against_their_force_turning_with_the_base(hardware_visit):
    from scipy.spatial.transform import Rotation

    tab = hardware_visit.tab
    scene = tab.evaluate("JSON.parse(document.getElementById('dcsim-scene').textContent)")
    thrusters = scene["thrusters"]
    duty = np.array(thrusters["duty"])
    frames = len(scene["times"])
    busiest = int(np.argmax((duty > 0).sum(axis=1)))
    hardware_visit.show(busiest / (frames - 1))
    plumes = tab.evaluate(
        "(() => { const t = document.getElementById('plot').data"
        ".find(t => t.name === 'thruster plumes'); return [t.x, t.y, t.z]; })()"
    )
    points = np.array(plumes, dtype=float).T.reshape(-1, 3, 3)  # start, tip, gap
    firing = np.flatnonzero(duty[busiest] > 0)
    assert len(firing) >= 2 and len(points) == len(firing)
    assert np.isnan(points[:, 2]).all()
    robot = next(g for g in scene["bodies"] if g["trace"]["name"] == "robot")["members"][0]
    base = Rotation.from_quat(robot["turns"][busiest])
    assert base.magnitude() == pytest.approx(np.pi / 4, abs=0.01)  # the plumes turn with it
    centre = np.array(robot["positions"][busiest])
    at = np.array(thrusters["positions"])[firing]
    direction = np.array(thrusters["directions"])[firing]
    length = thrusters["length"][0] + thrusters["length"][1] * duty[busiest, firing]
    np.testing.assert_allclose(points[:, 0], centre + base.apply(at), atol=1e-4)
    tip = centre + base.apply(at - length[:, None] * direction)
    np.testing.assert_allclose(points[:, 1], tip, atol=1e-4)  # the scene keeps 0.1 mm
    assert plume_pixels(hardware_visit) > 50
    hardware_visit.show(0.0)  # nothing fired before the first frame
    assert (
        tab.evaluate(
            "document.getElementById('plot').data.find(t => t.name === 'thruster plumes').x.length"
        )
        == 0
    )
    assert plume_pixels(hardware_visit) == 0
    assert hardware_visit.readout("thrusters firing") == "none"
    assert hardware_visit.errors == []
