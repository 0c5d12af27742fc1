"""FMUs built once per test session: the default scenario's two variants, the example PD."""

from __future__ import annotations

from pathlib import Path

import pytest

from dcsim.fmu.export import export_fmu

EXAMPLE_PD = Path(__file__).resolve().parents[2] / "fmu" / "pd_controller" / "pd_controller_fmu.py"


@pytest.fixture(scope="session")
def closed_loop_fmu(tmp_path_factory) -> Path:
    """The default scenario as a closed-loop FMU."""
    return export_fmu(None, tmp_path_factory.mktemp("fmu") / "closed_loop.fmu")


@pytest.fixture(scope="session")
def plant_fmu(tmp_path_factory) -> Path:
    """The default scenario's world as a plant-only FMU (K = 4 beacons)."""
    return export_fmu(None, tmp_path_factory.mktemp("fmu") / "plant.fmu", plant_only=True)


@pytest.fixture(scope="session")
def pd_fmu(tmp_path_factory) -> Path:
    """The example external PD controller (fmu/pd_controller), built with pythonfmu."""
    from pythonfmu import FmuBuilder

    return FmuBuilder.build_FMU(EXAMPLE_PD, dest=tmp_path_factory.mktemp("fmu") / "pd.fmu")
