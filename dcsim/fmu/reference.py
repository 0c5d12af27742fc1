"""Generate the variable tables of docs/fmu.md (``make docs``)."""

from __future__ import annotations

import sys
from pathlib import Path

from dcsim.docgen import update_block
from dcsim.fmu.variables import CLOSED_LOOP, DEFAULT_BEACONS, FmuVariable, plant_variables


def variables_table(variables: list[FmuVariable]) -> str:
    """A Markdown table of ``variables``."""
    types = {float: "Real", int: "Integer", bool: "Boolean"}
    lines = ["| name | causality | type | unit | meaning |", "|---|---|---|---|---|"]
    lines += [
        f"| `{v.name}` | {v.causality} | {types[v.type]} | {v.unit or '–'} | {v.description} |"
        for v in variables
    ]
    return "\n".join(lines) + "\n"


BEGIN_CLOSED = "<!-- begin: closed-loop variables (make docs) -->"
END_CLOSED = "<!-- end: closed-loop variables -->"
BEGIN_PLANT = "<!-- begin: plant variables (make docs) -->"
END_PLANT = "<!-- end: plant variables -->"


def write_reference(path: Path) -> bool:
    """Regenerate both variable tables in ``path``; return True if it changed."""
    changed = update_block(path, BEGIN_CLOSED, END_CLOSED, variables_table(CLOSED_LOOP))
    plant = variables_table(plant_variables(DEFAULT_BEACONS))
    return update_block(path, BEGIN_PLANT, END_PLANT, plant) or changed


if __name__ == "__main__":
    target = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/fmu.md")
    changed = write_reference(target)
    print(f"{target}: {'updated' if changed else 'already up to date'}")
