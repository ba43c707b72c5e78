"""Preset checks found by the audit: a sound speed the drop outruns is refused before any
kernel; ``sources`` credits defaults to the default; an empty ``--set`` value, a duplicated
YAML key, a folder and a missing $CROWNDEMO_PRESETS folder each give one clear error."""
import json

import pytest

from crowndemo import config
from crowndemo.cli import main
from crowndemo.core.params import Numerics

QUICK_U = 8.0           # presets/quick.yaml: scene.speed
MACH = Numerics().max_mach

SMALL = """\
title: small
scene: {film: 1.0e-3, drop: 4.0e-3, speed: 3.0, t_end: 5.0e-4}
quality: {draft: {l0: 3.0e-4}}
"""


def _error(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


# ---- 1. the sound speed against the impact speed ---------------------------------------------
def test_sound_speed_the_drop_outruns_is_refused_on_its_key():
    bound = QUICK_U / MACH          # the run stops when a speed exceeds max_mach * c
    with pytest.raises(config.PresetError) as e:
        config.load("quick", sets=["scene.sound_speed=1"])
    assert (e.value.source, e.value.key, e.value.value) == ("--set", "scene.sound_speed", 1.0)
    assert f"> U / max_mach = {bound:g} m/s" in e.value.allowed
    with pytest.raises(config.PresetError):      # the drop starts at U and gains speed
        config.load("quick", sets=[f"scene.sound_speed={bound}"])
    assert config.load("quick", sets=[f"scene.sound_speed={bound * 1.01}"]).physics.c > bound


def test_sound_speed_bound_follows_max_mach():
    sets = ["numerics.max_mach=2"]
    with pytest.raises(config.PresetError, match=r"allowed: > U / max_mach = 4 m/s"):
        config.load("quick", sets=sets + [f"scene.sound_speed={QUICK_U / 2}"])
    config.load("quick", sets=sets + [f"scene.sound_speed={QUICK_U / 2 * 1.01}"])


def test_max_mach_below_u_over_default_c_is_refused():
    # c = 5 U without scene.sound_speed, so max_mach must exceed 1/5
    with pytest.raises(config.PresetError) as e:
        config.load("quick", sets=["numerics.max_mach=0.2"])
    assert e.value.key == "numerics.max_mach" and "> U / c = 0.2" in e.value.allowed
    assert config.load("quick", sets=["numerics.max_mach=0.21"]).numerics.max_mach == 0.21


def test_sound_speed_in_a_file_names_the_file(tmp_path):
    path = tmp_path / "slow.yaml"
    path.write_text(SMALL.replace("speed: 3.0", "speed: 3.0, sound_speed: 2.0"))
    with pytest.raises(config.PresetError) as e:
        config.load(str(path))
    assert str(e.value).startswith(f"{path}: scene.sound_speed = 2.0: ")
    assert e.value.allowed == "> U / max_mach = 3 m/s"


def test_run_refuses_a_slow_sound_speed_before_any_kernel(monkeypatch, capsys):
    import crowndemo.cli.run as run_cli

    def no_backend(*args, **kwargs):
        raise AssertionError("the backend started")
    monkeypatch.setattr(run_cli, "start_backend", no_backend)
    assert main(["run", "quick", "--set", "scene.sound_speed=1", "--max-steps", "5"]) == 2
    assert _error(capsys).startswith("crowndemo: error: --set: scene.sound_speed = 1.0: ")


# the splash's speed scales with U, not c (config/estimate.py, the sound-speed study):
# 4 U (D/l0 / 30)^0.36 = 21.5 m/s = 2.7 U for quick's U = 8 m/s at D/l0 = 10, whatever c
@pytest.mark.parametrize("c, splash", [(10.0, "21.5 m/s = 2.7 U = 2.2 c"),
                                       (40.0, "21.5 m/s = 2.7 U = 0.54 c")])
def test_info_states_the_splash_speed_in_units_of_U_and_c(capsys, c, splash):
    assert main(["info", "quick", "--set", f"scene.sound_speed={c}"]) == 0
    assert f"the splash's ~{splash}" in capsys.readouterr().out


# ---- 2. sources -------------------------------------------------------------------------------
def test_sources_credit_only_what_a_source_wrote(tmp_path, capsys):
    path = tmp_path / "one.yaml"
    path.write_text("extends: quick\nnumerics: {}\nscene: {gap: 5.0e-4}\n")
    r = config.load(str(path), sets=["numerics.courant=0.1"])
    quick = r.doc.chain[0]
    assert quick.endswith("quick.yaml")
    assert r.where["gap"] == ("scene.gap", r.label)
    assert r.where["film"] == ("scene.film", quick) and r.where["l0"][1] == quick
    assert r.where["numerics.courant"] == ("numerics.courant", "--set")
    for name in ("re_ratio", "trim", "numerics.neighbour_list"):   # set by nobody
        assert r.where[name][1] == "default", name
    assert main(["info", str(path), "--json"]) == 0
    sources = json.loads(capsys.readouterr().out)["sources"]
    assert sources["gap"]["file"] == r.label and sources["trim"]["file"] == "default"


def test_sources_of_a_preset_without_extends(tmp_path):
    path = tmp_path / "small.yaml"
    path.write_text(SMALL)
    r = config.load(str(path))
    assert r.where["speed"] == ("scene.speed", r.label)
    assert {k for k, (_, src) in r.where.items() if src == "default"} == {
        "floor", "gap", "liquid", "gravity", "trim", "re_ratio", "symmetry", "trim_reach",
        "sound_speed_factor", "sound_speed"}     # c = k U from the default k


# ---- 3. an empty --set value -----------------------------------------------------------------
@pytest.mark.parametrize("item, key, why", [
    ("scene.speed=", "scene.speed", "no impact speed"),
    ("scene.film=", "scene.film", "no value given"),
    ("title=", "title", "no value given"),
    ("quality.draft.l0=", "quality.draft.l0", "no value given")])
def test_empty_set_value_is_named_as_the_source(capsys, item, key, why):
    assert main(["info", "quick", "--set", item]) == 2
    assert _error(capsys).startswith(f"crowndemo: error: --set {key}=: {key} = (missing): {why}")


def test_emptied_height_names_the_set_that_emptied_it():
    with pytest.raises(config.PresetError) as e:       # 2m-drop gives height, not speed
        config.load("2m-drop", sets=["scene.height="])
    assert (e.value.source, e.value.key) == ("--set scene.height=", "scene.speed")


def test_null_in_a_parent_names_the_parent(tmp_path):
    child = tmp_path / "child.yaml"
    child.write_text("extends: quick\nscene: {film: ~}\n")
    (tmp_path / "grandchild.yaml").write_text("extends: child.yaml\nscene: {speed: 5.0}\n")
    with pytest.raises(config.PresetError) as e:
        config.load(str(tmp_path / "grandchild.yaml"))
    assert (e.value.source, e.value.key) == (config.display(child), "scene.film")


# ---- 4. duplicate keys, folders, $CROWNDEMO_PRESETS -------------------------------------------
def test_duplicate_key_names_its_path_value_and_line(tmp_path, capsys):
    path = tmp_path / "dup.yaml"
    path.write_text("title: x\nscene:\n  film: 0.001\n  film: 0.002\n")
    assert main(["info", str(path)]) == 2
    assert _error(capsys).startswith(f"crowndemo: error: {path}: scene.film = 0.002: key given "
                                     "twice in one mapping (line 4, column 3)")


def test_duplicate_key_in_a_set_value_names_its_path():
    with pytest.raises(config.PresetError) as e:
        config.load("quick", sets=["scene.liquid={rho: 1000, rho: 900}"])
    assert (e.value.key, e.value.value) == ("scene.liquid.rho", 900)


def test_a_folder_is_not_a_preset(tmp_path, capsys):
    assert main(["info", str(tmp_path)]) == 2
    assert _error(capsys).startswith(f"crowndemo: error: {tmp_path}: a folder, not a preset "
                                     "file")
    (tmp_path / "child.yaml").write_text(f"extends: {tmp_path}/\n")
    with pytest.raises(config.PresetError, match="extends = .*: a folder, not a preset file"):
        config.load(str(tmp_path / "child.yaml"))


@pytest.mark.parametrize("cmd", [["presets"], ["info", "quick"]])
def test_missing_presets_folder_is_an_error(tmp_path, monkeypatch, capsys, cmd):
    missing = tmp_path / "nope"
    monkeypatch.setenv("CROWNDEMO_PRESETS", str(missing))
    assert main(cmd) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"crowndemo: error: $CROWNDEMO_PRESETS: no such folder: {missing}; "
                            "allowed: an existing folder of preset .yaml files, or unset for "
                            "presets/ next to the crowndemo package\n")


