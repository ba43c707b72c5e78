"""``crowndemo play``: the booth loop over recordings, in a window or into a video file."""
from __future__ import annotations

import os
import shlex
import sys

from .common import PROG, Fmt, UsageError, path_argument, start_backend

PLAY_EPILOG = """\
examples:
  crowndemo play                                   # every recording in recordings/, forever
  crowndemo play 2m-drop 3m-drop --loops 3         # these two, three times
  crowndemo play --lang ja                         # Japanese title cards
  crowndemo play --headless --out reel.mp4 --loops 1   # the booth reel as a video file
  crowndemo play recordings/quick --partial        # a folder; play it even if incomplete

A recording is a folder RECORDINGS/NAME (see 'crowndemo record'; RECORDINGS: --recordings,
$CROWNDEMO_RECORDINGS, else ./recordings) with frames/frame_*.png or video.mp4. Each is
preceded by a title card (the preset's title and description). A recording whose
metadata.json does not say "status": "complete" (without metadata: that has no video.mp4)
is skipped with a warning; --partial plays it with an "incomplete" marker. One recorded with
--no-render (metadata.json, no frames) has nothing to play: skipped with a warning too.
--out may not be a recording's own video (RECORDINGS/NAME/video.mp4): the reel would replace it.
The window opens at the top-left corner at --resolution (GGUI has no full-screen mode: give
the screen's size); Esc or closing it stops. Without a display, use --headless --out.
"""


def _check_out(out: str) -> None:
    """UsageError unless ``out`` is a video file name that can be written."""
    from ..render.video import VIDEO_SUFFIXES, is_video_path
    if not is_video_path(out):
        raise UsageError(f"--out {out}: the reel is written as H.264 MP4; give a file name "
                         "ending in " + " or ".join(VIDEO_SUFFIXES))
    if os.path.isdir(out):
        raise UsageError(f"--out {out}: is a folder; give a video file name")
    from ..record.files import folder_problem
    bad = folder_problem(os.path.dirname(os.path.abspath(out)))
    if bad:
        raise UsageError(f"--out {out}: cannot write into {bad[0]} ({bad[1]})")


def _check_not_a_recording_file(out: str, folders) -> None:
    """UsageError when ``out`` is a video of one of the recordings in ``folders``."""
    from ..render.player import owner_of
    hit = owner_of(out, folders)
    if hit:
        folder, name = hit
        raise UsageError(f"--out {out}: is the recording {folder}'s own video ({name}): the "
                         "reel would replace it; give a file outside the recordings' folders")


def _check_not_a_new_recording(out: str, root: str) -> None:
    """UsageError when ``out`` would be a video*.mp4 in a folder of the recordings folder:
    the next play would take that folder for a recording (a video without metadata)."""
    from ..render.player import owner_of
    target = os.path.realpath(out)
    folder = os.path.dirname(target)
    if os.path.dirname(folder) == os.path.realpath(root) and owner_of(out, [folder]):
        raise UsageError(f"--out {out}: a {os.path.basename(target)} in a folder of {root}/ "
                         f"would be played next time as a recording named "
                         f"{os.path.basename(folder)}; give another name or a file outside "
                         f"{root}/")


def _no_recordings(root: str, frameless) -> str:
    """Why there is nothing to play in ``root``, and how to record something that plays."""
    from ..record import recordings_root
    from ..render.player import NO_FRAMES
    if not frameless:
        return f"no recordings in {root}/ (make one with '{PROG} record PRESET')"
    where = "" if root == os.fspath(recordings_root()) else f" --recordings {shlex.quote(root)}"
    return (f"the recordings in {root}/ ({', '.join(frameless)}) have {NO_FRAMES}; record "
            f"one again without --no-render to play it, e.g. '{PROG} record {frameless[0]}"
            f"{where}' (with the --quality and --set it was made with)")


def _check_args(args) -> None:
    """UsageError for a bad option; fills in the defaults that depend on others."""
    from ..record import recordings_root
    if args.loops is not None and args.loops < 1:
        raise UsageError(f"--loops {args.loops}: must be >= 1")
    if args.headless and not args.out:
        raise UsageError("--headless needs --out FILE.mp4")
    if args.out and not args.headless:
        raise UsageError(f"--out {args.out}: only with --headless (without it the reel plays "
                         "in a window)")
    if args.headless:
        _check_out(args.out)
        if args.loops is None:
            args.loops = 1                     # a file cannot loop forever
    if not args.dir:                           # as record: $CROWNDEMO_RECORDINGS, else ./
        args.dir = os.fspath(recordings_root())


