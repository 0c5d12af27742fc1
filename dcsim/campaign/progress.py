"""A campaign's progress on a terminal: cases done, failed and running, rate and ETA."""

from __future__ import annotations

import sys
import time
from datetime import timedelta
from typing import TextIO

LINES_WITHOUT_TERMINAL = 20
"""Progress lines printed over a campaign when the output is not a terminal."""


class CampaignProgress:
    """Reports the cases of one campaign run as they end.

    On a terminal one line is rewritten in place; elsewhere (a log file, CI) a line is
    printed every twentieth of the cases.

    Parameters
    ----------
    total : int
        Cases to run now.
    stream : text stream, optional
        Where to write (standard error by default).
    """

    def __init__(self, total: int, stream: TextIO | None = None) -> None:
        self.total = total
        self.stream = stream if stream is not None else sys.stderr
        self.done = 0
        self.failed = 0
        self._started = time.perf_counter()
        self._every = max(1, total // LINES_WITHOUT_TERMINAL)
        self._live = self.stream.isatty()

    def case_ended(self, failed: bool, running: int) -> None:
        """Count one ended case; ``running`` cases are still on the workers."""
        self.done += 1
        self.failed += failed
        if self._live:
            self.stream.write("\r" + self.line(running) + "\x1b[K")
            self.stream.flush()
        elif self.done % self._every == 0 or self.done == self.total:
            self.stream.write(self.line(running) + "\n")
            self.stream.flush()

    def close(self) -> None:
        """End the rewritten line."""
        if self._live and self.done:
            self.stream.write("\n")
            self.stream.flush()

    def line(self, running: int) -> str:
        """``cases 17/40 (1 failed), 2 running, 0.81 cases/s, ETA 0:00:28``."""
        elapsed = time.perf_counter() - self._started
        rate = self.done / elapsed if elapsed > 0 else 0.0
        left = self.total - self.done
        eta = str(timedelta(seconds=round(left / rate))) if rate > 0 else "unknown"
        return (
            f"cases {self.done}/{self.total} ({self.failed} failed), {running} running, "
            f"{rate:.2f} cases/s, ETA {eta}"
        )
