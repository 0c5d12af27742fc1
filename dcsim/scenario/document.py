"""Raw scenario documents: YAML data that remembers where every key came from.

A :class:`ScenarioDocument` holds the parsed YAML, the line and column of every key,
and the ``--set`` overrides applied on top, so that a validation error can name the
file, the key path (``targets[3].motion.r``) and the line, or the override it came from.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from dcsim.errors import Problem, ScenarioError
from dcsim.scenario.yamltext import (
    MAX_DEPTH,
    MAX_FILE_BYTES,
    YamlInputError,
    compose,
    decode,
)

KeyPath = tuple[str | int, ...]
_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_-]*)|\[(\d+)\]")
APPEND = "[+]"
"""Ending of an override's key path that appends its value to the list there."""


def format_key_path(path: KeyPath) -> str:
    """Format a key path: ``("targets", 3, "motion", "r")`` → ``targets[3].motion.r``."""
    text = ""
    for item in path:
        text += f"[{item}]" if isinstance(item, int) else (f".{item}" if text else str(item))
    return text


def parse_key_path(text: str) -> KeyPath:
    """Parse ``targets[3].motion.r`` into ``("targets", 3, "motion", "r")``.

    Raises
    ------
    ValueError
        If ``text`` is not a dotted key path with optional ``[index]`` parts.
    """
    path: list[str | int] = []
    pos = 0
    while pos < len(text):
        if path and text[pos] == "." and not text.startswith("[", pos + 1):
            pos += 1
        match = _TOKEN.match(text, pos)
        if match is None or (not path and match.group(2)):
            raise ValueError(f"'{text}' is not a key path like targets[0].motion.r")
        path.append(match.group(1) if match.group(1) else int(match.group(2)))
        pos = match.end()
    if not path:
        raise ValueError("empty key path")
    return tuple(path)


def read_document_text(path: str | Path) -> str:
    """The text of the YAML file at ``path``.

    Raises
    ------
    ScenarioError
        If the file cannot be read, is larger than
        :data:`~dcsim.scenario.yamltext.MAX_FILE_BYTES`, or is not UTF-8 text.
    """
    try:
        with Path(path).open("rb") as file:
            raw = file.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ScenarioError(
            str(path), [Problem("", f"cannot read the file: {exc.strerror}")]
        ) from None
    if len(raw) > MAX_FILE_BYTES:
        message = f"the file is larger than {MAX_FILE_BYTES:,} bytes; a scenario needs far less"
        raise ScenarioError(str(path), [Problem("", message)])
    try:
        return decode(raw)
    except YamlInputError as exc:
        raise ScenarioError(str(path), [Problem("", str(exc), exc.line, exc.column)]) from None


