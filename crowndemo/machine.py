"""The machine a measurement ran on, for the recorded reports (BENCHMARKS.md, VALIDATION.md,
docs/regime.md): CPU model, cores, GPU, OS and software versions."""
from __future__ import annotations

import os
import platform
import subprocess
from typing import Dict, Optional


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def gpu_name() -> Optional[str]:
    try:
        out = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    names = [s.strip() for s in out.stdout.splitlines() if s.strip()]
    return ", ".join(names) if out.returncode == 0 and names else None


def os_name() -> str:
    return f"{platform.system()} {platform.release()}"


def machine_line() -> str:
    """The machine in one line, as validate and sweep --record report it: "CPU model, N cores,
    OS release"."""
    return f"{cpu_model()}, {os.cpu_count() or 1} cores, {os_name()}"


def machine() -> Dict:
    import numpy
    import taichi as ti

    info = {"cpu": cpu_model(), "cores": os.cpu_count() or 1, "usable_cores": usable_cores(),
            "python": platform.python_version(), "taichi": ".".join(map(str, ti.__version__)),
            "numpy": numpy.__version__, "os": os_name()}
    gpu = gpu_name()
    if gpu:
        info["gpu"] = gpu
    return info
