"""dcsim: a headless simulator framework for space debris collectors and free-flying robots.

The public API for plugin authors and scenario scripts lives in :mod:`dcsim.api`.
"""

__version__ = "0.1.0"
