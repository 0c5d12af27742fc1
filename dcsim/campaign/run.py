"""Running a campaign into its directory; resuming it; replaying one case.

A campaign directory holds::

    campaign.yaml         the campaign file as given
    base_scenario.yaml    the base scenario's text
    manifest.json         names, case count, dcsim version, start time
    results.jsonl         one line per ended case, written as each arrives
    cases/case-000017/    each case's run directory (scenario.yaml with its values
                          applied, telemetry, events, summary, case.json)
    results.csv, results.parquet, statistics.csv, plots/   when the run ends

``results.jsonl`` is the record: :func:`resume_campaign` runs the cases it lacks, and
Ctrl-C keeps every line written so far.
"""

from __future__ import annotations

import filecmp
import json
import os
import shutil
import time
from collections.abc import Callable, Mapping, Sequence
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, TextIO

from dcsim import __version__
from dcsim.campaign.cases import Case, campaign_cases, case_document
from dcsim.campaign.engine import ClusterOptions, TaskOutcome, dask_client, run_tasks, running_count
from dcsim.campaign.progress import CampaignProgress
from dcsim.campaign.results import metric_names, results_table, write_results
from dcsim.campaign.spec import Campaign, load_campaign, parse_campaign
from dcsim.campaign.worker import CaseTask, run_case
from dcsim.errors import DcsimError
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.directory import prepare_run_directory
from dcsim.run.setup import setup_run
from dcsim.scenario import ScenarioDocument, validate

if TYPE_CHECKING:
    import pandas

CAMPAIGN_FILE = "campaign.yaml"
BASE_FILE = "base_scenario.yaml"
MANIFEST_FILE = "manifest.json"
JOURNAL_FILE = "results.jsonl"
CASES_DIR = "cases"
COMPARED_FILES = ("telemetry.csv", "events.jsonl")
"""The files a replayed case must reproduce byte for byte."""


class CampaignDirectoryError(DcsimError):
    """A folder is not a campaign directory dcsim can resume or replay."""


@dataclass(frozen=True)
class CampaignRun:
    """What a campaign run left: its table, statistics and directory.

    Attributes
    ----------
    directory : Path
        The campaign directory.
    table : pandas.DataFrame
        One row per case (``results.csv``).
    statistics : pandas.DataFrame
        The metrics' statistics (``statistics.csv``).
    interrupted : bool
        Whether Ctrl-C stopped it (the cases not run have status ``not run``).
    """

    directory: Path
    table: pandas.DataFrame
    statistics: pandas.DataFrame
    interrupted: bool = False


@dataclass(frozen=True)
class Replay:
    """A case run again and compared with its recorded run.

    Attributes
    ----------
    case : Case
        The case.
    out : Path
        The replay's run directory.
    summary : dict
        The replay's summary.
    identical : dict of str to bool
        For ``telemetry.csv`` and ``events.jsonl``: byte-identical to the recorded run's.
    """

    case: Case
    out: Path
    summary: dict[str, Any]
    identical: dict[str, bool]


