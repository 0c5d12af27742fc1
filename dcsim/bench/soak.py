"""``dcsim bench soak``: a long run's memory and speed, and FMU instances over and over.

The default scenario is flown for N control ticks (targets delivered, the mission then
holds station), streaming its records into a run directory as ``dcsim run`` does. At
evenly spaced ticks the bench samples the process's resident memory (``VmRSS`` of
``/proc/self/status``, Linux) and the mean wall time per tick since the last sample.
The verdicts compare the memory at 10 % and at 100 % of the run (the first 10 % is
warm-up: imports, caches, the allocator settling) and the time per tick over the
second tenth of the run with the last tenth.

The FMU part exports the default scenario as the closed-loop FMU once, then
instantiates, initialises, steps, terminates and frees it again and again in this
process, sampling resident memory after each cycle.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

_FMU_STEPS = 10  # control periods flown per FMU cycle


@dataclass(frozen=True)
class SoakSample:
    """The state of a soak run at one sampled tick.

    Attributes
    ----------
    tick : int
        Control ticks flown.
    resident_bytes : int
        Resident memory of the process, bytes.
    tick_seconds : float
        Mean wall time per tick since the previous sample, s.
    """

    tick: int
    resident_bytes: int
    tick_seconds: float


@dataclass(frozen=True)
class SoakResult:
    """A soak run's samples and its verdicts.

    Attributes
    ----------
    samples : list of SoakSample
        Evenly spaced over the run.
    """

    samples: list[SoakSample]

    def _at(self, fraction: float) -> SoakSample:
        """The sample nearest to ``fraction`` of the run."""
        ticks = np.array([s.tick for s in self.samples])
        return self.samples[int(np.argmin(np.abs(ticks - fraction * ticks[-1])))]

    @property
    def memory_growth(self) -> float:
        """Relative growth of resident memory from 10 % to 100 % of the run."""
        start, end = self._at(0.1).resident_bytes, self.samples[-1].resident_bytes
        return (end - start) / start

    def tick_time(self, first: float, last: float) -> float:
        """Mean wall time per tick over the samples in ``(first, last]`` of the run, s."""
        total = self.samples[-1].tick
        chosen = [s.tick_seconds for s in self.samples if first * total < s.tick <= last * total]
        return float(np.mean(chosen))

    @property
    def tick_time_change(self) -> float:
        """Relative change of the time per tick from the second tenth to the last tenth."""
        early, late = self.tick_time(0.1, 0.2), self.tick_time(0.9, 1.0)
        return (late - early) / early


def resident_bytes() -> int:
    """Resident memory of this process, bytes (``VmRSS`` in ``/proc/self/status``)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    raise RuntimeError("VmRSS not found in /proc/self/status")


def soak(
    ticks: int,
    samples: int,
    out_dir: Path,
    progress: Callable[[str], None] = print,
) -> SoakResult:
    """Fly the default scenario for ``ticks`` control ticks, sampling ``samples`` times.

    Parameters
    ----------
    ticks : int
        Control ticks to fly.
    samples : int
        Samples, evenly spaced.
    out_dir : Path
        The run directory the records stream into.
    progress : callable
        Receives a line of text at every sample.
    """
    registry = PluginRegistry.discover()
    setup = setup_run(
        None,
        # One simulated second per tick is more than the ticks need at the default
        # 0.1 s control period, and stays within the scenario's bound on physics steps.
        [
            "mission.stop_on_all_delivered=false",
            f"world.duration={ticks}",
            "stop.on_collision=false",
        ],
        registry=registry,
    )
    runner = Runner(setup, out_dir)
    runner.open()
    every = max(ticks // samples, 1)
    found: list[SoakSample] = []
    started = time.perf_counter()
    try:
        for tick in range(1, ticks + 1):
            runner.advance()
            if tick % every == 0 or tick == ticks:
                now = time.perf_counter()
                flown = tick - (found[-1].tick if found else 0)
                found.append(SoakSample(tick, resident_bytes(), (now - started) / flown))
                started = now
                progress(
                    f"tick {tick}: {found[-1].resident_bytes / 2**20:.1f} MB resident, "
                    f"{1e6 * found[-1].tick_seconds:.0f} µs per tick"
                )
    finally:
        runner.close()
    return SoakResult(found)


def fmu_cycles(cycles: int, progress: Callable[[str], None] = print) -> list[int]:
    """Resident memory (bytes) after each of ``cycles`` FMU lifetimes in this process."""
    from dcsim.fmu.export import export_fmu
    from dcsim.fmu.instance import FmuInstance

    found = []
    with tempfile.TemporaryDirectory(prefix="dcsim-soak-") as tmp:
        path = export_fmu(None, Path(tmp) / "closed_loop.fmu")
        for cycle in range(1, cycles + 1):
            with FmuInstance(path, f"soak{cycle}") as fmu:
                fmu.initialise()
                period = float(fmu.description.model.defaultExperiment.stepSize)
                for k in range(_FMU_STEPS):
                    fmu.step(k * period, period)
                fmu.terminate()
            found.append(resident_bytes())
            if cycle % max(cycles // 10, 1) == 0:
                progress(f"FMU cycle {cycle}: {found[-1] / 2**20:.1f} MB resident")
    return found


def markdown_table(result: SoakResult, rows: int = 10) -> str:
    """About ``rows`` of the samples as a Markdown table, then the verdicts."""
    step = max(len(result.samples) // rows, 1)
    shown = result.samples[step - 1 :: step]
    lines = ["| tick | resident memory (MB) | time per tick (µs) |", "|---:|---:|---:|"]
    lines += [
        f"| {s.tick} | {s.resident_bytes / 2**20:.1f} | {1e6 * s.tick_seconds:.0f} |" for s in shown
    ]
    lines += [
        "",
        f"resident memory growth from 10 % to 100 % of the run: "
        f"{100 * result.memory_growth:+.1f} % (target ≤ 5 %)",
        f"time per tick, second tenth {1e6 * result.tick_time(0.1, 0.2):.0f} µs, last tenth "
        f"{1e6 * result.tick_time(0.9, 1.0):.0f} µs: {100 * result.tick_time_change:+.1f} % "
        "(target within ±10 %)",
    ]
    return "\n".join(lines)


def plot(result: SoakResult, path: Path) -> None:
    """Resident memory and time per tick against ticks flown, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ticks = np.array([s.tick for s in result.samples])
    figure, (memory, speed) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    resident = [s.resident_bytes / 2**20 for s in result.samples]
    memory.plot(ticks, resident, color="tab:blue")
    memory.set_ylabel("resident memory [MB]")
    memory.set_ylim(0, 1.2 * max(resident))
    speed.plot(ticks, [1e6 * s.tick_seconds for s in result.samples], color="tab:orange")
    speed.set_ylabel("time per tick [µs]")
    speed.set_ylim(bottom=0)
    speed.set_xlabel("control ticks flown")
    for axis in (memory, speed):
        axis.axvline(0.1 * ticks[-1], color="k", ls=":", lw=1)
        axis.grid(alpha=0.3)
    figure.suptitle("dcsim bench soak: the default scenario, streamed to disk")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
