"""brahe, a third-party orbit propagator, as a peer of :mod:`dcsim.bench.orbit_reference`.

brahe (``pip install 'dcsim[orbit-reference]'``, or ``pip install brahe``) integrates
orbits with its own force models and integrators. Flown with its point-mass gravity, or
with its closed-form Earth zonal gravity cut at J2, it must end where the reference's
two-body and J2 propagations end. brahe bakes its Earth constants into the zonal model,
so the reference is run with :data:`BRAHE_CONSTANTS` for the comparison.

brahe evaluates zonal gravity in an Earth-fixed frame; with its ``EARTH_ROTATION_ONLY``
transform that frame differs from ECI by a rotation about z, which leaves an axially
symmetric field unchanged, so its J2 is the reference's J2 in ECI. That transform needs
UT1 − UTC: :func:`propagate_brahe` installs brahe's static provider of zero Earth
orientation parameters (global to brahe in this process), so nothing is downloaded.
"""

from __future__ import annotations

import importlib.util
from typing import Any

import numpy as np

from dcsim.bench.orbit_reference import ORBIT_MODELS, Array, OrbitModel

BRAHE_CONSTANTS = {"mu": 3.986004415e14, "radius": 6378136.3, "j2": 1.0826261738522227e-3}
"""brahe's Earth gravity constants (its ``GM_EARTH``, ``R_EARTH``, ``J2_EARTH``, those of
EGM2008): μ m³/s², reference radius m, J2; keyword arguments of the reference's
propagators."""


def brahe_missing() -> str | None:
    """Why brahe cannot be used here, or None when it is importable."""
    if importlib.util.find_spec("brahe") is None:
        return "brahe is not installed (pip install 'dcsim[orbit-reference]', or pip install brahe)"
    return None


def _force_model(brahe: Any, model: OrbitModel) -> Any:
    if model not in ORBIT_MODELS:
        raise ValueError(f"unknown orbit model {model!r}; use one of {', '.join(ORBIT_MODELS)}")
    if model == "two-body":
        return brahe.ForceModelConfig.two_body()
    return brahe.ForceModelConfig(
        gravity=brahe.GravityConfiguration.earth_zonal(brahe.ZonalHarmonicsDegree.J2),
        frame_transform=brahe.FrameTransformationModel.EARTH_ROTATION_ONLY,
    )


def propagate_brahe(
    position: Array,
    velocity: Array,
    duration: float,
    model: OrbitModel = "two-body",
    tolerance: float = 1e-12,
) -> tuple[Array, Array]:
    """Propagate bodies in ECI with brahe's numerical orbit propagator.

    Parameters
    ----------
    position, velocity : ndarray (n, 3)
        ECI positions (m) and velocities (m/s) at t = 0.
    duration : float
        Propagation time, s.
    model : {"two-body", "j2"}
        brahe's point-mass gravity, or its Earth zonal gravity to J2.
    tolerance : float
        Absolute (m, m/s) and relative tolerance of brahe's RKN12(10) integrator.

    Returns
    -------
    position, velocity : ndarray (n, 3)
        ECI positions (m) and velocities (m/s) after ``duration``.
    """
    # brahe's own type stubs mistype its enum members and Epoch arithmetic
    brahe: Any = importlib.import_module("brahe")
    brahe.set_global_eop_provider_from_static_provider(brahe.StaticEOPProvider.from_zero())
    epoch = brahe.Epoch.from_datetime(2026, 1, 1, 0, 0, 0.0, 0.0, brahe.TimeSystem.UTC)
    config = (
        brahe.NumericalPropagationConfig.high_precision()
        .with_abs_tol(tolerance)
        .with_rel_tol(tolerance)
    )
    ends = []
    for start in np.concatenate([position, velocity], axis=1):
        propagator = brahe.NumericalOrbitPropagator(
            epoch, start, config, _force_model(brahe, model), None
        )
        propagator.propagate_to(epoch + duration)
        ends.append(np.asarray(propagator.current_state(), float))
    states = np.array(ends)
    return states[:, :3], states[:, 3:]
