"""What the two OMPL path planners share: seeding OMPL and worker processes.

Not a plugin itself (obstacle and endpoint checks are in ``obstacle_field``). Its pieces:

:func:`in_worker`
    Runs a solve in a process forked for it. OMPL seeds its random generator once per
    process (``ompl.util.RNG.setSeed`` is ignored after the first sample), so each plan
    runs in a fresh child forked from the planning process, which itself never samples:
    the child's seed always takes, and the same seed gives the same plan. A fork costs
    about 7 ms (docs/benchmarks.md gives the command). If OMPL's generator was
    already running in the planning process (other code sampled there first), the child
    reports that its seed did not take and the solve is repeated in a child of a
    forkserver that has imported only this module: the first such plan costs about
    0.7 s more, each later one about 90 ms more plus the import of the program's main
    module, which multiprocessing repeats in every such child.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import select
import signal
import time
from collections.abc import Callable
from typing import Any

WORKER_SLACK = 0.5
"""Seconds the planning process waits for a worker beyond its deadline before killing it."""


class SeedNotTaken(RuntimeError):
    """OMPL's generator was already running when a worker tried to seed it."""


def seed_ompl(seed: int) -> None:
    """Seed OMPL's generator for this process, or raise :class:`SeedNotTaken`."""
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_ERROR)
    ou.RNG.setSeed(seed)
    if ou.RNG.getSeed() != seed:
        raise SeedNotTaken(f"OMPL's generator kept seed {ou.RNG.getSeed()}, not {seed}")


# ------------------------------------------------------------------ worker processes


def _child(write_end: int, function: Callable[..., Any], args: tuple) -> None:
    """In a forked child: run ``function(*args)``, send the pickled outcome, exit."""
    try:
        outcome: tuple[str, Any] = ("ok", function(*args))
    except SeedNotTaken as error:
        outcome = ("unseeded", str(error))
    except Exception as error:  # sent to the parent, which raises it there
        outcome = ("error", f"{type(error).__name__}: {error}")
    with os.fdopen(write_end, "wb") as pipe:
        pipe.write(pickle.dumps(outcome))
    os._exit(0)


def _forked(function: Callable[..., Any], args: tuple, wait: float) -> tuple[str, Any]:
    """``function(*args)`` in a child forked from this process; ("timeout", None) if it
    gives no answer within ``wait`` s (it is killed)."""
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read_end)
        _child(write_end, function, args)
    os.close(write_end)
    chunks: list[bytes] = []
    deadline = time.monotonic() + wait
    with os.fdopen(read_end, "rb", buffering=0) as pipe:
        while True:
            ready, _, _ = select.select([pipe], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                return "timeout", None
            chunk = pipe.read(1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
    os.waitpid(pid, 0)
    if not chunks:
        return "error", "the worker died without an answer"
    return pickle.loads(b"".join(chunks))


def _forkserver_worker(connection: Any, function: Callable[..., Any], args: tuple) -> None:
    """Target of a forkserver process: send ``function(*args)``'s outcome back."""
    try:
        connection.send(("ok", function(*args)))
    except Exception as error:  # sent to the parent, which raises it there
        connection.send(("error", f"{type(error).__name__}: {error}"))
    finally:
        connection.close()


def _from_forkserver(function: Callable[..., Any], args: tuple, wait: float) -> tuple[str, Any]:
    """``function(*args)`` in a child of a forkserver that imported only this module."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([__name__])
    receiver, sender = context.Pipe(duplex=False)
    process = context.Process(target=_forkserver_worker, args=(sender, function, args))
    process.start()
    sender.close()
    try:
        if not receiver.poll(wait):
            return "timeout", None
        return receiver.recv()
    except EOFError:
        return "error", f"the worker died with exit code {process.exitcode}"
    finally:
        receiver.close()
        if process.is_alive():
            process.kill()
        process.join()


def in_worker(function: Callable[..., Any], args: tuple, deadline: float) -> Any | None:
    """``function(*args)`` in a fresh process (see the module's docstring).

    Parameters
    ----------
    function : callable
        A module-level function; it must seed OMPL with :func:`seed_ompl` first.
    args : tuple
        Its arguments (picklable for the forkserver fallback).
    deadline : float
        ``time.monotonic()`` by which the answer is due; the worker is killed
        :data:`WORKER_SLACK` s later.

    Returns
    -------
    object or None
        What ``function`` returned, or None if the worker gave no answer in time.

    Raises
    ------
    RuntimeError
        If ``function`` raised in the worker (its message is passed on).
    """
    wait = max(0.0, deadline - time.monotonic()) + WORKER_SLACK
    status, value = _forked(function, args, wait)
    if status == "unseeded":
        wait = max(0.0, deadline - time.monotonic()) + WORKER_SLACK + 2.0
        status, value = _from_forkserver(function, args, wait)
    if status == "timeout":
        return None
    if status != "ok":
        raise RuntimeError(f"OMPL worker failed: {value}")
    return value
