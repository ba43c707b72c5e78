"""``record_preset``: run a preset and hand every frame to a list of sinks (snapshots, any
extra sinks such as a renderer, the checkpoint, metadata.json), or resume such a run."""
from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable, List, Optional, Sequence

from ..core.health import InstabilityError
from ..interrupt import StopRequest, StopRun, stop_if_asked
from ..strictjson import finite_or_none
from . import checkpoint as ckpt
from . import snapshots
from .crown import CrownSink
from .files import CHECKPOINT, METADATA, SNAPSHOTS, PathLike, remove_rendered
from .metadata import MetadataSink
from .metadata import read as read_metadata
from .runlog import RunLog
from .sinks import COMPLETE, INTERRUPTED, unstable

if TYPE_CHECKING:
    from ..backend import Backend
    from ..config.resolve import Resolved
    from ..control import Session


class RecordError(ValueError):
    """A recording that cannot be made or resumed as asked (one line, for the user)."""


class AlreadyComplete(Exception):
    """``--resume`` of a complete recording: nothing to resume, nothing is touched."""

    def __init__(self, folder: Path, meta: dict):
        frames = meta.get("frames") or []
        super().__init__(f"{folder} is already complete ({len(frames)} frames to t = "
                         f"{(meta.get('simulated_s') or 0.0) * 1e3:.4g} ms): nothing to "
                         "resume, nothing changed; record without --resume to record it afresh")
        self.folder, self.meta = folder, meta


@dataclass
class RecordResult:
    status: str                     # complete | interrupted | unstable: ... | failed: ...
    folder: Path
    resolved: object
    scene: object
    sim: object
    log: RunLog
    frame_times: List[float]
    resumed: Optional[ckpt.Checkpoint] = None
    error: Optional[BaseException] = None
    replaced_frames: int = 0        # frames of an earlier recording removed at the start
    close_error: Optional[BaseException] = None   # a sink that failed to close (encoding)

    @property
    def complete(self) -> bool:
        return self.status == COMPLETE


def frame_times(resolved: Resolved) -> List[float]:
    """The recorded frames: t = 0 and every frame interval to the end time."""
    return [0.0] + list(resolved.frame_times())


def fingerprint(resolved: Resolved, precision: str) -> dict:
    """What must not change between a checkpoint and its resumption (JSON-normal form)."""
    kw = resolved.crown_kwargs()
    kw["numerics"] = asdict(kw["numerics"])
    data = {"preset": resolved.name, "quality": resolved.quality, "precision": precision,
            "crown": kw, "frame_times": frame_times(resolved)}
    return json.loads(json.dumps(finite_or_none(data)))


# Fingerprint keys added after the checkpoint format (FORMAT 1, dd88632), each with the value
# that ran before it existed, by the commit that added it: a checkpoint or recording that
# lacks a key was made with that value. SAME: an implementation choice whose results equal
# the other's to float rounding (core/params.py), so any value now continues it.
SAME = object()
ADDED_KEYS = {
    ("crown", "numerics", "collision"): 0.0,              # a937380: no collisions before it
    ("crown", "numerics", "restitution"): 0.2,            # a937380 (read with collisions only)
    ("crown", "numerics", "neighbour_list"): SAME,        # ba6a28f
    ("crown", "numerics", "cells_per_re"): SAME,          # af08c90
    ("crown", "numerics", "wall_model"): "particles",     # 6c534cf
    ("crown", "numerics", "courant_speed"): "absolute",   # 1843f81
    ("crown", "numerics", "approach"): 0.5,               # 1843f81 (read with "relative" only)
    ("crown", "numerics", "mirror_planes"): [],           # 6889de4
    ("crown", "numerics", "predictor_list"): SAME,        # 61e0a5a
    ("crown", "numerics", "surface_tension"): "potential",  # fa57f31
    ("crown", "numerics", "viscosity"): "laplacian",      # f50bdf2
    ("crown", "numerics", "stress_pairs"): "all",         # C3b, 2026-12-08
    ("crown", "symmetry"): "full",                        # e651047
    ("crown", "trim_reach"): 2.0,                         # e651047 (crown.TRIM_REACH)
}


