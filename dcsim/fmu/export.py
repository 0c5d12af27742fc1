"""``dcsim fmu export``: a scenario as an FMI 2.0 co-simulation FMU (built by pythonfmu)."""

from __future__ import annotations

import hashlib
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

from dcsim.fmu.instance import FmuError
from dcsim.fmu.slaves import SCENARIO_RESOURCE
from dcsim.fmu.variables import DEFAULT_BEACONS
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario import dump_scenario, read_scenario

_SCRIPT = '''"""FMU slave of dcsim scenario {name!r} ({variant}), written by `dcsim fmu export`."""

from dcsim.fmu.slaves import {base}, keep_namespace

keep_namespace(globals())  # see keep_namespace: pythonfmu releases it once per instance


class {model}({base}):
    """{variant} FMU of scenario {name!r}."""
{body}'''


def export_fmu(
    scenario: str | Path | None,
    out: str | Path,
    plant_only: bool = False,
    overrides: Sequence[str] = (),
    beacons: int = DEFAULT_BEACONS,
    registry: PluginRegistry | None = None,
) -> Path:
    """Build an FMI 2.0 co-simulation FMU of a scenario.

    Parameters
    ----------
    scenario : str or Path, optional
        Scenario file; the packaged default if None.
    out : str or Path
        FMU file to write (``.fmu``).
    plant_only : bool
        Export the world alone (force/torque, and a manipulator's joint torques or a free
        flyer's thruster on-times and wheel torques, in; state and sensors out) instead of
        the closed loop.
    overrides : sequence of str
        ``key.path=value`` overrides applied before the scenario is resolved.
    beacons : int
        For the plant FMU: how many nearest beacons' ranges it outputs (K ≥ 1).
    registry : PluginRegistry, optional
        Registry to resolve plugin parameters with; discovered if None.

    Returns
    -------
    Path
        The FMU written.

    Raises
    ------
    ScenarioError
        If the scenario or an override is invalid.
    FmuError
        If ``out`` does not end in ``.fmu`` or ``beacons`` < 1.
    """
    from pythonfmu import FmuBuilder  # imported here: only export needs the builder

    out = Path(out)
    if out.suffix != ".fmu":
        raise FmuError(f"the FMU file must end in .fmu: {out}")
    if beacons < 1:
        raise FmuError(f"beacons must be at least 1, got {beacons}")
    registry = registry if registry is not None else PluginRegistry.discover()
    resolved = read_scenario(scenario, overrides, registry)
    text = dump_scenario(resolved)
    variant = "plant" if plant_only else "closed-loop"
    # Python caches slave modules by name per process: a unique name per content.
    digest = hashlib.sha256(f"{variant}/{beacons}/{text}".encode()).hexdigest()[:12]
    module = f"dcsim_{variant.replace('-', '_')}_{digest}"
    with tempfile.TemporaryDirectory(prefix="dcsim-fmu-") as tmp:
        source, resources = Path(tmp) / "source", Path(tmp) / "resources"
        source.mkdir()
        resources.mkdir()
        (resources / SCENARIO_RESOURCE).write_text(text, encoding="utf-8")
        script = source / f"{module}.py"
        script.write_text(_script(resolved.name, plant_only, beacons), encoding="utf-8")
        out.parent.mkdir(parents=True, exist_ok=True)
        try:
            FmuBuilder.build_FMU(script, dest=out, project_files=[resources / SCENARIO_RESOURCE])
        finally:
            if str(source) in sys.path:  # the builder imports the script from there
                sys.path.remove(str(source))
    return out


def _script(name: str, plant_only: bool, beacons: int) -> str:
    if plant_only:
        return _SCRIPT.format(
            name=name,
            variant="plant",
            base="PlantSlave",
            model="DcsimPlant",
            body=f"\n    nearest_beacons = {beacons}\n",
        )
    return _SCRIPT.format(
        name=name, variant="closed-loop", base="ClosedLoopSlave", model="DcsimClosedLoop", body=""
    )
