"""``crowndemo bench``: particle-steps per second of the full step (BENCHMARKS.md)."""
from __future__ import annotations

import json
import os
import shlex
import sys
from typing import Sequence

from ..core.params import ParameterError
from .common import (PROG, Fmt, repo_root, start_backend)


BENCH_EPILOG = """\
examples:
  crowndemo bench                             # N = 100000 and 300000, 20 steps, table
  crowndemo bench --n 2000 --steps 3 --json   # a quick check
  crowndemo bench --arch cuda --n 1000000     # on an NVIDIA GPU
  crowndemo bench --record                    # append the results to BENCHMARKS.md

The scene is a k x k x kz block of water (k = round(N^(1/3)), l0 = 1 mm, re = 2.1 l0) resting
in a 3D tank with walls. particle-steps/s = fluid particles x steps / seconds; the first steps
(JIT compile) are not timed and are reported as compile_s.
"""


def _bench(args, argv: Sequence[str]) -> int:
    from .. import bench

    ns = args.n or list(bench.DEFAULT_NS)
    for n in ns:
        if n < 1:
            raise ParameterError("n", n, "an integer >= 1 (fluid particles)", "command line")
    if args.steps < 1:
        raise ParameterError("steps", args.steps, "an integer >= 1", "command line")
    start_backend(args)

    def progress(r):
        if not args.json:
            print(f"  N = {r['particles']['fluid']:,}: {r['particle_steps_per_s']:.3e} "
                  f"particle-steps/s", file=sys.stderr, flush=True)

    results = bench.run(ns, args.steps, on_result=progress)
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=2))
    else:
        print(bench.text_table(results))
    if args.record:
        path = os.path.join(repo_root(), "BENCHMARKS.md")
        bench.record(results, " ".join([PROG] + [shlex.quote(a) for a in argv]), path)
        print(f"{PROG}: appended to {path}", file=sys.stderr)
    return 0


def register(sub, common) -> None:
    p = sub.add_parser("bench", parents=common, formatter_class=Fmt, epilog=BENCH_EPILOG,
                       help="particle-steps per second of the full step on a 3D block",
                       description="Time the full explicit MPS step on a 3D block of water "
                                   "resting in a tank.")
    p.add_argument("--n", type=int, nargs="+", metavar="N",
                   help="fluid particles, one run each (default: 100000 300000)")
    p.add_argument("--steps", type=int, default=20, metavar="S", help="timed steps per run (default: 20)")
    p.add_argument("--json", action="store_true",
                   help="one JSON object per N (a list when several)")
    p.add_argument("--record", action="store_true",
                   help="append a section (machine, arch, date, command, table) to BENCHMARKS.md "
                        "at the repository root")
    p.set_defaults(func=_bench)
