"""Recordings: what a run leaves on disk, one job per module.

- ``sinks``      the frame-sink interface (``frame(sim, index, time)``, ``close(status)``);
- ``files``      the recordings/ layout, whether a folder can take one, atomic writes;
- ``runlog``     frames written, wall times, starts (kept across a resume);
- ``snapshots``  particles per frame, ``snapshots/frame_00000.npz``;
- ``crown``      the crown metrics per frame (sheet coherence too), into metadata.json;
- ``checkpoint`` the restartable state, ``checkpoint.npz``, for ``--resume``;
- ``metadata``   ``metadata.json``: parameters, counts, dt, health, wall time, status;
- ``vtk``        ParaView ``.vtp`` per frame + ``.pvd`` (writer and reader);
- ``recorder``   ``record_preset``: run a preset through the sinks, or resume it
  (``resume_point`` checks a resume first: AlreadyComplete, RecordError).

Layout of ``recordings/PRESET/``: ``metadata.json``, ``checkpoint.npz``,
``snapshots/frame_NNNNN.npz``, and ``vtk/`` after ``crowndemo export PRESET --vtk``.
"""
from .files import CHECKPOINT, METADATA, SNAPSHOTS, recording_dir, recordings_root
from .recorder import (AlreadyComplete, RecordError, RecordResult, fingerprint, frame_times,
                       record_preset, resume_point)
from .sinks import COMPLETE, INTERRUPTED, RUNNING, FrameSink

__all__ = ["record_preset", "resume_point", "RecordResult", "RecordError", "AlreadyComplete",
           "FrameSink", "fingerprint", "frame_times", "recording_dir", "recordings_root",
           "METADATA", "CHECKPOINT", "SNAPSHOTS", "COMPLETE", "INTERRUPTED", "RUNNING"]
