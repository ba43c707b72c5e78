"""The record/export/run command lines around recordings and sessions (in-process)."""
import json
import os

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
    (["export", "quick-2dd"], "quick-2d"),                 # did you mean
    (["run", "quick-2d", "--playlist", "/nonexistent/list.txt"], "cannot read the playlist"),
    # an empty path would quietly mean the default folder
    (["record", "quick-2d", "--recordings", ""], "--recordings: an empty path"),
    (["export", "quick-2d", "--vtk", "--out", " "], "--out: an empty path"),
    (["play", "--recordings", "", "--headless", "--out", "x.mp4"], "--recordings: an empty"),
    (["sweep", "quick-2d", "--out", ""], "--out: an empty path"),
    (["run", "quick-2d", "--playlist", ""], "--playlist: an empty path"),
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
    # the files the preset extends; the --set overrides are named in the sources instead
    assert meta["extends_chain"][-1].endswith("quick-2d.yaml") and all(
        c.endswith(".yaml") for c in meta["extends_chain"])
    assert meta["parameters"]["sources"]["t_end"]["file"] == "--set"
    assert main(argv + ["--resume", "--json"]) == 0
    meta = json.loads(capsys.readouterr().out)
    assert meta["complete"] and meta["steps"] > 5 and len(meta["frames"]) == 3
    assert meta["wall_seconds"]["starts"][1]["from_step"] == 5
    # other values than the checkpoint's: refused with the key that differs
    assert main(argv + ["--resume", "--set", "scene.speed=7"]) == 2
    assert "speed" in capsys.readouterr().err


def test_a_fresh_recording_without_rendering_removes_the_old_frames_and_videos(tmp_path,
                                                                            capsys):
    """The frames and video of an earlier (rendered) recording would pass for the new one's:
    play would show them."""
    argv = ["record", "quick-2d", "--recordings", str(tmp_path), "--quiet"] + SHORT
    assert main(argv) == 0
    folder = tmp_path / "quick-2d"
    assert list(folder.glob("frames/frame_*.png")) and (folder / "video.mp4").is_file()
    assert main(argv + ["--no-render", "--set", "scene.speed=3"]) == 0
    assert "replacing the earlier recording" in capsys.readouterr().err
    assert not list(folder.glob("frames/*.png"))
    assert not list(folder.glob("video*.mp4")) and not list(folder.glob("preview*.gif"))
    meta = json.loads((folder / "metadata.json").read_text())
    assert meta["complete"] and meta["recording_options"]["render"] is False


def test_resume_keeps_the_rendering_and_snapshot_options(tmp_path, capsys):
    """A resumed recording's frames and snapshots must match the first part's: other
    options are refused with the command that fits, which the interruption printed too."""
    import shlex

    import imageio.v3 as iio

    from crowndemo.record import snapshots
    argv = ["record", "quick-2d", "--recordings", str(tmp_path), "--quiet"] + SHORT
    first = argv + ["--resolution", "320x180", "--all-particles", "--orbit=-2"]
    assert main(first + ["--max-steps", "5"]) == 0
    err = capsys.readouterr().err
    command = err.split("to resume: ")[1].strip()
    for words in ("--resolution 320x180", "--all-particles", "--orbit=-2"):
        assert words in command
    assert main(argv + ["--resume"]) == 2          # the defaults: other options
    err = capsys.readouterr().err
    assert "recorded with other options" in err and "resolution 320x180 there, 1280x720 now" in err
    assert "all-particles True there, False now" in err and command in err
    assert main(shlex.split(command)[1:] + ["--quiet"]) == 0
    folder = tmp_path / "quick-2d"
    meta = json.loads((folder / "metadata.json").read_text())
    assert meta["complete"] and len(meta["frames"]) == 3
    sizes = {iio.imread(p).shape[:2] for p in folder.glob("frames/frame_*.png")}
    assert sizes == {(180, 320)} and len(list(folder.glob("frames/frame_*.png"))) == 3
    counts = {len(snapshots.read(folder / f["file"])["id"]) for f in meta["frames"]}
    assert counts == {meta["particles"]["initial"]["total"]}      # walls and dummies in each


def test_run_then_reuses_the_session(capsys):
    assert main(["run", "quick-2d", "--then", "quick-2d", "--max-steps", "3", "--json",
                 "--quiet"] + SHORT) == 0
    first, second = json.loads(capsys.readouterr().out)
    assert first["startup"]["reused_simulator"] is False
    assert second["startup"]["reused_simulator"] is True
    assert second["startup"]["kernels_compiled"] == 0
    assert first["steps"] == second["steps"] == 3


def _files(folder):
    """Every file under ``folder``: its bytes and modification time."""
    return {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in sorted(folder.rglob("*"))
            if p.is_file()}


