"""Shared fixtures: the console script, throw-away plugins, the default run, the wheel;
the shipped capture cut short.

A set-up shared by tests of several modules is made once per pytest-xdist worker; the
tests that read it carry its ``xdist_group`` mark so that ``--dist loadgroup`` runs
them in one worker, which makes it once in all.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
import venv
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from dcsim.api import TorqueFreeRotation, load_scenario, quaternion_between, rotation_matrix
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

REPO = Path(__file__).resolve().parents[1]
DCSIM = Path(sys.executable).with_name("dcsim")

SHARES_DEFAULT_RUN = pytest.mark.xdist_group("default-run")
SHARES_WHEEL = pytest.mark.xdist_group("wheel")

CAPTURE = REPO / "scenarios" / "debris_capture.yaml"
CAPTURE_TURNED_AT = 96.9
"""Time (s) into the shipped capture at which it asks its planner (96.95 s): a short
capture's target starts turned as the shipped one is at this time less the short
observation, so that it is planned for, and grasped, turned as the shipped run's is."""


@dataclass
class ApproachLine:
    """The line a capture's base approaches its target's untouched tumble along, from the
    scenario's initial state (what the mission takes from an exact track at t = 0).

    Attributes
    ----------
    centre : ndarray (3,)
        The target's centre of mass, m.
    axis : ndarray (3,)
        Unit angular momentum, on the fixture's side.
    facing : ndarray (4,)
        The base's attitude with its mount facing the target, turned least from the
        unturned start.
    below : ndarray (3,)
        The standoff height along the base's z axis, m: how far below the axis the line
        runs.
    """

    centre: np.ndarray
    axis: np.ndarray
    facing: np.ndarray
    below: np.ndarray

    def point(self, distance: float) -> np.ndarray:
        """The point ``distance`` out along the axis, below it as the standoff is.

        Parameters
        ----------
        distance : float
            Distance from the target's centre of mass along the axis, m.

        Returns
        -------
        ndarray (3,)
            The point, world frame, m.
        """
        return self.centre + distance * self.axis - self.below


def capture_approach_line(path: Path) -> ApproachLine:
    """The approach line of a capture scenario, its robot unturned.

    Parameters
    ----------
    path : Path
        The capture scenario's file.

    Returns
    -------
    ApproachLine
        The line its base approaches along.
    """
    scenario = load_scenario(path)
    target, mount = scenario.mission.target, np.array(scenario.robot.mount)
    rotation = rotation_matrix(target.unit_attitude())
    rate = rotation @ np.radians(target.angular_velocity_deg_s)  # world frame, rad/s
    axis = rotation @ target.inertia_tensor() @ rotation.T @ rate
    axis /= np.linalg.norm(axis)
    if axis @ (rotation @ np.array(target.fixture.position)) < 0.0:
        axis = -axis
    facing = quaternion_between(mount, -axis)
    below = scenario.mission.standoff_height * rotation_matrix(facing)[:, 2]
    return ApproachLine(np.array(target.position), axis, facing, below)


def short_capture(observation: float, duration: float) -> dict[str, object]:
    """Overrides that cut the shipped capture's approach and most of its observation.

    The base starts where the approach ends: ``standoff`` from the target's centre of
    mass on its angular momentum axis (fixed while it tumbles free) and
    ``standoff_height`` below it, its mount facing the target (the shipped base starts
    unturned). That is inside the approach planner's keep-out, on the approach line: the
    mission plans no flight and its move in is of zero length. The target starts turned as it is :data:`CAPTURE_TURNED_AT` less
    ``observation`` into the shipped run. The object sensor reports the truth: a watch
    of well under the shipped 5 s is too short for the tracker to learn the tumble (the
    shipped run's tracker watches it through its acquisition and the whole approach).

    Parameters
    ----------
    observation : float
        ``mission.observation_time`` of the short run, s.
    duration : float
        ``world.duration`` of the short run, s.

    Returns
    -------
    dict
        Scenario key paths and their values, for ``dcsim.api.run``'s ``overrides``.
    """
    scenario = load_scenario(CAPTURE)
    target, line = scenario.mission.target, capture_approach_line(CAPTURE)
    attitude = target.unit_attitude()
    rate = rotation_matrix(attitude) @ np.radians(target.angular_velocity_deg_s)
    tumble = TorqueFreeRotation(target.inertia_tensor(), attitude, rate)
    tumble.advance(CAPTURE_TURNED_AT - observation)
    return {
        "robot.initial.position": line.point(scenario.mission.standoff).tolist(),
        "robot.initial.attitude": line.facing.tolist(),
        "mission.target.attitude": list(tumble.attitude),
        "mission.observation_time": observation,
        "world.duration": duration,
        "sensors.objects": None,
    }


@dataclass
class CliResult:
    """Exit status and output of one ``dcsim`` invocation."""

    returncode: int
    stdout: str
    stderr: str


