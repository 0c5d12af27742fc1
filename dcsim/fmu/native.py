"""pythonfmu 0.7's native library at process exit: its interpreter state, released early.

The binary pythonfmu 0.7 puts in every FMU keeps a ``std::shared_ptr<PyState>`` at
namespace scope and resets it from a function marked ``__attribute__((destructor))``.
The library never leaves the process: its ``std::regex`` statics are ``STB_GNU_UNIQUE``
symbols, which make the loader mark it NODELETE, so an importer's ``dlclose`` (fmpy's
``freeLibrary``) leaves it mapped. At process exit the C++ exit handlers then destroy
the ``shared_ptr``, freeing its 128-byte block, and only afterwards does the loader's
``_dl_fini`` call the destructor function, which releases the same block again: it
decrements a count inside freed memory. Where the allocator keeps its free-list links
that write corrupts them, and a later ``free`` aborts the process (``corrupted
double-linked list``, exit code 134) after the script has finished; whether it does
depends on the allocator's state, so it happens in some runs only.

Reset early, while the process runs, the ``shared_ptr`` is empty at exit and both
destructors find nothing to free. The reset destroys the ``PyState`` object, which only
joins its thread when the interpreter existed before the library was loaded; when the
library started the interpreter itself (a host that is not Python), that thread would
finalise the interpreter, so the state is then left alone.
"""

from __future__ import annotations

import ctypes
import os
import sys
from pathlib import Path

RELEASE = "finalizePythonInterpreter"
"""The function of pythonfmu 0.7's library that resets its interpreter state."""


def release_interpreter_state(library: ctypes.CDLL) -> None:
    """Reset a loaded pythonfmu library's interpreter state now (see the module docstring).

    Call it only in a process whose interpreter existed before ``library`` was loaded.
    Instances already made keep working, and the library makes a new state at its next
    ``fmi2Instantiate``, so the call must follow the library's last instantiation.
    Libraries that are not pythonfmu's are left alone.

    Parameters
    ----------
    library : ctypes.CDLL
        An FMU's loaded binary.
    """
    release = getattr(library, RELEASE, None)
    if release is not None:
        release()


def release_own_library(resources: str | Path, model_identifier: str) -> None:
    """From inside a pythonfmu slave: reset the interpreter state of the library running it.

    Done only on Linux (the library's exit path above), in a process that is the Python
    interpreter itself (its interpreter cannot have been started by the library), and
    when the library is loaded from where the FMU standard puts it, next to the FMU's
    resources; otherwise nothing happens.

    Parameters
    ----------
    resources : str or Path
        The slave's resource folder (``<unzipped FMU>/resources``).
    model_identifier : str
        The FMU's model identifier, its binary's name (pythonfmu: the slave class name).
    """
    if sys.platform != "linux" or not _python_is_the_host():
        return
    binary = Path(resources).parent / "binaries" / "linux64" / f"{model_identifier}.so"
    try:
        library = ctypes.CDLL(str(binary), mode=os.RTLD_NOLOAD)
    except OSError:  # not loaded from there: leave it
        return
    release_interpreter_state(library)


def _python_is_the_host() -> bool:
    """True when this process is the Python interpreter program (not a host embedding it)."""
    return (
        bool(sys.executable) and Path("/proc/self/exe").resolve() == Path(sys.executable).resolve()
    )
