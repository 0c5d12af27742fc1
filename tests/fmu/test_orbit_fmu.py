"""A j2 world exported as a closed-loop FMU flies as `dcsim run` flies it."""

from __future__ import annotations

import numpy as np

from dcsim.fmu.export import export_fmu
from dcsim.fmu.instance import FmuInstance
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

J2 = ["world.orbit.model=j2", "world.duration=20"]
PERIOD = 0.1  # s


def test_a_j2_scenario_exports_and_flies_as_dcsim_runs_it(tmp_path):
    path = export_fmu(None, tmp_path / "j2.fmu", overrides=J2)
    runner = Runner(setup_run(None, J2))
    runner.run()
    telemetry = runner.recorder.telemetry()
    fmu = FmuInstance(path, "j2")
    fmu.initialise(start_values={})
    names = [f"position.{axis}" for axis in "xyz"]
    for i in range(1, 101):
        fmu.step((i - 1) * PERIOD, PERIOD)
    values = fmu.get(names)
    fmu.terminate()
    fmu.close()
    expected = [telemetry[c][100] for c in ("x", "y", "z")]
    assert np.array_equal([values[n] for n in names], expected)
    cw = Runner(setup_run(None, ["world.duration=20"]))
    cw.run()  # the same scenario under cw is elsewhere: the FMU flew the j2 world
    assert not np.array_equal([cw.recorder.telemetry()[c][100] for c in ("x", "y", "z")], expected)
