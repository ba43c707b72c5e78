"""The record/export/run command lines around recordings and sessions (in-process)."""
import json

import pytest

from crowndemo.cli import main

SHORT = ["--set", "scene.t_end=5e-5", "--set", "scene.frame_interval=2.5e-5"]


@pytest.mark.parametrize("cmd", [["record"], ["export"]])
def test_help(cmd, capsys):
    assert main(cmd + ["--help"]) == 0
    out = capsys.readouterr().out
    assert "usage: crowndemo" in out and "examples:" in out


@pytest.mark.parametrize("argv, words", [
    (["record", "quick-2d", "--then", "quick-2d"], "listed twice"),
    (["record", "quick-2d", "--resume", "--then", "quick"], "--resume takes one PRESET"),
    (["record", "quick-2d", "--checkpoint-every", "-1"], "--checkpoint-every"),
    (["export", "quick-2d"], "--vtk"),
    (["run", "quick-2d", "--playlist", "/nonexistent/list.txt"], "cannot read the playlist"),
])
def test_mistakes_exit_2(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("crowndemo: error: ") and words in err and "Traceback" not in err


def test_playlist_names_the_bad_line(tmp_path, capsys):
    p = tmp_path / "list.txt"
    p.write_text("# booth\nquick-2d\n\nquick-3d-nosuch\n")
    assert main(["run", "quick-2d", "--playlist", str(p)]) == 2
    assert "list.txt:4" in capsys.readouterr().err


def test_record_stop_and_resume(tmp_path, capsys):
    argv = ["record", "quick-2d", "--recordings", str(tmp_path), "--quiet"] + SHORT
    assert main(argv + ["--max-steps", "5"]) == 0
    err = capsys.readouterr().err
    assert "interrupted (max-steps)" in err and "--resume" in err
    meta = json.loads((tmp_path / "quick-2d" / "metadata.json").read_text())
    assert (meta["complete"], meta["status"], meta["steps"]) == (False, "interrupted", 5)
    assert main(argv + ["--resume", "--json"]) == 0
    meta = json.loads(capsys.readouterr().out)
    assert meta["complete"] and meta["steps"] > 5 and len(meta["frames"]) == 3
    assert meta["wall_seconds"]["starts"][1]["from_step"] == 5
    # other values than the checkpoint's: refused with the key that differs
    assert main(argv + ["--resume", "--set", "scene.speed=7"]) == 2
    assert "speed" in capsys.readouterr().err


def test_run_then_reuses_the_session(capsys):
    assert main(["run", "quick-2d", "--then", "quick-2d", "--max-steps", "3", "--json",
                 "--quiet"] + SHORT) == 0
    first, second = json.loads(capsys.readouterr().out)
    assert first["startup"]["reused_simulator"] is False
    assert second["startup"]["reused_simulator"] is True
    assert second["startup"]["kernels_compiled"] == 0
    assert first["steps"] == second["steps"] == 3
