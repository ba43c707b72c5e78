"""`crowndemo validate` and `crowndemo sweep` as commands: mistakes refused before the backend
starts, report files of this run only, Ctrl-C keeps the finished runs, strict JSON. The runs
themselves are replaced by fakes (the suites are tested in test_validate.py)."""
import json
import math
import types

import pytest

from crowndemo.cli import main
from crowndemo.validate import cases, runner
from crowndemo.validate import sweep as sweep_mod
from crowndemo.validate.sweep import Point


def _strict(text):
    """json.loads that refuses NaN and Infinity."""
    def refuse(name):
        raise AssertionError(f"not strict JSON: {name}")
    return json.loads(text, parse_constant=refuse)


@pytest.fixture
def no_backend(monkeypatch):
    """A backend that must not start: fails the test when asked for."""
    def refuse(args):
        raise AssertionError("the backend started")
    for mod in ("validate", "sweep"):
        monkeypatch.setattr(f"crowndemo.cli.{mod}.start_backend", refuse)


@pytest.fixture
def fake_backend(monkeypatch):
    be = types.SimpleNamespace(resolved="x64", precision="f32", fast_compile=False)
    for mod in ("validate", "sweep"):
        monkeypatch.setattr(f"crowndemo.cli.{mod}.start_backend", lambda args: be)


def _row(variant="base", error=0.01):
    return runner.Row("hydrostatic-2d", 2, variant, "H/l0", 20.0, 2e-3, 628, 669, 1.0, 0.5,
                      384.6, 391.6, error, "ok", "floor pressure", {"x": math.nan})


@pytest.fixture
def ran(monkeypatch):
    """Fake case runs: the cases asked for, and a Ctrl-C after the first row when told."""
    calls = {"cases": [], "interrupt": False, "everywhere": []}

    def run_suite(selected, quick, variants, on_row, everywhere=()):
        calls["cases"].append([c.name for c in selected])
        calls["everywhere"].append(list(everywhere))
        on_row(_row(error=math.nan))
        if calls["interrupt"]:
            raise KeyboardInterrupt
        on_row(_row("f64"))
    monkeypatch.setattr(runner, "run_suite", run_suite)
    return calls