# ---- found by feeding every key extreme values through `info PRESET --set` --------------------
def test_a_tiny_safety_number_is_named_as_the_cause():
    """A preset's own safety number that shrinks dt under DT_FLOOR is the key the error names,
    with the smallest value that passes (each limit is linear in its number); the approach
    limit (courant_speed: relative) used to raise a KeyError on numerics.dt_max."""
    from crowndemo.config.resolve import DT_FLOOR
    base = config.load("3m-drop")                  # courant_speed: relative
    assert base.numerics.courant_speed == "relative"
    for key in ("approach", "courant", "acoustic"):
        with pytest.raises(config.PresetError) as e:
            config.load("3m-drop", sets=[f"numerics.{key}=1e-9"])
        assert (e.value.source, e.value.key) == ("--set", f"numerics.{key}")
        assert f"bound by the {key} limit" in e.value.why
        need = float(e.value.allowed.split()[1])
        # the limit at the default number, scaled to the bound, is just above DT_FLOOR
        at_default = base.limits()[key] / getattr(base.numerics, key)
        assert DT_FLOOR <= at_default * need <= DT_FLOOR * 1.002
        assert config.load("3m-drop", sets=[f"numerics.{key}={need}"]).dt()[0] >= DT_FLOOR


def test_dt_max_below_the_floor_names_dt_max():
    with pytest.raises(config.PresetError) as e:
        config.load("quick", sets=["numerics.dt_max=1e-9"])
    assert (e.value.key, e.value.allowed) == ("numerics.dt_max", ">= 1e-08 s")


