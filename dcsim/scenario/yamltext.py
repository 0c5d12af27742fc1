"""Reading YAML text that may be anything: binary, huge, deeply nested or self-referring.

Scenario files and ``--set`` values come from users and may be broken in ways that
would otherwise crash or hang the parser: binary content, text that is not UTF-8,
nesting deep enough to exhaust the stack, aliases that refer to themselves or expand
into billions of values, integers too long to convert. Every such input raises a
:class:`YamlInputError` saying what is wrong and where.
"""

from __future__ import annotations

import sys
from typing import Any

import yaml

MAX_FILE_BYTES = 1_000_000
"""Largest scenario file read, in bytes (a field of 10,000 objects fits in 1 MB)."""

MAX_DEPTH = 50
"""Deepest nesting of lists and mappings, aliases expanded (scenarios need under 10)."""

MAX_VALUES = 1_000_000
"""Most values (scalars, lists and mappings) in one document, aliases expanded."""


class YamlInputError(ValueError):
    """Text that is not a YAML document dcsim can read.

    Parameters
    ----------
    message : str
        What is wrong and what to change.
    line, column : int or None
        1-based position of the problem in the text, when known.
    """

    def __init__(self, message: str, line: int | None = None, column: int | None = None) -> None:
        super().__init__(message)
        self.line = line
        self.column = column


def decode(raw: bytes) -> str:
    """The UTF-8 text of a file's bytes.

    Raises
    ------
    YamlInputError
        If the bytes hold a NUL byte (binary data, UTF-16) or are not valid UTF-8.
    """
    if b"\0" in raw:
        line, column = _line_column(raw[: raw.index(b"\0")].decode("utf-8", "replace"))
        raise YamlInputError(
            "the file holds NUL bytes: it is binary data (or UTF-16 text), "
            "not a YAML scenario; save it as UTF-8 text",
            line,
            column,
        )
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line, column = _line_column(raw[: exc.start].decode("utf-8", "replace"))
        raise YamlInputError(
            f"the file is not UTF-8 text (byte 0x{raw[exc.start]:02x}); save it as UTF-8",
            line,
            column,
        ) from None


def compose(text: str) -> tuple[yaml.Node | None, Any]:
    """Parse YAML ``text`` with the safe loader into its node graph and its data.

    Returns
    -------
    node : yaml.Node or None
        The document's root node (None for a stream without a document).
    data : Any
        The constructed data (None without a document).

    Raises
    ------
    YamlInputError
        On a syntax error, an unprintable character, or a document beyond the limits
        :data:`MAX_DEPTH` and :data:`MAX_VALUES`.
    """
    loader: _LimitedLoader | None = None
    try:
        loader = _LimitedLoader(text)
        node = loader.get_single_node()
        return node, (loader.construct_document(node) if node is not None else None)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (None, None)
        prefix = "" if isinstance(exc, _LimitError) else "not valid YAML: "
        raise YamlInputError(f"{prefix}{exc.problem or exc}", line, column) from None
    except yaml.reader.ReaderError as exc:
        line, column = _line_column(text[: exc.position])
        raise YamlInputError(
            f"not valid YAML: character #x{exc.character:04x} is not allowed in YAML text",
            line,
            column,
        ) from None
    finally:
        if loader is not None:
            loader.dispose()


def _line_column(before: str) -> tuple[int, int]:
    """1-based line and column of the character that follows the text ``before``."""
    return before.count("\n") + 1, len(before) - before.rfind("\n")


class _LimitError(yaml.MarkedYAMLError):
    """A document beyond dcsim's limits (reported without "not valid YAML")."""


class _LimitedLoader(yaml.SafeLoader):
    """The safe loader, keeping count of nesting and values with aliases expanded.

    Each anchored node remembers how many values and how many levels it spans, so an
    alias costs what its expansion would, and an alias inside its own anchor (recursive
    data) is refused.
    """

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self._depth = 0
        self._deepest = 0
        self._values = 0
        self._extents: dict[str, tuple[int, int]] = {}

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            extent = self._extents.get(event.anchor)
            if extent is None and event.anchor in self.anchors:
                raise _LimitError(
                    None,
                    None,
                    f"alias *{event.anchor} refers to a value that contains it; "
                    "recursive data is not allowed",
                    event.start_mark,
                )
            if extent is not None:
                self._grow(extent[0], self._depth + extent[1], event.start_mark)
            return super().compose_node(parent, index)
        self._depth += 1
        outer_deepest, self._deepest = self._deepest, self._depth
        before = self._values
        self._grow(1, self._depth, event.start_mark)
        node = super().compose_node(parent, index)
        if event.anchor is not None:
            self._extents[event.anchor] = (self._values - before, self._deepest - self._depth + 1)
        self._deepest = max(outer_deepest, self._deepest)
        self._depth -= 1
        return node

    def _grow(self, values: int, depth: int, mark: yaml.Mark) -> None:
        self._values += values
        self._deepest = max(self._deepest, depth)
        if depth > MAX_DEPTH:
            raise _LimitError(
                None,
                None,
                f"lists and mappings nest more than {MAX_DEPTH} levels deep (aliases expanded); "
                "a scenario needs far fewer",
                mark,
            )
        if self._values > MAX_VALUES:
            raise _LimitError(
                None,
                None,
                f"the document holds more than {MAX_VALUES:,} values (aliases expanded); "
                "a scenario needs far fewer",
                mark,
            )

    def construct_yaml_int(self, node: yaml.ScalarNode) -> int:
        try:
            return super().construct_yaml_int(node)
        except ValueError:
            raise _LimitError(
                None,
                None,
                f"an integer of more than {sys.get_int_max_str_digits()} digits; "
                "write a smaller number",
                node.start_mark,
            ) from None


_LimitedLoader.add_constructor("tag:yaml.org,2002:int", _LimitedLoader.construct_yaml_int)
