"""Presets: every shipped preset validates at every quality (no kernels), the quick presets run
through the `run` command, bad files and bad --set values give one clear error each, extends
chains and --set overrides resolve as documented."""
import json
import math
from dataclasses import fields

import pytest

from crowndemo import config
from crowndemo.cli import main
from crowndemo.config import estimate, schema
from crowndemo.core.lattice import n0_lambda0
from crowndemo.core.params import Numerics

SHIPPED = {"3m-drop", "2.5m-drop", "2m-drop", "20cm-drop", "thick-layer", "quick", "quick-2d"}


# ---- the shipped presets ----------------------------------------------------------------------
def test_shipped_presets_are_listed():
    assert SHIPPED <= set(config.preset_names())


def test_shipped_booth_playlist_names_shipped_presets():
    """presets/booth.txt, the playlist of the README's examples, lists the seed's other scenes
    (not 2m-drop, which the examples record first: a name listed twice is refused)."""
    from crowndemo.config.playlist import read_playlist
    names = [spec for spec, _ in read_playlist(str(config.presets_dir() / "booth.txt"))]
    assert names == ["3m-drop", "20cm-drop", "thick-layer"]
    for name in names:
        schema.validate(config.load_document(name))


@pytest.mark.parametrize("quality", config.QUALITIES)
@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_every_preset_validates_at_every_quality(name, quality):
    r = config.load(name, quality)
    assert r.quality == quality and r.name == name
    for text in (r.title, r.description):          # English and Japanese
        assert text.get("en") and text.get("ja")
    assert r.dim == (2 if name.endswith("-2d") else 3)
    kw = r.crown_kwargs()
    assert kw["film"] / kw["l0"] > 3 - 1e-9 and kw["drop"] / kw["l0"] > 3 - 1e-9
    dt, binding = r.dt()
    assert dt >= 1e-8 and binding in r.limits()


def test_preset_values_follow_the_seed():
    g = 9.81
    r = config.load("3m-drop", "booth")
    s = r.scene
    assert (s["speed"], s["film"], s["drop"], s["gap"], s["floor"]) == (8.0, 1e-3, 1e-2, 1e-3,
                                                                         0.09)
    assert r.liquid == {"name": "water", "rho": 998.0, "nu": 1.0e-6, "sigma": 0.0728}
    assert config.load("2.5m-drop").speed == 7.0
    assert config.load("2m-drop").speed == pytest.approx(math.sqrt(2 * g * 2.0))
    assert config.load("2m-drop").scene["height"] == 2.0
    assert config.load("20cm-drop").speed == 2.0
    thick = config.load("thick-layer")
    assert thick.scene["film"] == 1e-2 and thick.speed == 5.0
    assert abs(config.load("3m-drop", "booth").l0 - 3e-4) < 1e-12


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_presets_sound_speed_rule(name):
    """c = k U (S8) for every shipped preset at every quality: k = 10 for the crown presets
    (config/sound_speed.py; the seed's 5 stops the 3m-drop at contact at D/l0 = 100,
    VALIDATION.md "Sound speed"), the seed's k = 5 kept by the quick smoke tests; the slow-drop
    floor (the fall and capillary speeds, config/resolve.py) does not reach U there."""
    k = 5.0 if name.startswith("quick") else 10.0
    for quality in config.QUALITIES:
        r = config.load(name, quality)
        assert r.scene["sound_speed_factor"] == k
        assert r.physics.c == pytest.approx(k * r.speed, rel=1e-12)
        assert r.scene["sound_speed_source"] == f"{k:g} x speed"


def test_the_seeds_sound_speed_stays_selectable():
    """scene.sound_speed_factor = 5 gives the seed's c = 5 U; scene.sound_speed gives c."""
    r = config.load("3m-drop", "draft", ["scene.sound_speed_factor=5"])
    assert r.physics.c == pytest.approx(40.0) and r.where["sound_speed"][0] == \
        "scene.sound_speed_factor"
    r = config.load("3m-drop", "draft", ["scene.sound_speed=123"])
    assert r.physics.c == 123.0 and r.where["sound_speed"][0] == "scene.sound_speed"


