"""tools/device-measure.sh, the GPU measurements in phases for a lent GPU machine: what it would
run (DRY_RUN=1) must be commands this checkout accepts, on files and presets that exist, so a
session that is lent a GPU does not spend its device time on a stale flag."""
import os
import shlex
import subprocess

import pytest

from crowndemo.cli import build_parser
from crowndemo.config import load

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "tools", "device-measure.sh")
PHASES = ["check", "throughput", "seed", "variants"]


def dry_run(*phases, **env):
    run_env = {**os.environ, "DRY_RUN": "1", **env}
    return subprocess.run(["bash", SCRIPT, *phases], capture_output=True, text=True,
                          env=run_env, cwd="/")


def commands(out):
    return [shlex.split(line[2:]) for line in out.splitlines() if line.startswith("+ ")]


def test_every_phase_runs_commands_this_checkout_accepts(tmp_path):
    done = dry_run(*PHASES, OUT=str(tmp_path))
    assert done.returncode == 0, done.stderr
    cmds = commands(done.stdout)
    assert len(cmds) == 7                 # the tests, the tank, the preset, four variants
    benches = []
    for cmd in cmds:
        env = []
        if cmd[0] == "env":
            cmd = cmd[1:]
            while "=" in cmd[0]:
                env.append(cmd.pop(0))
        assert cmd[:3] in (["python3", "-m", "pytest"], ["python3", "-m", "crowndemo"])
        if cmd[2] == "pytest":
            tests = [a for a in cmd if a.startswith("tests/")]
            assert tests and all(os.path.exists(os.path.join(ROOT, t)) for t in tests)
            continue
        args = build_parser().parse_args(cmd[3:])     # a stale flag exits here
        assert args.command == "bench" and args.arch == "cuda" and args.record
        benches.append((env, args))
    tank = [a for _, a in benches if not a.preset]
    assert tank[0].n == [1000000, 12000000]       # the sizes
    assert [e for e, _ in benches].count(["CROWNDEMO_LIST_LAYOUT=slot"]) == 1
    preset = [a for _, a in benches if a.preset]
    assert len(preset) == 1
    resolved = load(preset[0].preset[0], quality=preset[0].quality)   # exists, no kernels
    assert resolved.name == "2.5m-drop" and resolved.quality == "seed"
    # each phase leaves its log, BENCHMARKS.md and the GPU's name where the device tool looks
    assert {"check.log", "throughput.log", "seed.log", "variants.log", "BENCHMARKS.md",
            "gpu.txt"} <= set(os.listdir(tmp_path))


@pytest.mark.parametrize("phases", [[], ["speed"]])
def test_no_phase_or_an_unknown_one_is_refused(tmp_path, phases):
    done = dry_run(*phases, OUT=str(tmp_path))
    assert done.returncode == 2
    assert "usage: tools/device-measure.sh" in done.stderr
