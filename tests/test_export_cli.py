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