def test_a_slow_drop_takes_its_sound_speed_from_the_capillary_speed():
    """At U = 0.5 m/s c = 5 U = 2.5 m/s would let the potential's cohesive stress, 2.25
    sigma/l0 in 2D at re = 2.1 l0 (README, Validation status), compress the liquid by
    2.25 sigma / (l0 rho c^2) = 26 %: c is 5 sqrt(2.25 sigma / (rho l0)) instead (4 %), and
    the run that went unstable at its 6th step with c = 5 U runs."""
    from crowndemo.core import simulator_for
    r = config.load("quick-2d", "draft", ["scene.speed=0.5", "scene.t_end=4e-4"])
    sigma, rho = r.liquid["sigma"], r.liquid["rho"]
    assert r.physics.c == pytest.approx(5.0 * math.sqrt(2.25 * sigma / (rho * r.l0)), rel=0.01)
    assert r.physics.c > 2.5 * 5.0 * r.speed
    assert r.scene["sound_speed_source"].startswith("5 x the capillary speed")
    scene = r.build_scene()
    assert scene.physics.c == r.physics.c
    sim = simulator_for(scene)
    sim.run(r.t_end)                                  # InstabilityError with c = 5 U
    assert sim.stats.steps > 20 and sim.stats.peak_max_density_excess < 0.5


def test_particle_classes_and_quick_is_quick():
    tp = estimate.throughput()
    booth = estimate.summary(config.load("3m-drop", "booth"), tp)["particles"]
    assert booth["exact"] and 250_000 < booth["fluid"] < 330_000       # the seed's 282,423
    whole = ["quality.seed.symmetry=full", "quality.seed.trim_reach=2"]
    seed = estimate.summary(config.load("2.5m-drop", "seed", whole), tp)["particles"]
    # the seed's 11,946,816 class: at l0 = 0.1 mm (0.09 mm would give (10/9)^3 more)
    assert 8e6 < seed["fluid"] < 14e6
    # the seed rung simulates a quarter (symmetry planes) of the film trimmed at 1.25 R_c:
    # a quarter of the whole scene with that trim
    trimmed = estimate.summary(config.load("2.5m-drop", "seed", whole[:1]), tp)["particles"]
    quarter = estimate.summary(config.load("2.5m-drop", "seed"), tp)["particles"]
    assert quarter["fluid"] == pytest.approx(trimmed["fluid"] / 4, rel=0.02)
    quick = estimate.summary(config.load("quick", "draft"), tp)
    assert quick["particles"]["fluid"] < 30_000 and quick["run_seconds"] < 60


def test_scaled_counts_match_the_built_scene():
    r = config.load("quick", "booth")
    exact = estimate.particle_counts(r)
    scaled = estimate.particle_counts(r, exact_up_to=0, scale_from=3e4)
    assert exact["exact"] and not scaled["exact"] and scaled["built_l0"] > r.l0
    for kind in ("fluid", "wall", "dummy"):
        assert scaled[kind] == pytest.approx(exact[kind], rel=0.06)


def test_presets_command(capsys):
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    for name in SHIPPED:
        assert name in out
    assert "DRAFT" in out and "BOOTH" in out and "SEED" in out
    assert main(["presets", "--json", "--rate", "1e6"]) == 0
    data = json.loads(capsys.readouterr().out)
    rows = {row["name"]: row for row in data["presets"]}
    assert set(rows) >= SHIPPED
    q = rows["quick"]["qualities"]["draft"]
    assert q["particles"]["fluid"] > 0 and q["steps"] > 0 and q["run_seconds_estimate"] > 0
    assert data["throughput"]["fluid_particle_steps_per_s"] == 1e6


