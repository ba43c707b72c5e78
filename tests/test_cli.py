"""The command line, called in-process (Taichi can only be initialised in the test process)."""
import json

import pytest

from crowndemo.cli import main
from crowndemo.core.lattice import n0_lambda0

HELP = [[], ["info"], ["scene"], ["scene", "tank"], ["scene", "dam-break"], ["scene", "patch"],
        ["bench"], ["validate"], ["sweep"], ["record"], ["export"], ["play"], ["live"]]


@pytest.mark.parametrize("cmd", HELP, ids=lambda c: " ".join(c) or "top")
def test_help_exits_0(cmd, capsys):
    assert main(cmd + ["--help"]) == 0
    out = capsys.readouterr().out
    assert "usage: crowndemo" in out
    assert "examples:" in out


# every command with --quality, and its default (None: the command picks the rung itself)
QUALITY_DEFAULT = {"run": "draft", "record": "draft", "live": "draft", "sweep": "draft",
                   "validate": "draft", "bench": None, "export": None, "info": None}


@pytest.mark.parametrize("cmd", sorted(QUALITY_DEFAULT))
def test_quality_and_set_options(cmd):
    """--quality and --set come from common.add_quality / add_sets: the rungs as choices, each
    command's default, --set repeatable into args.sets (validate has no --set)."""
    from crowndemo.cli import build_parser
    from crowndemo.cli.common import UsageError
    from crowndemo.config import QUALITIES

    parser = build_parser()
    argv = [cmd] + (["quick"] if cmd in ("run", "record", "export") else [])
    assert parser.parse_args(argv).quality == QUALITY_DEFAULT[cmd]
    sets = [] if cmd == "validate" else ["--set", "scene.speed=3", "--set", "numerics.courant="]
    args = parser.parse_args(argv + ["--quality", QUALITIES[-1]] + sets)
    assert args.quality == QUALITIES[-1]
    if cmd != "validate":
        assert args.sets == ["scene.speed=3", "numerics.courant="]
        assert parser.parse_args(argv).sets == []
    with pytest.raises(UsageError, match="--quality: invalid choice"):
        parser.parse_args(argv + ["--quality", "best"])


def test_exit_statuses_keep_their_values():
    """README and the tests name them: 3 unstable, 130 Ctrl-C."""
    from crowndemo.cli.common import EXIT_INTERRUPTED, EXIT_UNSTABLE
    assert (EXIT_UNSTABLE, EXIT_INTERRUPTED) == (3, 130)


