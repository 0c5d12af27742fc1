"""Cases on Dask: a local cluster or one at an address, and a loop that loses no case.

:func:`dask_client` connects to an existing scheduler (``tcp://host:port``) or starts a
:class:`distributed.LocalCluster` with one single-threaded worker process per core.
:func:`run_tasks` submits one task per case under its own key and takes the results
as they arrive: a task that raised is an outcome with the error, and a task whose
worker died is run again elsewhere by the scheduler until ``worker_deaths`` workers
have died running it, then it is an outcome with that reason. Ctrl-C cancels what is
left and is raised again for the caller to keep what finished.

A local cluster's worker processes are started by spawning: each imports the main
module again, as :mod:`multiprocessing` does. A script that starts a campaign when
imported would start one in every worker; :func:`dask_client` refuses that (and a main
module fed on standard input, which the workers cannot import) with a
:class:`ClusterError` that says what to change.

Workers hold one case at a time (``worker-saturation`` 1): a worker that dies takes
only the case it was running with it. A local cluster's workers run with
:data:`QUIET_WORKER_SETTINGS`: a case runs in a worker thread, and every wake-up of the
worker's event loop takes the GIL from it (docs/benchmarks.md, "Campaigns on Dask").
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import sys
import uuid
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from dcsim.errors import DcsimError

if TYPE_CHECKING:
    from distributed import Client, Future

CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a scheduler given by address, unless the options say otherwise."""

QUIET_WORKER_SETTINGS: dict[str, Any] = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}
"""Dask settings that keep a worker's event loop off the running case's GIL.

Dask's defaults sample the case's stack every 10 ms (the statistical profiler), check
the event loop every 20 ms, read the process's resources every 0.5 s and its memory
every 0.1 s. Each wake-up takes the GIL from the case: with the profiler off and the
rest at Dask's defaults, a 300-s case of the default scenario took about 3.5 s in a
worker against 2.7 s in a plain process (docs/benchmarks.md). The memory limits still
hold, checked each second.
"""


class ClusterError(DcsimError):
    """The Dask cluster cannot be reached or started."""


@dataclass(frozen=True)
class ClusterOptions:
    """Where cases run.

    Attributes
    ----------
    scheduler : str or None
        Address of an existing Dask scheduler (``tcp://host:port``); None starts a
        local cluster.
    workers : int or None
        Worker processes of the local cluster (one per core when None).
    worker_deaths : int
        Workers that may die running one case before it is a failed case (local
        cluster only; an existing scheduler keeps its own
        ``distributed.scheduler.allowed-failures``).
    connect_timeout : float or None
        Seconds to wait for the scheduler at ``scheduler`` (a scheduler started by a
        batch job may need longer); None waits :data:`CONNECT_TIMEOUT`. Only with
        ``scheduler``.

    Raises
    ------
    ValueError
        If ``connect_timeout`` is not positive, or given without ``scheduler``.
    """

    scheduler: str | None = None
    workers: int | None = None
    worker_deaths: int = 3
    connect_timeout: float | None = None

    def __post_init__(self) -> None:
        if self.connect_timeout is None:
            return
        if self.scheduler is None:
            raise ValueError("connect_timeout is for a scheduler given by address")
        if not self.connect_timeout > 0:
            raise ValueError(f"connect_timeout must be positive, got {self.connect_timeout}")

    @property
    def scheduler_wait(self) -> float:
        """Seconds to wait for the scheduler at :attr:`scheduler`."""
        return CONNECT_TIMEOUT if self.connect_timeout is None else self.connect_timeout


@dataclass(frozen=True)
class TaskOutcome:
    """How one task ended: its value, or why it has none.

    Attributes
    ----------
    index : int
        The task's index (the case's).
    value : object
        What the task returned (None when it failed).
    error : str or None
        Why it failed: the exception it raised, or that its workers died.
    """

    index: int
    value: Any = None
    error: str | None = None