@dataclass
class ScenarioDocument:
    """A scenario's raw data with source positions.

    Attributes
    ----------
    filename : str
        Name of the file as the user gave it.
    data : dict
        The parsed YAML mapping, overrides applied.
    marks : dict
        Key path → (line, column), 1-based, of each key in the file.
    overrides : dict
        Key path → the ``--set`` text that set it.
    """

    filename: str
    data: dict[str, Any]
    marks: dict[KeyPath, tuple[int, int]] = field(default_factory=dict)
    overrides: dict[KeyPath, str] = field(default_factory=dict)

    @classmethod
    def from_text(cls, text: str, filename: str) -> ScenarioDocument:
        """Parse YAML ``text`` (safe loader) into a document.

        Raises
        ------
        ScenarioError
            On a YAML syntax error, a document beyond the limits of
            :mod:`dcsim.scenario.yamltext`, a duplicated key, an empty text, or a top
            level that is not a mapping.
        """
        try:
            node, data = compose(text)
        except YamlInputError as exc:
            raise ScenarioError(filename, [Problem("", str(exc), exc.line, exc.column)]) from None
        if node is None:
            message = "the file is empty; a scenario is a mapping of sections"
            raise ScenarioError(filename, [Problem("", message, 1, 1)])
        if not isinstance(data, dict):
            raise ScenarioError(
                filename, [Problem("", "the top level must be a mapping of sections", 1, 1)]
            )
        doc = cls(filename, data)
        duplicates: list[Problem] = []
        doc._collect_marks(node, (), duplicates)
        if duplicates:
            raise ScenarioError(filename, duplicates)
        return doc

    @classmethod
    def from_file(cls, path: str | Path) -> ScenarioDocument:
        """Read and parse the scenario file at ``path``.

        Raises
        ------
        ScenarioError
            If the file cannot be read (see :func:`read_document_text`) or parsed.
        """
        return cls.from_text(read_document_text(path), str(path))

    def _collect_marks(self, node: yaml.Node, path: KeyPath, duplicates: list[Problem]) -> None:
        if isinstance(node, yaml.MappingNode):
            seen: set[Any] = set()
            for key_node, value_node in node.value:
                key = key_node.value
                child = path + (key,)
                line, column = key_node.start_mark.line + 1, key_node.start_mark.column + 1
                if key in seen:
                    duplicates.append(
                        Problem(format_key_path(child), "key given twice", line, column)
                    )
                seen.add(key)
                self.marks[child] = (line, column)
                self._collect_marks(value_node, child, duplicates)
        elif isinstance(node, yaml.SequenceNode):
            for index, item in enumerate(node.value):
                child = path + (index,)
                self.marks[child] = (item.start_mark.line + 1, item.start_mark.column + 1)
                self._collect_marks(item, child, duplicates)

    def apply_override(self, assignment: str) -> None:
        """Apply one ``key.path=value`` override; the value is parsed as YAML.

        A key path ending in ``[+]`` (``mission.targets[+]={...}``) appends the value to the list
        there, which is created if the document has none.

        Raises
        ------
        ScenarioError
            If the assignment is malformed or its path cannot exist in the document.
        """
        source = f"--set {assignment}"
        key_text, sep, value_text = assignment.partition("=")
        key_text = key_text.strip()
        append = key_text.endswith(APPEND)
        try:
            if not sep:
                raise ValueError("expected key.path=value")
            if APPEND in key_text and not append:
                raise ValueError(
                    f"{APPEND} must end the key path: give the whole item as the value"
                )
            path = parse_key_path(key_text.removesuffix(APPEND))
            if len(path) + append > MAX_DEPTH:
                raise ValueError(f"the key path is more than {MAX_DEPTH} keys long")
            value = compose(value_text)[1] if value_text.strip() else None
        except ValueError as exc:
            raise ScenarioError(self.filename, [Problem("", str(exc), source=source)]) from None
        container: Any = self.data
        steps = path if append else path[:-1]
        following = (*path[1:], 0) if append else path[1:]
        for depth, (key, nxt) in enumerate(zip(steps, following, strict=True)):
            container = self._descend(container, key, path[: depth + 1], nxt, source)
        if append:
            path = self._append(container, path, value, source)
        else:
            self._assign(container, path, value, source)
        self.overrides[path] = source

    def _descend(
        self, container: Any, key: str | int, where: KeyPath, nxt: str | int, source: str
    ) -> Any:
        if isinstance(key, int):
            self._check_index(container, key, where, source)
            return container[key]
        if not isinstance(container, dict):
            self._fail(where[:-1], "is a list: select an item with [index] first", source)
        if not isinstance(container.get(key), dict | list):
            container[key] = [] if isinstance(nxt, int) else {}
        return container[key]

    def _assign(self, container: Any, path: KeyPath, value: Any, source: str) -> None:
        key = path[-1]
        if isinstance(key, int):
            self._check_index(container, key, path, source)
        elif not isinstance(container, dict):
            self._fail(path[:-1], "is a list: select an item with [index] first", source)
        container[key] = value

    def _append(self, container: Any, path: KeyPath, value: Any, source: str) -> KeyPath:
        """Append ``value`` to the list at ``path``; the key path of the new item."""
        if not isinstance(container, list):
            self._fail(path, "is not a list: [+] appends to a list", source)
        container.append(value)
        return (*path, len(container) - 1)

    def _check_index(self, container: Any, index: int, where: KeyPath, source: str) -> None:
        if not isinstance(container, list):
            self._fail(where, "is not a list here", source)
        if index >= len(container):
            self._fail(
                where,
                f"index {index} is out of range (the list has {len(container)} items; "
                f"{APPEND} appends)",
                source,
            )

    def _fail(self, path: KeyPath, message: str, source: str) -> None:
        raise ScenarioError(self.filename, [Problem(format_key_path(path), message, source=source)])

    def problem(self, path: KeyPath, message: str) -> Problem:
        """A :class:`Problem` at ``path``, located at the nearest known key or override."""
        source = next((src for p, src in self.overrides.items() if path[: len(p)] == p), None)
        for end in range(len(path), -1, -1):
            mark = self.marks.get(path[:end])
            if mark is not None:
                return Problem(format_key_path(path), message, *mark, source=source)
        return Problem(format_key_path(path), message, source=source)
