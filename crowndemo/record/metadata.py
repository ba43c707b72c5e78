"""``metadata.json``: what a recording is and how far it got.

Written (atomically) when the run starts with ``complete: false, status: "running"``, again at
every frame, and at the end with the final status: "complete", "interrupted",
"unstable: <message>" or "failed: <error>" (an error, e.g. while encoding the video). A run
killed outright therefore leaves ``complete: false``.
"""
from __future__ import annotations

import json
import platform
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Optional, Sequence

from ..core.symmetry import fraction, plane_names, symmetry_name
from ..strictjson import finite_or_none
from .files import CHECKPOINT, PathLike, atomic_write_json
from .runlog import RunLog
from .sinks import COMPLETE, RUNNING

if TYPE_CHECKING:
    from ..backend import Backend
    from ..config.resolve import Resolved
    from ..core.step import Simulator
    from ..scenes.base import Scene

FORMAT = 1


def versions() -> dict:
    import numpy
    import taichi

    from .. import __version__
    return {"crowndemo": __version__, "taichi": ".".join(map(str, taichi.__version__)),
            "numpy": numpy.__version__, "python": platform.python_version()}


def build(resolved: Resolved, scene: Scene, sim: Simulator, log: RunLog, status: str,
          frame_times: Sequence[float], checkpoint_every: int,
          backend: Optional[Backend] = None, fingerprint: Optional[dict] = None,
          options: Optional[dict] = None) -> dict:
    """The metadata of a recording as a dict (JSON-ready). ``options``: how its files are
    made (rendering, snapshots), which a resumed run must keep (cli/record.py)."""
    s, h = sim.stats, sim.stats.health
    kw = resolved.crown_kwargs()
    kw["numerics"] = asdict(kw["numerics"])
    be = backend
    return finite_or_none({
        "format": FORMAT,
        "complete": status == COMPLETE, "status": status, "stopped_by": log.stopped_by,
        "preset": resolved.name, "file": resolved.label, "extends_chain": resolved.doc.files,
        "quality": resolved.quality, "dim": resolved.dim, "title": resolved.title,
        "parameters": {"values": resolved.values, "crown": kw,
                       "sources": {k: {"key": key, "file": src}
                                   for k, (key, src) in sorted(resolved.where.items())}},
        "physics": asdict(scene.physics), "sound_speed_m_s": scene.physics.c,
        "model": resolved.model.describe(),
        # mirror planes (core/symmetry.py): the particles, counts and energies are of the
        # simulated part, the crown metrics and frames of the whole
        "symmetry": symmetry_name(sim.model.mirror_planes),
        "symmetry_planes": plane_names(sim.model.mirror_planes),
        "simulated_fraction": fraction(sim.model.mirror_planes),
        "particles": {"initial": scene.counts(), "now": sim.counts()},
        "left_out": scene.info.get("left_out", []), "scene_info": scene.info,
        "t_end_s": resolved.t_end, "simulated_s": s.time, "steps": s.steps,
        "dt": {"min_s": s.dt_min, "max_s": s.dt_max, "binding_limits": dict(s.binding)},
        "health": {"max_speed_m_s": h.max_speed, "max_density_excess": h.max_density_excess,
                   "peak_max_speed_m_s": s.peak_max_speed,
                   "peak_max_density_excess": s.peak_max_density_excess,
                   "energy_start_J": s.energy_start, "energy_J": h.energy,
                   "left_domain": dict(h.left), "left_domain_total": h.left_total,
                   "nonfinite": h.nonfinite},
        "wall_seconds": {"setup": log.setup_seconds, "stepping": s.wall_seconds,
                         "starts": log.starts},
        "versions": versions(),
        "backend": None if be is None else {"arch": be.arch, "resolved_arch": be.resolved,
                                            "precision": be.precision, "seed": be.seed,
                                            "single_thread": be.single_thread,
                                            "fast_compile": be.fast_compile},
        "frames_planned": [{"index": i, "time_s": t} for i, t in enumerate(frame_times)],
        "frames": log.frames,
        "checkpoint": {"file": CHECKPOINT, "every_frames": checkpoint_every},
        "fingerprint": fingerprint,
        "recording_options": options,
    })


class MetadataSink:
    """Rewrites metadata.json at every frame and at the end."""

    def __init__(self, path: PathLike, resolved, scene, sim, log: RunLog, frame_times,
                 checkpoint_every: int, backend=None, fingerprint: Optional[dict] = None,
                 options: Optional[dict] = None):
        self.path = Path(path)
        self.args = (resolved, scene, sim, log)
        self.frame_times, self.every, self.backend = list(frame_times), checkpoint_every, backend
        self.fingerprint, self.options = fingerprint, options

    def write(self, status: str) -> dict:
        data = build(*self.args, status, self.frame_times, self.every, self.backend,
                     self.fingerprint, self.options)
        atomic_write_json(self.path, data)
        return data

    def frame(self, sim: Simulator, index: int, time: float) -> None:
        self.write(RUNNING)

    def close(self, status: str) -> None:
        self.write(status)


def read(path: PathLike) -> Optional[dict]:
    """metadata.json as a dict; None when there is none; ValueError when it is not a JSON
    object."""
    path = Path(path)
    if not path.is_file():
        return None
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    if not isinstance(data, dict):
        raise ValueError(f"{path}: not a recording's metadata (a JSON {type(data).__name__}, "
                         "not an object)")
    return data


__all__ = ["MetadataSink", "build", "read", "versions"]
