"""A process that ran the closed-loop FMU exits cleanly: docs/fmu.md's fmpy examples, run
as written from the FMU's folder, each in fresh processes, all exit with code 0.

pythonfmu 0.7's library freed its interpreter state twice at exit (dcsim/fmu/native.py),
which aborted some of these processes after they had printed their results."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow  # 40 fresh processes, about 2 minutes

RUNS = 20  # fresh processes per example
AT_ONCE = 2
EXAMPLE = re.compile(r"```python\n(.*?)```", re.S)


def docs_example(call: str, span: str, shorter: str) -> str:
    """The docs/fmu.md example that makes ``call``, its simulated ``span`` made ``shorter``.

    Only the span changes: the FMU is opened, stepped and freed, and the interpreter
    exits, exactly as the docs show.
    """
    text = (REPO / "docs" / "fmu.md").read_text(encoding="utf-8")
    (code,) = [block for block in EXAMPLE.findall(text) if f"{call}(" in block and span in block]
    return code.replace(span, shorter)


def run_script(folder: Path) -> subprocess.CompletedProcess:
    """``python example.py`` in a fresh process, from ``folder``."""
    return subprocess.run(
        [sys.executable, "example.py"], cwd=folder, capture_output=True, text=True, timeout=300
    )


@pytest.mark.parametrize(
    ("call", "span", "shorter"),
    [
        ("FmuInstance", "range(600)", "range(50)"),
        ("simulate_fmu", "stop_time=300.0", "stop_time=5.0"),
    ],
)
def test_the_closed_loop_fmu_examples_exit_with_code_0_every_time(
    closed_loop_fmu, tmp_path, call, span, shorter
):
    shutil.copy(closed_loop_fmu, tmp_path / "default.fmu")
    (tmp_path / "example.py").write_text(docs_example(call, span, shorter), encoding="utf-8")
    with ThreadPoolExecutor(AT_ONCE) as pool:
        runs = list(pool.map(run_script, [tmp_path] * RUNS))
    assert all(run.stdout for run in runs)  # every run printed its results
    failed = [(run.returncode, run.stderr.strip()[-200:]) for run in runs if run.returncode]
    assert not failed, f"{len(failed)} of {RUNS} runs failed: {failed}"
