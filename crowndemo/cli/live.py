"""``crowndemo live``: the interactive booth mode (sliders, a Drop button, a live run)."""
from __future__ import annotations

from .common import PROG, Fmt, add_quality, add_sets, start_backend

LIVE_EPILOG = """\
examples:
  crowndemo live                          # quick-2d at draft quality (a 2D slice, fast)
  crowndemo live quick                    # a small 3D drop (slower on a CPU)
  crowndemo live --colour milk --booth    # white milk, 1920x1080
  crowndemo live --arch cuda quick        # on a GPU

Sliders set the fall height (U = sqrt(2 g H)), the film thickness and the drop diameter;
Drop restarts the run with them (they are checked like --set values: a refused value is
shown in the panel and the current run goes on). Drag with the left mouse button outside
the panel to orbit the camera; Up/Down zoom; Esc quits. Needs a display and Vulkan.
"""


NO_DISPLAY_ADVICE = (f"live mode needs a window; without one, use '{PROG} record PRESET', "
                     f"then '{PROG} play --headless --out FILE.mp4'")


def _live(args, argv) -> int:
    from ..render import options
    from ..render.live import run_live
    from ..render.live_control import LiveController
    from ..render.window import check_available, require_display

    settings = options.settings_from_args(args)
    # the preset and --set values first (no Taichi yet), then the display, then Vulkan
    controller = LiveController(args.preset, args.quality, sets=args.sets)
    require_display(NO_DISPLAY_ADVICE)
    start_backend(args)
    check_available()
    run_live(controller, settings)
    return 0


def register(sub, common) -> None:
    from ..render.live_control import DEFAULT_PRESET, QUALITY
    from ..render.options import add_render_options

    p = sub.add_parser("live", parents=common, formatter_class=Fmt, epilog=LIVE_EPILOG,
                       help="interactive window: choose the drop, watch it splash",
                       description="Live mode: a GGUI window with sliders for fall height, "
                                   "film thickness and drop size, a Drop button, and the "
                                   "simulation running live at draft quality.")
    p.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET",
                   help="the preset the sliders start from (default: %(default)s)")
    add_quality(p, QUALITY)
    add_sets(p)
    add_render_options(p, lang=False, recording=False)
    p.set_defaults(func=_live)


__all__ = ["register"]
