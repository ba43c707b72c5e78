"""The ``crowndemo`` command line: one module per command, each with ``register(sub, common)``.

User mistakes (bad flags, parameters out of range, an unavailable arch) print one line
``crowndemo: error: ...`` on stderr and return 2; an unstable run prints the reason and
returns 3; Ctrl-C returns 130; a closed stdout (``| head``) returns 141 quietly.
"""
from __future__ import annotations

import os

# Taichi prints a version banner on stdout when imported; keep stdout clean for --json.
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "0")

import importlib  # noqa: E402
import sys  # noqa: E402
from typing import Optional, Sequence  # noqa: E402

from .. import __version__  # noqa: E402
from ..backend import BackendError  # noqa: E402
from ..config import PresetError  # noqa: E402
from ..core.health import InstabilityError  # noqa: E402
from ..core.params import ParameterError  # noqa: E402
from ..render.window import RenderError  # noqa: E402
from .common import (EXIT_INTERRUPTED, EXIT_PIPE, EXIT_UNSTABLE, PROG, Fmt,  # noqa: E402
                     Parser, UsageError, backend_options, error, parameter_message)

# the command modules, in the order `crowndemo --help` lists them
COMMANDS = ["presets", "info", "run", "record", "export", "play", "live", "scene", "validate",
            "sweep", "bench"]

MAIN_EPILOG = """\
examples:
  crowndemo presets                              # the presets, particles and run time
  crowndemo info 3m-drop --quality booth         # every parameter of a preset, no kernels
  crowndemo run quick                            # a small 3D crown (well under a minute)
  crowndemo run 3m-drop --set scene.speed=6      # a preset with an override
  crowndemo info --dim 3 --l0 1e-4               # constants and time-step limits
  crowndemo scene dam-break --dim 3 --t-end 0.05  # a short 3D dam break
  crowndemo bench --n 100000 --steps 20          # particle-steps per second

Run 'crowndemo COMMAND --help' for the options of a command.
Exit status: 0 ok, 1 a recording's video could not be made or a validation check failed,
2 a usage or parameter error, 3 the simulation became unstable, 130 interrupted (Ctrl-C),
141 stdout closed early (a pipe into head).
"""


def build_parser() -> Parser:
    common = [backend_options()]
    parser = Parser(prog=PROG, formatter_class=Fmt, epilog=MAIN_EPILOG,
                    description="Milk-crown demo: the explicit MPS particle method in Taichi.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(sub, common)
    return parser


def main(argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except UsageError as e:
        return error(str(e))
    except SystemExit as e:            # --help, --version
        return e.code if isinstance(e.code, int) else 0
    try:
        return args.func(args, argv)
    except (UsageError, PresetError, BackendError, RenderError) as e:
        return error(str(e))
    except ParameterError as e:
        return error(parameter_message(e))
    except InstabilityError as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return EXIT_UNSTABLE
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # the reader of stdout went away (`crowndemo info ... | head`): no traceback, and
        # nothing more written to the closed pipe, exit flush included
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_PIPE


__all__ = ["main", "build_parser", "COMMANDS"]
