"""Absurd or misplaced command-line input: one line ``crowndemo: error: ...`` naming the option
and its range, exit status 2, before any kernel runs (and figures that agree across commands)."""
import argparse
import json
import re

import pytest

from crowndemo.cli import main
from crowndemo.config import schema


def _one_line_error(argv, capsys) -> str:
    """Run ``argv``; assert exit status 2 and a single ``crowndemo: error:`` line; return it."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("crowndemo: error: "), err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


def _no_backend(monkeypatch, module) -> None:
    """Fail the test if ``module`` starts Taichi."""
    def started(args):
        raise AssertionError("the backend started before the input was checked")
    monkeypatch.setattr(module, "start_backend", started)


# ---- 1. info --dim/--l0: the ranges of a preset's keys, no overflow --------------------------
@pytest.mark.parametrize("option, value, field", [
    ("--l0", "1e300", schema.RUNG_KEYS["l0"]),
    ("--l0", "0.011", schema.RUNG_KEYS["l0"]),
    ("--speed", "1e300", schema.SCENE_KEYS["speed"]),
    ("--sound-speed", "1e300", schema.SCENE_KEYS["sound_speed"]),
    ("--rho", "1e300", schema.LIQUID_KEYS["rho"]),
    ("--nu", "1e300", schema.LIQUID_KEYS["nu"]),
    ("--sigma", "1e300", schema.LIQUID_KEYS["sigma"]),
    ("--re-ratio", "1e300", schema.SCENE_KEYS["re_ratio"]),
])
def test_info_lattice_options_share_the_presets_ranges(option, value, field, capsys):
    argv = ["info", "--dim", "3", "--l0", "1e-3"] + [f"{option}={value}"]
    err = _one_line_error(argv, capsys)
    assert f"(option {option})" in err and f"allowed: {field.allowed()}" in err


@pytest.mark.parametrize("extra, option", [
    (["--l0", "1e-300"], "--l0"),                         # the lattice sums underflowed
    (["--l0", "1e-7"], "--l0"),                           # dt below the floor of a run
    (["--l0", "1e-3", "--rho", "1e-300"], "--rho"),       # no l0 in range helps
])
def test_info_lattice_refuses_what_a_run_would(extra, option, capsys):
    err = _one_line_error(["info", "--dim", "2"] + extra, capsys)
    assert f"(option {option})" in err and "allowed: " in err


def test_info_lattice_refuses_an_infinite_dt():
    """l0 / v overflows only for a subnormal speed (no nu, no sigma), which this process,
    Taichi started, flushes to 0: the check itself, on the limits it would see."""
    import math

    from crowndemo.cli.info_lattice import _check_dt_floor
    from crowndemo.core.params import Numerics, ParameterError, Physics
    physics = Physics(dim=2, l0=1e-3, v_max=1.0, nu=0.0, sigma=0.0)
    with pytest.raises(ParameterError, match="speed"):
        _check_dt_floor(physics, Numerics(), {"courant": math.inf, "acoustic": math.inf})


def test_info_lattice_speed_is_named_as_its_option(capsys):
    err = _one_line_error(["info", "--dim", "3", "--l0", "1e-3", "--speed", "60"], capsys)
    assert "error: speed = 60.0 is out of range" in err and "v_max" not in err


def test_info_lattice_finest_l0_it_names_passes(capsys):
    err = _one_line_error(["info", "--dim", "3", "--l0", "1e-7"], capsys)
    finest = re.search(r"allowed: >= (\S+) m", err).group(1)
    assert main(["info", "--dim", "3", "--l0", finest, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["dt_s"] >= 1e-8


def test_info_lattice_at_the_edges_of_the_ranges(capsys):
    assert main(["info", "--dim", "3", "--l0", "0.01", "--speed", "50", "--rho", "25000",
                 "--sigma", "1", "--nu", "0.1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["dt_s"] > 0


def test_lattice_constants_refuse_a_spacing_they_cannot_sum():
    from crowndemo.core.lattice import LatticeConstants
    from crowndemo.core.params import ParameterError
    for l0 in (1e300, 1e-300):
        with pytest.raises(ParameterError, match="l0"):
            LatticeConstants.compute(3, l0, 2.1, 998.0, 0.0728)


# ---- 2. presets --rate, scene sizes ------------------------------------------------------------
@pytest.mark.parametrize("rate", ["1e-300", "999", "2e12", "inf"])
def test_presets_rate_has_a_range(rate, capsys):
    err = _one_line_error(["presets", f"--rate={rate}"], capsys)
    assert "(option --rate)" in err and ">= 1000 and <= 1e+12" in err


def test_presets_rate_at_its_ends_prints_short_run_times(capsys):
    for rate in ("1e3", "1e12"):
        assert main(["presets", "--rate", rate]) == 0
        out = capsys.readouterr().out
        assert max(len(line) for line in out.splitlines()) < 200
        assert not re.search(r"\binf\b", out)


@pytest.mark.parametrize("argv, option", [
    (["scene", "tank", "--dim", "2", "--width", "1e300"], "--width"),
    (["scene", "tank", "--dim", "3", "--depth", "1e3"], "--depth"),
    (["scene", "dam-break", "--dim", "3", "--a", "1e3"], "--a"),
    (["scene", "patch", "--dim", "2", "--side", "1e300"], "--side"),
    (["scene", "tank", "--dim", "2", "--l0", "1e-300"], "--l0"),
    (["scene", "tank", "--dim", "2", "--l0", "1e-300", "--width", "1e10"], "--l0"),
    (["scene", "tank", "--t-end", "1e300"], "--t-end"),
    (["scene", "tank", "--nu", "1e300"], "--nu"),
    (["scene", "patch", "--sigma", "1e300"], "--sigma"),
])
def test_scene_refuses_absurd_sizes_before_taichi(argv, option, monkeypatch, capsys):
    from crowndemo.cli import scene
    _no_backend(monkeypatch, scene)
    err = _one_line_error(argv, capsys)
    assert f"(option {option})" in err and len(err) < 300


@pytest.mark.parametrize("name, dim, key", [("tank", 2, "width"), ("tank", 3, "depth"),
                                            ("dam-break", 3, "a"), ("patch", 3, "side")])
def test_scene_size_bound_it_names_fits(name, dim, key, monkeypatch, capsys):
    """The largest size the message allows passes the check; a little more does not."""
    from crowndemo.cli import scene
    from crowndemo.cli.scene import SCENES, _numerics, _values
    from crowndemo.core.params import ParameterError
    _no_backend(monkeypatch, scene)
    err = _one_line_error(["scene", name, "--dim", str(dim), f"--{key}", "1e300"], capsys)
    top = float(re.search(r"<= (\S+) m", err).group(1))
    args = argparse.Namespace(dim=dim, gradient="pmin", courant=0.2, acoustic=1.0,
                              **{k: None for k in SCENES[name]["defaults"][dim]})
    setattr(args, key, top)
    _values(name, args, _numerics(args))
    setattr(args, key, top * 1.02)
    with pytest.raises(ParameterError, match=key):
        _values(name, args, _numerics(args))


# ---- 3. info's frame count is record's ---------------------------------------------------------
def test_info_counts_the_frames_record_writes(capsys):
    from crowndemo import config
    from crowndemo.record import frame_times
    assert main(["info", "quick-2d", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["scene"]["frames"] == len(frame_times(config.load("quick-2d"))) == 5
    assert main(["info", "quick-2d"]) == 0
    assert "5 frames, every 0.25 ms from t = 0" in capsys.readouterr().out
    assert main(["info", "quick-2d", "--set", "scene.frame_interval="]) == 0
    assert "1 frame (t = 0; no frame_interval)" in capsys.readouterr().out


# ---- 4. --set is no parent preset ----------------------------------------------------------
def test_info_shows_set_overrides_apart_from_the_extends_chain(capsys):
    assert main(["info", "quick", "--set", "scene.speed=7"]) == 0
    out = capsys.readouterr().out
    assert "  extends " not in out and "--set <-" not in out
    assert "  overrides   --set scene.speed=7\n" in out
    assert main(["info", "quick-2d", "--set", "scene.speed=7", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["extends_chain"] == ["presets/quick.yaml", "presets/quick-2d.yaml"]
    assert data["overrides"] == ["scene.speed=7"]


# ---- 5. 2D energies are per unit depth -------------------------------------------------------
def test_scene_json_names_the_energy_unit(capsys):
    assert main(["scene", "dam-break", "--dim", "2", "--t-end", "1e-9", "--json",
                 "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out)["energy_unit"] == "J/m (per unit depth)"


# ---- 6. bench --set: a preset's checks, before Taichi ------------------------------------------
@pytest.mark.parametrize("item, words", [
    ("numerics.cournt=1", ["--set: numerics.cournt", "did you mean 'courant'"]),
    ("numerics.courant=nan", ["--set: numerics.courant", "not a number", "> 0 and <= 2"]),
    ("numerics.fixed_dt=1", ["--set: numerics.fixed_dt", "breaks a time-step limit",
                             "N = 2,000"]),
    ("numerics.fixed_dt=1e-9", ["--set: numerics.fixed_dt", ">= 1e-08 and <= 1 s"]),
])
def test_bench_set_is_checked_as_a_presets(item, words, monkeypatch, capsys):
    from crowndemo.cli import bench
    _no_backend(monkeypatch, bench)
    err = _one_line_error(["bench", "--n", "2000", "--steps", "1", "--set", item], capsys)
    for word in words:
        assert word in err


@pytest.mark.parametrize("argv, words", [
    (["bench", "--n", "2000", "--max-steps", "3"],
     ["--quality and --max-steps apply to --preset runs only"]),
    (["bench", "--quality", "booth"], ["--quality and --max-steps apply to --preset runs only"]),
    (["bench", "--preset", "quick", "--n", "1000"], ["--n and --compare apply to the tank"]),
    (["bench", "--set", "numerics.courant=0.3", "--compare"], ["--set or --compare"]),
])
def test_bench_misplaced_options_are_usage_errors(argv, words, monkeypatch, capsys):
    from crowndemo.cli import bench
    _no_backend(monkeypatch, bench)
    err = _one_line_error(argv, capsys)
    assert "'given'" not in err and "out of range" not in err
    for word in words:
        assert word in err