def with_added_keys(saved: dict, now: dict) -> dict:
    """``saved`` (a fingerprint) with each ADDED_KEYS key it lacks set to the value that ran
    before the key existed (now's value for a SAME key); the keys it has are left as they are."""
    out = json.loads(json.dumps(saved))
    for path, before in ADDED_KEYS.items():
        into, there = out, now
        for k in path[:-1]:
            into, there = into.get(k), (there or {}).get(k)
            if not isinstance(into, dict):
                break
        else:
            if path[-1] not in into:
                into[path[-1]] = (there or {}).get(path[-1]) if before is SAME else before
    return out


def _other_parameters(path: Path, saved: dict, now: dict) -> None:
    """RecordError naming the keys whose values differ, if any (a key that came after the
    file counts as the value that ran before it: ADDED_KEYS)."""
    diff = ckpt.differences(with_added_keys(saved, now), now)
    if diff:
        raise RecordError(f"{path} was made with other parameters ("
                          f"{'; '.join(diff[:4])}{'; ...' if len(diff) > 4 else ''}); "
                          "resume with the same preset, --quality, --set and --precision, "
                          "or record without --resume")


def readable_metadata(folder: PathLike) -> dict:
    """The recording's metadata.json; {} when it is missing or unreadable (for a resume the
    checkpoint decides)."""
    try:
        return read_metadata(Path(folder) / METADATA) or {}
    except (OSError, ValueError):
        return {}


def resume_point(resolved: Resolved, out_dir: PathLike, precision: str) -> ckpt.Checkpoint:
    """The checkpoint that ``--resume`` continues from, checked before anything runs or is
    written: AlreadyComplete when metadata.json says the recording is complete; RecordError
    when there is no checkpoint or either was made with other parameters."""
    folder = Path(out_dir)
    now = fingerprint(resolved, precision)
    meta = readable_metadata(folder)
    if meta.get("complete") is True:
        _other_parameters(folder / METADATA, meta.get("fingerprint") or {}, now)
        raise AlreadyComplete(folder, meta)
    try:
        saved = ckpt.load(folder / CHECKPOINT)
    except ckpt.CheckpointError as e:
        raise RecordError(f"{e}; record without --resume to start afresh") from None
    _other_parameters(folder / CHECKPOINT, saved.fingerprint, now)
    return saved


def failed(e: BaseException) -> str:
    """The status of a recording that an error ended."""
    return f"failed: {type(e).__name__}: {e}"


def _close(sinks: Sequence, status: str, result: RecordResult) -> str:
    """Close every sink with ``status``; returns the final status. A sink whose close fails
    (the video encoder) is kept in ``result.close_error``; a run that had completed then
    ends "failed: ..." (Ctrl-C: "interrupted") for the sinks after it, metadata.json last,
    so a recording is never left "running" or marked complete without its files."""
    for sink in sinks:
        try:
            sink.close(status)
        except (Exception, KeyboardInterrupt) as e:
            result.close_error = result.close_error or e
            if status == COMPLETE and isinstance(e, KeyboardInterrupt):
                status, result.log.stopped_by = INTERRUPTED, "ctrl-c (at once)"
            elif status == COMPLETE:
                status = failed(e)
    return status


