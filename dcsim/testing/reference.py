"""Generate the table of conformance checks in docs/plugins.md (``make docs``)."""

from __future__ import annotations

import sys
from pathlib import Path

from dcsim.registry.interfaces import PLUGIN_KINDS
from dcsim.report.docgen import update_block
from dcsim.testing import checks_for

BEGIN = "<!-- BEGIN GENERATED CHECK LIST (make docs) -->"
END = "<!-- END GENERATED CHECK LIST -->"


def render_checks() -> str:
    """Every check, the kinds it applies to and its contract, as a Markdown table (the
    mission contract's checks last, for the kind ``mission``)."""
    from dcsim.testing.missions import MISSION_CHECKS  # the missions load the world engine

    seen: dict[str, tuple[list[str], str]] = {}
    for kind in PLUGIN_KINDS:
        for check in checks_for(kind):
            seen.setdefault(check.name, ([], check.contract))[0].append(kind)
    rows = ["| check | kinds | contract |", "|---|---|---|"]
    for name, (kinds, text) in seen.items():
        applies = "all" if len(kinds) == len(PLUGIN_KINDS) else ", ".join(kinds)
        rows.append(f"| `{name}` | {applies} | {text} |")
    rows += [f"| `{check.name}` | mission | {check.contract} |" for check in MISSION_CHECKS]
    return "\n".join(rows) + "\n"


if __name__ == "__main__":
    target = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/plugins.md")
    changed = update_block(target, BEGIN, END, render_checks())
    print(f"{target}: {'updated' if changed else 'already up to date'}")
