"""Generated blocks in the documentation, kept in sync with the code by tests.

A generated block sits between a begin and an end marker line in a Markdown file;
:func:`update_block` rewrites it. ``make docs`` regenerates every block.
"""

from __future__ import annotations

from pathlib import Path


def replace_block(text: str, begin: str, end: str, content: str) -> str:
    """``text`` with everything between the ``begin`` and ``end`` markers replaced."""
    head, found, rest = text.partition(begin)
    if not found or end not in rest:
        raise ValueError(f"markers {begin!r} ... {end!r} not found")
    _, _, tail = rest.partition(end)
    return f"{head}{begin}\n{content}{end}{tail}"


def block(text: str, begin: str, end: str) -> str:
    """The content of the generated block of ``text`` (without its markers)."""
    return text.split(begin, 1)[1].split(end, 1)[0].removeprefix("\n")


def update_block(path: Path, begin: str, end: str, content: str) -> bool:
    """Rewrite the generated block of the file at ``path``; return True if it changed."""
    text = path.read_text(encoding="utf-8")
    new = replace_block(text, begin, end, content)
    path.write_text(new, encoding="utf-8")
    return new != text
