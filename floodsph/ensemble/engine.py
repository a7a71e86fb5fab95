"""The dask.distributed cluster that runs the members, and the progress bar over them.

Without ``--scheduler`` a ``dask.distributed.LocalCluster`` of worker *processes* is started,
each with one dask thread (one member at a time) and ``NUMBA_NUM_THREADS`` = the threads per
worker in its environment, so that workers x threads does not oversubscribe the cores. Its
size comes from :func:`plan_workers`. With ``--scheduler ADDRESS`` the members go to an
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
import uuid
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass

from floodsph.ensemble.members import MemberResult, MemberTask, run_member
from floodsph.errors import InputError

log = logging.getLogger(__name__)

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
    with dask.config.set(CLUSTER_CONFIG):
        cluster = LocalCluster(n_workers=plan.workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None,
                               silence_logs=logging.ERROR,
                               env={"NUMBA_NUM_THREADS": threads, "OMP_NUM_THREADS": threads})
    with cluster, Client(cluster) as client:
        yield client


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
              progress: bool = True) -> None:
    """Run every task on the client's cluster; ``on_result`` gets each result as it comes.

    On an interruption (Ctrl-C) the tasks not finished are cancelled before it propagates.
    """
    from distributed import as_completed

    futures = {}
    for task in tasks:
        future = client.submit(run_member, task, key=f"floodsph-{task.id}-{uuid.uuid4().hex}")
        futures[future] = task
    bar = MemberProgress(len(tasks), progress)
    try:
        for future in as_completed(list(futures)):
            result = _result(future, futures[future])
            if result.status != "completed":
                log.warning("member %s %s: %s", result.id, result.status, result.error)
            on_result(result)
            bar.update(result)
    except BaseException:
        client.cancel(list(futures))
        raise
    finally:
        bar.close()


def _result(future, task: MemberTask) -> MemberResult:
    """The task's result, or a failed member carrying the task's exception."""
    try:
        return future.result()
    except Exception as exc:  # a lost worker or a task that could not run: a failed member
        return MemberResult(task.id, "failed", None, f"{type(exc).__name__}: {exc}")