@pytest.fixture
def dcsim_cli(tmp_path):
    """Run the installed ``dcsim`` console script; ``extra_path`` dirs go on PYTHONPATH."""

    def run(
        *args: str, extra_path: list[Path] = (), env: dict[str, str] | None = None
    ) -> CliResult:
        environment = {k: v for k, v in os.environ.items() if k != "DCSIM_LOAD_PLUGINS"}
        environment["PYTHONPATH"] = os.pathsep.join(str(p) for p in extra_path)
        environment.update(env or {})
        done = subprocess.run(
            [str(DCSIM), *args],
            capture_output=True,
            text=True,
            env=environment,
            cwd=tmp_path,
            timeout=120,
        )
        return CliResult(done.returncode, done.stdout, done.stderr)

    return run


@pytest.fixture(scope="session")
def default_run(tmp_path_factory) -> tuple[Runner, dict, Path]:
    """The default scenario flown to its end: the runner, the summary, the run directory.

    Tests that read it are marked ``SHARES_DEFAULT_RUN``.
    """
    out = tmp_path_factory.mktemp("default")
    runner = Runner(setup_run(None, registry=PluginRegistry.discover()), out)
    return runner, runner.run(), out


def make_distribution(
    root: Path,
    dist: str,
    version: str,
    modules: dict[str, str],
    entry_points: dict[str, str],
    group: str = "dcsim",
) -> Path:
    """Install a throw-away distribution under ``root``: modules plus a dist-info.

    ``importlib.metadata`` finds it like any installed package once ``root`` is on the
    path, so the registry discovers its entry points (of ``group``) for real.
    """
    root.mkdir(parents=True, exist_ok=True)
    for name, source in modules.items():
        (root / f"{name}.py").write_text(textwrap.dedent(source))
    info = root / f"{dist.replace('-', '_')}-{version}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
    lines = "\n".join(f"{k} = {v}" for k, v in entry_points.items())
    (info / "entry_points.txt").write_text(f"[{group}]\n{lines}\n")
    return root


GOOD_PLUGIN = """
    import numpy as np
    from dcsim.api import Command, Controller, PluginParams, hookimpl, quantity

    class HoldParams(PluginParams):
        gain: float = quantity(1.0, unit="1/s", gt=0, description="Velocity damping gain.")

    class HoldController(Controller):
        name = "hold"
        summary = "Damps the velocity to zero"
        Params = HoldParams

        def reset(self, robot):
            self.robot = robot

        def command(self, time, estimate, reference, surroundings):
            return Command(force=-self.params.gain * self.robot.mass * np.asarray(estimate.velocity))

    @hookimpl
    def dcsim_plugin_classes():
        return [HoldController]
"""


@pytest.fixture
def good_plugin_dist(tmp_path) -> Path:
    """A third-party distribution ``dcsim-hold`` providing the ``hold`` controller."""
    return make_distribution(
        tmp_path / "site_good",
        "dcsim-hold",
        "1.2.3",
        {"dcsim_hold": GOOD_PLUGIN},
        {"hold": "dcsim_hold"},
    )


@dataclass
class FreshEnvironment:
    """A new virtual environment with dcsim installed from its wheel (and pytest)."""

    root: Path
    wheel: Path

    def run(
        self, program: str, *args: str, cwd: Path, timeout: float = 600
    ) -> subprocess.CompletedProcess:
        """Run one of the environment's programs (``dcsim``, ``python``, ``pip``)."""
        environment = {
            k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")
        }
        return subprocess.run(
            [str(self.root / "bin" / program), *args],
            cwd=cwd,
            capture_output=True,
            text=True,
            env=environment,
            timeout=timeout,
        )


# What a checkout holds besides its sources: left out of the copy a wheel is built from.
NOT_SOURCES = shutil.ignore_patterns(
    ".git", ".venv", "build", "dist", "*.egg-info", "__pycache__", "runs", ".*_cache", "*.fmu"
)


@dataclass
class WheelBuild:
    """A wheel built by pip, and what pip and the build backend printed."""

    path: Path
    output: str


@pytest.fixture(scope="session")
def wheel_build(tmp_path_factory) -> WheelBuild:
    """dcsim built as a wheel from a copy of this checkout.

    Tests that read it, or ``fresh_env``, are marked ``SHARES_WHEEL``. Built from a
    copy so that no build directory is shared with another test process or left in the
    checkout.
    """
    source = tmp_path_factory.mktemp("source") / "dcsim"
    shutil.copytree(REPO, source, ignore=NOT_SOURCES)
    out = tmp_path_factory.mktemp("wheel")
    done = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "-w", str(out), str(source)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    return WheelBuild(next(out.glob("dcsim-*.whl")), done.stdout + done.stderr)


@pytest.fixture(scope="session")
def wheel(wheel_build) -> Path:
    """dcsim built as a wheel from this checkout."""
    return wheel_build.path


@pytest.fixture(scope="session")
def fresh_env(wheel, tmp_path_factory) -> FreshEnvironment:
    """A fresh environment where dcsim was installed as a user would: from the wheel."""
    root = tmp_path_factory.mktemp("fresh") / "env"
    venv.create(root, with_pip=True)
    env = FreshEnvironment(root, wheel)
    installed = env.run(
        "python", "-m", "pip", "install", "--quiet", str(wheel), "pytest", cwd=root.parent
    )
    assert installed.returncode == 0, installed.stderr
    return env
