"""``dcsim bench campaign``: what the campaign engine costs and what two workers gain.

The same cases of a campaign run three ways: one after the other in this process,
as ``dcsim run`` would run them (the direct baseline, no plots, like a campaign's
cases), then as a campaign on a local Dask cluster of each worker count, then directly
once more. The two direct passes bracket the campaigns, so that a machine whose speed
drifts over the minutes of the bench (a shared virtual machine does) moves the baseline
with it: the baseline is their mean.

Two overheads are reported. *Per case*: the median over the cases of a case's own wall
time inside the one-worker campaign's worker (set-up included) against the same case
run directly (the mean of its two direct runs); the median is not moved by the
worker's first case, which also imports dcsim and its plugins. *In all*: the one-worker campaign's
wall time, which adds starting the cluster, the workers' imports and the results
table, statistics and plots at the end, against the direct runs'. The
speed-up is one worker's wall time over each other count's. The tables of every worker
count must be equal (bar wall times): the same cases on any cluster.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import yaml

from dcsim.campaign import ClusterOptions, campaign_cases, load_campaign, run_campaign
from dcsim.campaign.cases import Case, case_document
from dcsim.campaign.spec import Campaign
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

TIMING_COLUMNS = ("case_wall_time_s", "wall_time_s", "real_time_factor")
"""Columns that hold wall times, left out when tables are compared."""


@dataclass(frozen=True)
class CampaignBench:
    """Wall times of one set of cases run directly and as campaigns.

    Attributes
    ----------
    cases : int
        Cases run each way.
    direct_case_s : tuple of list of float
        Each case's wall time in the direct passes before and after the campaigns, s.
    campaign_s : dict of int to float
        Worker count → the campaign's wall time, s.
    worker_case_s : list of float
        Each case's wall time in the one-worker campaign's worker (set-up included, as
        the direct passes time it), s.
    same_results : bool
        Whether every worker count gave the same table (wall times aside).
    """

    cases: int
    direct_case_s: tuple[list[float], list[float]]
    campaign_s: dict[int, float]
    worker_case_s: list[float]
    same_results: bool

    @property
    def direct_s(self) -> tuple[float, float]:
        """The direct passes' wall times, before and after the campaigns, s."""
        before, after = self.direct_case_s
        return sum(before), sum(after)

    @property
    def baseline_s(self) -> float:
        """The direct wall time: the mean of the passes before and after, s."""
        return statistics.fmean(self.direct_s)

    def case_overhead(self) -> float:
        """The median over the cases of a case's extra wall time in a worker, as a
        fraction of its direct wall time (the mean of its two direct runs)."""
        ratios = [
            worker / statistics.fmean(direct)
            for worker, *direct in zip(self.worker_case_s, *self.direct_case_s, strict=True)
        ]
        return statistics.median(ratios) - 1.0

    def overhead(self) -> float:
        """The one-worker campaign's extra wall time in all, as a fraction of the direct runs'."""
        return self.campaign_s[1] / self.baseline_s - 1.0

    def speed_up(self, workers: int) -> float:
        """One worker's wall time over ``workers``'."""
        return self.campaign_s[1] / self.campaign_s[workers]


def bench_campaign(
    path: Path,
    out: Path,
    cases: int,
    workers: Sequence[int],
    duration: float | None,
    progress: Callable[[str], None] = print,
) -> CampaignBench:
    """Run the first ``cases`` cases of campaign ``path`` directly, on each worker count,
    then directly again.

    ``duration`` (s) replaces ``world.duration`` in every case (the campaign's own when
    None). Run directories go under ``out``.
    """
    campaign = load_campaign(with_duration(path, out, duration))
    registry = PluginRegistry.discover()
    selected = campaign_cases(campaign, registry, cases)
    before = _run_directly(campaign, selected, registry, out / "direct")
    progress(f"direct: {len(selected)} cases in {sum(before):.1f} s")
    walls, tables = {}, {}
    for count in sorted({1, *workers}):
        began = time.perf_counter()
        run = run_campaign(campaign, out / f"workers-{count}", ClusterOptions(workers=count), cases)
        walls[count] = time.perf_counter() - began
        tables[count] = run.table
        progress(f"{count} worker(s): {walls[count]:.1f} s")
    after = _run_directly(campaign, selected, registry, out / "direct-again")
    progress(f"direct again: {len(selected)} cases in {sum(after):.1f} s")
    # the table's rows and the direct passes both follow the case index
    in_workers = [float(t) for t in tables[1].sort_values("case")["case_wall_time_s"]]
    compared = [t.drop(columns=list(TIMING_COLUMNS), errors="ignore") for t in tables.values()]
    same = all(table.equals(compared[0]) for table in compared)
    return CampaignBench(len(selected), (before, after), walls, in_workers, same)


def markdown_table(bench: CampaignBench) -> str:
    """The bench's figures as a Markdown table, with the two overheads below it."""
    lines = [
        "| run | wall time [s] | per case [s] | speed-up over 1 worker | overhead over direct |",
        "|---|---:|---:|---:|---:|",
    ]
    for label, wall in zip(("before", "after"), bench.direct_s, strict=True):
        lines.append(
            f"| direct, one after the other ({label} the campaigns) | {wall:.1f} | "
            f"{wall / bench.cases:.2f} | | |"
        )
    for count, wall in sorted(bench.campaign_s.items()):
        overhead = f"{100 * bench.overhead():+.1f} %" if count == 1 else ""
        lines.append(
            f"| campaign, {count} worker{'s' if count > 1 else ''} | {wall:.1f} | "
            f"{wall / bench.cases:.2f} | {bench.speed_up(count):.2f} × | {overhead} |"
        )
    in_workers = sum(bench.worker_case_s)
    fixed = bench.campaign_s[1] - in_workers
    verdict = "equal" if bench.same_results else "DIFFERENT"
    lines += [
        "",
        f"Per case: {in_workers / bench.cases:.2f} s in the one-worker campaign's worker "
        f"against {bench.baseline_s / bench.cases:.2f} s direct (mean of both passes); "
        f"median overhead of a case {100 * bench.case_overhead():+.1f} %. The campaign's "
        f"fixed costs (cluster, imports, results and plots): {fixed:.1f} s.",
        f"Results tables of every worker count: {verdict}.",
    ]
    return "\n".join(lines)


def _run_directly(
    campaign: Campaign, cases: Sequence[Case], registry: PluginRegistry, out: Path
) -> list[float]:
    """Run ``cases`` one after the other in this process into ``out``; each one's wall
    time, set-up included, s."""
    walls = []
    for case in cases:
        began = time.perf_counter()
        setup = setup_run(case_document(campaign.base, case), registry=registry)
        Runner(setup, out / case.name, plots=False).run()
        walls.append(time.perf_counter() - began)
    return walls


def with_duration(path: Path, out: Path, duration: float | None) -> Path:
    """A copy of campaign ``path`` in folder ``out`` whose cases run for ``duration`` s
    (the campaign's own when None); its base scenario is named by absolute path."""
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    data["scenario"] = str((path.parent / data["scenario"]).resolve())
    if duration is not None:
        data["set"] = {**(data.get("set") or {}), "world.duration": duration}
    out.mkdir(parents=True, exist_ok=True)
    copy = out / path.name
    copy.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return copy
