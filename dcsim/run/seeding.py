"""Random-number plumbing: one scenario seed, one independent generator per component.

Each component (the world, each plugin role) gets a generator from a
:class:`numpy.random.SeedSequence` keyed by the scenario seed and the component's
name. Keying by name rather than by order means adding a component never changes the
random numbers another one draws.
"""

from __future__ import annotations

import zlib

import numpy as np


def component_seed(seed: int, component: str) -> np.random.SeedSequence:
    """The seed sequence of ``component`` (e.g. ``"localiser"``) for scenario ``seed``."""
    return np.random.SeedSequence(entropy=seed, spawn_key=(zlib.crc32(component.encode()),))


def component_rng(seed: int, component: str) -> np.random.Generator:
    """A fresh generator for ``component`` under scenario ``seed``.

    Parameters
    ----------
    seed : int
        The scenario seed (non-negative).
    component : str
        The component's name, e.g. ``"world"`` or ``"controller"``.

    Returns
    -------
    numpy.random.Generator
        The same stream for the same seed and name, independent across names.
    """
    return np.random.default_rng(component_seed(seed, component))
