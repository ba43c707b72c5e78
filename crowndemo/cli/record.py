"""``crowndemo record``: simulate presets and save their frames, checkpoint and metadata into
recordings/PRESET/, or resume an interrupted recording."""
from __future__ import annotations

import json
import os
import shlex
import sys
from pathlib import Path
from typing import List, Optional

from ..config import DEFAULT_QUALITY
from ..core.params import ParameterError
from .common import (CTRL_C_NOTICE, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_UNSTABLE, PRESET_HELP,
                     PROG, Fmt, Progress, UsageError, add_quality, add_sequence_options, add_sets,
                     load_presets, path_argument, print_summary, require_folder,
                     start_backend)

RECORD_EPILOG = """\
examples:
  crowndemo record quick                          # recordings/quick/: frames + metadata.json
  crowndemo record 3m-drop --quality booth        # ~289k particles, 17 frames
  crowndemo record quick --then quick-2d          # one after another, one compiled session
  crowndemo record 2m-drop --playlist presets/booth.txt   # then the seed's other scenes
  crowndemo record 3m-drop --resume               # continue after Ctrl-C (same options)
  crowndemo record quick --set scene.t_end=5e-4 --checkpoint-every 4
  crowndemo record quick --style particles --colour speed   # spheres coloured by speed

Output in RECORDINGS/PRESET/ (RECORDINGS: --recordings, $CROWNDEMO_RECORDINGS, else
./recordings): frames/frame_NNNNN.png (rendered offscreen with GGUI; needs a Vulkan driver,
e.g. Debian's mesa-vulkan-drivers; --no-render skips it; by default the liquid's surface,
reconstructed from the particles each frame, --style particles draws spheres), video.mp4
and preview.gif (made
when the recording completes; an incomplete one gets video.partial.mp4), and
snapshots/frame_NNNNN.npz (particles at t = 0 and every frame interval;
fluid only unless --all-particles), checkpoint.npz (the full state, for --resume) and
metadata.json (parameters, particle counts, dt, health, wall time, versions, frames, and
status: running, complete, interrupted or unstable). Recording a preset afresh replaces
its earlier recording, frames and videos included (said on stderr). Files are written
under a temporary name and renamed, so a file that exists is whole.

Ctrl-C stops after the current step: the frames so far are kept, a checkpoint is saved,
metadata.json says "interrupted", and the command prints how to resume (exit 130). A
resumed run with --single-thread ends bit for bit where an uninterrupted one would; --resume
of a complete recording says so and changes nothing (exit 0).
An unstable run keeps its frames, marks metadata.json "unstable: ..." and exits 3.
--max-steps stops every preset of --then and --playlist at step N (each resumable).
When the video cannot be made, its files get the .partial names, metadata.json says
"failed: ..." and the command exits 1.
"""



def extra_sinks(resolved, folder: Path, args) -> List:
    """Frame sinks that run after the snapshot of each frame: the renderer (PNG frames, then
    the MP4 and GIF), unless --no-render. Checks Vulkan before any simulation time is spent."""
    from ..render import sink_from_args
    sink = sink_from_args(args, resolved, os.fspath(folder), resume=args.resume)
    return [sink] if sink is not None else []


def _spec(r) -> str:
    """How to name the preset again: its name if that finds the same file, else its path."""
    from ..config import PresetError, find
    try:
        return r.name if find(r.name) == r.doc.path else r.label
    except PresetError:
        return r.label


# the options that shape a recording's files: a resumed run must keep those of MATCHED
MATCHED = ("render", "resolution", "style", "colour", "lang", "orbit", "all_particles")


def recording_options(args) -> dict:
    """How the command makes a recording's files (JSON-normal), kept in metadata.json."""
    from ..render.options import colour_of, style_of
    return {"render": bool(args.render), "resolution": list(args.resolution),
            "style": style_of(args), "colour": colour_of(args), "lang": args.lang,
            "orbit": float(args.orbit),
            "fps": float(args.fps), "video": bool(args.video),
            "all_particles": bool(args.all_particles),
            "checkpoint_every": int(args.checkpoint_every)}


