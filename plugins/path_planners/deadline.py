"""A planning deadline: work that takes long checks it and stops with :class:`OutOfTime`."""

from __future__ import annotations

import time


class OutOfTime(Exception):
    """The deadline passed before the work was done; the message says how far it got."""


def check(deadline: float, progress: str) -> None:
    """Raise :class:`OutOfTime` saying ``progress`` if ``time.perf_counter()`` is past
    ``deadline``."""
    if time.perf_counter() > deadline:
        raise OutOfTime(progress)
