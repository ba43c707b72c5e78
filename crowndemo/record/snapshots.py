"""Particle snapshots: one compressed ``.npz`` per frame, ``snapshots/frame_00000.npz``.

Each holds, in particle-id order: ``pos`` (N x dim, m), ``vel`` (m/s), ``pressure`` (Pa, from
the number density at the frame's positions, S21), ``number_density``, ``kind`` (0 fluid,
1 wall, 2 dummy, 3 gone), ``id``, and the scalars ``time`` (s) and ``index``. Fluid particles
only by default (parked particles are counted in metadata.json instead).
"""
from __future__ import annotations

from pathlib import Path
from typing import Dict

import numpy as np

from ..core.state import FLUID
from .files import SNAPSHOTS, PathLike, atomic_write, frame_name
from .runlog import RunLog

FIELDS = ("pos", "vel", "pressure", "number_density", "kind", "id")


class SnapshotSink:
    """Writes the particles at every frame and enters the frame in the run log."""

    def __init__(self, recording: PathLike, log: RunLog, fluid_only: bool = True):
        self.recording = Path(recording)
        self.folder = self.recording / SNAPSHOTS
        self.log, self.fluid_only = log, fluid_only

    def frame(self, sim, index: int, time: float) -> None:
        sim.refresh_pressure()              # P and n at the frame's positions (output only)
        path = self.folder / frame_name(index)
        write(path, sim.snapshot(), index, time, self.fluid_only)
        self.log.add_frame(index, time, path.relative_to(self.recording).as_posix())

    def close(self, status: str) -> None:
        pass


def write(path: PathLike, snap: Dict[str, np.ndarray], index: int, time: float,
          fluid_only: bool = True) -> None:
    keep = snap["kind"] == FLUID if fluid_only else slice(None)
    arrays = {k: snap[k][keep] for k in FIELDS}
    atomic_write(path, lambda f: np.savez_compressed(
        f, time=np.float64(time), index=np.int64(index), **arrays))


def read(path: PathLike) -> Dict[str, np.ndarray]:
    """A snapshot as a dict of arrays (``time`` and ``index`` as Python numbers)."""
    with np.load(path, allow_pickle=False) as z:
        out = {k: z[k] for k in z.files}
    out["time"], out["index"] = float(out["time"]), int(out["index"])
    return out


def remove_from(folder: PathLike, first: int = 0) -> int:
    """Delete the snapshots with index >= ``first``; returns how many."""
    gone = 0
    for p in sorted(Path(folder).glob("frame_*.npz")):
        if int(p.stem[len("frame_"):]) >= first:
            p.unlink()
            gone += 1
    return gone


__all__ = ["SnapshotSink", "write", "read", "remove_from", "FIELDS"]
