"""The Python examples of README.md, docs/python.md, docs/campaigns.md and docs/gym.md run
as saved scripts, and a script that starts a campaign without its guard gets a dcsim error.

Each ```` ```python ```` block is saved as a script of its own and run with this
environment's Python in a new process, in a folder of its own holding a copy of the
repository's ``scenarios/``. A script is where Dask's worker processes import the main
module again, which an example run inside the test process would not show. For test
time, the copy's ``campaigns/default_dispersed.yaml`` has 8 cases (not 40) flown 20 s
each (not 600); the examples themselves run as written.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.conftest import REPO

DOCS = ("README.md", "docs/python.md", "docs/campaigns.md", "docs/gym.md")
BLOCK = re.compile(r"```python\n(.*?)```", re.S)
CAMPAIGN = Path("campaigns") / "default_dispersed.yaml"
SHORTENED = {"cases: 40\n": "cases: 8\nset:\n  world.duration: 20.0\n"}
"""Text replaced in the copy of the campaign file: fewer and shorter cases."""

GUARD_MESSAGE = "run_campaign was called while Python was importing the main module"


def examples() -> list:
    """Every Python block of the documents, one test parameter each."""
    return [
        pytest.param(code, id=f"{document}-{number}")
        for document in DOCS
        for number, code in enumerate(BLOCK.findall((REPO / document).read_text("utf-8")), 1)
    ]


@pytest.fixture(scope="module")
def scenarios(tmp_path_factory) -> Path:
    """A copy of the repository's scenarios with the campaign shortened."""
    copy = tmp_path_factory.mktemp("docs") / "scenarios"
    shutil.copytree(REPO / "scenarios", copy)
    text = (copy / CAMPAIGN).read_text("utf-8")
    for old, new in SHORTENED.items():
        assert text.count(old) == 1, f"{CAMPAIGN} no longer holds {old!r}"
        text = text.replace(old, new)
    (copy / CAMPAIGN).write_text(text, "utf-8")
    return copy


def run_script(folder: Path, scenarios: Path, code: str) -> subprocess.CompletedProcess:
    """Save ``code`` as ``folder/example.py`` and run it there with this Python."""
    (folder / "scenarios").symlink_to(scenarios)
    (folder / "example.py").write_text(code, "utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run(
        [sys.executable, "example.py"],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_every_document_has_its_python_examples():
    counts = {
        document: len(BLOCK.findall((REPO / document).read_text("utf-8"))) for document in DOCS
    }
    assert counts == {
        "README.md": 1,
        "docs/python.md": 3,
        "docs/campaigns.md": 1,
        "docs/gym.md": 3,
    }


def test_the_gym_pages_command_example_prints_what_the_page_says(scenarios, tmp_path):
    text = (REPO / "docs" / "gym.md").read_text("utf-8")
    done = run_script(tmp_path, scenarios, BLOCK.findall(text)[-1])
    assert done.returncode == 0, done.stderr
    assert f"prints `{done.stdout.strip()}`" in text


@pytest.mark.parametrize("code", examples())
def test_a_documented_example_runs_as_a_saved_script(code, scenarios, tmp_path):
    done = run_script(tmp_path, scenarios, code)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr


def test_a_script_that_runs_a_campaign_without_its_guard_gets_a_dcsim_error(scenarios, tmp_path):
    code = textwrap.dedent(
        """\
        from dcsim.api import run_campaign

        print("imported")
        run_campaign("scenarios/campaigns/default_dispersed.yaml", "runs/unguarded", cases=2)
        """
    )
    done = run_script(tmp_path, scenarios, code)
    assert done.returncode == 1
    assert f"dcsim.campaign.engine.ClusterError: {GUARD_MESSAGE}" in done.stderr
    assert 'under `if __name__ == "__main__":`' in done.stderr
    assert "ClusterError: cannot start a local Dask cluster (" in done.stderr
    assert not (tmp_path / "runs" / "unguarded").exists()


def test_a_campaign_fed_on_standard_input_is_refused_with_what_to_do(scenarios, tmp_path):
    (tmp_path / "scenarios").symlink_to(scenarios)
    code = (
        "from dcsim.api import DcsimError, run_campaign\n"
        'if __name__ == "__main__":\n'
        "    try:\n"
        '        run_campaign("scenarios/campaigns/default_dispersed.yaml", "runs/piped", cases=2)\n'
        "    except DcsimError as error:\n"
        "        print(error)\n"
    )
    done = subprocess.run(
        [sys.executable], input=code, cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("a local Dask cluster cannot start from a main module read")
    assert "save the code as a script" in done.stdout
