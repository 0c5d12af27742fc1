"""One case, run inside a Dask worker: its run directory written once, atomically.

A case runs into a hidden attempt folder (``cases/.case-000017-<random>``) that is
renamed to ``cases/case-000017`` only when complete. A case that runs twice (its
worker died after finishing, before the result was fetched) finds the finished folder
and returns its result without running again; if two attempts finish together, the
rename of the second fails and its folder is removed. Either way one result remains.
"""

from __future__ import annotations

import json
import os
import shutil
import time
import uuid
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from dcsim import __version__
from dcsim.campaign.cases import Case, case_document
from dcsim.errors import DcsimError
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.recording import to_json
from dcsim.run.setup import setup_run
from dcsim.scenario import ScenarioDocument

CASE_FILE = "case.json"
"""The manifest in each case's run directory: index, seed, values, overrides, version."""


@dataclass(frozen=True)
class CaseTask:
    """What a worker needs to run one case.

    Attributes
    ----------
    cases_dir : Path
        The campaign's ``cases/`` folder (the same path on every worker).
    campaign : str
        The campaign's name.
    base : ScenarioDocument
        The base scenario.
    case : Case
        The case.
    plots : bool
        Draw the case's plots.
    """

    cases_dir: Path
    campaign: str
    base: ScenarioDocument
    case: Case
    plots: bool


def run_case(task: CaseTask) -> dict[str, Any]:
    """Run one case into its run directory; return its result.

    A case whose plugin raises or whose run fails is a result with status ``failed``
    and the reason, not an exception: only a dying worker loses the attempt.

    Returns
    -------
    dict
        ``case`` (index), ``status``, ``reason``, ``summary`` (the run's summary, plain
        data) and ``wall_time_s`` (the case in the worker, set-up included, s).
    """
    final = task.cases_dir / task.case.name
    done = read_case_result(final)
    if done is not None:
        return done
    attempt = task.cases_dir / f".{task.case.name}-{uuid.uuid4().hex[:8]}"
    attempt.mkdir(parents=True)
    started = time.perf_counter()
    summary = _run(task, attempt)
    result = {
        "case": task.case.index,
        "status": summary["status"],
        "reason": summary["reason"],
        "summary": summary,
        "wall_time_s": time.perf_counter() - started,
    }
    _write_json(attempt / CASE_FILE, {**case_manifest(task), "result": result})
    try:
        os.rename(attempt, final)
    except OSError:  # another attempt finished first: keep its result
        shutil.rmtree(attempt, ignore_errors=True)
        return read_case_result(final) or result
    return result


def case_manifest(task: CaseTask) -> dict[str, Any]:
    """What the case was: enough to repeat it with ``dcsim run``."""
    case = task.case
    return {
        "campaign": task.campaign,
        "case": case.index,
        "draw": case.draw,
        "seed": case.seed,
        "values": case.values,
        "base_scenario": task.base.filename,
        "overrides": list(case.overrides),
        "dcsim_version": __version__,
    }


def read_case_result(directory: Path) -> dict[str, Any] | None:
    """The result stored in a finished case's run directory, or None."""
    try:
        return json.loads((directory / CASE_FILE).read_text(encoding="utf-8"))["result"]
    except (OSError, ValueError, KeyError):
        return None


def _run(task: CaseTask, out: Path) -> dict[str, Any]:
    """Run the case into ``out``; its summary (one saying why, if it could not start)."""
    from dcsim.run.loop import Runner  # the world engine loads PyBullet

    try:
        runner = Runner(
            setup_run(case_document(task.base, task.case), registry=_registry()),
            out,
            plots=task.plots,
        )
    except DcsimError as error:  # e.g. a plugin not installed on this worker
        return {"status": "failed", "reason": str(error)}
    try:
        return json.loads(to_json(runner.run()))
    except Exception as error:  # a bug: the runner wrote the records and the summary
        reason = f"{type(error).__name__}: {error}"
        return {**(runner.summary or {}), "status": "failed", "reason": reason}


@cache
def _registry() -> PluginRegistry:
    """The installed plugins, discovered once per worker process."""
    return PluginRegistry.discover()


def _write_json(path: Path, data: Any) -> None:
    path.write_text(json.dumps(data, indent=2, default=str) + "\n", encoding="utf-8")
