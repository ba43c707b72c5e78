"""Particle snapshots: one compressed ``.npz`` per frame, ``snapshots/frame_00000.npz``.

Each holds, in particle-id order: ``pos`` (N x dim, m), ``vel`` (m/s), ``pressure`` (Pa, from
the number density at the frame's positions, S21), ``number_density``, ``kind`` (0 fluid,
1 wall, 2 dummy, 3 gone), ``id``, and the scalars ``time`` (s) and ``index``. Fluid particles
only by default (parked particles are counted in metadata.json instead).
"""
from __future__ import annotations

import zipfile
import zlib
from pathlib import Path
from typing import TYPE_CHECKING, Dict, Sequence

import numpy as np

from ..core.state import FLUID
from .files import SNAPSHOTS, PathLike, atomic_write, frame_name
from .runlog import RunLog

if TYPE_CHECKING:
    from ..core.step import Simulator

FIELDS = ("pos", "vel", "pressure", "number_density", "kind", "id")
SCALARS = ("time", "index")
# what reading a damaged .npz raises (a truncated archive, a bad CRC, a stray .npy or text)
NPZ_ERRORS = (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile, zlib.error)


class SnapshotError(ValueError):
    """A snapshot file that cannot be read or is not a snapshot (one line, naming it)."""


class SnapshotSink:
    """Writes the particles at every frame and enters the frame in the run log."""

    def __init__(self, recording: PathLike, log: RunLog, fluid_only: bool = True):
        self.recording = Path(recording)
        self.folder = self.recording / SNAPSHOTS
        self.log, self.fluid_only = log, fluid_only

    def frame(self, sim: Simulator, index: int, time: float) -> None:
        sim.refresh_pressure()              # P and n at the frame's positions (output only)
        path = self.folder / frame_name(index)
        write(path, sim.snapshot(), index, time, self.fluid_only, sim.model.mirror_planes)
        self.log.add_frame(index, time, path.relative_to(self.recording).as_posix())

    def close(self, status: str) -> None:
        pass


def write(path: PathLike, snap: Dict[str, np.ndarray], index: int, time: float,
          fluid_only: bool = True, symmetry_planes: Sequence[int] = ()) -> None:
    """One frame's particles; ``symmetry_planes``: the mirror planes of a half or quarter run
    (core/symmetry.py; axes, 0: x = 0, 1: y = 0), stored so that a reader can mirror it."""
    keep = snap["kind"] == FLUID if fluid_only else slice(None)
    arrays = {k: snap[k][keep] for k in FIELDS}
    atomic_write(path, lambda f: np.savez_compressed(
        f, time=np.float64(time), index=np.int64(index),
        symmetry_planes=np.asarray(tuple(symmetry_planes), dtype=np.int64), **arrays))


def open_npz(path: PathLike) -> np.lib.npyio.NpzFile:
    """``np.load`` of an .npz archive; ValueError, short, when the file is none (truncated,
    or overwritten by something else), where numpy would talk of pickles."""
    with open(path, "rb") as f:
        if not zipfile.is_zipfile(f):
            raise ValueError("not an .npz archive: truncated or another kind of file")
    return np.load(path, allow_pickle=False)


def why(e: BaseException) -> str:
    """What went wrong reading an .npz file, in a few words."""
    text = getattr(e, "strerror", None) or str(e) or type(e).__name__
    damaged = isinstance(e, (zipfile.BadZipFile, zlib.error, EOFError))
    return f"damaged data: {text}" if damaged else text


def read(path: PathLike) -> Dict[str, np.ndarray]:
    """A snapshot as a dict of arrays (``time`` and ``index`` as Python numbers);
    SnapshotError naming the file when it is damaged or not a snapshot."""
    try:
        with open_npz(path) as z:
            out = {k: z[k] for k in z.files}
        _check(out)
        out["time"], out["index"] = float(out["time"]), int(out["index"])
        # the simulated part's mirror planes; none in a whole run (and in older recordings)
        out["symmetry_planes"] = tuple(int(a) for a in out.get("symmetry_planes", ()))
    except NPZ_ERRORS as e:
        raise SnapshotError(f"{path}: cannot read the snapshot ({why(e)})") from None
    return out


def _check(snap: Dict[str, np.ndarray]) -> None:
    """ValueError unless ``snap`` holds every field: N x 2 or N x 3 positions and velocities,
    one value per particle of the rest, one number for time and index."""
    missing = [k for k in FIELDS + SCALARS if k not in snap]
    if missing:
        raise ValueError(f"no {', '.join(missing)}")
    pos = snap["pos"]
    if pos.ndim != 2 or pos.shape[1] not in (2, 3) or snap["vel"].shape != pos.shape:
        raise ValueError(f"positions {pos.shape}, velocities {snap['vel'].shape}; "
                         "expected N x 2 or N x 3 each")
    bad = [k for k in FIELDS[2:] if snap[k].shape != (len(pos),)]
    if bad:
        raise ValueError(f"{', '.join(bad)}: not one value per particle")
    bad = [k for k in SCALARS if snap[k].size != 1]
    if bad:
        raise ValueError(f"{', '.join(bad)}: not one number")


def remove_from(folder: PathLike, first: int = 0) -> int:
    """Delete the snapshots with index >= ``first``; returns how many."""
    gone = 0
    for p in sorted(Path(folder).glob("frame_*.npz")):
        if int(p.stem[len("frame_"):]) >= first:
            p.unlink()
            gone += 1
    return gone


__all__ = ["SnapshotSink", "SnapshotError", "write", "read", "open_npz", "remove_from",
           "FIELDS", "NPZ_ERRORS"]
