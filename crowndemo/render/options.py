"""The rendering options of the commands that record (``add_render_options``) and the frame
sink built from them (``sink_from_args``), so that plugging rendering into a command is two
lines."""
from __future__ import annotations

import argparse
import math
import os
from typing import TYPE_CHECKING, Callable, Optional, Tuple

from .captions import LANGS
from .colours import DEFAULT_MODE, MODES
from .renderer import BOOTH_RESOLUTION, DEFAULT_RESOLUTION
from .view import DEFAULT_STYLE, STYLES, RenderSettings, default_colour

if TYPE_CHECKING:
    from ..config.resolve import Resolved
    from .sink import FrameSink

ORBIT_DEFAULT = 1.0          # degrees per frame when --orbit is given without a value


def parse_resolution(text: str) -> Tuple[int, int]:
    """'1280x720' -> (1280, 720)."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not WIDTHxHEIGHT, e.g. 1280x720") from None
    if not (16 <= w <= 7680 and 16 <= h <= 4320):
        raise argparse.ArgumentTypeError(f"{text!r}: width and height must be 16..7680 and "
                                         "16..4320 pixels")
    return w, h


# --fps: 0.1 (a frame every 10 s, a slideshow) to 240 (the fastest common display rate);
# outside it ffmpeg's frame-rate ratio and the GIF's 16-bit frame delay overflow, and only
# after the whole simulation, when the video is made.
FPS_RANGE = (0.1, 240.0)
# --orbit: degrees per frame, either way; a bigger turn looks the same as a smaller one the
# other way, and a non-finite one puts the camera nowhere (blank frames).
ORBIT_RANGE = (-180.0, 180.0)


def bounded(lo: float, hi: float, unit: str) -> Callable[[str], float]:
    """An argparse type: a finite number in ``lo..hi`` (``unit`` names it in the error)."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not lo <= value <= hi:          # NaN fails every comparison
            raise argparse.ArgumentTypeError(f"{text!r}: allowed: a number from {lo:g} to "
                                             f"{hi:g} ({unit})")
        return value
    return parse


def add_render_options(parser: argparse.ArgumentParser, lang: bool = True,
                       recording: bool = True) -> None:
    """--colour, --lang, --resolution/--booth, --orbit and (``recording``) --style, --fps,
    --no-video and --no-render. ``lang=False`` leaves --lang to a command that already has
    it. Without ``recording`` (live) the particles are drawn as spheres."""
    g = parser.add_argument_group("rendering options")
    if recording:
        g.add_argument("--style", choices=STYLES, default=DEFAULT_STYLE,
                       help="surface: the liquid's surface reconstructed from the particles "
                            "(splashsurf), a milk-white sheet seen from low; particles: each "
                            f"particle a lit sphere (default: {DEFAULT_STYLE})")
    g.add_argument("--colour", "--color", dest="colour", choices=MODES, default=None,
                   help="what the colour shows; milk is a white look (default: "
                        + (f"{default_colour('surface')} on the surface, " if recording else "")
                        + f"{DEFAULT_MODE} on spheres)")
    if lang:
        g.add_argument("--lang", choices=LANGS, default="en",
                       help="caption language; ja needs a CJK font (default: en)")
    size = g.add_mutually_exclusive_group()
    size.add_argument("--resolution", type=parse_resolution, default=DEFAULT_RESOLUTION,
                      metavar="WxH", help="image size in pixels (default: %dx%d)"
                      % DEFAULT_RESOLUTION)
    size.add_argument("--booth", dest="resolution", action="store_const",
                      const=BOOTH_RESOLUTION, help="booth size, %dx%d" % BOOTH_RESOLUTION)
    orbit_lo, orbit_hi = ORBIT_RANGE
    g.add_argument("--orbit", type=bounded(*ORBIT_RANGE, "degrees per frame"), nargs="?",
                   const=ORBIT_DEFAULT, default=0.0, metavar="DEG",
                   help=f"turn the camera DEG degrees per frame about the drop's axis, "
                        f"{orbit_lo:g} to {orbit_hi:g} (default: fixed; --orbit alone: "
                        f"{ORBIT_DEFAULT:g})")
    if recording:
        fps_lo, fps_hi = FPS_RANGE
        g.add_argument("--fps", type=bounded(*FPS_RANGE, "frames per second"),
                       default=RenderSettings.fps,
                       help=f"frames per second of the video, {fps_lo:g} to {fps_hi:g} "
                            f"(default: {RenderSettings.fps:g})")
        g.add_argument("--no-video", dest="video", action="store_false",
                       help="write the PNG frames only, no video.mp4 or preview.gif")
        g.add_argument("--no-render", dest="render", action="store_false",
                       help="render nothing (no frames, no video; needs no Vulkan)")


def style_of(args: argparse.Namespace) -> str:
    """The drawing style the options ask for (a command without --style draws spheres)."""
    return getattr(args, "style", "particles")


def colour_of(args: argparse.Namespace) -> str:
    """The colour field the options ask for: --colour, else the style's default."""
    return args.colour or default_colour(style_of(args))


def settings_from_args(args: argparse.Namespace) -> RenderSettings:
    fps = getattr(args, "fps", RenderSettings.fps)
    return RenderSettings(colour=colour_of(args), lang=getattr(args, "lang", "en") or "en",
                          resolution=tuple(args.resolution), orbit=args.orbit,
                          video=getattr(args, "video", True), fps=fps, style=style_of(args))


def sink_from_args(args: argparse.Namespace, resolved: Resolved, out_dir: str,
                   resume: bool = False) -> Optional[FrameSink]:
    """The FrameSink for a recording of ``resolved`` into ``out_dir`` (frames in
    ``out_dir/frames``), or None with --no-render. Checks Vulkan first: a RenderError (with how
    to install a driver) comes before any simulation time is spent."""
    if not getattr(args, "render", True):
        return None
    from .sink import FrameSink
    from .view import PresetView
    from .window import check_available
    check_available()
    return FrameSink(os.fspath(out_dir), PresetView.from_resolved(resolved,
                                                                  settings_from_args(args)),
                     resume=resume)


__all__ = ["add_render_options", "settings_from_args", "style_of", "colour_of", "sink_from_args", "parse_resolution",
           "bounded", "FPS_RANGE", "ORBIT_RANGE"]