@pytest.mark.parametrize("key", ["scene.frame_interval", "quality.draft.frame_interval"])
def test_more_frames_than_an_hour_of_video_is_refused_before_listing_them(key):
    """A frame interval of 1e-30 s planned 2e27 frames: `info` filled 23 GB and was killed."""
    from crowndemo.config.resolve import MAX_FRAMES
    with pytest.raises(config.PresetError) as e:
        config.load("quick", sets=[f"{key}=1e-30"])
    r = config.load("quick")
    assert e.value.key == key and f"more than {MAX_FRAMES:,}" in e.value.why
    bound = float(e.value.allowed.split(" = ")[-1].split()[0])
    assert len(config.load("quick", sets=[f"{key}={bound}"]).frame_times()) <= MAX_FRAMES
    assert bound == pytest.approx(r.t_end / MAX_FRAMES, rel=1e-3)


@pytest.mark.parametrize("text, why", [
    ("title: " + "[" * 5000 + "]" * 5000 + "\n", "not valid YAML: nested too deeply"),
    ("extends: quick\nscene: {speed: " + "9" * 5000 + "}\n",
     "not valid YAML: a value it cannot read (Exceeds the limit (4300 digits)"),
])
def test_yaml_python_cannot_read_is_one_clear_error(tmp_path, capsys, text, why):
    """Nesting deeper than Python's recursion limit, and an integer longer than it converts
    (4300 digits), raised a traceback from PyYAML."""
    path = tmp_path / "odd.yaml"
    path.write_text(text)
    assert main(["info", str(path)]) == 2
    assert _error(capsys).startswith(f"crowndemo: error: {path}: {why}")
    assert main(["info", "quick", "--set", "scene.speed=" + "9" * 5000]) == 2
    assert "--set scene.speed: not valid YAML" in _error(capsys)


def test_a_wide_drop_on_a_thin_film_is_estimated_without_building_it():
    """A coarse build must keep 3 particles across the film: for a 50 mm drop on a 0.1 mm
    film at l0 = 10 um that build alone held 3.4e9 particles and `info` asked numpy for
    25 GB. Past BUILD_AT_MOST the counts come from the sizes: the drop's volume and the
    film's over l0^3, the floor's wall layers over its area."""
    import math
    import tracemalloc

    from crowndemo.config import estimate
    r = config.load("3m-drop", sets=["quality.draft.l0=1e-5", "scene.film=1e-4",
                                     "scene.drop=0.05"])
    tracemalloc.start()
    p = estimate.particle_counts(r)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 50e6                                          # bytes: nothing was built
    assert not p["exact"] and p["built_l0"] is None
    assert p["n_drop"] == pytest.approx(math.pi / 6 * 0.05 ** 3 / 1e-5 ** 3, rel=1e-9)
    area = math.pi * p["extent_m"] ** 2      # the film's disc: the reach, or half the floor
    assert p["n_film"] == pytest.approx(area * 1e-4 / 1e-5 ** 3, rel=1e-9)
    assert p["total"] > r.max_particles()                       # info says it is refused
    with pytest.raises(config.PresetError, match="more than the"):
        r.build_scene()
