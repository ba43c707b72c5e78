"""What every ``crowndemo`` command shares: the error types and formatter, the backend options,
preset loading, running a simulator with a progress line, and the run summary.

User mistakes (bad flags, parameters out of range, an unavailable arch) print one line
``crowndemo: error: ...`` on stderr and return EXIT_USAGE (2); an unstable run prints the reason
and returns EXIT_UNSTABLE (3); Ctrl-C returns EXIT_INTERRUPTED (130).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from typing import Callable, Dict, Optional, Sequence

from ..backend import ARCHS, PRECISIONS
from ..core.params import Numerics, ParameterError
from ..interrupt import StopRun, stop_if_asked

PROG = "crowndemo"
# exit statuses besides 0, the same for every command (MAIN_EPILOG in cli/__init__ lists them)
EXIT_FAILED = 1             # a video could not be made, a validation check or a sweep point failed
EXIT_USAGE = 2              # a usage or parameter error (error() below): "error: ..."
EXIT_UNSTABLE = 3           # the run broke a health limit (InstabilityError): "unstable: ..."
EXIT_INTERRUPTED = 130      # stopped by Ctrl-C (128 + SIGINT, as a shell reports it)
EXIT_PIPE = 141             # stdout closed early (128 + SIGPIPE, as a shell reports it)
PROGRESS_EVERY_S = 2.0
NUMERICS = Numerics()       # the core's defaults, shown in --help

# command-line option for each parameter name that a ParameterError can carry
OPTION_OF = {"dim": "--dim", "l0": "--l0", "v_max": "--speed", "speed": "--speed",
             "re_ratio": "--re-ratio",
             "rho": "--rho", "nu": "--nu", "sigma": "--sigma", "sound_speed": "--sound-speed",
             "pressure_gradient": "--gradient", "t_end": "--t-end", "width": "--width",
             "depth": "--depth", "a": "--a", "side": "--side", "n": "--n", "steps": "--steps",
             "courant": "--courant", "acoustic": "--acoustic", "max_steps": "--max-steps",
             "rate": "--rate"}


class UsageError(Exception):
    """A command-line mistake found by argparse."""


def _looks_numeric(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


class Parser(argparse.ArgumentParser):
    _argv: Sequence[str] = ()

    def parse_args(self, args=None, namespace=None):
        # on the class: a subcommand's parser reports its own errors
        Parser._argv = tuple(sys.argv[1:] if args is None else args)
        return super().parse_args(args, namespace)

    def error(self, message):          # one line, no usage dump, no SystemExit
        raise UsageError(f"{message}{self._value_hint(message)} (see '{self.prog} --help')")

    def _value_hint(self, message: str) -> str:
        """argparse reads a value such as "-inf" or "-1e3" as an unknown option, not as the
        value of the option before it: say how to write it."""
        argv = list(Parser._argv)
        prefix = "unrecognized arguments: "
        if message.startswith(prefix):
            tokens = message[len(prefix):].split()
        elif message.endswith(": expected one argument"):
            tokens = [argv[at + 1] for at in range(len(argv) - 1)
                      if message.startswith(f"argument {argv[at]}")
                      or f"/{argv[at]}:" in message]
        else:
            return ""
        for token in tokens:
            if token.startswith("-") and _looks_numeric(token) and token in argv[1:]:
                at = argv.index(token, 1)
                option = argv[at - 1] if argv[at - 1].startswith("--") else "--OPTION"
                return f"; a value that starts with '-' goes after '=': {option}={token}"
        return ""


class Fmt(argparse.RawDescriptionHelpFormatter):
    def __init__(self, prog):
        super().__init__(prog, max_help_position=32)


def backend_options() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(add_help=False)
    g = p.add_argument_group("backend options")
    g.add_argument("--arch", choices=ARCHS, default=None,
                   help="Taichi backend; auto tries CUDA and falls back to the CPU "
                        "(default: $CROWNDEMO_ARCH, else cpu)")
    g.add_argument("--precision", choices=PRECISIONS, default="f32",
                   help="float precision of every field and kernel (default: f32)")
    g.add_argument("--seed", type=int, default=0, help="Taichi random seed (default: 0)")
    g.add_argument("--single-thread", action="store_true",
                   help="one CPU thread: bit-identical results from run to run")
    g.add_argument("--fast-compile", action="store_true", default=None,
                   help="CPU arch: compile in a fraction of the time (Taichi's advanced "
                        "IR optimisations off, the grid walk's rows in a loop: a 3D model in "
                        "about 5 s), steps 5-15 %% slower; for first and short runs "
                        "(default: $CROWNDEMO_FAST_COMPILE=1, else off)")
    return p


def start_backend(args):
    import contextlib

    from .. import backend
    # ti.init prints "[Taichi] Starting on arch=..." on stdout: send it to stderr
    with contextlib.redirect_stdout(sys.stderr):
        return backend.init(args.arch, args.precision, args.seed, args.single_thread,
                            fast_compile=args.fast_compile)


def fmt_counts(counts: Dict[str, int]) -> str:
    parts = [f"{counts[k]:,} {k}" for k in ("fluid", "wall", "dummy", "gone") if counts.get(k)]
    return ", ".join(parts) + f" ({sum(counts.values()):,} total)"


FIRST_STEP = "first step (kernels compiled or loaded from the cache)"


class Progress:
    """A step callback: a progress line on stderr every ~2 s (simulated time, steps/s, ETA);
    the first step of the process's run (it compiles the kernels or loads them from Taichi's
    offline cache) is timed apart."""

    def __init__(self, t_end: float, quiet: bool, max_steps: Optional[int] = None,
                 first_label: str = FIRST_STEP):
        self.t_end, self.quiet, self.max_steps = t_end, quiet, max_steps
        self.first_label = first_label
        self.started = time.perf_counter()
        self.first_step_s: Optional[float] = None
        self.mark = (self.started, 0, 0.0)      # wall, steps, simulated time

    def __call__(self, s) -> None:
        now = time.perf_counter()
        st = s.stats
        if self.first_step_s is None:          # compiling: not in the rate
            self.first_step_s = now - self.started
            if not self.quiet:
                print(f"  {self.first_label} {self.first_step_s:.1f} s", file=sys.stderr,
                      flush=True)
            self.mark = (now, st.steps, st.time)
            return
        t_mark, steps_mark, sim_mark = self.mark
        if self.quiet or now - t_mark < PROGRESS_EVERY_S:
            return
        rate = (st.steps - steps_mark) / (now - t_mark)
        sim_rate = (st.time - sim_mark) / (now - t_mark)
        left = (self.t_end - st.time) / sim_rate if sim_rate > 0 else math.inf
        if self.max_steps is not None and rate > 0:
            left = min(left, (self.max_steps - st.steps) / rate)
        print(f"  t = {st.time * 1e3:8.3f} / {self.t_end * 1e3:g} ms  step {st.steps:6d}"
              f"  {rate:7.1f} steps/s  ETA {clock(left)}  max speed "
              f"{st.health.max_speed:.3g} m/s", file=sys.stderr, flush=True)
        self.mark = (now, st.steps, st.time)


def simulate(sim, t_end: float, quiet: bool, frame_times: Sequence[float] = (),
             max_steps: Optional[int] = None,
             on_frame: Optional[Callable[[object, int], None]] = None,
             stop=None, first_label: str = FIRST_STEP) -> Dict:
    """Run ``sim`` to ``t_end`` (or ``max_steps``, or until ``stop.requested``: Ctrl-C) with a
    progress line on stderr every ~2 s; returns the stats, the peak health figures, whether
    and why the run stopped early (stopped_by: max-steps | ctrl-c) and the first step's time."""
    progress = Progress(t_end, quiet, max_steps, first_label)

    def on_step(s):
        progress(s)
        stop_if_asked(s.stats.steps, max_steps, stop)

    stopped_by = None
    try:
        stats = sim.run(t_end, frame_times=frame_times, on_frame=on_frame, on_step=on_step)
    except StopRun as e:
        stats, stopped_by = sim.stats, e.by
    peak = {"speed": stats.peak_max_speed, "excess": stats.peak_max_density_excess}
    return {"stats": stats, "peak": peak, "stopped_early": stopped_by is not None,
            "stopped_by": stopped_by, "first_step_s": progress.first_step_s}


