"""``crowndemo play``: the booth loop over recordings, in a window or into a video file."""
from __future__ import annotations

import os
import sys

from .common import PROG, Fmt, UsageError, start_backend

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
is skipped with a warning; --partial plays it with an "incomplete" marker.
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


def _check_args(args) -> None:
    """UsageError for a bad option; fills in the defaults that depend on others."""
    from ..record import recordings_root
    if args.loops is not None and args.loops < 1:
        raise UsageError(f"--loops {args.loops}: must be >= 1")
    if args.fps <= 0 or args.card_seconds < 0:
        raise UsageError("--fps must be > 0 and --card-seconds >= 0")
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


def _play(args, argv) -> int:
    from ..render import player
    from ..render.window import check_available

    _check_args(args)
    names = args.recordings or player.list_recordings(args.dir)
    if not names:
        raise UsageError(f"no recordings in {args.dir}/ (make one with '{PROG} record PRESET')")
    try:
        chosen = player.select([player.open_recording(n, args.dir) for n in names],
                               args.partial)
    except player.PlayError as e:
        raise UsageError(str(e)) from None
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
              f"({len(chosen)} recordings x {args.loops} loops)", file=sys.stderr)
        return 0
    player.play_in_window(frames, size, args.fps)
    return 0


def register(sub, common) -> None:
    from ..render.captions import LANGS
    from ..render.options import parse_resolution
    from ..render.player import CARD_SECONDS
    from ..render.renderer import BOOTH_RESOLUTION

    p = sub.add_parser("play", parents=common, formatter_class=Fmt, epilog=PLAY_EPILOG,
                       help="play recordings in a loop (the booth), or into a video file",
                       description="Play recordings one after another with a title card "
                                   "before each, forever or --loops N times, full size in a "
                                   "window, or with --headless into a video file.")
    p.add_argument("recordings", nargs="*", metavar="PRESET",
                   help="recordings to play: names under --recordings or folder paths "
                        "(default: all)")
    p.add_argument("--recordings", dest="dir", metavar="DIR",
                   help="the folder of recordings (default: $CROWNDEMO_RECORDINGS, else "
                        "./recordings)")
    p.add_argument("--loops", type=int, default=None,
                   help="play the list N times (default: forever; 1 with --headless)")
    p.add_argument("--headless", action="store_true",
                   help="no window: write the reel to --out")
    p.add_argument("--out", metavar="FILE.mp4", help="the video file of --headless")
    p.add_argument("--lang", choices=LANGS, default="en",
                   help="title-card language; ja needs a CJK font (default: en)")
    p.add_argument("--partial", action="store_true",
                   help="also play incomplete recordings, marked as such")
    p.add_argument("--fps", type=float, default=12.0,
                   help="frames per second (default: %(default)g)")
    p.add_argument("--card-seconds", type=float, default=CARD_SECONDS,
                   help="how long each title card shows (default: %(default)g)")
    p.add_argument("--resolution", type=parse_resolution, default=BOOTH_RESOLUTION,
                   metavar="WxH", help="window or video size (default: %dx%d)"
                   % BOOTH_RESOLUTION)
    p.set_defaults(func=_play)


__all__ = ["register"]