def _count(n: int, word: str) -> str:
    """'1 loop', '3 loops'."""
    return f"{n} {word}{'' if n == 1 else 's'}"


def _play(args, argv) -> int:
    from ..render import player
    from ..render.window import check_available

    _check_args(args)
    frameless = [] if args.recordings else player.frameless_recordings(args.dir)
    names = args.recordings or player.list_recordings(args.dir)
    if not names:
        raise UsageError(_no_recordings(args.dir, frameless))
    try:
        found = [player.open_recording(n, args.dir) for n in names]
    except player.PlayError as e:
        raise UsageError(str(e)) from None
    if args.headless:                  # every recording's video stays, played or not
        here = player.list_recordings(args.dir) + frameless
        _check_not_a_recording_file(args.out, [r.path for r in found]
                                    + [os.path.join(args.dir, n) for n in here])
        _check_not_a_new_recording(args.out, args.dir)
    player.warn_frameless(frameless)
    chosen = player.select(found, args.partial)
    if not chosen:
        raise UsageError("every recording named is incomplete (--partial plays them)")
    if not args.headless:
        player.require_display()
        start_backend(args)
        check_available()
    size = tuple(args.resolution)
    frames = player.reel(chosen, size, args.loops, round(args.card_seconds * args.fps),
                         args.lang)
    if args.headless:
        n = player.play_to_file(frames, args.out, args.fps)
        print(f"{PROG}: wrote {args.out}: {n} frames, {n / args.fps:.1f} s at {args.fps:g} fps "
              f"({_count(len(chosen), 'recording')} x {_count(args.loops, 'loop')})",
              file=sys.stderr)
        return 0
    player.play_in_window(frames, size, args.fps)
    return 0


def register(sub, common) -> None:
    from ..render.captions import LANGS
    from ..render.options import FPS_RANGE, bounded, parse_resolution
    from ..render.player import CARD_RANGE, CARD_SECONDS
    from ..render.renderer import BOOTH_RESOLUTION

    p = sub.add_parser("play", parents=common, formatter_class=Fmt, epilog=PLAY_EPILOG,
                       help="play recordings in a loop (the booth), or into a video file",
                       description="Play recordings one after another with a title card "
                                   "before each, forever or --loops N times, full size in a "
                                   "window, or with --headless into a video file.")
    p.add_argument("recordings", nargs="*", metavar="PRESET",
                   help="recordings to play: names under --recordings or folder paths "
                        "(default: all)")
    p.add_argument("--recordings", type=path_argument, dest="dir", metavar="DIR",
                   help="the folder of recordings (default: $CROWNDEMO_RECORDINGS, else "
                        "./recordings)")
    p.add_argument("--loops", type=int, default=None,
                   help="play the list N times (default: forever; 1 with --headless)")
    p.add_argument("--headless", action="store_true",
                   help="no window: write the reel to --out")
    p.add_argument("--out", type=path_argument, metavar="FILE.mp4",
                   help="the video file of --headless")
    p.add_argument("--lang", choices=LANGS, default="en",
                   help="title-card language; ja needs a CJK font (default: en)")
    p.add_argument("--partial", action="store_true",
                   help="also play incomplete recordings, marked as such")
    p.add_argument("--fps", type=bounded(*FPS_RANGE, "frames per second"), default=12.0,
                   help="frames per second, %g to %g (default: %%(default)g)" % FPS_RANGE)
    p.add_argument("--card-seconds", type=bounded(*CARD_RANGE, "seconds; 0: no title cards"),
                   default=CARD_SECONDS,
                   help="how long each title card shows, %g to %g seconds; 0: no cards "
                        "(default: %%(default)g)" % CARD_RANGE)
    p.add_argument("--resolution", type=parse_resolution, default=BOOTH_RESOLUTION,
                   metavar="WxH", help="window or video size (default: %dx%d)"
                   % BOOTH_RESOLUTION)
    p.set_defaults(func=_play)


__all__ = ["register"]