def clock(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "--:--"
    s = int(round(seconds))
    if s >= 3600:
        return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"
    return f"{s // 60}:{s % 60:02d}"


def run_result(run: Dict, counts: Dict[str, int], setup_s: float) -> Dict:
    """The JSON part shared by `scene` and `run`: stats, health with peaks, particles."""
    d = run["stats"].as_dict()
    return {"particles": counts, "setup_seconds": setup_s, **d}


def print_summary(head: str, run: Dict, counts: Dict[str, int], sound_speed: float,
                  setup_s: float, obs: Optional[Dict] = None, dim: int = 3) -> None:
    """The summary of a run on stdout: particles, steps and dt with the limits that bound it,
    health, an observable when there is one, wall time. In 2D energies are per unit depth."""
    stats, peak = run["stats"], run["peak"]
    h = stats.health
    e0, e1 = stats.energy_start, h.energy
    de = f" ({(e1 - e0) / abs(e0) * 100:+.2f} %)" if e0 else ""
    binding = ", ".join(f"{k} {v}" for k, v in stats.binding.most_common())
    left = ", ".join(f"{v} {k}" for k, v in h.left.items()) or "none"
    print(head)
    print(f"  particles   {fmt_counts(counts)}")
    early = {"max-steps": " (stopped early: --max-steps)", "ctrl-c": " (interrupted: Ctrl-C)"
             }.get(run.get("stopped_by"), "")
    dts = (f"dt {stats.dt_min:.3g} .. {stats.dt_max:.3g} s" if stats.dt_max > 0 else
           "every step cut short to land on a frame time or the end")
    print(f"  simulated   {stats.time * 1e3:.4g} ms in {stats.steps:,} steps{early}; {dts}; "
          f"steps bound by: {binding}")
    print(f"  health      max speed {h.max_speed:.4g} m/s (peak {peak['speed']:.4g}, "
          f"c = {sound_speed:.4g}); max density excess n/n0 - 1 = "
          f"{h.max_density_excess:.4g} (peak {peak['excess']:.4g})")
    unit = "J" if dim == 3 else "J/m"
    print(f"              energy {e0:.6g} {unit} -> {e1:.6g} {unit}{de}; left the domain: {left}")
    if obs:
        print(f"  result      {obs['text']}")
    rate = stats.steps / stats.wall_seconds if stats.wall_seconds > 0 else math.nan
    print(f"  wall time   {setup_s + stats.wall_seconds:.2f} s (set-up {setup_s:.2f} s, "
          f"stepping {stats.wall_seconds:.2f} s incl. compiling or loading the kernels, "
          f"{rate:.1f} steps/s)")


PRESET_HELP = "a preset name (see 'crowndemo presets') or a path to a preset YAML file"
SET_HELP = ("override a preset value, KEY.PATH=VALUE with VALUE read as YAML, e.g. "
            "scene.speed=7, quality.draft.l0=4e-4, numerics.courant=0.1; repeatable; "
            "an empty VALUE restores the default")


def add_quality(p, default: Optional[str], help: str = "quality rung",
                shown: Optional[str] = None) -> None:
    """--quality, one of the quality rungs. ``default`` None leaves the choice to the command
    (it can tell whether the option was given); ``shown`` is then the rung the help names as
    the default (else config.DEFAULT_QUALITY, what load_preset falls back to). ``help`` is
    the text before "(default: ...)"."""
    from ..config import DEFAULT_QUALITY, QUALITIES
    if default is not None:
        shown = default
    p.add_argument("--quality", choices=QUALITIES, default=default,
                   help=f"{help} (default: {shown or DEFAULT_QUALITY})")


def add_sets(p, help: str = SET_HELP) -> None:
    """--set KEY=VALUE, repeatable, into ``args.sets`` (a list, empty when none)."""
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help=help)


