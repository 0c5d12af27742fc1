"""``dcsim campaign``: run, resume and replay campaigns from the command line."""

from __future__ import annotations

import sys
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING

import click

from dcsim.cli.options import cluster_choice, cluster_options, out_dir_option
from dcsim.run.directory import file_name_part

if TYPE_CHECKING:
    from dcsim.campaign import CampaignRun, ClusterOptions

EXIT_INTERRUPTED = 130


@click.group("campaign", short_help="Many cases of one scenario on Dask.")
def campaign_group() -> None:
    """Many cases of one scenario on Dask: Monte Carlo draws and sweeps (docs/campaigns.md)."""


@campaign_group.command("run", short_help="Run a campaign file's cases and collect them.")
@click.argument("campaign", type=click.Path(dir_okay=False, path_type=Path))
@out_dir_option("Campaign directory to write. Default: runs/campaigns/NAME-YYYYmmdd-HHMMSS.")
@click.option("--force", is_flag=True, help="Replace the campaign directory if it holds anything.")
@click.option(
    "--cases",
    type=click.IntRange(min=1),
    help="Run only the first N cases (the same N cases every time).",
)
@cluster_options
def run_command(
    campaign: Path,
    out: Path | None,
    force: bool,
    cases: int | None,
    scheduler: str | None,
    connect_timeout: float | None,
    workers: int | None,
    worker_deaths: int,
) -> None:
    """Run the cases of CAMPAIGN (a campaign file) and collect their results.

    Every case is generated and checked before anything runs. Each case writes its run
    directory under DIR/cases/; as cases end their results are appended to
    DIR/results.jsonl, and at the end DIR/results.csv, results.parquet,
    statistics.csv and plots/ are written. Ctrl-C keeps the finished cases; `dcsim
    campaign resume DIR` runs the rest. A failed case is a row with its reason (exit
    status 0); exit status 130 when interrupted.
    """
    from dcsim.campaign import load_campaign, run_campaign

    loaded = load_campaign(campaign)
    if out is None:
        stamp = f"{datetime.now():%Y%m%d-%H%M%S}"
        out = Path("runs") / "campaigns" / f"{file_name_part(loaded.spec.name)}-{stamp}"
    options = cluster_choice(scheduler, workers, worker_deaths, connect_timeout)
    count = loaded.spec.total_cases if cases is None else min(cases, loaded.spec.total_cases)
    click.echo(f"campaign {loaded.spec.name}: {count} cases {_where(options)} → {out}", err=True)
    _report(run_campaign(loaded, out, options, cases, force))


@campaign_group.command("resume", short_help="Run the cases of a campaign that have no result.")
@click.argument("directory", type=click.Path(file_okay=False, exists=True, path_type=Path))
@cluster_options
def resume_command(
    directory: Path,
    scheduler: str | None,
    connect_timeout: float | None,
    workers: int | None,
    worker_deaths: int,
) -> None:
    """Run the cases of campaign DIRECTORY that have no result yet (after Ctrl-C or a crash)."""
    from dcsim.campaign import resume_campaign

    options = cluster_choice(scheduler, workers, worker_deaths, connect_timeout)
    click.echo(f"resuming {directory} {_where(options)}", err=True)
    _report(resume_campaign(directory, options))


@campaign_group.command("rerun", short_help="Run one case again and compare it byte for byte.")
@click.argument("directory", type=click.Path(file_okay=False, exists=True, path_type=Path))
@click.option("--case", "index", type=click.IntRange(min=0), required=True, help="Case index.")
@out_dir_option("Run directory of the replay. Default: DIRECTORY/reruns/case-NNNNNN.")
def rerun_command(directory: Path, index: int, out: Path | None) -> None:
    """Run one case of campaign DIRECTORY again here and compare it with its recorded run.

    Exit status 1 when its telemetry or events differ from the recorded run's.
    """
    from dcsim.campaign import replay_case

    replay = replay_case(directory, index, out)
    summary = replay.summary
    click.echo(f"case {index} (seed {replay.case.seed}): {summary['status']} ({summary['reason']})")
    for name, same in replay.identical.items():
        click.echo(f"  {name}: {'identical to' if same else 'DIFFERS from'} the recorded run")
    click.echo(f"  replay in {replay.out}")
    if not all(replay.identical.values()):
        sys.exit(1)


def _where(options: ClusterOptions) -> str:
    from dcsim.campaign.engine import local_worker_count

    if options.scheduler is not None:
        return f"on the cluster at {options.scheduler}"
    count = options.workers or local_worker_count()
    return f"on a local cluster of {count} worker{'s' if count != 1 else ''}"


def _report(run: CampaignRun) -> None:
    """Print the outcome counts and the statistics; exit 130 if interrupted."""
    table = run.table
    counts = table["status"].value_counts()
    click.echo(", ".join(f"{count} {status}" for status, count in counts.items()))
    failed = table[table["status"] == "failed"]
    for row in failed.head(5).itertuples():
        click.echo(f"  case {row.case} failed: {row.reason}")
    if len(failed) > 5:
        click.echo(f"  and {len(failed) - 5} more failed cases (results.csv has every reason)")
    if len(run.statistics):
        shown = run.statistics.drop(columns=["std", "p5", "p95"], errors="ignore")
        click.echo(shown.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    click.echo(f"results in {run.directory}")
    if run.interrupted:
        click.echo(
            f"interrupted: the finished cases are kept; dcsim campaign resume {run.directory} "
            "runs the rest",
            err=True,
        )
        sys.exit(EXIT_INTERRUPTED)
