"""``crowndemo export``: a recording as ParaView files (.vtp per frame + a .pvd series), and
with --surface the liquid surface's meshes too."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

from .common import (EXIT_INTERRUPTED, EXIT_UNSTABLE, PRESET_HELP, PROG, SET_HELP, Fmt,
                     Progress, UsageError, add_quality, add_sets, load_preset, path_argument,
                     require_folder, start_backend)
from .record import _recordings_option

EXPORT_EPILOG = """\
examples:
  crowndemo export quick                           # recordings/quick -> recordings/quick/vtk/
  crowndemo export 3m-drop --out /tmp/crown        # somewhere else
  crowndemo export quick --recordings runs         # from runs/quick
  crowndemo export quick --surface                 # + the liquid surface, for ParaView/Blender

Reads RECORDINGS/PRESET (RECORDINGS: --recordings, $CROWNDEMO_RECORDINGS, else
./recordings): the frames listed in its metadata.json. When there is no recording, the
preset is recorded first, without rendering (as 'crowndemo record PRESET --no-render' with
the same --quality, --set and backend options), then exported. An interrupted recording
exports the frames it has and says how to resume it.

Writes, in the one format (VTK; --vtk is the default and may be left out),
OUT/frame_NNNNN.vtp (XML PolyData, one vertex per particle, raw binary data; point
data: velocity, pressure, number_density, kind, id; 2D runs get z = 0) and OUT/PRESET.pvd
(every frame with its time in s): open the .pvd in ParaView. With --surface, also
OUT/surface_NNNNN.vtp (the liquid surface reconstructed from the fluid particles with
splashsurf, as the frames draw it: triangles with point data Normals, speed, pressure,
height; a run with symmetry planes mirrored into the whole) and OUT/PRESET-surface.pvd.
frame_*.vtp (and surface_*.vtp) files in OUT that are not part of this export are removed. Default OUT: RECORDINGS/PRESET/vtk. All or
nothing: a snapshot that cannot be read (truncated, overwritten) is named in an error and
OUT is left as it was.
With --quality or --set, an existing recording must have been made with the same values.
"""


def _read_meta(path: Path) -> Optional[dict]:
    """A recording's metadata.json (None when there is none); UsageError naming the file when
    it cannot be read or is not a recording's (a truncated file, say)."""
    from ..record.metadata import read

    try:
        meta = read(path)
    except (OSError, ValueError) as e:          # JSONDecodeError and UnicodeDecodeError too
        raise UsageError(f"{path}: cannot read it ({e}); allowed: the metadata.json of a "
                         "recording: record it again") from None
    if meta is not None and not (isinstance(meta, dict) and _frames_ok(meta.get("frames"))
                                 and "complete" in meta):
        raise UsageError(f"{path}: not a recording's metadata (no list of frames with file "
                         "and time_s); allowed: the metadata.json of a recording: record it "
                         "again")
    return meta


def _frames_ok(frames) -> bool:
    """A list of frames, each with its file and time."""
    return isinstance(frames, list) and all(
        isinstance(f, dict) and isinstance(f.get("file"), str) and
        isinstance(f.get("time_s"), (int, float)) for f in frames)