def test_resume_of_a_complete_recording_touches_nothing(tmp_path, capsys, monkeypatch):
    argv = ["record", "quick-2d", "--recordings", str(tmp_path), "--quiet"] + SHORT
    assert main(argv) == 0
    folder = tmp_path / "quick-2d"
    before = _files(folder)
    assert folder / "video.mp4" in before and folder / "metadata.json" in before
    capsys.readouterr()

    def no_backend(args):
        raise AssertionError("Taichi started for a complete recording")
    monkeypatch.setattr("crowndemo.cli.record.start_backend", no_backend)
    assert main(argv + ["--resume"]) == 0
    err = capsys.readouterr().err
    assert "already complete" in err and "nothing to resume" in err
    assert _files(folder) == before
    # other values than the recording's: refused, still nothing touched
    assert main(argv + ["--resume", "--set", "scene.speed=7"]) == 2
    assert "speed" in capsys.readouterr().err and _files(folder) == before


@pytest.mark.parametrize("where, words", [
    ("afile", "afile: not a folder"),                       # a file
    ("afile/sub", "afile: not a folder"),                   # under a file
    ("rec", "quick-2d: not a folder"),                      # rec/quick-2d is a file
    ("/proc/crowndemo-nope", "cannot create it"),           # a parent that takes no folders
])
def test_unusable_recordings_folder_exit_2_before_taichi(where, words, tmp_path, capsys,
                                                          monkeypatch):
    if where.startswith("/proc") and not os.path.isdir("/proc"):
        pytest.skip("no /proc")
    (tmp_path / "afile").touch()
    (tmp_path / "rec").mkdir()
    (tmp_path / "rec" / "quick-2d").touch()

    def no_backend(args):
        raise AssertionError("Taichi started before the folder was checked")
    monkeypatch.setattr("crowndemo.cli.record.start_backend", no_backend)
    folder = tmp_path / where
    assert main(["record", "quick-2d", "--recordings", str(folder), "--max-steps", "1",
                 "--no-render"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"crowndemo: error: --recordings {folder}: ") and words in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_max_steps_stops_each_preset_of_a_chain(tmp_path, capsys):
    """Like run: every preset of --then / --playlist is recorded, each stopped at step N and
    marked so (resumable), exit 0."""
    (tmp_path / "q2.yaml").write_text("extends: quick-2d\n")
    (tmp_path / "list.txt").write_text(f"{tmp_path / 'q3.yaml'}\n")
    (tmp_path / "q3.yaml").write_text("extends: quick-2d\n")
    rec = tmp_path / "rec"
    assert main(["record", "quick-2d", "--then", str(tmp_path / "q2.yaml"), "--playlist",
                 str(tmp_path / "list.txt"), "--max-steps", "3", "--no-render", "--quiet",
                 "--json", "--recordings", str(rec)] + SHORT) == 0
    out, err = capsys.readouterr()
    metas = json.loads(out)
    assert [m["preset"] for m in metas] == ["quick-2d", "q2", "q3"]
    for m in metas:
        meta = json.loads((rec / m["preset"] / "metadata.json").read_text())
        assert (meta["status"], meta["stopped_by"], meta["steps"]) == ("interrupted",
                                                                      "max-steps", 3)
        assert (rec / m["preset"] / "checkpoint.npz").is_file()
    assert err.count("interrupted (max-steps)") == 3 and "Traceback" not in err


def test_encoding_failure_marks_the_recording_failed(tmp_path, capsys, monkeypatch):
    """A video that cannot be made: one error line, exit 1, metadata.json "failed: ...",
    only partial names; the presets after it are not recorded (as after an unstable one)."""
    from crowndemo.render import video

    def broken(*args, **kw):
        raise OverflowError("int too big to convert")
    monkeypatch.setattr(video, "encode_gif", broken)
    (tmp_path / "q2.yaml").write_text("extends: quick-2d\n")
    rec = tmp_path / "rec"
    assert main(["record", "quick-2d", "--then", str(tmp_path / "q2.yaml"), "--recordings",
                 str(rec), "--resolution", "160x90", "--quiet"] + SHORT) == 1
    err = capsys.readouterr().err
    assert err.startswith("crowndemo: error: making the video failed (OverflowError: ")
    assert "not recorded: q2" in err and len(err.strip().splitlines()) == 1
    folder = rec / "quick-2d"
    meta = json.loads((folder / "metadata.json").read_text())
    assert meta["complete"] is False and meta["status"].startswith("failed: OverflowError")
    assert meta["render"]["outputs"] == {"video": "video.partial.mp4"}
    names = {p.name for p in folder.iterdir()}
    assert "video.partial.mp4" in names and not names & {"video.mp4", "preview.gif"}
    assert not (rec / "q2").exists()
