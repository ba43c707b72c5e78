"""Checkpoints: the full restartable state of a recording in one ``checkpoint.npz``.

It holds every persistent particle field in storage order (exit reasons and parked particles
included), the health counters, the run statistics (health peaks and wall time included) with
the dt and binding logs, the last health report (which sets the next dt), the run log (frames,
wall times, starts), the index of the next frame, and a fingerprint of the parameters, so
that ``--resume`` refuses a checkpoint of other parameters. With ``Simulator.restore_state``
the resumed run takes the same steps as an uninterrupted one (bit for bit on one thread).
"""
from __future__ import annotations

import json
from array import array
from collections import Counter
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Dict, List

import numpy as np

from ..core.health import HealthReport
from ..core.step import RunStats, Simulator
from .files import PathLike, atomic_write
from .runlog import RunLog
from .sinks import INTERRUPTED
from .snapshots import NPZ_ERRORS, open_npz, why

FORMAT = 1


class CheckpointError(ValueError):
    """A checkpoint that is missing, unreadable or of other parameters."""


@dataclass
class Checkpoint:
    saved: dict               # Simulator.save_state()
    log: RunLog
    next_frame: int
    fingerprint: dict

    @property
    def time(self) -> float:
        return self.saved["stats"].time

    @property
    def steps(self) -> int:
        return self.saved["stats"].steps


# RunStats fields saved as they are; binding, the logs and the health report need converting
_LOGS = ("binding", "dt_log", "bound_log", "health")
_SCALARS = tuple(f.name for f in fields(RunStats) if f.name not in _LOGS)


def _stats_json(s: RunStats) -> dict:
    d = {k: getattr(s, k) for k in _SCALARS}
    d.update(binding=dict(s.binding), health=asdict(s.health))
    return d


def _stats_from(d: dict, dt_log: np.ndarray, bound_log: np.ndarray, log: dict) -> RunStats:
    """RunStats from ``_stats_json``. Checkpoints from before the peaks moved into RunStats
    kept them in the run log; without either, the last health report is the best bound."""
    h = HealthReport(**d["health"])
    scalars = {k: d[k] for k in _SCALARS if k in d}
    scalars.setdefault("peak_max_speed", log.get("peak_max_speed", h.max_speed))
    scalars.setdefault("peak_max_density_excess",
                       log.get("peak_max_density_excess", h.max_density_excess))
    return RunStats(**scalars, binding=Counter(d["binding"]), health=h,
                    dt_log=array("d", dt_log.tolist()), bound_log=array("B", bound_log.tolist()))


def save(path: PathLike, saved: dict, log: RunLog, next_frame: int, fingerprint: dict) -> None:
    """Write ``Simulator.save_state()`` and the run log atomically to ``path``."""
    stats = saved["stats"]
    meta = {"format": FORMAT, "next_frame": next_frame, "fingerprint": fingerprint,
            "stats": _stats_json(stats), "n_fluid": saved["n_fluid"], "log": log.to_json()}
    arrays = {f"particles/{k}": v for k, v in saved["particles"].items()}
    arrays.update({f"lists/{k}": v for k, v in saved.get("lists", {}).items()})
    arrays.update(health_counters=saved["health_counters"],
                  dt_log=np.asarray(stats.dt_log, dtype=np.float64),
                  bound_log=np.asarray(stats.bound_log, dtype=np.uint8),
                  meta=np.array(json.dumps(meta)))
    atomic_write(path, lambda f: np.savez_compressed(f, **arrays))


def load(path: PathLike) -> Checkpoint:
    """The checkpoint in ``path``; CheckpointError naming the file when there is none, it is
    damaged (truncated, overwritten) or of another format."""
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"{path}: no checkpoint to resume from")
    try:
        return _read(path)
    except CheckpointError:
        raise
    except NPZ_ERRORS + (TypeError,) as e:
        raise CheckpointError(f"{path}: unreadable checkpoint ({why(e)})") from None


def _read(path: Path) -> Checkpoint:
    with open_npz(path) as z:
        meta = json.loads(str(z["meta"]))
        if not isinstance(meta, dict):
            raise ValueError("its meta entry is not a JSON object")
        if meta.get("format") != FORMAT:
            raise CheckpointError(f"{path}: checkpoint format {meta.get('format')!r}; this "
                                  f"version reads format {FORMAT}")
        for k in ("stats", "log", "fingerprint"):
            if not isinstance(meta.get(k), dict):
                raise ValueError(f"its meta entry has no {k}")
        particles = {k.split("/", 1)[1]: z[k] for k in z.files if k.startswith("particles/")}
        saved = {"particles": particles, "health_counters": z["health_counters"],
                 "stats": _stats_from(meta["stats"], z["dt_log"], z["bound_log"], meta["log"]),
                 "n_fluid": meta["n_fluid"]}
        lists = {k.split("/", 1)[1]: z[k] for k in z.files if k.startswith("lists/")}
        if lists:           # the density pass's lists for the next predictor (Simulator)
            saved["lists"] = lists
    return Checkpoint(saved, RunLog.from_json(meta["log"]), int(meta["next_frame"]),
                      meta["fingerprint"])


def differences(saved: dict, now: dict, prefix: str = "") -> List[str]:
    """Keys whose values differ between two fingerprints, as 'key: saved -> now'; a long
    list is summarised ('frames: 21 every 0.1 ms to 2 ms -> 17 every 0.25 ms to 4 ms')."""
    def short(v, ms: bool) -> str:
        if not (isinstance(v, list) and len(v) > (1 if ms else 4) and
                all(isinstance(x, (int, float)) for x in v)):
            return repr(v)
        f, u = (1e3, " ms") if ms else (1, "")
        steps = [y - x for x, y in zip(v, v[1:])]
        even = all(abs(d - steps[0]) <= 1e-9 * max(1.0, abs(steps[0])) for d in steps[:-1])
        how = f"every {steps[0] * f:g}{u}" if even else f"from {v[0] * f:g}{u}"
        return f"{len(v)} {how} to {v[-1] * f:g}{u}"

    out = []
    for k in sorted(set(saved) | set(now)):
        a, b = saved.get(k), now.get(k)
        if isinstance(a, dict) and isinstance(b, dict):
            out += differences(a, b, f"{prefix}{k}.")
        elif a != b:
            ms = k == "frame_times"
            name = "frames" if ms else k
            out.append(f"{prefix}{name}: {short(a, ms)} -> {short(b, ms)}")
    return out


class CheckpointSink:
    """Saves a checkpoint every ``every`` frames (0: never) and when the run is interrupted."""

    def __init__(self, path: PathLike, sim, log: RunLog, fingerprint: Dict, every: int = 1,
                 next_frame: int = 0):
        if every < 0:
            raise ValueError(f"checkpoint every {every} frames; allowed: an integer >= 0")
        self.path, self.sim, self.log = Path(path), sim, log
        self.fingerprint, self.every, self.next_frame = fingerprint, every, next_frame

    def frame(self, sim: Simulator, index: int, time: float) -> None:
        self.next_frame = index + 1
        if self.every and index % self.every == 0:
            self.save()

    def save(self) -> None:
        save(self.path, self.sim.save_state(), self.log, self.next_frame, self.fingerprint)

    def close(self, status: str) -> None:
        if status == INTERRUPTED:      # stopped between steps: a consistent state
            self.save()


__all__ = ["Checkpoint", "CheckpointError", "CheckpointSink", "save", "load", "differences"]