def _export(args) -> int:
    from ..record import METADATA, RecordError, recording_dir, recordings_root
    from ..record.sinks import INTERRUPTED
    from ..record.recorder import fingerprint, record_preset

    r = load_preset(args.preset, args)
    root = Path(args.recordings) if args.recordings else recordings_root()
    folder = recording_dir(r.name, root)
    out = Path(args.out) if args.out else folder / "vtk"
    require_folder("--out" if args.out else "--out (default RECORDINGS/PRESET/vtk)", str(out))
    meta = _read_meta(folder / METADATA)
    code = 0
    if meta is None:
        require_folder(_recordings_option(args), str(folder))
        print(f"{PROG}: no recording in {folder}: recording {r.name} ({r.quality}) first",
              file=sys.stderr, flush=True)
        be = start_backend(args)
        try:
            res = record_preset(r, folder, on_step=Progress(r.t_end, args.quiet), backend=be)
        except RecordError as e:
            raise UsageError(str(e)) from None
        if not res.complete:
            resume = ("" if res.status.startswith("unstable") else
                      f"; '{PROG} record {r.name} --resume --no-render', with the same "
                      "--quality, --set and --recordings, continues it")
            print(f"{PROG}: the recording ended {res.status}{resume}", file=sys.stderr)
            code = EXIT_UNSTABLE if res.status.startswith("unstable") else EXIT_INTERRUPTED
        meta = _read_meta(folder / METADATA)
    elif args.quality is not None or args.sets:
        from ..record.checkpoint import differences
        from ..record.recorder import with_added_keys
        now = fingerprint(r, args.precision)
        diff = differences(with_added_keys(meta.get("fingerprint") or {}, now), now)
        if diff:
            raise UsageError(f"{folder} was recorded with other values ({'; '.join(diff[:3])})"
                             f"; record it again or leave out --quality/--set")
    files = [folder / f["file"] for f in meta["frames"]]
    missing = [str(f) for f in files if not f.is_file()]
    if missing:
        raise UsageError(f"{folder}: metadata.json lists frames that are missing: "
                         f"{', '.join(missing[:3])}")
    if not files:
        raise UsageError(f"{folder}: the recording has no frame yet")
    pvd = _write_vtk(files, out, r.name)
    if args.surface:
        _write_surface(files, out, r, meta)
    state = "" if meta["complete"] else f" (the recording is {meta.get('status')})"
    if meta.get("status") == INTERRUPTED:
        state += (f"; '{PROG} record {r.name} --resume', with the same --quality, --set and "
                  "--recordings, continues it")
    print(f"{PROG}: wrote {len(files)} frames, t = {meta['frames'][0]['time_s'] * 1e3:g} .. "
          f"{meta['frames'][-1]['time_s'] * 1e3:g} ms, to {out}{state}; open {pvd} in ParaView",
          file=sys.stderr)
    return code


def _write_vtk(files, out: Path, name: str) -> Path:
    """vtk.export, all or nothing, then frame_*.vtp in ``out`` not part of it removed;
    UsageError naming a damaged snapshot (``out`` is left as it was)."""
    from ..record import vtk
    from ..record.snapshots import SnapshotError

    try:
        pvd = vtk.export(files, out, name)
    except SnapshotError as e:
        raise UsageError(f"{e}; nothing exported ({out} left as it was); allowed: the "
                         f"snapshots of a whole recording: record it again ('{PROG} record "
                         f"{name}', with the same --quality, --set and --recordings)") from None
    keep = {f"{f.stem}.vtp" for f in files}
    for old in out.glob("frame_*.vtp"):
        if old.name not in keep:
            old.unlink()
    return pvd


def _write_surface(files, out: Path, r, meta: dict) -> Path:
    """surface_vtk.export with the recording's symmetry planes; UsageError naming a damaged
    snapshot; says what the reconstruction cost."""
    from ..record import surface_vtk
    from ..record.snapshots import SnapshotError

    try:
        pvd, seconds = surface_vtk.export(files, out, r.name, r.l0, surface_vtk.planes_of(meta))
    except SnapshotError as e:
        raise UsageError(f"{e}; the surface was not exported; allowed: the snapshots of a "
                         f"whole recording: record it again") from None
    print(f"{PROG}: the liquid surface of {len(files)} frames, {seconds:.2f} s a frame, to "
          f"{pvd}", file=sys.stderr)
    return pvd


def register(sub, common) -> None:
    p = sub.add_parser("export", parents=common, formatter_class=Fmt, epilog=EXPORT_EPILOG,
                       help="write a recording as ParaView files (.vtp per frame + .pvd; "
                            "--surface: the liquid's meshes too)",
                       description="Export a recording's frames for ParaView; records the "
                                   "preset first when there is no recording.")
    p.add_argument("preset", metavar="PRESET", help=PRESET_HELP)
    p.add_argument("--vtk", action="store_true",
                   help="VTK XML: frame_NNNNN.vtp per frame and PRESET.pvd (the one format, "
                        "and the default: may be left out)")
    p.add_argument("--surface", action="store_true",
                   help="also the liquid surface per frame: surface_NNNNN.vtp (triangles, "
                        "normals, speed, pressure, height) and PRESET-surface.pvd")
    p.add_argument("--out", type=path_argument, metavar="DIR",
                   help="output folder (default: RECORDINGS/PRESET/vtk)")
    p.add_argument("--recordings", type=path_argument, metavar="DIR",
                   help="folder of the recordings (default: $CROWNDEMO_RECORDINGS, else "
                        "./recordings)")
    add_quality(p, None, "quality rung, when recording first")
    add_sets(p, SET_HELP + " (when recording first)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=lambda a, argv: _export(a))
