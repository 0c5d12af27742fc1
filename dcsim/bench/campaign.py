"""``dcsim bench campaign``: what the campaign engine costs and what two workers gain.

The same cases of a campaign run three ways: one after the other in this process,
as ``dcsim run`` would run them (the direct baseline, no plots, like a campaign's
cases), then as a campaign on a local Dask cluster of each worker count. The
campaign's wall time includes starting the cluster, the workers' imports and the
results table, statistics and plots at the end. The per-case overhead is the one-
worker campaign's wall time against the direct runs'; the speed-up is one worker's
wall time over each other count's. The tables of every worker count must be equal
(bar wall times): the same cases on any cluster.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import yaml

from dcsim.campaign import ClusterOptions, campaign_cases, load_campaign, run_campaign
from dcsim.campaign.cases import case_setup
from dcsim.registry import PluginRegistry
from dcsim.runner import Runner

TIMING_COLUMNS = ("case_wall_time_s", "wall_time_s", "real_time_factor")
"""Columns that hold wall times, left out when tables are compared."""


@dataclass(frozen=True)
class CampaignBench:
    """Wall times of one set of cases run directly and as campaigns.

    Attributes
    ----------
    cases : int
        Cases run each way.
    direct_s : float
        The direct runs' total wall time, s.
    campaign_s : dict of int to float
        Worker count → the campaign's wall time, s.
    same_results : bool
        Whether every worker count gave the same table (wall times aside).
    """

    cases: int
    direct_s: float
    campaign_s: dict[int, float]
    same_results: bool

    def overhead(self) -> float:
        """The one-worker campaign's extra wall time per case, as a fraction of a direct run's."""
        return self.campaign_s[1] / self.direct_s - 1.0

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
    """Run the first ``cases`` cases of campaign ``path`` directly and on each worker count.

    ``duration`` (s) replaces ``world.duration`` in every case (the campaign's own when
    None). Run directories go under ``out``.
    """
    campaign = load_campaign(_with_duration(path, out, duration))
    registry = PluginRegistry.discover()
    selected = campaign_cases(campaign, registry, cases)
    began = time.perf_counter()
    for case in selected:
        setup = case_setup(campaign.base, case, registry)
        Runner(setup, out / "direct" / case.name, plots=False).run()
    direct = time.perf_counter() - began
    progress(f"direct: {len(selected)} cases in {direct:.1f} s")
    walls, tables = {}, []
    for count in sorted({1, *workers}):
        began = time.perf_counter()
        run = run_campaign(campaign, out / f"workers-{count}", ClusterOptions(workers=count), cases)
        walls[count] = time.perf_counter() - began
        tables.append(run.table.drop(columns=list(TIMING_COLUMNS), errors="ignore"))
        progress(f"{count} worker(s): {walls[count]:.1f} s")
    same = all(table.equals(tables[0]) for table in tables)
    return CampaignBench(len(selected), direct, walls, same)


def markdown_table(bench: CampaignBench) -> str:
    """The bench's figures as a Markdown table."""
    per_case = bench.direct_s / bench.cases
    lines = [
        "| run | wall time [s] | per case [s] | speed-up over 1 worker | overhead over direct |",
        "|---|---:|---:|---:|---:|",
        f"| direct, one after the other | {bench.direct_s:.1f} | {per_case:.2f} | | |",
    ]
    for count, wall in sorted(bench.campaign_s.items()):
        overhead = f"{100 * bench.overhead():+.1f} %" if count == 1 else ""
        lines.append(
            f"| campaign, {count} worker{'s' if count > 1 else ''} | {wall:.1f} | "
            f"{wall / bench.cases:.2f} | {bench.speed_up(count):.2f} × | {overhead} |"
        )
    verdict = "equal" if bench.same_results else "DIFFERENT"
    lines.append(f"\nResults tables of every worker count: {verdict}.")
    return "\n".join(lines)


def _with_duration(path: Path, out: Path, duration: float | None) -> Path:
    """A copy of campaign ``path`` in ``out`` whose cases run for ``duration`` s."""
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    data["scenario"] = str((path.parent / data["scenario"]).resolve())
    if duration is not None:
        data["set"] = {**(data.get("set") or {}), "world.duration": duration}
    out.mkdir(parents=True, exist_ok=True)
    copy = out / path.name
    copy.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return copy
