"""When a sensor model reads: the sampling clock and the ``rate`` parameter they share.

A sensor is asked once per control tick. One with a rate reads at its sampling
instants ``k / rate`` (``k = 0, 1, …``): on the first tick at or after each instant it
gives a reading, and nothing on the ticks between. A rate at or above the control rate
reads every tick, as does no rate (null).
"""

from __future__ import annotations

import math
from typing import Any

from dcsim.api import quantity

_SLACK = 1e-6
"""Fraction of a sampling interval by which a tick may fall short of an instant and still
read at it (control ticks are sums of physics steps, not exact multiples)."""


def rate_field(default: float | None) -> Any:
    """The ``rate`` parameter of a sensor model: readings per second (Hz), or null to
    read every control tick, with ``default`` its default."""
    return quantity(
        default,
        unit="Hz",
        gt=0,
        description="Readings per second, at the first control tick on or after each "
        "sampling instant k/rate; null reads every tick.",
    )


class SampleClock:
    """Says on which control ticks a sensor reads.

    Parameters
    ----------
    rate : float or None
        Readings per second, Hz; None for every tick.
    """

    def __init__(self, rate: float | None) -> None:
        self.rate = rate
        self._next = 0.0

    def due(self, time: float) -> bool:
        """Whether the sensor reads at ``time`` (s); if so, the next instant is set."""
        rate = self.rate
        if rate is None:
            return True
        if time * rate < self._next * rate - _SLACK:
            return False
        self._next = (math.floor(time * rate + _SLACK) + 1) / rate
        return True
