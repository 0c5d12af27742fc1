"""A planning deadline: work that takes long checks it and stops with :class:`OutOfTime`.

Deadlines are ``time.monotonic()`` seconds, the clock of :meth:`PathProblem.due`.
"""

from __future__ import annotations

import time


class OutOfTime(Exception):
    """The deadline passed before the work was done; the message says how far it got."""


def check(deadline: float, progress: str) -> None:
    """Raise :class:`OutOfTime` saying ``progress`` if ``time.monotonic()`` is past
    ``deadline``."""
    if time.monotonic() > deadline:
        raise OutOfTime(progress)