def run_campaign(
    campaign: Campaign | str | Path,
    out: Path,
    cluster: ClusterOptions | None = None,
    cases: int | None = None,
    force: bool = False,
    stream: TextIO | None = None,
) -> CampaignRun:
    """Run a campaign's cases (the first ``cases`` of them) on Dask into ``out``.

    Every case is generated and checked before the directory is touched or a worker
    starts.

    Raises
    ------
    CampaignError
        If the campaign or any of its cases is invalid.
    RunDirectoryError
        If ``out`` holds something (without ``force``) or cannot be written.
    ClusterError
        If the cluster cannot be reached or started, or a local one is asked for while
        Python imports the main module in a worker process (a script without its
        ``if __name__ == "__main__":`` guard) or from standard input.
    """
    if not isinstance(campaign, Campaign):
        campaign = load_campaign(campaign)
    selected, metrics = _checked(campaign, cases)
    if not force and out.is_dir() and any(out.iterdir()):
        prepare_run_directory(out)  # refused now, before a cluster starts

    def prepare() -> None:
        prepare_run_directory(out, force)
        (out / CAMPAIGN_FILE).write_text(campaign.text, encoding="utf-8")
        (out / BASE_FILE).write_text(campaign.base_text, encoding="utf-8")
        manifest = {
            "name": campaign.spec.name,
            "campaign_file": campaign.filename,
            "base_scenario": campaign.base.filename,
            "cases": len(selected),
            "total_cases": campaign.spec.total_cases,
            "dcsim_version": __version__,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        (out / MANIFEST_FILE).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")

    return _execute(out, campaign, selected, metrics, cluster, {}, stream, prepare)


def resume_campaign(
    directory: Path, cluster: ClusterOptions | None = None, stream: TextIO | None = None
) -> CampaignRun:
    """Run the cases of a campaign directory that have no result yet.

    Raises
    ------
    CampaignDirectoryError
        If ``directory`` is not a campaign directory.
    """
    campaign, count = load_campaign_directory(directory)
    selected, metrics = _checked(campaign, count)
    finished = read_journal(directory / JOURNAL_FILE)
    return _execute(directory, campaign, selected, metrics, cluster, finished, stream)


def replay_case(directory: Path, index: int, out: Path | None = None) -> Replay:
    """Run case ``index`` of a campaign directory again, here, and compare it.

    The case is rebuilt from the stored campaign (its seed from its index), run into
    ``out`` (``DIR/reruns/case-000017`` by default, replaced if present) and its
    telemetry and events compared byte for byte with the recorded run's.

    Raises
    ------
    CampaignDirectoryError
        If ``directory`` is not a campaign directory, or has no case ``index``.
    """
    from dcsim.run.loop import Runner  # the world engine loads PyBullet

    campaign, count = load_campaign_directory(directory)
    if not 0 <= index < count:
        raise CampaignDirectoryError(f"{directory} has cases 0 to {count - 1}, not case {index}")
    registry = PluginRegistry.discover()
    case = campaign_cases(campaign, registry, index + 1)[index]
    out = out if out is not None else directory / "reruns" / case.name
    prepare_run_directory(out, force=True)
    setup = setup_run(case_document(campaign.base, case), registry=registry)
    summary = Runner(setup, out, plots=campaign.spec.case_plots).run()
    recorded = directory / CASES_DIR / case.name
    identical = {
        name: (recorded / name).exists() and filecmp.cmp(recorded / name, out / name, shallow=False)
        for name in COMPARED_FILES
    }
    return Replay(case, out, summary, identical)


def load_campaign_directory(directory: Path) -> tuple[Campaign, int]:
    """The campaign stored in ``directory`` and how many of its cases it runs.

    Raises
    ------
    CampaignDirectoryError
        If a stored file is missing or unreadable.
    """
    try:
        manifest = json.loads((directory / MANIFEST_FILE).read_text(encoding="utf-8"))
        text = (directory / CAMPAIGN_FILE).read_text(encoding="utf-8")
        base_text = (directory / BASE_FILE).read_text(encoding="utf-8")
        count = int(manifest["cases"])
        filename, base_name = manifest["campaign_file"], manifest["base_scenario"]
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise CampaignDirectoryError(
            f"{directory} is not a campaign directory dcsim can read ({error}); "
            f"it is made by dcsim campaign run"
        ) from None
    spec = parse_campaign(text, filename)
    base = ScenarioDocument.from_text(base_text, base_name)
    return Campaign(spec, filename, text, base, base_text), count


def read_journal(path: Path) -> dict[int, dict[str, Any]]:
    """Case index → result, from ``results.jsonl`` (a torn last line is skipped)."""
    results: dict[int, dict[str, Any]] = {}
    if not path.exists():
        return results
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            result = json.loads(line)
            results[int(result["case"])] = result
        except (ValueError, KeyError, TypeError):
            continue
    return results


def _checked(campaign: Campaign, count: int | None) -> tuple[list[Case], list[str]]:
    """The campaign's first ``count`` cases and its metrics, all checked."""
    cases = campaign_cases(campaign, PluginRegistry.discover(), count)
    return cases, metric_names(campaign, validate(campaign.base).mission.type)


def _execute(
    directory: Path,
    campaign: Campaign,
    cases: Sequence[Case],
    metrics: Sequence[str],
    cluster: ClusterOptions | None,
    finished: Mapping[int, dict[str, Any]],
    stream: TextIO | None,
    prepare: Callable[[], None] | None = None,
) -> CampaignRun:
    """Run the cases without a result; write the table whatever happens.

    ``prepare`` (making the directory) is called once the cluster is reached, so that
    a cluster that cannot be reached leaves nothing behind.
    """
    results = dict(finished)
    pending = [case for case in cases if case.index not in results]
    progress = CampaignProgress(len(pending), stream)
    interrupted = False
    with ExitStack() as stack:
        client = stack.enter_context(dask_client(cluster or ClusterOptions())) if pending else None
        if prepare is not None:
            prepare()
        cases_dir = directory / CASES_DIR
        cases_dir.mkdir(exist_ok=True)
        _remove_attempts(cases_dir)
        tasks = {
            case.index: CaseTask(
                cases_dir, campaign.spec.name, campaign.base, case, campaign.spec.case_plots
            )
            for case in pending
        }
        journal = stack.enter_context((directory / JOURNAL_FILE).open("a", encoding="utf-8"))
        try:
            if tasks:
                assert client is not None  # made whenever cases are pending
                run_tasks(client, run_case, tasks, _Recorder(journal, results, progress, client))
        except KeyboardInterrupt:
            interrupted = True
        finally:
            progress.close()
    _remove_attempts(cases_dir)
    table = results_table(campaign, cases, results, metrics)
    summary = write_results(directory, campaign, table, metrics)
    return CampaignRun(directory, table, summary, interrupted)


class _Recorder:
    """Journals each ended case and counts it on the progress line."""

    def __init__(
        self,
        journal: IO[str],
        results: dict[int, dict[str, Any]],
        progress: CampaignProgress,
        client: Any,
    ) -> None:
        self.journal, self.results, self.progress, self.client = journal, results, progress, client

    def __call__(self, outcome: TaskOutcome) -> None:
        result = outcome.value if outcome.error is None else _failed(outcome)
        self.results[outcome.index] = result
        self.journal.write(json.dumps(result) + "\n")
        self.journal.flush()
        os.fsync(self.journal.fileno())
        self.progress.case_ended(result["status"] == "failed", running_count(self.client))


def _failed(outcome: TaskOutcome) -> dict[str, Any]:
    """The result of a case that returned none (its task raised or its workers died)."""
    return {
        "case": outcome.index,
        "status": "failed",
        "reason": outcome.error,
        "summary": {},
        "wall_time_s": None,
    }


def _remove_attempts(cases_dir: Path) -> None:
    """Remove unfinished attempt folders (``.case-*``) left by workers that died."""
    for attempt in cases_dir.glob(".case-*"):
        shutil.rmtree(attempt, ignore_errors=True)