def test_info_json_matches_lattice_and_limits(capsys):
    assert main(["info", "--dim", "3", "--l0", "1e-4", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    n0, lam = n0_lambda0(3, 1e-4, 2.1 * 1e-4)
    assert data["n0"] == n0
    assert data["lambda0"] == lam
    assert data["C"] < 0
    c = data["sound_speed"]
    assert c == pytest.approx(5.0 * data["speed"])
    assert data["limits_s"]["acoustic"] == pytest.approx(1e-4 / c, rel=1e-12)
    assert set(data["limits_s"]) == {"courant", "acoustic", "viscous", "capillary"}
    assert data["binding"] in data["limits_s"]
    assert data["dt_s"] == min(v for v in data["limits_s"].values() if v is not None)


def test_info_table(capsys):
    assert main(["info", "--dim", "2", "--l0", "1e-3", "--sound-speed", "20"]) == 0
    out = capsys.readouterr().out
    for word in ("n0", "lambda0", "courant", "acoustic", "viscous", "capillary", "binds"):
        assert word in out


@pytest.mark.parametrize("argv, key", [
    (["info", "--dim", "4", "--l0", "1e-3"], "dim"),
    (["info", "--dim", "3", "--l0", "-1"], "l0"),
    (["info", "--dim", "3", "--l0", "1e-3", "--re-ratio", "9"], "re_ratio"),
    (["info", "--dim", "3", "--l0", "nan"], "l0"),
    (["info", "--dim", "3"], "--l0"),
    (["info", "--dim", "3", "--l0", "x"], "--l0"),
    (["info", "--dim", "3", "--l0", "1e-4", "--sound-speed", "1e-3"], "--sound-speed"),
    (["scene", "dam-break", "--dim", "2", "--a", "-0.1"], "a"),
    (["scene", "tank", "--a", "0.1"], "--a"),
    (["bench", "--n", "0"], "n"),
    (["bench", "--set", "scene.speed=3"], "--preset"),
    (["bench", "--set", "numerics.cells_per_re=7"], "numerics.cells_per_re"),
    (["bench", "--set", "numerics.courant=0.3", "--compare"], "--compare"),
    (["bench", "--preset", "quick", "--n", "1000"], "--preset"),
    (["bench", "--preset", "nosuch-preset"], "nosuch-preset"),
    (["bench", "--preset", "quick", "--set", "scene.speed=-1"], "scene.speed"),
    (["bench", "--preset", "quick", "--max-steps", "0"], "max-steps"),
    (["bench", "--preset", "quick", "--max-steps", "1"], "an integer >= 2"),
    (["bench", "--set", "numerics.allow_unsafe_dt=true"], "numerics.allow_unsafe_dt"),
    (["presets", "--rate", "0"], "--rate"),
    (["presets", "--rate", "-1"], "--rate"),
    (["scene", "tank", "--dim", "3", "--l0", "1e-5"], "--l0"),
    (["scene", "tank", "--l0", "0.04", "--t-end", "0.01"], "--width"),
    (["scene", "patch", "--side", "1e-4"], "--side"),
    (["scene", "dam-break", "--dim", "2", "--l0", "2e-6"], "--l0"),
    (["nosuch"], "nosuch"),
])
def test_bad_input_exits_2_with_one_line(argv, key, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("crowndemo: error: ")
    assert key in err
    assert "Traceback" not in err
    assert err.count("\n") == 1


def test_bad_arch_from_environment(monkeypatch, capsys):
    monkeypatch.setenv("CROWNDEMO_ARCH", "tpu")
    assert main(["bench", "--n", "10", "--steps", "1"]) == 2
    err = capsys.readouterr().err
    assert "crowndemo: error: " in err and "CROWNDEMO_ARCH" in err


def test_bench_json(capsys):
    assert main(["bench", "--n", "2000", "--steps", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert isinstance(data, dict)
    assert data["particle_steps_per_s"] > 0
    assert abs(data["particles"]["fluid"] - 2000) < 100
    assert data["particles"]["total"] > data["particles"]["fluid"]
    assert data["steps"] == 3 and data["seconds"] > 0
    assert data["compile_s"] >= 0
    assert data["bytes_per_particle"] > 0
    assert data["precision"] == "f32"
    assert data["list_layout"] == "particle"          # the default storage of the list


def test_bench_tank_with_numerics_overrides(capsys):
    """--set numerics.KEY=VALUE on the tank block: compiled with those numerics, labelled with
    them, and the scene built for them (the analytic plane floor replaces the floor's
    particle layers)."""
    from crowndemo.bench import block_shape
    from crowndemo.core import Numerics
    from crowndemo.scenes import hydrostatic_tank
    assert main(["bench", "--n", "2000", "--steps", "1", "--no-stages", "--json",
                 "--fast-compile", "--set", "numerics.wall_model=plane",
                 "--set", "numerics.neighbour_list=false"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["label"] == "wall_model=plane, neighbour_list=False"
    assert data["model"]["plane_floor"] and not data["model"]["neighbour_list"]
    k, kz = block_shape(2000)
    plane = hydrostatic_tank(dim=3, l0=1e-3, width=k * 1e-3, depth=kz * 1e-3, re_ratio=2.1,
                             numerics=Numerics(wall_model="plane"))
    assert data["particles"]["total"] == len(plane.pos)
    assert len(plane.pos) < len(hydrostatic_tank(dim=3, l0=1e-3, width=k * 1e-3,
                                                 depth=kz * 1e-3, re_ratio=2.1).pos)


def test_bench_preset_json(capsys):
    from crowndemo.core.step import STAGES
    assert main(["bench", "--preset", "quick", "--quality", "draft", "--max-steps", "3",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["preset"] == "quick" and data["quality"] == "draft"
    assert data["steps"] == 3 and 0 < data["simulated_s"] < data["t_end_s"]
    # the whole wall time holds the set-up, the first step and the timed steps
    assert data["run_s"] >= data["setup_s"] + data["first_step_s"] + data["seconds"] - 1e-3
    assert data["startup_s"] == pytest.approx(data["setup_s"] + data["first_step_s"])
    assert data["particle_steps_per_s"] == pytest.approx(
        data["particles"]["fluid"] * 2 / data["seconds"])
    assert set(data["stage_ms"]) <= set(STAGES) and data["stage_ms"]["density"] > 0
    assert data["particles"]["total"] > data["particles"]["fluid"] > 10_000


def test_bench_preset_unstable_reports_the_finished_ones(tmp_path, capsys):
    # the drop starts at U = c/5: max_mach * c just above U passes the preset's check
    # (config/resolve.py), and gravity takes the falling drop past it in the first step.
    # quick-2d finishes its 2 steps first; its row is printed, then the one-line error.
    bad = tmp_path / "unstable.yaml"
    bad.write_text("extends: quick\nnumerics: {max_mach: 0.2000001}\n")
    assert main(["bench", "--preset", "quick-2d", str(bad), "--quality", "draft",
                 "--max-steps", "2", "--no-stages"]) == 3
    out, err = capsys.readouterr()
    assert "quick-2d draft" in out and "unstable draft" not in out
    assert "unstable at step 1" in err and "Traceback" not in err


def test_run_chain_unstable_reports_the_finished_ones(tmp_path, capsys):
    """A later preset of a chain going unstable: the finished runs are still reported (with
    --json, a list ending in the unstable one's step and cause), the error names the preset,
    and the presets after it are named as not run; exit 3."""
    bad = tmp_path / "unstable.yaml"           # max_mach * c just above U: the first step
    bad.write_text("extends: quick-2d\nnumerics: {max_mach: 0.2000001}\n")
    assert main(["run", "quick-2d", "--then", str(bad), "quick-2d", "--max-steps", "2",
                 "--json", "--quiet"]) == 3
    out, err = capsys.readouterr()
    first, broken = json.loads(out)
    assert first["preset"] == "quick-2d" and first["steps"] == 2
    assert broken["preset"] == "unstable" and broken["unstable"]["step"] == 1
    assert "max_mach" in broken["unstable"]["what"]
    assert "crowndemo: unstable: unstable at step 1" in err and "not run: quick-2d" in err


def test_scene_dam_break_2d(capsys):
    assert main(["scene", "dam-break", "--dim", "2", "--t-end", "0.005"]) == 0
    out = capsys.readouterr().out
    for word in ("fluid", "steps", "acoustic", "max speed", "energy", "left the domain",
                 "wall time"):
        assert word in out


def test_scene_json(capsys):
    assert main(["scene", "dam-break", "--dim", "2", "--t-end", "0.002", "--json",
                 "--quiet"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["steps"] > 0 and data["time_s"] == pytest.approx(0.002)
    assert data["particles"]["fluid"] == 5000
    assert data["health"]["left_domain"] == {}


@pytest.mark.parametrize("name, dim, l0", [("tank", 2, 1e-3), ("tank", 3, 1.3e-3),
                                           ("dam-break", 2, 1e-3), ("dam-break", 3, 1.3e-3),
                                           ("patch", 2, 1e-4), ("patch", 3, 1.3e-4)])
def test_a_scene_is_counted_before_numpy_builds_it(name, dim, l0):
    """The count that refuses a scene too large for one simulator (before Taichi starts or
    numpy allocates its lattice) is the built scene's, within a few per cent."""
    from crowndemo import scenes
    from crowndemo.cli.scene import SCENES, _particles

    val = {**SCENES[name]["defaults"][dim], "l0": l0}
    if name == "tank":
        built = scenes.hydrostatic_tank(dim=dim, l0=l0, width=val["width"], depth=val["depth"])
    elif name == "dam-break":
        built = scenes.dam_break(dim=dim, l0=l0, a=val["a"])
    else:
        built = scenes.square_patch(dim=dim, l0=l0, side=val["side"])
    assert _particles(name, dim, val) == pytest.approx(len(built.pos), rel=0.07)


def test_a_scene_too_large_is_refused_before_taichi_starts(monkeypatch, capsys):
    from crowndemo.cli import scene

    def started(args):
        raise AssertionError("the backend started before the size check")
    monkeypatch.setattr(scene, "start_backend", started)
    assert main(["scene", "patch", "--dim", "3", "--l0", "1e-6"]) == 2
    err = capsys.readouterr().err
    assert "one simulator holds at most 38,347,922" in err     # core.step.max_particles, 3D


def test_a_closed_stdout_ends_quietly():
    """`crowndemo info ... | head -1`: exit 141 (128 + SIGPIPE), no traceback. (Closing the
    pipe after a line races the command: all it prints fits the pipe's buffer.)"""
    import subprocess
    import sys
    proc = subprocess.Popen([sys.executable, "-m", "crowndemo", "info", "2m-drop", "--set",
                             "scene.height=1.5"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()     # the reader is gone before the command (still importing) writes
    err = proc.stderr.read().decode()
    assert proc.wait() == 141, err
    assert "Traceback" not in err and "BrokenPipe" not in err


def test_json_is_strict_when_no_step_sets_a_dt_range(capsys):
    """A run whose only step is cut short to land on its end has no dt range: null, not
    Infinity (which JSON lacks), and the text summary says why."""
    import json

    def no_constants(name):
        raise AssertionError(f"non-standard JSON constant {name}")
    assert main(["scene", "dam-break", "--t-end", "1e-9", "--json", "--quiet"]) == 0
    data = json.loads(capsys.readouterr().out, parse_constant=no_constants)
    assert data["steps"] == 1 and data["dt_min_s"] is None and data["dt_max_s"] is None
    assert main(["scene", "dam-break", "--t-end", "1e-9", "--quiet"]) == 0
    assert "every step cut short to land on a frame time or the end" in capsys.readouterr().out


def test_scene_summary_gives_the_units_of_its_sizes():
    from crowndemo.cli.scene import _sizes
    assert _sizes({"l0": 1e-3, "width": 0.04, "depth": 0.08, "nu": 1e-3, "t_end": 0.2}) == \
        "width 0.04 m, depth 0.08 m, nu 0.001 m^2/s"
    assert _sizes({"l0": 2e-3, "a": 0.03, "t_end": 0.1}) == "a 0.03 m"
    assert _sizes({"l0": 1e-4, "side": 2e-3, "sigma": 0.0728}) == "side 0.002 m, sigma 0.0728 N/m"


def test_first_step_line_allows_for_the_offline_cache(capsys):
    """The first step compiles the kernels or loads them from Taichi's offline cache."""
    import types

    from crowndemo.cli.common import Progress
    Progress(1.0, quiet=False)(types.SimpleNamespace(stats=types.SimpleNamespace(steps=1,
                                                                                 time=0.0)))
    err = capsys.readouterr().err
    assert "first step (kernels compiled or loaded from the cache)" in err
    assert "(compiling)" not in err
