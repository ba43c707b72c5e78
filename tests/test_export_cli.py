"""`crowndemo export` refuses what it cannot use in one line, before the backend starts: an
output folder that is a file, a recordings folder that is a file, a metadata.json that is not
whole."""
import pytest

from crowndemo.cli import main


@pytest.fixture(autouse=True)
def no_backend(monkeypatch):
    def refuse(args):
        raise AssertionError("the backend started")
    monkeypatch.setattr("crowndemo.cli.export.start_backend", refuse)


def _one_error(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("crowndemo: error: "), err
    return err


@pytest.mark.parametrize("sub", ["", "/sub"])
def test_out_that_is_a_file_is_refused(tmp_path, capsys, sub):
    (tmp_path / "afile").write_text("")
    argv = ["export", "quick-2d", "--vtk", "--recordings", str(tmp_path / "R"), "--out",
            f"{tmp_path / 'afile'}{sub}"]
    assert main(argv) == 2
    assert f"--out {tmp_path / 'afile'}{sub}: " in _one_error(capsys)
    assert not (tmp_path / "R").exists()                  # nothing recorded, nothing made


def test_recordings_folder_that_is_a_file_is_refused(tmp_path, capsys):
    (tmp_path / "R").write_text("")
    argv = ["export", "quick-2d", "--vtk", "--recordings", str(tmp_path / "R"), "--out",
            str(tmp_path / "vtk")]
    assert main(argv) == 2
    assert f"--recordings {tmp_path / 'R' / 'quick-2d'}: " in _one_error(capsys)


@pytest.mark.parametrize("text, what", [('{"format": 1, "complete": tr', "cannot read it"),
                                        ("[1, 2]", "not a recording's metadata"),
                                        ('{"complete": true, "frames": [1]}',
                                         "not a recording's metadata"),
                                        (b"\xff\xfe{", "cannot read it")])
def test_metadata_that_is_not_whole_is_named(tmp_path, capsys, text, what):
    meta = tmp_path / "R" / "quick-2d" / "metadata.json"
    meta.parent.mkdir(parents=True)
    meta.write_bytes(text if isinstance(text, bytes) else text.encode())
    assert main(["export", "quick-2d", "--vtk", "--recordings", str(tmp_path / "R")]) == 2
    err = _one_error(capsys)
    assert f"{meta}: {what}" in err and "record it again" in err


def test_vtk_is_the_default_format(tmp_path, capsys):
    """Without --vtk the export goes on (here to the first check) instead of asking for it."""
    (tmp_path / "afile").write_text("")
    argv = ["export", "quick-2d", "--recordings", str(tmp_path / "R"), "--out",
            str(tmp_path / "afile")]
    assert main(argv) == 2
    err = _one_error(capsys)
    assert "choose a format" not in err and f"--out {tmp_path / 'afile'}: " in err


def test_help_says_vtk_is_the_default(capsys):
    assert main(["export", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "the default: may be left out" in out


def test_other_quality_summarises_the_frame_times(tmp_path, capsys):
    """The frame times differ as a summary, not as two long lists of floats."""
    import json

    from crowndemo.cli.common import load_preset
    from crowndemo.record.recorder import fingerprint

    args = type("A", (), {"quality": "draft", "sets": [], "precision": "f32"})()
    fp = fingerprint(load_preset("quick-2d", args), "f32")
    fp["frame_times"] = [0.0] + [i * 1e-4 for i in range(1, 21)]
    meta = tmp_path / "R" / "quick-2d" / "metadata.json"
    meta.parent.mkdir(parents=True)
    meta.write_text(json.dumps({"complete": True, "status": "complete", "fingerprint": fp,
                                "frames": [{"file": "f.npz", "time_s": 0.0}]}))
    assert main(["export", "quick-2d", "--quality", "booth", "--recordings",
                 str(tmp_path / "R")]) == 2
    err = _one_error(capsys)
    assert "frames: 21 every 0.1 ms to 2 ms -> " in err and "frame_times" not in err
    assert "quality: 'draft' -> 'booth'" in err and len(err) < 400
