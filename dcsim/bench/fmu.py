"""``dcsim bench fmu``: the closed-loop FMU's cost per step against ``dcsim run``'s tick.

One scenario, one run: the scenario is exported as a closed-loop FMU, then flown
alternately (``repeats`` times each, so background load hits both alike):

- **native**: the runner that ``dcsim run`` uses, recording in memory;
- **FMU**: the exported FMU in fmpy, stepped with the control period as communication
  step, every output read after every step (what an importer does).

Both cover the same simulated time; each is reported as wall time per control tick
(the median over the repeats), and the overhead as the FMU's extra time per tick in
percent of the native tick.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from dcsim.fmu.export import export_fmu
from dcsim.fmu.instance import FmuInstance
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run


@dataclass(frozen=True)
class FmuBenchResult:
    """Wall time per control tick, s, of each repeat.

    Attributes
    ----------
    ticks : int
        Control ticks per measurement.
    native, fmu : list of float
        Seconds per tick of each repeat, natively and through the FMU.
    """

    ticks: int
    native: list[float]
    fmu: list[float]

    @property
    def native_tick(self) -> float:
        """Median native wall time per tick, s."""
        return statistics.median(self.native)

    @property
    def fmu_tick(self) -> float:
        """Median FMU wall time per step, s."""
        return statistics.median(self.fmu)

    @property
    def overhead(self) -> float:
        """The FMU's extra time per tick, in percent of the native tick (medians)."""
        return 100.0 * (self.fmu_tick - self.native_tick) / self.native_tick


def bench_fmu(
    scenario: str | Path | None,
    duration: float,
    repeats: int,
    overrides: Sequence[str] = (),
    progress: Callable[[str], None] | None = None,
) -> FmuBenchResult:
    """Time the closed-loop FMU against the native runner on the same scenario.

    Parameters
    ----------
    scenario : str or Path, optional
        Scenario file; the packaged default if None.
    duration : float
        Simulated seconds per measurement (the scenario's duration is set to it).
    repeats : int
        Measurements of each kind.
    overrides : sequence of str
        Further scenario overrides.
    progress : callable, optional
        Called with a line of text after each measurement.

    Returns
    -------
    FmuBenchResult
        Seconds per tick of every repeat, both ways.
    """
    say = progress or (lambda line: None)
    overrides = [*overrides, f"world.duration={duration}", "mission.stop_on_all_delivered=false"]
    registry = PluginRegistry.discover()
    with tempfile.TemporaryDirectory(prefix="dcsim-bench-fmu-") as tmp:
        path = export_fmu(scenario, Path(tmp) / "closed_loop.fmu", overrides=overrides)
        native, fmu, ticks = [], [], 0
        for k in range(repeats):
            ticks, seconds = _native(scenario, overrides, registry)
            native.append(seconds / ticks)
            fmu.append(_fmu(path, ticks) / ticks)
            native_ms, fmu_ms = 1e3 * native[-1], 1e3 * fmu[-1]
            say(f"repeat {k + 1}/{repeats}: native {native_ms:.3f} ms/tick, FMU {fmu_ms:.3f} ms")
    return FmuBenchResult(ticks, native, fmu)


def _native(
    scenario: str | Path | None, overrides: Sequence[str], registry: PluginRegistry
) -> tuple[int, float]:
    """Ticks flown and their wall time, s (opening and closing the run not counted)."""
    runner = Runner(setup_run(scenario, overrides, registry=registry))
    runner.open()
    ticks, started = 0, time.perf_counter()
    while not runner.ended:
        runner.advance()
        ticks += 1
    elapsed = time.perf_counter() - started
    runner.close()
    return ticks, elapsed


def _fmu(path: Path, ticks: int) -> float:
    """Wall time, s, of ``ticks`` steps of the FMU with all outputs read after each."""
    with FmuInstance(path, "bench") as fmu:
        fmu.initialise()
        period = float(fmu.description.model.defaultExperiment.stepSize)
        outputs = fmu.description.names("output")
        started = time.perf_counter()
        for k in range(ticks):
            fmu.step(k * period, period)
            fmu.get(outputs)
        elapsed = time.perf_counter() - started
        fmu.terminate()
    return elapsed


def markdown_table(result: FmuBenchResult) -> str:
    """The medians and the overhead as a Markdown table."""
    native, fmu = result.native_tick, result.fmu_tick
    return (
        "\n".join(
            [
                "| measurement | wall time per control tick (median) | repeats |",
                "|---|---|---|",
                f"| native runner (`dcsim run`) | {1e3 * native:.3f} ms | {len(result.native)} |",
                f"| closed-loop FMU in fmpy (doStep + all outputs) | {1e3 * fmu:.3f} ms "
                f"| {len(result.fmu)} |",
                f"| FMU overhead | {result.overhead:+.1f} % of the native tick | |",
            ]
        )
        + "\n"
    )
