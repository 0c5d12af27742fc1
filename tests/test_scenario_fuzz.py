"""Broken scenario files never crash `dcsim validate`: mutations of the shipped scenarios.

Each example takes a shipped scenario, breaks it (values of the wrong type, NaN and
infinities, extreme numbers, deleted and unknown keys, sections replaced by scalars or
lists, or its text cut or sprinkled with bytes) and runs `dcsim validate` on it
in-process. The command must accept the file or reject it with `error:` lines and exit
status 2, and never raise anything else.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
import yaml
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dcsim.cli.main import cli
from tests.conftest import REPO

SHIPPED = sorted(
    [*(REPO / "scenarios").glob("*.yaml"), *(REPO / "dcsim" / "scenarios").glob("*.yaml")]
)
TEXTS = {f"{path.parent.name}/{path.name}": path.read_text() for path in SHIPPED}

DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml's is faster

KeyPath = tuple[str | int, ...]

JUNK = st.one_of(
    st.sampled_from(
        [math.nan, math.inf, -math.inf, 1e300, -1e300, 0, 0.0, -1, 1e-300, 5e-324, 10**30]
    ),
    st.sampled_from([2**63, -(2**63), 2**31, 10**4000, True, None, "", "x", "1e300", ".inf"]),
    st.integers(),
    st.floats(),
    st.text(max_size=20),
    st.lists(st.floats(), max_size=5),
    st.dictionaries(st.text(max_size=8), st.integers(), max_size=3),
    st.builds(lambda: [[[[[[[[[[1]]]]]]]]]]),
    st.builds(lambda: list(range(1000))),
)


def paths(data: Any, prefix: KeyPath = ()) -> list[KeyPath]:
    """Every key path in ``data``, containers before their contents."""
    found: list[KeyPath] = [prefix] if prefix else []
    if isinstance(data, dict):
        for key, value in data.items():
            found += paths(value, (*prefix, key))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            found += paths(value, (*prefix, index))
    return found


def parent(data: Any, path: KeyPath) -> Any:
    for key in path[:-1]:
        data = data[key]
    return data


def mutate(data: dict, draw: st.DrawFn) -> None:
    """Apply one random mutation to ``data`` in place."""
    path = draw(st.sampled_from(paths(data)))
    container, key = parent(data, path), path[-1]
    action = draw(st.sampled_from(["replace", "replace", "delete", "unknown", "grow"]))
    if action == "replace":
        container[key] = draw(JUNK)
    elif action == "delete":
        del container[key]
    elif action == "unknown" and isinstance(container[key], dict):
        container[key][draw(st.sampled_from(["colour", "1", "", "world", "nan"]))] = draw(JUNK)
    elif action == "grow" and isinstance(container[key], list) and container[key]:
        container[key] = container[key] * 2


@st.composite
def broken_texts(draw: st.DrawFn) -> bytes:
    """The text of a shipped scenario with a few mutations, as bytes."""
    text = TEXTS[draw(st.sampled_from(sorted(TEXTS)))]
    if draw(st.integers(0, 9)) == 0:  # damage the text itself
        raw = text.encode()
        cut = draw(st.integers(0, len(raw)))
        return raw[:cut] + draw(st.binary(max_size=8)) + raw[cut + draw(st.integers(0, 40)) :]
    data = yaml.safe_load(text)
    for _ in range(draw(st.integers(1, 4))):
        if data:
            mutate(data, draw)
    return yaml.dump(data, Dumper=DUMPER, sort_keys=False).encode()


@pytest.fixture(scope="module")
def runner() -> CliRunner:
    return CliRunner()


@settings(
    max_examples=150,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(text=broken_texts())
def test_validate_accepts_or_reports_any_mutated_scenario(text, runner, tmp_path):
    path = tmp_path / "mutated.yaml"
    path.write_bytes(text)
    result = runner.invoke(cli, ["validate", str(path)])
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"{result.exception!r} on:\n{text[:2000]!r}"
    )
    assert result.exit_code in (0, 2), result.output
    assert "Traceback" not in result.output
    if result.exit_code == 2:
        assert f"error: {path}: invalid scenario" in result.output
    else:
        assert result.output == f"ok {path}\n"