def _option_words(options: dict) -> List[str]:
    """``options`` (recording_options) as command-line words, defaults left out."""
    from ..render import RenderSettings
    d = RenderSettings()
    words = []
    if not options["render"]:
        words.append("--no-render")
    else:
        if tuple(options["resolution"]) != tuple(d.resolution):
            words += ["--resolution", "%dx%d" % tuple(options["resolution"])]
        style = options.get("style", "particles")     # recorded before --style: spheres
        if style != d.style:
            words += ["--style", style]
        if options["colour"] != RenderSettings(style=style).colour:
            words += ["--colour", options["colour"]]
        if options["lang"] != d.lang:
            words += ["--lang", options["lang"]]
        if options["orbit"] != d.orbit:
            words.append(f"--orbit={options['orbit']:g}")     # "=": a value may start with -
        if options["fps"] != d.fps:
            words += ["--fps", f"{options['fps']:g}"]
        if not options["video"]:
            words.append("--no-video")
    if options["all_particles"]:
        words.append("--all-particles")
    if options["checkpoint_every"] != 1:
        words += ["--checkpoint-every", str(options["checkpoint_every"])]
    return words


def _check_options(folder: Path, saved: Optional[dict], r, args) -> None:
    """UsageError when --resume is asked with rendering or snapshot options other than the
    recording's (its frames and snapshots would not match), with the command that fits."""
    now = recording_options(args)
    if not isinstance(saved, dict) or not all(k in saved for k in now):
        return          # a recording made before the options were kept: not checked
    diff = [f"{k.replace('_', '-')} {_shown(saved[k])} there, {_shown(now[k])} now"
            for k in MATCHED if saved[k] != now[k]]
    if diff:
        raise UsageError(f"{folder} was recorded with other options ({'; '.join(diff)}): its "
                         f"frames and snapshots would not match. To resume: "
                         f"{_resume_command(r, args, saved)}")


