"""The one place that calls ``ti.init``: arch, float precision, random seed, threads."""
from __future__ import annotations

import atexit
import contextlib
import os
import sys
from dataclasses import dataclass
from typing import Optional

import taichi as ti

ARCHS = ("cpu", "cuda", "vulkan", "gpu", "auto")
PRECISIONS = ("f32", "f64")


@dataclass(frozen=True)
class Backend:
    arch: str          # what was asked for
    resolved: str      # what Taichi started on (x64, arm64, cuda, vulkan, ...)
    precision: str
    seed: int
    single_thread: bool
    fast_compile: bool = False    # Taichi's advanced IR optimisations off on the CPU arch
    threads: Optional[int] = None  # CPU threads (None: Taichi's default, every core)


_current: Optional[Backend] = None


class BackendError(ValueError):
    """A bad arch/precision choice, reported before any kernel runs."""


def _finish() -> None:
    """At exit: close any GGUI window, then finish Taichi, which writes the kernels compiled
    in this process to Taichi's offline cache. Interpreter shutdown alone does not always
    finish it (it depends on the order in which objects are collected): runs then compiled
    every kernel afresh each time (BENCHMARKS.md, the 20:48 section)."""
    global _current
    if _current is None:
        return
    window = sys.modules.get("crowndemo.render.window")
    if window is not None:
        window._close_all()
    ti.reset()
    _current = None


ON, OFF = ("1", "true", "yes", "on"), ("", "0", "false", "no", "off")


def _switch(variable: str) -> bool:
    """An on/off environment variable; another value is an error, not silently off."""
    value = os.environ.get(variable, "").strip().lower()
    if value not in ON + OFF:
        raise BackendError(f"${variable} = {os.environ[variable]!r}: allowed 1, true, yes, on "
                           "(on) or 0, false, no, off, empty (off)")
    return value in ON


def _arch_object(name: str):
    return {"cpu": ti.cpu, "cuda": ti.cuda, "vulkan": ti.vulkan, "gpu": ti.gpu}[name]


def init(arch: Optional[str] = None, precision: str = "f32", seed: int = 0,
         single_thread: bool = False, quiet: bool = True,
         fast_compile: Optional[bool] = None, threads: Optional[int] = None) -> Backend:
    """Start Taichi once per process.

    ``arch`` falls back to ``$CROWNDEMO_ARCH`` and then to ``cpu``. ``auto`` is CUDA where
    Taichi finds it, else the CPU. ``single_thread`` makes CPU runs bit-reproducible.
    ``fast_compile`` (None: ``$CROWNDEMO_FAST_COMPILE`` = 1, true, yes or on) turns Taichi's advanced IR
    optimisations off on the CPU arch and has the grid walk loop over its rows (core/grid.py):
    the 3D crown step compiles in about 5 s instead of 20-92 s and steps 5-15 % slower
    (BENCHMARKS.md, "Compiling" and "The walk's rows in a loop"); no effect on other archs.
    ``threads``: the CPU arch's thread count (a sweep's Dask worker: its share of the cores;
    ``single_thread`` is 1). A second call with the same settings is a no-op; with other
    settings Taichi is reset.
    """
    global _current
    if fast_compile is None:
        fast_compile = _switch("CROWNDEMO_FAST_COMPILE")
    arch = (arch or os.environ.get("CROWNDEMO_ARCH") or "cpu").lower()
    if arch not in ARCHS:
        raise BackendError(f"arch {arch!r} is not one of {', '.join(ARCHS)} "
                           "(--arch or CROWNDEMO_ARCH)")
    if precision not in PRECISIONS:
        raise BackendError(f"precision {precision!r} is not one of {', '.join(PRECISIONS)}")
    if threads is not None and not (isinstance(threads, int) and threads >= 1):
        raise BackendError(f"threads = {threads!r}: allowed: an integer >= 1")
    if single_thread:
        threads = 1
    wanted = (arch, precision, int(seed), bool(single_thread), bool(fast_compile), threads)
    if _current is not None and (_current.arch, _current.precision, _current.seed,
                                 _current.single_thread, _current.fast_compile,
                                 _current.threads) == wanted:
        return _current
    if _current is not None:
        ti.reset()
    else:
        atexit.register(_finish)    # once: _current is None only before the first init
    target = arch
    if arch == "auto":
        # CUDA, else the CPU; never Taichi's other GPU backends: without a GPU, Vulkan is
        # Mesa's software driver (lavapipe, which make installs for the renderer), about 20
        # times slower than the CPU arch (BENCHMARKS.md, "Compiling")
        from taichi.lang.misc import is_arch_supported
        target = "cuda" if is_arch_supported(ti.cuda) else "cpu"
    kwargs = dict(default_fp=ti.f64 if precision == "f64" else ti.f32,
                  default_ip=ti.i32, random_seed=int(seed), offline_cache=True,
                  advanced_optimization=not (fast_compile and target == "cpu"),
                  log_level=ti.WARN if quiet else ti.INFO)
    if threads is not None:
        kwargs["cpu_max_num_threads"] = threads
    # ti.init prints "[Taichi] Starting on arch=..." on stdout, at every start (a restart for
    # another precision too): it goes to stderr, so that stdout holds only what the command
    # prints (one JSON document with --json)
    with contextlib.redirect_stdout(sys.stderr):
        ti.init(arch=_arch_object(target), **kwargs)    # falls back to the CPU if CUDA fails
    if arch in ("cuda", "vulkan", "gpu") and ti.lang.impl.current_cfg().arch in (ti.x64, ti.arm64):
        raise BackendError(f"arch {arch!r} was asked for but Taichi found no such device "
                           "(it fell back to the CPU); use --arch cpu")
    resolved = str(ti.lang.impl.current_cfg().arch).split(".")[-1]
    _current = Backend(arch, resolved, precision, int(seed), bool(single_thread),
                       bool(fast_compile), threads)
    return _current


def fast_compiling() -> bool:
    """Whether the running backend compiles fast (``fast_compile`` on the CPU arch): kernels
    then also loop over the grid walk's rows instead of unrolling them (core/grid.py)."""
    b = current()
    return b.fast_compile and b.resolved in ("x64", "arm64")


def current() -> Backend:
    """The running backend; starts the default (CPU, f32) one if none is running."""
    return _current if _current is not None else init()


def is_f64() -> bool:
    return current().precision == "f64"
