"""The docs' text: links to the cited sources resolve, and no text speaks of one machine."""

from __future__ import annotations

import re

import pytest

from tests.conftest import REPO

PAGES = sorted((REPO / "docs").glob("*.md")) + [REPO / "README.md"]
REFERENCES = REPO / "docs" / "references.md"
SOURCE_TEXT = [
    *PAGES,
    *sorted((REPO / "dcsim").rglob("*.py")),
    *sorted((REPO / "plugins").rglob("*.py")),
    *sorted((REPO / "scenarios").rglob("*.yaml")),
    *sorted((REPO / "dcsim" / "scenarios").rglob("*.yaml")),
]


def slug(heading: str) -> str:
    """The anchor GitHub gives a Markdown heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def test_every_link_to_the_references_names_an_entry_and_every_entry_is_linked():
    entries = {
        slug(line[3:]) for line in REFERENCES.read_text().splitlines() if line.startswith("## ")
    }
    assert len(entries) == 5
    linked = set()
    for page in PAGES:
        for anchor in re.findall(r"references\.md#([\w-]+)", page.read_text()):
            assert anchor in entries, f"{page.name}: no entry #{anchor} in references.md"
            linked.add(anchor)
    assert linked == entries


@pytest.mark.parametrize(
    "pattern",
    [
        r"/work/",
        r"/tmp/fresh",
        r"/home/",
        r"\b[Ii]ssue \d+",
        r"\b(source|thesis|sources) 00\d",
        r"\|\s*00[0-5]\b",  # a table's source column
    ],
)
def test_no_text_names_a_machine_s_folders_or_the_work_s_own_tickets(pattern):
    """Nor the sources by an index number of their own: docs/references.md names them."""
    found = [
        f"{path.relative_to(REPO)}:{number}"
        for path in SOURCE_TEXT
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if re.search(pattern, line)
    ]
    assert found == []
