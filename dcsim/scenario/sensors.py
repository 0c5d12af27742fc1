"""The sensing profiles: which model, with which numbers, each of the robot's sensors has.

A scenario's ``sensors:`` section names a profile and, for any sensor, a model of its
own (:class:`~dcsim.scenario.model.SensorsSection`); :func:`sensor_choices` resolves the
two into one model choice per sensor, or None where the sensor reports the truth.

The realistic profile's numbers and their sources:

- star tracker: 6 arcsec (1σ) about each cross-boresight axis and 40 arcsec about the
  boresight (body z), 5 Hz: Blue Canyon Technologies' Nano Star Tracker datasheet; a
  mounting misalignment of 10 arcsec about each axis (an assumed calibration residual);
- gyros: angle random walk 0.15 °/√h and bias instability 0.5 °/h (Safran Sensonor
  STIM300 datasheet), the instability taken as a rate random walk that reaches it in
  1000 s (0.95 °/h/√h), and an initial bias of 0.5 °/h (1σ per axis); read every tick;
- object sensor (a lidar): 5 cm range noise, 0.2° bearing noise, 95 % detection
  probability, 10 Hz, seeing all round (several heads) but not shapes;
- beacon ranges: the scenario's own ``beacons`` noise, with no bias, outliers or
  dropouts (those are for benches and users to set).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from dcsim.errors import PluginError
from dcsim.registry.interfaces import SENSOR_SLOTS, SensorModel
from dcsim.scenario.model import SensorChoice, SensorsSection

if TYPE_CHECKING:
    from dcsim.registry.discovery import PluginRegistry

IDEAL: dict[str, SensorChoice | None] = {
    "beacon_ranges": SensorChoice(model="beacon-range"),
    "star_tracker": None,
    "gyros": None,
    "objects": None,
}
"""The ideal profile: white-noise beacon ranges; attitude, rate and objects exact."""

REALISTIC: dict[str, SensorChoice | None] = {
    "beacon_ranges": SensorChoice(model="beacon-range"),
    "star_tracker": SensorChoice(
        model="star-tracker",
        params={"noise": [6.0, 6.0, 40.0], "rate": 5.0, "misalignment": [10.0, 10.0, 10.0]},
    ),
    "gyros": SensorChoice(
        model="gyros",
        params={"angle_random_walk": 0.15, "rate_random_walk": 0.95, "initial_bias": 0.5},
    ),
    "objects": SensorChoice(
        model="object-sensor",
        params={
            "range_noise": 0.05,
            "bearing_noise": 0.2,
            "detection_probability": 0.95,
            "rate": 10.0,
            "field_of_view": 360.0,
            "sees_shapes": False,
        },
    ),
}
"""The realistic profile: a small satellite's star tracker and gyros and a lidar (the
module's docstring names the sources)."""

PROFILES: dict[str, dict[str, SensorChoice | None]] = {"ideal": IDEAL, "realistic": REALISTIC}
"""Every sensing profile by name."""


def sensor_choices(section: SensorsSection) -> dict[str, SensorChoice | None]:
    """The model of each sensor (:data:`~dcsim.registry.interfaces.SENSOR_SLOTS`): the
    one the section gives, else its profile's; None where the sensor reports the truth.

    A sensor given with its profile's model keeps the profile's parameters it does not
    set (``sensors.gyros: {model: gyros, params: {initial_bias: 0}}`` under
    ``realistic`` changes that one number).
    """
    profile = PROFILES[section.profile]
    return {slot: _merged(getattr(section, slot), profile[slot]) for slot in SENSOR_SLOTS}


def _merged(given: SensorChoice | None, default: SensorChoice | None) -> SensorChoice | None:
    """``given`` over ``default``: the default's parameters kept under the same model."""
    if given is None:
        return default
    if default is None or given.model != default.model:
        return given
    return given.model_copy(update={"params": {**default.params, **given.params}})


def sensor_model_class(registry: PluginRegistry, slot: str, model: str) -> type[SensorModel]:
    """The registered sensor model ``model``, checked to measure the sensor ``slot``.

    Raises
    ------
    PluginNotFoundError
        If no sensor model has that name.
    PluginError
        If it measures another sensor.
    """
    cls = registry.get("sensor", model).cls
    measures = getattr(cls, "measures", None)
    if measures != slot:
        raise PluginError(
            f"sensor model '{model}' measures {measures}, not {slot}: give it as sensors.{measures}"
        )
    return cls  # type: ignore[return-value]