# ---- validate ---------------------------------------------------------------------------------
@pytest.mark.parametrize("sub", ["", "/sub"])
def test_validate_out_that_is_a_file_is_refused_first(tmp_path, capsys, no_backend, sub):
    f = tmp_path / "afile"
    f.write_text("")
    assert main(["validate", "hydrostatic-2d", "--quick", "--out", f"{f}{sub}"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("crowndemo: error: --out ")
    assert f"{f}: not a folder" in err and "Traceback" not in err


def test_validate_list_refuses_case_names(capsys, no_backend):
    assert main(["validate", "--list", "nosuchcase"]) == 2
    assert "--list takes no case names (got nosuchcase)" in capsys.readouterr().err


def test_validate_misspelt_case_suggests_the_closest(capsys, no_backend):
    assert main(["validate", "dam-brake-2d"]) == 2
    assert "unknown case dam-brake-2d (did you mean 'dam-break-2d'?)" in \
        capsys.readouterr().err


def test_validate_list_json(capsys, no_backend):
    assert main(["validate", "--list", "--json"]) == 0
    data = _strict(capsys.readouterr().out)
    table = cases.all_cases(full=True)
    assert [c["name"] for c in data["cases"]] == list(table)
    assert data["cases"][0]["scales"] == list(table[data["cases"][0]["name"]].scales)
    assert "verdicts" in data["groups"] and "3m-drop" in data["groups"]["verdicts"]


def test_validate_runs_a_case_named_twice_once(tmp_path, ran, fake_backend):
    argv = ["validate", "laplace-2d", "hydrostatic-2d", "laplace-2d", "hydrostatic-2d",
            "--out", str(tmp_path)]
    assert main(argv) == 0
    assert ran["cases"] == [["laplace-2d", "hydrostatic-2d"]]


def test_validate_at_every_resolution_takes_a_variant_of_the_cases(tmp_path, capsys, ran,
                                                                    fake_backend):
    """--at-every-resolution names a settings variant of the cases selected (refused before
    the backend starts otherwise, naming the allowed ones), not with --no-variants; the
    suite gets it."""
    assert main(["validate", "stress-laplace-3d", "--at-every-resolution", "re=3.1",
                 "--out", str(tmp_path)]) == 0
    assert ran["everywhere"] == [["re=3.1"]]
    capsys.readouterr()
    assert main(["validate", "hydrostatic-2d", "--at-every-resolution", "re=3.1",
                 "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "--at-every-resolution re=3.1: not a variant of the cases selected; allowed: " \
        "f64, safety/2" in err and err.count("error") == 1
    assert main(["validate", "stress-laplace-3d", "--no-variants", "--at-every-resolution",
                 "re=3.1", "--out", str(tmp_path)]) == 2
    assert "--no-variants runs none" in capsys.readouterr().err
    assert len(ran["everywhere"]) == 1


def test_quick_leaves_out_the_costly_cases_unless_named():
    """--quick with no names leaves out the 3m-drop crown, the 3D free drop (10 periods of a
    3D drop) and the verdicts; named, they run."""
    from crowndemo.cli.validate import QUICK_LEAVES_OUT, _names
    table = cases.all_cases(full=True)
    quick = _names(types.SimpleNamespace(cases=[], quick=True), table)
    assert not set(QUICK_LEAVES_OUT) & set(quick)
    assert "stress-free-drop-2d" in quick and "stability" in quick
    assert set(_names(types.SimpleNamespace(cases=[], quick=False), table)) >= set(
        QUICK_LEAVES_OUT)
    named = _names(types.SimpleNamespace(cases=["stress-free-drop-3d"], quick=True), table)
    assert named == ["stress-free-drop-3d"]


def test_quick_compiles_fast_unless_the_environment_says(tmp_path, ran, monkeypatch):
    """--quick asks the backend for the fast compile, unless $CROWNDEMO_FAST_COMPILE is set
    (then the backend reads it); the report's header says which."""
    asked = []

    def start(args):
        asked.append(args.fast_compile)
        return types.SimpleNamespace(resolved="x64", precision="f32",
                                     fast_compile=bool(args.fast_compile))
    monkeypatch.setattr("crowndemo.cli.validate.start_backend", start)
    monkeypatch.delenv("CROWNDEMO_FAST_COMPILE", raising=False)
    argv = ["validate", "hydrostatic-2d", "--out", str(tmp_path)]
    assert main(argv + ["--quick"]) == 0
    assert "x64, f32, fast compile; date" in (tmp_path / "validation.md").read_text()
    assert main(argv) == 0
    assert "x64, f32; date" in (tmp_path / "validation.md").read_text()
    monkeypatch.setenv("CROWNDEMO_FAST_COMPILE", "0")
    assert main(argv + ["--quick"]) == 0
    assert asked == [True, None, None]


def test_validate_json_is_strict(tmp_path, capsys, ran, fake_backend):
    assert main(["validate", "hydrostatic-2d", "--out", str(tmp_path), "--json"]) == 0
    for text in ((tmp_path / "validation.json").read_text(), capsys.readouterr().out):
        data = _strict(text)
        assert data["cases"][0]["error"] is None and data["cases"][0]["extra"]["x"] is None
        assert data["cases"][1]["error"] == 0.01 and data["interrupted"] is False


def test_validate_describes_the_machine_as_bench_does(tmp_path, ran, fake_backend):
    """One description of the machine (machine.machine_line): "CPU, N cores, OS release"."""
    from crowndemo import machine as host
    assert main(["validate", "hydrostatic-2d", "--out", str(tmp_path)]) == 0
    machine = _strict((tmp_path / "validation.json").read_text())["machine"]
    assert machine == host.machine_line()
    assert machine.startswith(host.cpu_model() + ", ") and " cores, " in machine
    assert f"Machine: {machine};" in (tmp_path / "validation.md").read_text()


def test_validate_replaces_the_cases_report_as_a_whole(tmp_path, capsys, monkeypatch, ran,
                                                        fake_backend):
    """An older plot that this run could not redraw is removed; the other runs' reports
    (stability.md, verdicts.md, headed by their own command) and other files stay."""
    for name in ("error_vs_time.png", "stability.md", "verdicts.md", "notes.txt"):
        (tmp_path / name).write_text("an earlier run")
    monkeypatch.setitem(__import__("sys").modules, "matplotlib", None)   # no matplotlib
    assert main(["validate", "hydrostatic-2d", "--out", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "notes.txt", "stability.md", "validation.csv", "validation.json", "validation.md",
        "verdicts.md"]
    assert (tmp_path / "stability.md").read_text() == "an earlier run"
    files = _strict((tmp_path / "validation.json").read_text())["files"]
    assert "matplotlib" in files["plot_skipped"] and "plot" not in files
    err = capsys.readouterr().err
    assert "stability.md" not in err          # nothing said of the reports left alone


def test_validate_ctrl_c_writes_the_finished_rows(tmp_path, capsys, ran, fake_backend):
    ran["interrupt"] = True
    assert main(["validate", "hydrostatic-2d", "--out", str(tmp_path), "--record"]) == 130
    md = (tmp_path / "validation.md").read_text()
    assert "Interrupted (Ctrl-C)" in md.split("### ")[0]          # in the header
    assert md.count("| base |") == 1 and "| f64 |" not in md
    data = _strict((tmp_path / "validation.json").read_text())
    assert data["interrupted"] is True and len(data["cases"]) == 1
    assert "VALIDATION.md not rewritten" in capsys.readouterr().err


def test_validate_ctrl_c_before_any_row_replaces_the_older_report(tmp_path, capsys,
                                                                   monkeypatch, fake_backend):
    """Interrupted before the first case finished: validation.md is this run's, marked, with
    no row, not an earlier run's left as if it were this one's."""
    (tmp_path / "validation.md").write_text("an earlier run\n| base | 1 |")
    (tmp_path / "validation.csv").write_text("an earlier run")

    def run_suite(selected, quick, variants, on_row, everywhere=()):
        raise KeyboardInterrupt
    monkeypatch.setattr(runner, "run_suite", run_suite)
    assert main(["validate", "hydrostatic-2d", "--out", str(tmp_path)]) == 130
    md = (tmp_path / "validation.md").read_text()
    assert "Interrupted (Ctrl-C)" in md and "an earlier run" not in md and "| base |" not in md
    assert "an earlier run" not in (tmp_path / "validation.csv").read_text()
    assert _strict((tmp_path / "validation.json").read_text())["cases"] == []


def test_validate_help_names_every_variant_the_code_runs(capsys):
    assert main(["validate", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    names = runner.variant_names(cases.all_cases(full=True).values())
    assert {"plane-floor", "relative-courant", "untrimmed", "f64"} <= set(names)
    assert f"base settings only (no {', '.join(names)})" in text        # --no-variants
    assert ", ".join(names) in text.split("examples:")[1]               # the epilog


def test_validate_help_names_the_case_families(capsys):
    assert main(["validate", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    listed = text.split("Cases: ", 1)[1].split("; groups:", 1)[0]
    families = {f.strip() for f in listed.replace(" (each -2d and -3d)", "").split(",")}
    for name in cases.all_cases(full=True):      # every case, by its family or its own name
        family = name[:-3] if name.endswith(("-2d", "-3d")) else name
        assert family in families, name


# ---- sweep --------------------------------------------------------------------------------------
@pytest.mark.parametrize("args, message", [
    (["--film", "0"], "--film 0: out of range; allowed: > 0"),
    (["--film", "-1e-3"], "--film -0.001: out of range; allowed: > 0"),
    (["--film", "1.2e-3", "-2e0"], "--film -2: out of range"),
    (["--speed", "-2"], "--speed -2: out of range; allowed: > 0"),
    (["--speed", "2", "900"], "--speed 900: out of range"),
    (["--film", "1e-4"], "--film 0.0001 does not fit the preset: "),
])
def test_sweep_bad_point_names_the_option_before_the_backend(capsys, no_backend, args,
                                                              message):
    assert main(["sweep", "quick-2d", *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"crowndemo: error: {message}"), err


def test_sweep_out_that_is_a_file_is_refused_first(tmp_path, capsys, no_backend):
    (tmp_path / "afile").write_text("")
    assert main(["sweep", "quick-2d", "--film", "1.2e-3", "--speed", "2", "--out",
                 str(tmp_path / "afile")]) == 2
    assert "error: --out " in capsys.readouterr().err


@pytest.fixture
def swept(monkeypatch):
    """Fake sweep runs: a NaN radius, and a Ctrl-C after the first point when told."""
    calls = {"interrupt": False, "points": 0}

    def run_resolved(resolved, on_point):
        calls["points"] = len(resolved)
        for i, r in enumerate(resolved):
            if i and calls["interrupt"]:
                raise KeyboardInterrupt
            on_point(Point(r.scene["film"], r.speed, False, 1e-3, math.nan, 10, 1.0,
                           "ran to the end"))
    monkeypatch.setattr(sweep_mod, "run_resolved", run_resolved)
    monkeypatch.setattr(sweep_mod, "plot", lambda *a: "matplotlib is not installed")
    return calls


def test_sweep_records_overrides_and_removes_an_old_image(tmp_path, swept, fake_backend):
    (tmp_path / "regime.png").write_text("an earlier map")
    argv = ["sweep", "quick-2d", "--film", "1.2e-3", "--speed", "2", "3", "--set",
            "scene.t_end=3e-4", "--out", str(tmp_path)]
    assert main(argv) == 0
    assert not (tmp_path / "regime.png").exists()
    md = (tmp_path / "regime.md").read_text()
    assert "overrides (--set): `scene.t_end=3e-4`" in md and "--set scene.t_end=3e-4" in md
    data = _strict((tmp_path / "regime.json").read_text())
    assert data["sets"] == ["scene.t_end=3e-4"] and "scene.t_end=3e-4" in data["command"]
    assert data["points"][0]["base_radius"] is None and data["interrupted"] is False


def test_sweep_ctrl_c_writes_the_points_that_ran(tmp_path, swept, fake_backend):
    swept["interrupt"] = True
    argv = ["sweep", "quick-2d", "--film", "1.2e-3", "--speed", "2", "3", "--out",
            str(tmp_path)]
    assert main(argv) == 130
    md = (tmp_path / "regime.md").read_text()
    assert "Interrupted (Ctrl-C): 1 of 2 points ran" in md
    data = _strict((tmp_path / "regime.json").read_text())
    assert data["interrupted"] is True and len(data["points"]) == 1
    assert data["points_planned"] == 2


def test_record_keeps_the_sections_other_commands_write():
    # validate --record rewrites VALIDATION.md; the sound-speed study's sections, which its own
    # command writes, come through (each to the next '## ' heading), its own sections do not
    from crowndemo.cli.validate import kept_sections
    old = ("# Validation\n\n## Stability suite\n\nold table\n\n## Sound speed\n\nstudy\n\n"
           "## Sound speed: the rule chosen\n\nwhy\n")
    new = ["# Validation", "", "## Stability suite", "", "new table", ""]
    assert kept_sections(old, new) == ["## Sound speed", "", "study", "",
                                       "## Sound speed: the rule chosen", "", "why", ""]
    assert kept_sections("# Validation\n\n## Stability suite\n\nx\n", new) == []
