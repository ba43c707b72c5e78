"""Sweep points on Dask (dask.distributed): a LocalCluster of worker processes on this machine
(``workers``), or the workers of a running scheduler (``scheduler``, an address such as
tcp://host:8786, which dask-jobqueue or dask-kubernetes start on SLURM, PBS or Kubernetes).
Each worker is a process with its own Taichi runtime and its own compiled simulator, reused
for its points; results arrive as they finish. A worker that dies (killed, out of memory) has
its point run again once, on a fresh worker; a second death reports the point as failed.
Imported only when a sweep asks for workers: dask is an optional extra."""
from __future__ import annotations

import time
import uuid
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from ..machine import usable_cores
from . import sweep

EXTRA = "pip install 'crowndemo[cluster]'"
RETRIES = 1             # a point whose worker died is run again this many times


class DispatchError(RuntimeError):
    """Dask missing, a bad worker count, or no scheduler at the address."""


def distributed():
    """The dask.distributed module, or a DispatchError naming the extra."""
    try:
        import distributed as dist
    except ImportError:
        raise DispatchError("--workers and --scheduler run the points on Dask, which is not "
                            f"installed: {EXTRA} (or pip install 'dask[distributed]')") from None
    return dist


def threads_per_worker(workers: int, cores: Optional[int] = None) -> int:
    """Taichi threads for each of ``workers`` local workers so that together they use the
    cores without oversubscribing them; DispatchError when there are more workers than
    cores."""
    cores = usable_cores() if cores is None else cores
    if not (isinstance(workers, int) and 1 <= workers <= cores):
        raise DispatchError(f"--workers {workers}: allowed 1 to {cores} on this machine (its "
                            f"{cores} usable cores, at least one thread a worker)")
    return cores // workers


@dataclass
class Progress:
    total: int
    done: int = 0
    failed: int = 0
    running: int = 0
    started: float = 0.0

    @property
    def eta_s(self) -> Optional[float]:
        finished = self.done + self.failed
        if finished == 0:
            return None
        return (time.perf_counter() - self.started) / finished * (self.total - finished)


@dataclass
class Failure:
    film: float
    speed: float
    cause: str


class Cluster:
    """A Dask client on a LocalCluster of ``workers`` processes, or on the scheduler at
    ``scheduler``; a context manager that closes what it started."""

    def __init__(self, workers: Optional[int] = None, scheduler: Optional[str] = None,
                 threads: Optional[int] = None):
        if (workers is None) == (scheduler is None):
            raise DispatchError("give either --workers N or --scheduler ADDRESS")
        self.workers, self.scheduler = workers, scheduler
        share = None if workers is None else threads_per_worker(workers)   # checks the count
        self.threads = threads if threads is not None else share
        self.client = self.cluster = None
        self._futures: dict = {}

    def __enter__(self) -> "Cluster":
        dist = distributed()
        import signal

        import dask
        from .dispatch_worker import LeaveCtrlCToTheSweep
        try:
            if self.scheduler is None:
                # the worker processes start with Ctrl-C ignored (inherited), the plugin
                # keeps it so in those a nanny restarts; retries of a point whose worker
                # died: Dask's own count, which the scheduler reads at its start (a running
                # scheduler keeps its own, 3 by default)
                previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
                try:
                    with dask.config.set({"distributed.scheduler.allowed-failures": RETRIES}):
                        self.cluster = dist.LocalCluster(
                            n_workers=self.workers, threads_per_worker=1, processes=True,
                            dashboard_address=None, silence_logs=50)
                finally:
                    signal.signal(signal.SIGINT, previous)
                self.client = dist.Client(self.cluster)
            else:
                self.client = dist.Client(self.scheduler, timeout="10s")
            self.client.register_plugin(LeaveCtrlCToTheSweep())
        except OSError as e:
            self.close()
            raise DispatchError(f"--scheduler {self.scheduler}: no Dask scheduler answered "
                                f"({e})") from None
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        for obj in (self.client, self.cluster):
            if obj is not None:
                try:
                    obj.close()
                except Exception:           # closing after a lost scheduler: nothing to keep
                    pass
        self.client = self.cluster = None

    @property
    def slots(self) -> int:
        """Points that run at once: the workers' threads (one point a worker thread)."""
        info = self.client.scheduler_info()
        return max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))

    def describe(self) -> str:
        info = self.client.scheduler_info()
        n = len(info.get("workers", {}))
        where = "a local Dask cluster" if self.scheduler is None else \
            f"the Dask scheduler at {self.scheduler}"
        threads = "all cores" if self.threads is None else f"{self.threads} Taichi thread" + \
            ("s" if self.threads > 1 else "")
        return f"{where}: {n} worker{'s' if n != 1 else ''}, {threads} each"

    def run(self, resolved: Sequence, spec,
            on_point: Callable[[sweep.Point], None],
            on_failure: Callable[[Failure], None],
            on_progress: Optional[Callable[[Progress], None]] = None
            ) -> Tuple[List[sweep.Point], List[Failure]]:
        """Run every point, collect them as they finish; Ctrl-C cancels those not done and
        re-raises (what finished has gone to ``on_point``). Points are handed out one a worker
        thread, the rest kept back here: a worker that dies then takes only the point it was
        running with it (Dask counts a death against every task a worker holds)."""
        dist = distributed()
        from .dispatch_worker import run_point
        waiting = list(resolved)
        futures = self._futures = {}
        progress = Progress(len(waiting), started=time.perf_counter())
        points: List[sweep.Point] = []
        failures: List[Failure] = []
        done = dist.as_completed()

        def submit_more() -> None:
            slots = self.slots
            while waiting and len(futures) < slots:
                r = waiting.pop(0)
                f = self.client.submit(run_point, r, spec, pure=False,
                                       key=f"point-{uuid.uuid4().hex[:8]}")
                futures[f] = sweep.key_of(r)
                done.add(f)
            progress.running = len(futures)
        try:
            submit_more()
            if on_progress:
                on_progress(progress)
            for f in done:
                film, speed = futures.pop(f)
                if f.status == "finished":
                    p = sweep.Point.from_dict(f.result())
                    points.append(p)
                    progress.done += 1
                    on_point(p)
                else:
                    failures.append(Failure(film, speed, _cause(f)))
                    progress.failed += 1
                    on_failure(failures[-1])
                submit_more()
                if on_progress:
                    on_progress(progress)
        except KeyboardInterrupt:
            self.client.cancel(list(futures), force=True)
            raise
        return points, failures

    def running_points(self) -> Dict[str, Tuple[float, float]]:
        """The Dask keys of the points handed out and not finished -> (film, speed)."""
        return {f.key: v for f, v in list(self._futures.items())}


def _cause(future) -> str:
    """Why a point failed: its worker died twice, or the exception it raised."""
    e = future.exception()
    if type(e).__name__ == "KilledWorker":
        return (f"its worker died {RETRIES + 1} times while running it (killed or out of "
                "memory)")
    if future.status == "cancelled":
        return "cancelled"
    return f"{type(e).__name__}: {e}"


__all__ = ["Cluster", "DispatchError", "Failure", "Progress", "threads_per_worker",
           "distributed", "EXTRA"]