def test_info_preset_text_and_json(capsys):
    assert main(["info", "3m-drop"]) == 0
    out = capsys.readouterr().out
    for word in ("quality draft", "n0", "lambda0", "sound speed", "courant", "acoustic",
                 "viscous", "capillary", "binds", "particles", "memory", "steps", "run time",
                 "left out", "quality.draft.t_end"):
        assert word in out, word
    assert main(["info", "3m-drop", "--quality", "booth", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    n0, lam = n0_lambda0(3, 3e-4, 2.1 * 3e-4)
    assert d["n0"] == pytest.approx(n0) and d["lambda0"] == pytest.approx(lam)
    assert d["sound_speed_m_s"] == pytest.approx(10 * 8.0)     # c = 10 U (config/sound_speed.py)
    assert d["dt_s"] == min(v for v in d["limits_s"].values() if v is not None)
    assert d["binding"] in d["binding_ties"]
    p = d["particles"]
    assert p["fluid"] + p["wall"] + p["dummy"] == p["total"] and p["exact"]
    assert d["memory_bytes"] > 0 and d["steps_at_U"] == math.ceil(4e-3 / d["dt_s"] - 1e-9) + 16
    assert d["steps"] > d["steps_at_U"] and d["run_seconds_estimate"] > d["run_seconds_at_U"]
    assert d["left_out"] == [] or all(isinstance(s, str) for s in d["left_out"])
    # the crown presets take the Courant limit on relative speeds (README, the paragraph of
    # that name): after contact the splash's speeds scale with U (estimate.py; the sound-speed
    # study, VALIDATION.md): 1.5 U relative, and the approach limit at the splash's 4 U at
    # D/l0 = 30 growing as (D/l0)^0.36; the acoustic limit l0/c binds here, at 0.9 of it
    assert d["numerics"]["courant_speed"] == "relative"
    assert d["limits_s"]["approach"] == pytest.approx(0.5 * 3e-4 / 8.0)
    c, U, l0 = d["sound_speed_m_s"], 8.0, 3e-4
    splash = 4.0 * U * (1e-2 / l0 / 30) ** 0.36
    assert d["relative_speed_m_s"] == pytest.approx(1.5 * U)
    assert d["splash_speed_m_s"] == pytest.approx(splash)
    assert d["binding_after_contact"] == "acoustic"
    assert d["dt_after_contact_s"] == pytest.approx(0.9 * min(
        0.2 * l0 / (1.5 * U), 0.5 * l0 / splash, l0 / c))
    assert main(["info", "3m-drop", "--quality", "booth", "--json",
                 "--set", "numerics.courant_speed=absolute"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert "approach" not in a["limits_s"] and a["relative_speed_m_s"] is None
    assert a["dt_after_contact_s"] == pytest.approx(0.2 * l0 / splash)     # the Courant limit
    assert a["steps"] > d["steps"]


def test_info_lattice_form_still_works_and_forms_do_not_mix(capsys):
    assert main(["info", "--dim", "3", "--l0", "1e-4", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["dim"] == 3
    assert main(["info", "3m-drop", "--dim", "3"]) == 2
    assert "--dim" in capsys.readouterr().err
    assert main(["info", "--dim", "3", "--l0", "1e-4", "--set", "scene.speed=2"]) == 2
    assert "need a PRESET" in capsys.readouterr().err


# ---- runs (kernels): a few steps at draft size ------------------------------------------------
def test_run_quick_and_quick_2d_smoke(capsys):
    assert main(["run", "quick", "--then", "quick-2d", "--max-steps", "3", "--json"]) == 0
    captured = capsys.readouterr()
    runs = json.loads(captured.out)
    assert [r["preset"] for r in runs] == ["quick", "quick-2d"]
    assert [r["dim"] for r in runs] == [3, 2]
    for r in runs:
        assert r["quality"] == "draft" and r["steps"] == 3 and r["stopped_early"]
        assert r["particles"]["fluid"] > 0 and r["health"]["nonfinite"] == 0
        assert r["time_s"] > 0 and r["dt_min_s"] > 0
    assert "crowndemo: run quick (1 of 2)" in captured.err      # the progress header


def test_run_summary_text(capsys):
    assert main(["run", "quick-2d", "--max-steps", "2", "--set", "scene.speed=4"]) == 0
    out = capsys.readouterr().out
    assert "preset quick-2d (draft): 2D" in out and "U = 4 m/s" in out
    for word in ("particles", "simulated", "steps bound by", "health", "wall time",
                 "stopped early"):
        assert word in out, word
    assert " J/m -> " in out            # a 2D run's energy is per unit depth


# ---- bad preset files: one clear error each --------------------------------------------------
GOOD = """\
title: {en: "test", ja: "テスト"}
scene:
  floor: 0.05
  film: 1.0e-3
  drop: 4.0e-3
  speed: 3.0
  gap: 5.0e-4
  t_end: 5.0e-4
  frame_interval: 2.5e-4
quality:
  draft: {l0: 3.0e-4}
"""


def _with(old, new):
    assert old in GOOD
    return GOOD.replace(old, new)


BAD = [  # (id, file text, quality, fragments of the message after "<file>: ")
    ("misspelt key", _with("  film:", "  flim:"), "draft",
     ["scene.flim = 0.001: unknown key (did you mean 'film'?)", "allowed: floor, film, drop"]),
    ("wrong type", _with("film: 1.0e-3", "film: thin"), "draft",
     ["scene.film = 'thin': not a number", "allowed: > 0 and <= 0.1 m"]),
    ("missing value", _with("  drop: 4.0e-3\n", ""), "draft",
     ["scene.drop = (missing): no value given", "allowed: > 0 and <= 0.1 m"]),
    ("negative thickness", _with("film: 1.0e-3", "film: -1.0e-3"), "draft",
     ["scene.film = -0.001: out of range", "allowed: > 0 and <= 0.1 m"]),
    ("zero thickness", _with("film: 1.0e-3", "film: 0"), "draft",
     ["scene.film = 0.0: out of range", "allowed: > 0"]),
    ("drop larger than the container", _with("drop: 4.0e-3", "drop: 0.06"), "draft",
     ["scene.drop = 0.06: the drop is wider than the container floor",
      "allowed: < scene.floor = 0.05 m"]),
    ("drop overlapping the film", _with("gap: 5.0e-4", "gap: -1.0e-3"), "draft",
     ["scene.gap = -0.001: out of range", "allowed: >= 0 and <= 0.1 m"]),
    ("speed too high", _with("speed: 3.0", "speed: 80"), "draft",
     ["scene.speed = 80.0: out of range", "allowed: > 0 and <= 50 m/s"]),
    ("height too high", _with("speed: 3.0", "height: 500"), "draft",
     ["scene.height = 500.0: gives U = sqrt(2 g H) = 99.05 m/s", "allowed: <= 127.4 m"]),
    ("speed and height", _with("speed: 3.0", "speed: 3.0\n  height: 1.0"), "draft",
     ["scene.height = 1.0: give scene.speed or scene.height, not both"]),
    ("no speed", _with("  speed: 3.0\n", ""), "draft",
     ["scene.speed = (missing): no impact speed", "scene.height", "allowed: > 0 and <= 50 m/s"]),
    ("sound speed factor too small", _with("speed: 3.0", "speed: 3.0\n  sound_speed_factor: 1.5"),
     "draft", ["scene.sound_speed_factor = 1.5: out of range", "allowed: >= 2 and <= 100"]),
    ("dt below 1e-8 s", _with("speed: 3.0", "speed: 40").replace("l0: 3.0e-4", "l0: 1.0e-6"),
     "draft", ["scene.sound_speed_factor = 10.0: the time step would be 2.5e-09 s (bound by "
               "the acoustic limit), below 1e-08 s",
               "allowed: <= 2.5 at U = 40 m/s and l0 = 1e-06 m (c = k U)"]),
    ("dt below 1e-8 s at the seed's c", _with("speed: 3.0", "speed: 40\n  sound_speed_factor: 5")
     .replace("l0: 3.0e-4", "l0: 1.0e-6"),
     "draft", ["scene.speed = 40.0: the time step would be 5e-09 s (bound by the courant "
               "limit), below 1e-08 s", "allowed: U <= 20 m/s at l0 = 1e-06 m"]),
    ("l0 too coarse for the film", _with("l0: 3.0e-4", "l0: 5.0e-4"), "draft",
     ["quality.draft.l0 = 0.0005: too coarse: 2 particles across the film",
      "allowed: <= h/3 = 0.0003333 m"]),
    ("l0 too coarse for the drop", _with("drop: 4.0e-3", "drop: 8.0e-4"), "draft",
     ["quality.draft.l0 = 0.0003: too coarse: 2.67 particles across the drop",
      "allowed: <= D/3 = 0.0002667 m"]),
    ("bad dim", "dim: 4\n" + GOOD, "draft", ["dim = 4: not one of the choices", "allowed: 3 or 2"]),
    ("misspelt quality", _with("  draft:", "  boot:"), "draft",
     ["quality.boot = {l0: 0.0003}: unknown key (did you mean 'booth'?)",
      "allowed: draft, booth, seed"]),
    ("no such rung", GOOD, "booth",
     ["quality.booth = (missing): this preset defines no such quality rung", "allowed: draft"]),
    ("bad gradient", GOOD + "numerics: {pressure_gradient: foo}\n", "draft",
     ["numerics.pressure_gradient = 'foo': not one of the choices",
      "allowed: seed or pmin or sum"]),
    ("courant out of range", GOOD + "numerics: {courant: 5}\n", "draft",
     ["numerics.courant = 5.0: out of range", "allowed: > 0 and <= 2"]),
    ("fixed dt too large", GOOD + "numerics: {fixed_dt: 1.0e-3}\n", "draft",
     ["numerics.fixed_dt = 0.001: breaks a time-step limit", "allowed: <= "]),
    ("unknown liquid", _with("  gap:", "  liquid: mlik\n  gap:"), "draft",
     ["scene.liquid = 'mlik': unknown liquid (did you mean 'milk'?)",
      "allowed: a liquid name (water, milk)"]),
    ("unknown liquid name", _with("  gap:", "  liquid: {name: honey}\n  gap:"), "draft",
     ["scene.liquid.name = 'honey': not one of the choices", "allowed: water or milk"]),
    ("sigma in mN/m", _with("  gap:", "  liquid: {sigma: 72.8}\n  gap:"), "draft",
     ["scene.liquid.sigma = 72.8: out of range", "allowed: >= 0 and <= 1 N/m"]),
    ("frames longer than the run", _with("frame_interval: 2.5e-4", "frame_interval: 1.0e-3"),
     "draft", ["scene.frame_interval = 0.001: longer than the run", "allowed: <= t_end"]),
    ("trim not a bool", _with("  gap:", "  trim: 3\n  gap:"), "draft",
     ["scene.trim = 3: not true or false", "allowed: true or false"]),
    ("no title", GOOD.split("\n", 1)[1], "draft", ["title = (missing): no value given"]),
    ("scene not a mapping", "title: t\nscene: 3\nquality: {draft: {l0: 1.0e-4}}\n", "draft",
     ["scene = 3: not a mapping", "allowed: a mapping with keys floor, film"]),
    ("not YAML", GOOD + "  bad: [1, 2\n", "draft", ["not valid YAML at line"]),
    ("not a mapping", "- 1\n- 2\n", "draft", ["not a preset: the top level must be a mapping"]),
    ("duplicate key", _with("  gap: 5.0e-4\n", "  gap: 5.0e-4\n  gap: 1.0e-3\n"), "draft",
     ["scene.gap = 0.001: key given twice in one mapping (line 8, column 3)"]),
    ("extends nothing", "extends: nosuch-preset\n" + GOOD, "draft",
     ["extends = 'nosuch-preset': no such preset in", "allowed: ", "3m-drop"]),
]


@pytest.mark.parametrize("text, quality, fragments", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_preset_file_gives_one_clear_error(tmp_path, capsys, text, quality, fragments):
    path = tmp_path / "bad.yaml"
    path.write_text(text, encoding="utf-8")
    assert main(["info", str(path), "--quality", quality]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"crowndemo: error: {path}: "), err
    assert err.count("\n") == 1 and "Traceback" not in err
    for fragment in fragments:
        assert fragment in err, (fragment, err)


def test_error_in_a_parent_names_the_parent(tmp_path, capsys):
    (tmp_path / "parent.yaml").write_text(_with("film: 1.0e-3", "film: -1.0e-3"),
                                         encoding="utf-8")
    child = tmp_path / "child.yaml"
    child.write_text("extends: parent.yaml\nscene: {speed: 2.0}\n")
    assert main(["run", str(child)]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path / 'parent.yaml'}: scene.film = -0.001: out of range" in err


def test_extends_cycle(tmp_path):
    (tmp_path / "a.yaml").write_text("extends: b.yaml\n" + GOOD, encoding="utf-8")
    (tmp_path / "b.yaml").write_text("extends: a.yaml\n")
    with pytest.raises(config.PresetError, match="extends cycle"):
        config.load(str(tmp_path / "a.yaml"))


BAD_SETS = [
    ("scene.flim=1e-3", ["scene.flim = 0.001: unknown key (did you mean 'film'?)"]),
    ("scene.speed=fast", ["scene.speed = 'fast': not a number", "allowed: > 0 and <= 50 m/s"]),
    ("scene.film=-1", ["scene.film = -1.0: out of range", "allowed: > 0 and <= 0.1 m"]),
    ("scene.gap=-0.001", ["scene.gap = -0.001: out of range", "allowed: >= 0"]),
    ("scene.speed=60", ["scene.speed = 60.0: out of range", "<= 50 m/s"]),
    ("quality.draft.l0=0.01", ["quality.draft.l0 = 0.01: too coarse", "allowed: <= h/3"]),
    ("numerics.courant=0", ["numerics.courant = 0.0: out of range", "allowed: > 0 and <= 2"]),
    ("numerics.gradient=sum", ["numerics.gradient = 'sum': unknown key "
                               "(did you mean 'pressure_gradient'?)"]),
    ("dim=3.5", ["dim = 3.5: not one of the choices", "allowed: 3 or 2"]),
    ("scene.speed", ["scene.speed = (missing): no value: write KEY=VALUE",
                     "allowed: KEY.PATH=VALUE"]),
    ("=3", ["(empty key) = '3': not a dotted key path"]),
    ("scene.speed=[1,", ["not valid YAML"]),
    ("extends=3m-drop", ["extends = '3m-drop': extends cannot be changed with --set"]),
    ("scene.liquid.rho=1", ["scene.liquid.rho = 1.0: out of range", ">= 100 and <= 25000"]),
]


@pytest.mark.parametrize("item, fragments", BAD_SETS, ids=[b[0] for b in BAD_SETS])
def test_bad_set_gives_one_clear_error(capsys, item, fragments):
    assert main(["info", "quick", "--set", item]) == 2
    err = capsys.readouterr().err
    assert err.startswith("crowndemo: error: --set"), err
    assert err.count("\n") == 1 and "Traceback" not in err
    for fragment in fragments:
        assert fragment in err, (fragment, err)


def test_a_slow_drop_too_fine_for_its_sound_speed_names_l0(capsys):
    """c from the capillary speed, which grows as 1/sqrt(l0): the acoustic dt l0/c falls as
    l0^1.5, and the finest l0 named gives dt = 1e-8 s. Water (sigma 0.0728 N/m, rho 998
    kg/m^3) at 3e-7 m: c = 5 sqrt(2.25 sigma / (rho l0)) = 117 m/s, dt = l0/c = 2.56e-9 s
    (acoustic safety 1), so l0 >= 3e-7 (1e-8 / 2.56e-9)^(2/3) = 7.44e-7 m."""
    argv = ["info", "quick-2d", "--set", "quality.draft.l0=3e-7", "--set", "scene.speed=0.01"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "quality.draft.l0 = 3e-07" in err and "c = 5 x the capillary speed" in err
    assert "allowed: >= 7.44e-07 m" in err and err.count("\n") == 1


def test_unknown_preset_name_suggests_one(capsys):
    assert main(["run", "3m-dorp"]) == 2
    err = capsys.readouterr().err
    assert "preset = '3m-dorp': no such preset" in err and "did you mean '3m-drop'?" in err


def test_error_message_format():
    with pytest.raises(config.PresetError) as e:
        config.load("quick", sets=["scene.drop=0.2"])
    assert str(e.value) == ("--set: scene.drop = 0.2: out of range; allowed: > 0 and <= 0.1 m")


# ---- extends and --set ------------------------------------------------------------------------
def test_extends_chain(tmp_path):
    sub = tmp_path / "sub"
    sub.mkdir()
    (tmp_path / "child.yaml").write_text(
        "extends: 3m-drop\n"                     # a preset name
        "title: {en: child}\n"
        "scene:\n  speed: 5.0\n  t_end: 3.0e-3\n  liquid: {sigma: 0.05}\n"
        "numerics: {courant: 0.1}\n")
    (sub / "grandchild.yaml").write_text(
        "extends: ../child.yaml\n"               # a path relative to this file
        "scene: {height: 0.5, frame_interval: ~}\n"
        "quality: {booth: {l0: 2.5e-4}}\n")
    r = config.load(str(sub / "grandchild.yaml"), "draft")
    assert [c.rsplit("/", 1)[-1] for c in r.doc.chain] == ["3m-drop.yaml", "child.yaml",
                                                          "grandchild.yaml"]
    assert r.title["en"] == "child" and "ja" not in r.title
    assert r.scene["film"] == 1e-3 and r.scene["drop"] == 1e-2       # from 3m-drop
    assert r.speed == pytest.approx(math.sqrt(2 * 9.81 * 0.5))       # height replaced speed
    assert r.where["speed"][0] == "scene.height"
    assert r.where["speed"][1].endswith("grandchild.yaml")
    assert r.t_end == 3e-3           # the child's scene.t_end beats 3m-drop's draft t_end
    assert r.where["t_end"][0] == "scene.t_end"
    assert r.frame_times() == []     # null removed the inherited frame interval
    assert r.liquid == {"name": "water", "rho": 998.0, "nu": 1e-6, "sigma": 0.05}
    assert r.numerics.courant == 0.1 and r.numerics.acoustic == Numerics().acoustic
    assert r.l0 == 3.3e-4 and config.load(str(sub / "grandchild.yaml"), "booth").l0 == 2.5e-4
    assert r.description["en"].startswith("A 10 mm water drop")      # inherited


def test_set_overrides():
    base = config.load("3m-drop")
    assert base.t_end == 2e-3 and base.where["t_end"][0] == "quality.draft.t_end"
    r = config.load("3m-drop", "draft", [
        "scene.speed=5", "scene.t_end=5e-4", "numerics.courant=0.1",
        "quality.draft.l0=3e-4", "scene.liquid.sigma=0", "scene.sound_speed=30"])
    assert r.speed == 5.0 and r.l0 == 3e-4 and r.numerics.courant == 0.1
    assert r.t_end == 5e-4 and r.where["t_end"] == ("scene.t_end", "--set")  # beats the rung
    assert r.liquid["sigma"] == 0.0 and not r.model.surface_tension
    assert r.physics.c == 30.0
    assert config.load("3m-drop", sets=["scene.height=1"]).speed == pytest.approx(
        math.sqrt(2 * 9.81))                                         # height replaces speed
    assert config.load("3m-drop", sets=["scene.speed=5", "scene.speed=6"]).speed == 6.0
    assert config.load("3m-drop", sets=["scene.frame_interval="]).frame_times() == []
    assert config.load("3m-drop", sets=["dim=2"]).dim == 2
    assert config.load("3m-drop", sets=["scene.liquid=milk"]).liquid["name"] == "milk"


def test_presets_folder_from_the_environment(tmp_path, monkeypatch, capsys):
    (tmp_path / "mine.yaml").write_text(GOOD, encoding="utf-8")
    (tmp_path / "_base.yaml").write_text(GOOD, encoding="utf-8")  # hidden: for extends
    monkeypatch.setenv("CROWNDEMO_PRESETS", str(tmp_path))
    assert config.preset_names() == ["mine"]
    assert config.load("mine").speed == 3.0
    assert main(["presets", "--json"]) == 0
    assert [p["name"] for p in json.loads(capsys.readouterr().out)["presets"]] == ["mine"]
    (tmp_path / "broken.yaml").write_text(_with("film: 1.0e-3", "film: 0"), encoding="utf-8")
    assert main(["presets"]) == 2                      # the good ones listed, the bad one named
    captured = capsys.readouterr()
    assert "mine" in captured.out and "broken" not in captured.out
    assert "broken.yaml: scene.film = 0.0: out of range" in captured.err


@pytest.mark.parametrize("cmd", [["presets"], ["run"], ["info"]])
def test_help_exits_0(cmd, capsys):
    assert main(cmd + ["--help"]) == 0
    out = capsys.readouterr().out
    assert "usage: crowndemo" in out and "examples:" in out


def test_yaml_reads_exponent_floats_and_the_schema_covers_numerics(tmp_path):
    from crowndemo.config.yamlio import load_text
    assert load_text("a: 1e-3\nb: 2E5\nc: 7\nd: .inf\n", "x") == {
        "a": 1e-3, "b": 2e5, "c": 7, "d": math.inf}
    # mirror_planes comes from scene.symmetry (the scene is built as the part), not numerics
    assert set(schema.NUMERICS_KEYS) == {f.name for f in fields(Numerics)} - {
        "allow_unsafe_dt", "mirror_planes"}


def test_run_time_estimate_reads_the_tuned_rows_of_a_compare_table(tmp_path):
    """`bench --compare` sections label their rows seed / tuned: the estimate takes the tuned
    figure (what runs) of the newest section, at its largest N."""
    md = tmp_path / "BENCHMARKS.md"
    md.write_text(
        "# Benchmarks\n\n## 2026-01-01 00:00 UTC\n\n- machine: X, 2 cores\n\n"
        "| fluid | total | steps | seconds | particle-steps/s | compile s | bytes/particle | arch "
        "| precision |\n| ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- |\n"
        "| 1,000 | 2,000 | 20 | 1.0 | 1.000e+05 | 1.00 | 92 | cpu (x64) | f32 |\n\n"
        "## 2026-01-02 00:00 UTC\n\n- machine: Y, 2 cores\n\n"
        "| variant | fluid | total | steps | seconds | particle-steps/s | compile s | "
        "bytes/particle | arch | precision |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: "
        "| ---: | --- | --- |\n"
        "| seed | 3,000 | 4,500 | 20 | 1.0 | 5.000e+05 | 1.00 | 104 | cpu (x64) | f32 |\n"
        "| tuned | 3,000 | 4,500 | 20 | 1.0 | 9.000e+05 | 2.00 | 332 | cpu (x64) | f32 |\n")
    tp = estimate.throughput(md)
    assert tp.rate == 9.0e5 and tp.bytes_per_particle == 332 and tp.total_per_fluid == 1.5
    assert "Y" in tp.source