def _shown(value) -> str:
    if isinstance(value, list):
        return "x".join(str(v) for v in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def _resume_command(r, args, options: Optional[dict] = None) -> str:
    """The command that resumes ``r``'s recording: these args' preset values and backend,
    and the recording options (``options``, else the args')."""
    words = [PROG, "record", _spec(r)]
    if args.quality != DEFAULT_QUALITY:
        words += ["--quality", args.quality]
    for s in args.sets:
        words += ["--set", s]
    if args.recordings:
        words += ["--recordings", args.recordings]
    for opt in ("arch", "precision"):
        if getattr(args, opt) not in (None, "f32"):
            words += [f"--{opt}", getattr(args, opt)]
    if args.single_thread:
        words.append("--single-thread")
    if args.fast_compile:
        words.append("--fast-compile")
    words += _option_words(options or recording_options(args))
    return " ".join(shlex.quote(w) for w in words + ["--resume"])


def _recordings_option(args) -> str:
    """Where the recordings folder came from, to name it in an error."""
    if args.recordings:
        return "--recordings"
    return "$CROWNDEMO_RECORDINGS" if os.environ.get("CROWNDEMO_RECORDINGS") else "recordings"


def _check_folders(root: Path, names: List[str], args) -> None:
    """UsageError, before Taichi starts, when a recording folder ROOT/NAME cannot be created
    or written (ROOT a file, a parent that cannot hold folders, no permission)."""
    from ..record import recording_dir

    for name in names:
        require_folder(_recordings_option(args), recording_dir(name, root), shown=root)


def _resume_point(r, folder: Path, args):
    """The checkpoint --resume continues from, checked before Taichi starts (the render sink,
    made next, would remove the video of the recording), with the recording's options."""
    from ..record import RecordError
    from ..record.recorder import readable_metadata, resume_point
    try:
        saved = resume_point(r, folder, args.precision)
    except RecordError as e:
        raise UsageError(str(e)) from None
    _check_options(folder, readable_metadata(folder).get("recording_options"), r, args)
    return saved


def _record(args) -> int:
    from ..control import Session
    from ..interrupt import StopRequest
    from ..record import METADATA, RecordError, recording_dir, recordings_root
    from ..record.metadata import read as read_metadata
    from ..record.recorder import AlreadyComplete, record_preset

    if args.max_steps is not None and args.max_steps < 1:
        raise ParameterError("max_steps", args.max_steps, "an integer >= 1", "command line")
    if args.checkpoint_every < 0:
        raise UsageError(f"--checkpoint-every {args.checkpoint_every}: allowed: an integer >= 0 "
                         "(frames between checkpoints; 0: only when interrupted)")
    resolved = load_presets(args)                # every mistake before any run
    names = [r.name for r in resolved]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise UsageError(f"{', '.join(twice)} listed twice: each preset records into "
                         "RECORDINGS/PRESET, so the second would replace the first")
    if args.resume and len(resolved) > 1:
        raise UsageError("--resume takes one PRESET (no --then or --playlist)")
    root = Path(args.recordings) if args.recordings else recordings_root()
    _check_folders(root, [r.name for r in resolved], args)
    resume_from = None
    if args.resume:
        try:
            resume_from = _resume_point(resolved[0], recording_dir(resolved[0].name, root), args)
        except AlreadyComplete as e:          # nothing to do: say so, touch nothing
            print(f"{PROG}: {e}", file=sys.stderr)
            _dump([{"folder": str(e.folder), **e.meta}], args)
            return 0
    be = start_backend(args)
    session = Session()
    stop = StopRequest(CTRL_C_NOTICE)
    out = []
    with stop.catching():
        for i, r in enumerate(resolved):
            folder = recording_dir(r.name, root)
            progress = Progress(r.t_end, args.quiet, args.max_steps)

            def announce(res, i=i, r=r):
                if res.replaced_frames:
                    print(f"{PROG}: replacing the earlier recording in {folder} "
                          f"({res.replaced_frames} frames)", file=sys.stderr)
                if args.quiet:
                    return
                nth = f" ({i + 1} of {len(resolved)})" if len(resolved) > 1 else ""
                c = res.scene.counts()
                how = (f"resuming at t = {res.resumed.time * 1e3:.4g} ms, step "
                       f"{res.resumed.steps:,}, frame {res.resumed.next_frame}"
                       if res.resumed else f"{len(res.frame_times)} frames")
                print(f"{PROG}: record {r.name}{nth} into {folder}, quality {r.quality}, "
                      f"{r.dim}D, {c['fluid']:,} fluid of {c['total']:,} particles, arch "
                      f"{be.resolved}, {be.precision}; to {r.t_end * 1e3:g} ms, {how}; "
                      f"{session.events[-1]}", file=sys.stderr, flush=True)

            render = extra_sinks(r, folder, args)
            try:
                res = record_preset(r, folder, render, args.resume,
                                    session=session, checkpoint_every=args.checkpoint_every,
                                    fluid_only=not args.all_particles, max_steps=args.max_steps,
                                    on_step=progress, on_start=announce, stop=stop, backend=be,
                                    resume_from=resume_from,
                                    options=recording_options(args))
            except BaseException as e:
                for sink in render:           # a run that never started: free the window
                    sink.release()
                if isinstance(e, RecordError):
                    raise UsageError(str(e)) from None
                raise
            meta = read_metadata(folder / METADATA)
            if render:
                meta = _add_render_timing(folder, meta, render[0], res)
            out.append({"folder": str(folder), **meta})
            if not args.json:
                run = {"stats": res.sim.stats, "stopped_by": res.log.stopped_by,
                       "peak": {"speed": res.sim.stats.peak_max_speed,
                                "excess": res.sim.stats.peak_max_density_excess}}
                head = (f"preset {r.name} ({r.quality}): {r.dim}D, l0 = {r.l0:g} m, U = "
                        f"{r.speed:.4g} m/s; arch {be.resolved}, {be.precision}")
                print_summary(head, run, res.sim.counts(), res.scene.physics.c,
                              res.log.setup_seconds, dim=r.dim)
                print(f"  recording   {folder}: {len(res.log.frames)} of "
                      f"{len(res.frame_times)} frames; status {res.status.split(':')[0]}")
            if render and not args.json:
                t = meta["render"]
                surface = (f" ({t['surface_seconds_per_frame']:.2f} s of it the surface)"
                           if t.get("surface_seconds") else "")
                print(f"  rendering   {t['frames']} frames, {t['render_seconds_per_frame']:.2f} s "
                      f"a frame{surface} against {t['simulation_seconds_per_frame']:.2f} s of "
                      f"simulation a frame; video and preview {t['encode_seconds']:.1f} s: "
                      f"{', '.join(os.path.basename(v) for v in t['outputs'].values()) or 'none'}")
            code = _ending(r, res, folder, args, [x.name for x in resolved[i + 1:]])
            if code is not None:
                _dump(out, args)
                return code
    _dump(out, args)
    return 0


def _ending(r, res, folder: Path, args, left: List[str]) -> Optional[int]:
    """Say how a recording that did not complete ended; the exit status when the presets
    after it (``left``) are not to be recorded, None to go on (--max-steps stops each)."""
    kept = f"kept {len(res.log.frames)} frames in {folder}"
    not_recorded = f"; not recorded: {', '.join(left)}" if left else ""
    if res.close_error is not None:
        e = res.close_error
        print(f"{PROG}: error: making the video failed ({type(e).__name__}: {e}); {kept}, "
              f"metadata.json says {res.status.split(':')[0]!r}{not_recorded}", file=sys.stderr)
        return EXIT_FAILED
    if res.status.startswith("unstable"):
        print(f"{PROG}: {res.error}", file=sys.stderr)
        print(f"{PROG}: {kept}{not_recorded}", file=sys.stderr)
        return EXIT_UNSTABLE
    if res.complete:
        return None
    t, k = res.sim.stats.time, res.sim.stats.steps
    ctrl_c = res.log.stopped_by == "ctrl-c"
    print(f"{PROG}: interrupted ({res.log.stopped_by}) at t = {t * 1e3:.4g} ms, step {k:,}; "
          f"{kept}; to resume: {_resume_command(r, args)}" + (not_recorded if ctrl_c else ""),
          file=sys.stderr)
    return EXIT_INTERRUPTED if ctrl_c else None


def _add_render_timing(folder: Path, meta: dict, sink, res) -> dict:
    """Render time per frame set against simulation time per frame (stepping only), written
    into metadata.json: rendering must not dominate a recording."""
    from ..record.files import METADATA, atomic_write_json

    timing = sink.timing()
    frames = max(timing["frames"], 1)
    timing["simulation_seconds_per_frame"] = res.sim.stats.wall_seconds / frames
    timing["outputs"] = {k: os.path.basename(v) for k, v in sink.outputs.items()}
    meta["render"] = timing
    atomic_write_json(folder / METADATA, meta)
    return meta


def _dump(out, args) -> None:
    if args.json:
        print(json.dumps(out[0] if len(out) == 1 else out, indent=2))


def register(sub, common) -> None:
    p = sub.add_parser("record", parents=common, formatter_class=Fmt, epilog=RECORD_EPILOG,
                       help="run a preset and save its rendered frames, video, snapshots, "
                            "checkpoint and metadata",
                       description="Record a preset: simulate it and write, at every frame, "
                                   "a rendered image and the particles, then a video, a "
                                   "checkpoint and metadata.json into "
                                   "RECORDINGS/PRESET/; --resume continues after Ctrl-C.")
    p.add_argument("preset", metavar="PRESET", help=PRESET_HELP)
    add_quality(p, DEFAULT_QUALITY)
    add_sets(p)
    add_sequence_options(p)
    p.add_argument("--resume", action="store_true",
                   help="continue from RECORDINGS/PRESET/checkpoint.npz with the same "
                        "--quality, --set, --precision and rendering and snapshot options "
                        "as the first time (the interruption prints the command; other "
                        "values are refused)")
    p.add_argument("--recordings", type=path_argument, metavar="DIR",
                   help="folder of the recordings (default: $CROWNDEMO_RECORDINGS, else "
                        "./recordings); each preset goes to DIR/PRESET")
    p.add_argument("--checkpoint-every", type=int, default=1, metavar="K",
                   help="save the checkpoint every K frames; 0: only when interrupted "
                        "(default: 1)")
    p.add_argument("--all-particles", action="store_true",
                   help="snapshots with wall and dummy particles too (default: fluid only)")
    p.add_argument("--max-steps", type=int, metavar="N",
                   help="stop each preset at step N (counted from t = 0) as if interrupted: "
                        "a checkpoint is saved and --resume continues (exit 0)")
    p.add_argument("--json", action="store_true",
                   help="print metadata.json (a list with several presets)")
    from ..render import add_render_options
    add_render_options(p)
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=lambda a, argv: _record(a))