def load_preset(spec: str, args, quality: Optional[str] = None):
    from .. import config
    return config.load(spec, quality or args.quality or config.DEFAULT_QUALITY, args.sets)


CTRL_C_NOTICE = f"{PROG}: Ctrl-C: stopping after this step (press it again to stop at once)"


def add_sequence_options(p) -> None:
    """--then and --playlist: several presets, one after another, in one process."""
    p.add_argument("--then", action="extend", nargs="+", default=[], metavar="PRESET",
                   help="presets to run afterwards, one after another in this process "
                        "(one compiled simulator per model, reused)")
    p.add_argument("--playlist", type=path_argument, metavar="FILE",
                   help="a file with one preset per line (# comments), run after PRESET and "
                        "--then")


def load_presets(args) -> list:
    """PRESET, --then and --playlist resolved, every mistake found before any run."""
    from .. import config
    from ..config.playlist import read_playlist

    quality = args.quality or config.DEFAULT_QUALITY
    specs = [(s, "command line") for s in [args.preset] + list(args.then or [])]
    if getattr(args, "playlist", None):
        specs += read_playlist(args.playlist)
    return [config.load(spec, quality, args.sets, source) for spec, source in specs]


def path_argument(text: str) -> str:
    """argparse type of a file or folder option: an empty value is refused rather than taken
    for the default, which would write somewhere the user did not name."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path; allowed: a path (leave the option "
                                         "out for its default)")
    return text


def require_folder(option: str, folder, shown=None) -> None:
    """UsageError, before any simulation, when files cannot be written into ``folder`` (a
    file, a parent that is a file, no permission); tried for real and left as it was. The
    message names ``option`` and ``shown`` (default: the folder itself)."""
    from ..record.files import folder_problem

    shown = folder if shown is None else shown
    bad = folder_problem(folder)
    if bad:
        at, what = bad
        where = "" if os.path.abspath(at) == os.path.abspath(shown) else f"{at}: "
        raise UsageError(f"{option} {shown}: {where}{what}; allowed: a folder that exists or "
                         "can be created, and can be written")


def repo_root() -> str:
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def error(message: str) -> int:
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return EXIT_USAGE


def parameter_message(e: ParameterError) -> str:
    opt = OPTION_OF.get(e.key)
    where = f" (option {opt})" if opt else ""
    return f"{e.key} = {e.value!r} is out of range; allowed: {e.allowed}{where}"

