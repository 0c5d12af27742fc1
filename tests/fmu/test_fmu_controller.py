"""The `fmu` controller: conformance, flying the example PD FMU like `pd`, mapping errors."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.controllers.fmu_controller import SIGNALS, FmuController, FmuControllerParams

from dcsim.api import Reference, RobotSpec, StateEstimate, Surroundings
from dcsim.errors import PluginParameterError
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from dcsim.testing import checks_for

TOLERANCE = 1e-9  # m, m/s: the FMU computes pd's gains as ω² and 2ζω, pd from the poles


def fly(overrides):
    runner = Runner(setup_run(None, overrides, registry=PluginRegistry.discover()))
    return runner.run(), runner.recorder.telemetry()


def with_fmu(path, **params):
    mapping = {"path": str(path), **params}
    return ["controller.plugin=fmu", f"controller.params={mapping!r}"]


@pytest.fixture(scope="module")
def example_controller(pd_fmu):
    """The `fmu` controller with the example PD FMU as its default."""

    class ExampleParams(FmuControllerParams):
        path: str = str(pd_fmu)

    class ExamplePD(FmuController):
        Params = ExampleParams

    ExamplePD.__module__ = FmuController.__module__  # the public-API check reads the plugin's
    return ExamplePD


@pytest.mark.parametrize("check", checks_for("controller"), ids=lambda c: c.name)
def test_keeps_the_controller_contracts(example_controller, check):
    check.run(example_controller)


def test_example_pd_fmu_flies_the_default_mission_like_pd(pd_fmu):
    # the example FMU is pd's translation loop alone: both fly with the attitude free
    free = ["mission.attitude=free"]
    pd_summary, pd_run = fly(free)
    fmu_summary, fmu_run = fly([*free, *with_fmu(pd_fmu)])
    assert fmu_summary["status"] == "completed"
    assert fmu_summary["delivered"] == pd_summary["delivered"] == 4
    assert list(fmu_run["mode"]) == list(pd_run["mode"])
    for column in ("x", "y", "z", "vx", "vy", "vz"):
        assert np.max(np.abs(fmu_run[column] - pd_run[column])) < TOLERANCE, column
    assert fmu_summary["delta_v_mps"] == pytest.approx(pd_summary["delta_v_mps"], abs=TOLERANCE)


@pytest.mark.parametrize(
    "params, message",
    [
        ({"inputs": {"position.q": "position.x"}}, "has no variable 'position.q'"),
        ({"inputs": {"force.x": "position.x"}}, "'force.x' is an output, not an input"),
        ({"inputs": {"position.x": "altitude"}}, "unknown dcsim signal 'altitude'"),
        ({"outputs": {"force.x": "position.x"}}, "'position.x' is an input, not an output"),
        ({"outputs": {"thrust.x": "force.x"}}, "unknown command component 'thrust.x'"),
        ({"parameters": {"gain": 2.0}}, "has no variable 'gain'"),
        ({"parameters": {"mass": 2.0}}, "'mass' is an input, not a parameter"),
    ],
)
def test_mappings_are_checked_against_the_model_description(pd_fmu, params, message):
    with pytest.raises(PluginParameterError, match=message):
        FmuController({"path": str(pd_fmu), **params})


def test_a_missing_or_broken_fmu_is_named(tmp_path):
    with pytest.raises(PluginParameterError, match="no FMU file"):
        FmuController({"path": str(tmp_path / "none.fmu")})
    broken = tmp_path / "broken.fmu"
    broken.write_text("not a zip")
    with pytest.raises(PluginParameterError, match="not a readable FMU"):
        FmuController({"path": str(broken)})


def test_a_step_size_unlike_the_control_period_fails_the_run_clearly(pd_fmu):
    summary, _ = fly(with_fmu(pd_fmu, step_size=0.2))
    assert summary["status"] == "failed"
    assert "set step_size to the scenario's control period" in summary["reason"]


def test_the_command_is_clipped_and_a_new_run_restarts_the_fmu(example_controller):
    # The FMU's own force limit fed with the mass (100): only the plugin can clip to 5 N.
    inputs = {n: n for n in SIGNALS if n.startswith(("position", "velocity", "reference"))}
    inputs.update(mass="mass", speed_limit="speed_limit", max_force="mass")
    controller = example_controller({"inputs": inputs, "parameters": {"bandwidth": 5.0}})
    controller.reset(RobotSpec(mass=100.0, inertia=10.0 * np.eye(3), radius=0.5, max_force=5.0, max_torque=0.5,
                               max_speed=0.5))  # fmt: skip
    far = Reference(time=0.0, position=[100.0, 0.0, 0.0])
    here = StateEstimate(time=0.0, position=[0.0, 0.0, 0.0], velocity=[0.0, 0.0, 0.0])
    forces = [controller.command(0.1 * k, here, far, Surroundings(())).force for k in range(3)]
    assert [np.linalg.norm(f) for f in forces] == pytest.approx([5.0] * 3)
    restarted = controller.command(0.0, here, far, Surroundings(()))  # a new run
    assert np.allclose(restarted.force, forces[0])
    assert controller.next_time == pytest.approx(0.1)
