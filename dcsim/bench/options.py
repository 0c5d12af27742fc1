"""Option values of the ``dcsim bench`` commands: comma-separated lists and
``NAME:key=value`` plugin specs, read with errors that say what to change."""

from __future__ import annotations

from typing import Any

import yaml

from dcsim.errors import DcsimError


def comma_words(text: str, option: str) -> list[str]:
    """The comma-separated words of an option's value.

    Parameters
    ----------
    text : str
        The value, e.g. ``line,grid``.
    option : str
        The option's name, for the error (``--cross-sections``).

    Raises
    ------
    DcsimError
        When it names nothing.
    """
    words = [word.strip() for word in text.split(",") if word.strip()]
    if not words:
        raise DcsimError(f"{option}: name at least one")
    return words


def comma_numbers(text: str, option: str) -> list[float]:
    """The comma-separated numbers of an option's value (``2,6``), in the option's unit.

    Raises
    ------
    DcsimError
        When it names nothing or a word is no number.
    """
    try:
        return [float(word) for word in comma_words(text, option)]
    except ValueError:
        raise DcsimError(f"{option}: expected numbers like 2,6, got {text!r}") from None


def plugin_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """The name and parameters of ``NAME[:key=value...]``, each value read as YAML.

    Returns
    -------
    name : str
        ``NAME``.
    params : dict
        The parameters given (``{"ants": 60}`` for ``ant-colony:ants=60``), unchecked.

    Raises
    ------
    DcsimError
        When an assignment is not ``key=value``.
    """
    name, *assignments = spec.split(":")
    params = {}
    for assignment in assignments:
        key, equals, value = assignment.partition("=")
        if not equals or not key:
            raise DcsimError(f"'{assignment}' in '{spec}' is not key=value")
        params[key] = yaml.safe_load(value)
    return name, params
