"""PyBullet, imported without its banner, DIRECT clients and URDF loading.

PyBullet prints ``pybullet build time: ...`` from C on standard error when it is
imported, which would clutter every command's output; the import here sends it to a
discarded file descriptor. Import ``pb`` from this module, never ``pybullet`` itself.
"""

from __future__ import annotations

import ctypes
import os
import sys
import tempfile
from pathlib import Path
from types import ModuleType


def _import_quietly() -> ModuleType:
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        import pybullet

        ctypes.CDLL(None).fflush(None)
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return pybullet


pb = _import_quietly()


def connect_direct() -> int:
    """Connect a new PyBullet DIRECT client (no GUI), zero gravity, and return its id."""
    client = pb.connect(pb.DIRECT)
    pb.setGravity(0, 0, 0, physicsClientId=client)
    return client


def load_urdf(client: int, text: str) -> int:
    """Load URDF ``text`` as a floating-base multibody with the file's inertias and
    return its body id."""
    with tempfile.TemporaryDirectory(prefix="dcsim-urdf-") as folder:
        path = Path(folder) / "robot.urdf"
        path.write_text(text, encoding="utf-8")
        return pb.loadURDF(
            str(path),
            useFixedBase=False,
            flags=pb.URDF_USE_INERTIA_FROM_FILE,
            physicsClientId=client,
        )


MAX_SPEED = 1e5
"""Speed above which PyBullet would clamp a multibody's velocities, m/s (or rad/s for a
joint). PyBullet's default, 100, is below relative speeds that a drift of tens of
kilometres reaches in a two-body world; bodies of dcsim's worlds are set to this."""