def local_worker_count() -> int:
    """Cores this process may use: the local cluster's default worker count."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@contextmanager
def dask_client(options: ClusterOptions) -> Iterator[Client]:
    """A Dask client on the chosen cluster; a local cluster is closed on exit.

    Raises
    ------
    ClusterError
        If the scheduler cannot be reached in ``options.scheduler_wait`` seconds or
        the local cluster cannot start.
    """
    import dask
    from distributed import Client, LocalCluster

    _quiet_logs()
    if options.scheduler is not None:
        try:
            client = Client(options.scheduler, timeout=options.scheduler_wait)
        except (OSError, TimeoutError, ValueError) as error:
            raise ClusterError(
                f"cannot reach the Dask scheduler at {options.scheduler}: {error}"
            ) from None
        with client:
            yield client
        return
    _check_main_module()
    settings = {
        "distributed.scheduler.allowed-failures": options.worker_deaths - 1,
        "distributed.scheduler.worker-saturation": 1.0,
        **QUIET_WORKER_SETTINGS,
    }
    try:
        with dask.config.set(settings):
            cluster = LocalCluster(
                n_workers=options.workers or local_worker_count(),
                threads_per_worker=1,
                processes=True,
                dashboard_address="127.0.0.1:0",  # loopback, any free port: campaigns side by side
                silence_logs=logging.CRITICAL,
            )
    except (OSError, TimeoutError) as error:
        raise ClusterError(f"cannot start a local Dask cluster: {error}") from None
    except RuntimeError as error:  # a worker process failed while it started
        raise ClusterError(
            f"cannot start a local Dask cluster ({error}): its worker processes import the "
            'main module again, so a script must run campaigns under `if __name__ == "__main__":`;'
            " the error a worker printed above says what failed"
        ) from None
    with cluster, Client(cluster) as client:
        yield client


def _check_main_module() -> None:
    """Refuse a local cluster whose worker processes could not import the main module.

    Raises
    ------
    ClusterError
        If this process is a worker still importing the main module (the script has
        no ``if __name__ == "__main__":`` guard), or the main module was read from
        standard input.
    """
    if getattr(multiprocessing.current_process(), "_inheriting", False):
        raise ClusterError(
            "run_campaign was called while Python was importing the main module in a new "
            "process: Dask's worker processes import the main module again, and each would "
            "start the campaign anew. Put the script's calls under "
            '`if __name__ == "__main__":`'
        )
    main_file = getattr(sys.modules.get("__main__"), "__file__", None)
    if main_file is not None and not os.path.exists(main_file):
        raise ClusterError(
            f"a local Dask cluster cannot start from a main module read from {main_file} "
            "(its worker processes import the main module again from its file): save the "
            "code as a script, with the calls that run campaigns under `if __name__ == "
            '"__main__":`, and run `python SCRIPT`'
        )


def run_tasks(
    client: Client,
    function: Callable[[Any], Any],
    tasks: Mapping[int, Any],
    on_outcome: Callable[[TaskOutcome], None],
    name: str = "dcsim-case",
) -> None:
    """Run ``function(task)`` for every task on the cluster; report each as it ends.

    Parameters
    ----------
    client : distributed.Client
        The cluster.
    function : callable
        An importable function (workers import it by name).
    tasks : mapping of int to object
        Index → the argument of its call.
    on_outcome : callable
        Called in this process with each :class:`TaskOutcome`, in the order they end.
    name : str
        Prefix of the task keys (a random token keeps them apart on a shared cluster).

    Raises
    ------
    KeyboardInterrupt
        After cancelling the tasks not yet ended; the outcomes reported so far stand.
    """
    from distributed import as_completed

    token = uuid.uuid4().hex[:8]
    futures = {
        client.submit(function, task, key=f"{name}-{token}-{index}", pure=False): index
        for index, task in tasks.items()
    }
    try:
        for future in as_completed(futures):
            on_outcome(_outcome(futures[future], future))
            future.release()
    except BaseException:
        client.cancel(list(futures))
        raise


def running_count(client: Client) -> int:
    """Tasks the workers are running now (at most one per worker thread)."""
    assigned = sum(len(keys) for keys in client.processing().values())
    return min(assigned, sum(client.nthreads().values()))


def _outcome(index: int, future: Future) -> TaskOutcome:
    from distributed.scheduler import KilledWorker

    try:
        return TaskOutcome(index, future.result())
    except KilledWorker:
        return TaskOutcome(
            index,
            error="its worker died every time it ran (killed, crashed or out of memory); "
            "the scheduler's retries were used up",
        )
    except Exception as error:  # the task raised: the error is its outcome
        return TaskOutcome(index, error=f"{type(error).__name__}: {error}")


def _quiet_logs() -> None:
    """Keep Dask's own log lines (a dying worker, a lost key) off the terminal."""
    for logger in ("distributed", "distributed.scheduler", "distributed.nanny"):
        logging.getLogger(logger).setLevel(logging.CRITICAL)
