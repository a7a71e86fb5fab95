"""The dask.distributed cluster that runs the members, and the progress bar over them.

Without ``--scheduler`` a ``dask.distributed.LocalCluster`` of worker *processes* is started,
each with one dask thread (one member at a time) and ``NUMBA_NUM_THREADS`` = the threads per
worker in its environment, so that workers x threads does not oversubscribe the cores (or the
``NUMBA_NUM_THREADS`` the user set: :func:`thread_budget`). Its size comes from
:func:`plan_workers`. The workers start with SIGINT, SIGTERM and SIGHUP ignored: a Ctrl-C at
the terminal (sent to every process of the job) or a scheduler's SIGTERM is the main
process's to handle, which records the ending and closes the cluster
(``floodsph.ensemble.runner``); a worker does not die mid-member with a traceback of its
own. With ``--scheduler ADDRESS`` the members go to an
existing cluster (dask-jobqueue, dask-kubernetes, ``dask scheduler`` + ``dask worker``), whose
workers must import floodsph and see the ensemble folder at the same path; start them with
``--nthreads 1`` (a worker thread per member) and ``NUMBA_NUM_THREADS`` set.

Each member runs as one task (:func:`floodsph.ensemble.members.run_member`) that returns its
result; a task that raises (a worker killed by the system, say) is recorded as a failed
member too, and the other members go on.
"""

from __future__ import annotations

import logging
import os
import threading
import time
import uuid
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass, replace

from floodsph.ensemble.manifest import NOT_RUN
from floodsph.ensemble.members import MemberResult, MemberTask, run_member
from floodsph.errors import InputError

log = logging.getLogger(__name__)

#: How often the main process looks for finished members and stop requests [s].
POLL_S = 0.25
#: How long running members get to write their checkpoint once the ensemble stops [s]
#: (SLURM's default grace between SIGTERM and SIGKILL is 30 s).
STOP_GRACE_S = 20.0

INSTALL_HINT = ("floodsph ensemble needs dask.distributed, which is not installed; install it "
                "with: pip install 'floodsph[ensemble]'")


#: The dask configuration of the local cluster, against dask's defaults:
#:
#: * its workers start without ``MALLOC_TRIM_THRESHOLD_=65536`` (None unsets it; a value in
#:   the user's environment still wins): it turns off glibc's adaptive mmap threshold, so that
#:   every map-sized temporary array is mapped afresh, and a sample member ran in 3.5-4.1 s
#:   instead of 2.6-2.8 s. A member per worker frees its memory when it ends anyway;
#: * no stack profiler (it samples every thread every 10 ms for a dashboard not started);
#: * the event-loop tick (a check for a blocked loop) every 1 s instead of 20 ms, and the
#:   system monitor every 5 s instead of 0.5 s: an idle 2-worker cluster then takes 3 % of a
#:   core instead of 9 %, CPU the members get back.
CLUSTER_CONFIG = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
}


def require_distributed() -> None:
    """Raise InputError with the install command when dask.distributed is missing."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise InputError(INSTALL_HINT) from None


def machine_cores() -> int:
    """The cores this process may use (its CPU affinity where the system has one)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def thread_budget() -> int:
    """The numba threads the ensemble may share out: ``NUMBA_NUM_THREADS`` when the user set
    it (also by ``floodsph --threads N``), else the machine's cores (:func:`machine_cores`)."""
    value = os.environ.get("NUMBA_NUM_THREADS", "")
    try:
        told = int(value)
    except ValueError:
        told = 0
    return told if told > 0 else machine_cores()


@dataclass(frozen=True)
class WorkerPlan:
    """How many worker processes run members at once, and the numba threads of each."""

    workers: int
    threads_per_worker: int


