"""What a sweep's Dask worker runs (``validate.dispatch`` submits it): one point through the
worker's own compiled simulator, and a plugin that leaves Ctrl-C to the sweep's process, which
cancels the points and closes the cluster (a worker stopped by the same Ctrl-C would print
its traceback). Needs dask.distributed: imported on workers and by ``dispatch`` only."""
from __future__ import annotations

import signal
import threading
from dataclasses import dataclass
from typing import Optional

from distributed import WorkerPlugin

from .. import backend
from ..control import Session
from . import sweep


@dataclass(frozen=True)
class BackendSpec:
    """What each worker passes to backend.init."""
    arch: Optional[str]
    precision: str = "f32"
    seed: int = 0
    threads: Optional[int] = None
    fast_compile: bool = False


_worker: dict = {}      # per worker process: the backend spec and its Session
_one_at_a_time = threading.Lock()   # one Taichi runtime a process: a worker started with
#                                     several threads still runs its points in turn


# CPython 3.11's ast module keeps its recursion depth per interpreter, not per thread
# (python/cpython gh-106905): Taichi parsing a kernel in the worker's task thread while another
# thread of the worker builds an AST can end in this SystemError. It is the interpreter's
# bookkeeping, not the point's: seen once in a full suite (tests/test_sweep_dask.py, U = 5
# failed while its neighbour worker was being killed).
AST_DEPTH_ERROR = "AST constructor recursion depth mismatch"


def run_point(resolved, spec: BackendSpec) -> dict:
    """One point through this worker's simulator (``sweep.measure_point``), as a dict; run
    once more if the first try hits CPython's AST depth error (AST_DEPTH_ERROR)."""
    with _one_at_a_time:
        backend.init(spec.arch, spec.precision, spec.seed, threads=spec.threads,
                     fast_compile=spec.fast_compile)
        if _worker.get("spec") != spec:         # a new backend: the old simulators are gone
            _worker.update(spec=spec, session=Session())
        try:
            return sweep.measure_point(resolved, _worker["session"]).as_dict()
        except SystemError as e:
            if AST_DEPTH_ERROR not in str(e):
                raise
        return sweep.measure_point(resolved, _worker["session"]).as_dict()


class LeaveCtrlCToTheSweep(WorkerPlugin):
    """SIGINT ignored in the worker process (its event loop's thread is the main thread)."""
    name = "crowndemo-leave-ctrl-c"

    def setup(self, worker) -> None:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)


__all__ = ["BackendSpec", "run_point", "LeaveCtrlCToTheSweep"]