def record_preset(resolved: Resolved, out_dir: PathLike, sinks_extra: Sequence = (),
                  resume: bool = False, *, session: Optional[Session] = None,
                  checkpoint_every: int = 1, fluid_only: bool = True,
                  max_steps: Optional[int] = None, on_step: Optional[Callable] = None,
                  on_start: Optional[Callable] = None, stop: Optional[StopRequest] = None,
                  backend: Optional[Backend] = None,
                  resume_from: Optional[ckpt.Checkpoint] = None,
                  options: Optional[dict] = None) -> RecordResult:
    """Record ``resolved`` (a config.Resolved) into ``out_dir``; returns how it ended.

    ``sinks_extra`` are frame sinks called after the snapshot and the crown metrics (which
    enter the frame's entry of metadata.json's ``frames``) and before the checkpoint and
    metadata. ``resume`` continues from ``out_dir/checkpoint.npz`` (``resume_from``: that
    checkpoint, already loaded by ``resume_point``), raising what ``resume_point`` raises
    (AlreadyComplete, RecordError) before anything is written. ``stop`` is an object whose
    ``requested`` turns true to stop after the current step (Ctrl-C); ``max_steps`` stops at
    that step count (resumed steps included); both end "interrupted" with a checkpoint to
    resume from.
    An InstabilityError ends "unstable: ..." (returned in ``error``, not raised); frames
    written so far are kept. A sink that fails to close (the video encoder) is returned in
    ``close_error``, not raised (Ctrl-C is, once every sink is closed); a run that had
    completed then ends "failed: ...". ``on_step(sim)`` runs after every step (progress),
    ``on_start(result)`` once the simulator is loaded. ``options``: how the files are made
    (the command's rendering and snapshot options), kept in metadata.json for ``--resume``.
    A fresh recording first removes an earlier one's snapshots, checkpoint, metadata, frames
    and videos.
    """
    from .. import backend as backend_mod
    from ..control import Session

    t0 = time.perf_counter()
    be = backend or backend_mod.current()
    folder = Path(out_dir)
    frames = frame_times(resolved)
    print_ = fingerprint(resolved, be.precision)
    saved = None
    replaced = 0
    if resume:
        saved = resume_from or resume_point(resolved, folder, be.precision)
        snapshots.remove_from(folder / SNAPSHOTS, saved.next_frame)   # re-made from here
    else:       # an earlier recording's files would pass for this one's (frames too)
        replaced = snapshots.remove_from(folder / SNAPSHOTS, 0)
        for name in (CHECKPOINT, METADATA):
            (folder / name).unlink(missing_ok=True)
        if folder.is_dir():
            remove_rendered(folder)
    folder.mkdir(parents=True, exist_ok=True)

    session = session or Session()
    scene = resolved.build_scene()
    sim = session.load(scene)
    if saved is not None:
        sim.restore_state(saved.saved)
        log, start = saved.log, saved.next_frame
    else:
        log, start = RunLog(), 0
    result = RecordResult("running", folder, resolved, scene, sim, log, frames, saved,
                          replaced_frames=replaced)
    checkpoint = ckpt.CheckpointSink(folder / CHECKPOINT, sim, log, print_, checkpoint_every,
                                     start)
    meta = MetadataSink(folder / METADATA, resolved, scene, sim, log, frames, checkpoint_every,
                        be, print_, options)
    sinks = [snapshots.SnapshotSink(folder, log, fluid_only), CrownSink(resolved, scene, log),
             *sinks_extra, checkpoint, meta]
    log.start(sim.stats.steps, time.perf_counter() - t0)
    log.stopped_by = None
    meta.write("running")
    if on_start:
        on_start(result)

    def on_frame(s, i: int) -> None:
        index = start + i
        for sink in sinks:
            sink.frame(s, index, frames[index])

    def after_step(s) -> None:
        if on_step:
            on_step(s)
        stop_if_asked(s.stats.steps, max_steps, stop)

    closing = sinks
    try:
        stop_if_asked(sim.stats.steps, max_steps, None)
        sim.run(resolved.t_end, frames[start:], on_frame=on_frame, on_step=after_step)
        status = COMPLETE
    except StopRun as e:
        status, log.stopped_by = INTERRUPTED, e.by
    except InstabilityError as e:
        status, result.error = unstable(str(e)), e
    except KeyboardInterrupt as e:    # a second Ctrl-C, perhaps inside a step: no checkpoint
        status, log.stopped_by, result.error = INTERRUPTED, "ctrl-c (at once)", e
        closing = [k for k in sinks if k is not checkpoint]
    except Exception as e:
        status, result.error = failed(e), e
        closing = [k for k in sinks if k is not checkpoint]
    result.status = _close(closing, status, result)
    if isinstance(result.error, (KeyboardInterrupt, Exception)) and not isinstance(
            result.error, InstabilityError):
        raise result.error
    if isinstance(result.close_error, KeyboardInterrupt):
        raise result.close_error
    return result


__all__ = ["record_preset", "resume_point", "readable_metadata", "RecordResult", "RecordError",
           "AlreadyComplete",
           "fingerprint", "frame_times"]