def plan_workers(members: int, cores: int, member_bytes: int, available_bytes: int | None,
                 workers: int | None = None, threads: int | None = None) -> WorkerPlan:
    """Size the local cluster from the cores and a member's peak-memory estimate.

    At most ``available_bytes // member_bytes`` members fit in memory at once; the workers
    are as many as fit, as there are cores (``cores // threads`` when the threads per worker
    are given) and as there are members, and each gets ``cores // workers`` threads unless
    told. Explicit ``workers`` / ``threads`` are used as given.
    """
    fit = members if available_bytes is None else available_bytes // max(member_bytes, 1)
    if workers is None:
        per_worker = threads or 1
        workers = max(1, min(members, cores // per_worker, fit))
    if threads is None:
        threads = max(1, cores // workers)
    if workers * threads > cores:
        log.warning("%d workers x %d threads exceed the %d cores; members will run slower",
                    workers, threads, cores)
    if available_bytes is not None and workers > fit:
        log.warning("%d members at once may not fit in memory (about %d do)", workers, fit)
    return WorkerPlan(workers, threads)


@contextmanager
def open_client(plan: WorkerPlan, scheduler: str | None):
    """A dask Client on a new LocalCluster of ``plan``, or on the cluster at ``scheduler``."""
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout="30s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect: {exc}") from None
        with client:
            yield client
        return
    import dask

    threads = str(plan.threads_per_worker)
    with dask.config.set(CLUSTER_CONFIG), _stop_signals_ignored():
        cluster = LocalCluster(n_workers=plan.workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None,
                               silence_logs=logging.ERROR,
                               env={"NUMBA_NUM_THREADS": threads, "OMP_NUM_THREADS": threads})
    with cluster, Client(cluster) as client:
        yield client


@contextmanager
def _stop_signals_ignored():
    """Ignore the stop signals while the worker processes are spawned: an ignored signal
    stays ignored in a child, across exec (a handler does not), and Python keeps it so.

    A stop signal sent to the main process in these few seconds (the cluster's start) is lost
    with them: the ensemble goes on, and the signal must be sent again.
    """
    import signal

    from floodsph.simulation.stop_signals import SIGNALS

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.getsignal(sig) for sig in SIGNALS}
    for sig in SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def cluster_workers(client) -> int:
    """The number of workers of the client's cluster; warns about multi-threaded ones."""
    workers = client.scheduler_info()["workers"]
    if not workers:
        log.warning("the cluster has no workers yet; the members wait until some join")
    threaded = [w for w in workers.values() if w.get("nthreads", 1) > 1]
    if threaded:
        log.warning("%d worker(s) have more than one thread and will run several members at "
                    "once; start dask workers with --nthreads 1", len(threaded))
    return len(workers)


class MemberProgress:
    """A tqdm bar over members with the counts done and failed, and the ETA.

    Off when ``enabled`` is False, and when stderr is not a terminal.
    """

    def __init__(self, total: int, enabled: bool = True):
        from tqdm import tqdm

        self.done = 0
        self.failed = 0
        self.bar = tqdm(total=total, unit="member", desc="members",
                        disable=None if enabled else True, dynamic_ncols=True)
        self.bar.set_postfix_str("0 done, 0 failed")

    def update(self, result: MemberResult) -> None:
        if result.status == "completed":
            self.done += 1
        else:
            self.failed += 1
        self.bar.set_postfix_str(f"{self.done} done, {self.failed} failed", refresh=False)
        self.bar.update(1)

    def close(self) -> None:
        self.bar.close()


def run_tasks(client, tasks: list[MemberTask], on_result: Callable[[MemberResult], None],
              progress: bool = True, stop=None) -> None:
    """Run every task on the client's cluster; ``on_result`` gets each result as it comes.

    ``stop`` (a :class:`~floodsph.simulation.stop_signals.StopSignals`, armed here) is polled
    every :data:`POLL_S`: once a stop is requested the running members are asked to stop
    (a ``distributed.Event`` they poll: each writes its checkpoint and ends
    ``interrupted``), their results are awaited for up to :data:`STOP_GRACE_S`, the members
    not started are cancelled, and :class:`~floodsph.simulation.stop_signals.RunInterrupted`
    is raised. On any other interruption the tasks not finished are cancelled before it
    propagates.
    """
    from distributed import Event, as_completed

    from floodsph.simulation.stop_signals import RunInterrupted

    event_name = f"floodsph-stop-{uuid.uuid4().hex}"
    futures = {}
    for task in tasks:
        task = replace(task, stop_event=event_name)
        future = client.submit(run_member, task, key=f"floodsph-{task.id}-{uuid.uuid4().hex}")
        futures[future] = task
    bar = MemberProgress(len(tasks), progress)
    pending = as_completed(list(futures))

    def collect() -> None:
        for future in pending.next_batch(block=False):
            result = _result(future, futures[future])
            if result.status == NOT_RUN:  # its turn came after the stop: recorded as not run
                continue
            if result.status != "completed":
                log.warning("member %s %s: %s", result.id, result.status, result.error)
            on_result(result)
            bar.update(result)

    try:
        if stop is not None:
            stop.armed = True
        while not pending.is_empty():
            if stop is not None and stop():
                Event(event_name, client=client).set()
                deadline = time.monotonic() + STOP_GRACE_S
                while not pending.is_empty() and time.monotonic() < deadline:
                    collect()
                    time.sleep(POLL_S)
                raise RunInterrupted(f"interrupted by {stop.requested}")
            collect()
            time.sleep(POLL_S)
    except BaseException:
        client.cancel(list(futures))
        raise
    finally:
        if stop is not None:
            stop.armed = False
        bar.close()


def _result(future, task: MemberTask) -> MemberResult:
    """The task's result, or a failed member carrying the task's exception."""
    try:
        return future.result()
    except Exception as exc:  # a lost worker or a task that could not run: a failed member
        return MemberResult(task.id, "failed", None, f"{type(exc).__name__}: {exc}")
