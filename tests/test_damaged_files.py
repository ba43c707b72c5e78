"""Damaged input files give one line `crowndemo: error: ...` naming the file (exit 2, no
traceback) and leave nothing half-written: a playlist that is not UTF-8, a snapshot that is
truncated or overwritten (export), a checkpoint that is truncated (record --resume)."""
import shutil

import numpy as np
import pytest

from crowndemo.cli import main
from crowndemo.record import checkpoint, snapshots

SETS = ["--set", "scene.t_end=5e-5", "--set", "scene.frame_interval=2.5e-5"]


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A complete quick-2d recording of three frames (with its checkpoint.npz)."""
    root = tmp_path_factory.mktemp("rec")
    assert main(["record", "quick-2d", "--no-render", "--quiet", "--recordings", str(root)]
                + SETS) == 0
    return root / "quick-2d"


@pytest.fixture
def copy(recording, tmp_path):
    """A copy of the recording to damage: RECORDINGS/quick-2d."""
    folder = tmp_path / "R" / "quick-2d"
    shutil.copytree(recording, folder)
    return folder


def _one_error(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("crowndemo: error: "), err
    assert "Traceback" not in err
    return err


def _truncate(path, size: int) -> None:
    path.write_bytes(path.read_bytes()[:size])


def _flip(path, start: int = 200, stop: int = 1200) -> None:
    """Garble bytes inside the archive's data, leaving its directory whole."""
    data = bytearray(path.read_bytes())
    data[start:stop] = bytes(b ^ 0x5A for b in data[start:stop])
    path.write_bytes(bytes(data))


# --- playlist ----------------------------------------------------------------------------

def test_playlist_that_is_not_utf8_names_the_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pl.txt").write_bytes(b"quick-2d\n\xe9t\xe9\n")
    assert main(["run", "quick-2d", "--playlist", "pl.txt", "--max-steps", "2"]) == 2
    err = _one_error(capsys)
    assert "pl.txt:2: not UTF-8 text (byte 0xe9)" in err and "allowed: a UTF-8 text" in err


# --- snapshots ---------------------------------------------------------------------------

def _damage(path, how: str) -> None:
    if how == "truncated":
        _truncate(path, 3000)
    elif how == "text":
        path.write_text("not a snapshot\n")
    elif how == "garbled":
        _flip(path)
    elif how == "npy":
        with path.open("wb") as f:
            np.save(f, np.arange(3))
    else:                                       # an archive without the snapshot's arrays
        np.savez(path, pos=np.zeros((3, 2)))


@pytest.mark.parametrize("how, what", [("truncated", "not an .npz archive"),
                                       ("text", "not an .npz archive"),
                                       ("garbled", "damaged data"),
                                       ("npy", "not an .npz archive"),
                                       ("partial", "no vel, pressure")])
def test_snapshot_reader_names_the_file(copy, how, what):
    path = copy / "snapshots" / "frame_00001.npz"
    _damage(path, how)
    with pytest.raises(snapshots.SnapshotError) as e:
        snapshots.read(path)
    assert str(e.value).startswith(f"{path}: cannot read the snapshot (") and what in str(e.value)


def _export(folder) -> int:
    return main(["export", "quick-2d", "--vtk", "--recordings", str(folder.parent)])


def _files(folder) -> dict:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.mark.parametrize("how", ["truncated", "text"])
def test_export_of_a_damaged_snapshot_writes_nothing(copy, capsys, how):
    bad = copy / "snapshots" / "frame_00002.npz"
    _damage(bad, how)
    assert _export(copy) == 2
    err = _one_error(capsys)
    assert f"{bad}: cannot read the snapshot" in err and "record it again" in err
    assert not (copy / "vtk").exists()              # no vtk/ and no .vtp of frames 0 and 1


def test_export_of_a_damaged_snapshot_keeps_the_earlier_export(copy, capsys):
    assert _export(copy) == 0
    (copy / "vtk" / "frame_00000.vtp").write_text("earlier")  # not what this export writes
    (copy / "vtk" / "frame_00009.vtp").write_text("stale")    # an export removes it on success
    before = _files(copy / "vtk")
    _flip(copy / "snapshots" / "frame_00001.npz")
    capsys.readouterr()
    assert _export(copy) == 2
    assert "frame_00001.npz: cannot read the snapshot (damaged data" in _one_error(capsys)
    assert _files(copy / "vtk") == before            # untouched, no temporary folder left


def test_export_into_a_new_nested_out_leaves_no_folder(copy, capsys, tmp_path):
    _damage(copy / "snapshots" / "frame_00001.npz", "truncated")      # after one frame
    out = tmp_path / "a" / "b" / "vtk"
    argv = ["export", "quick-2d", "--vtk", "--recordings", str(copy.parent), "--out", str(out)]
    assert main(argv) == 2
    _one_error(capsys)
    assert not (tmp_path / "a").exists()


# --- checkpoint --------------------------------------------------------------------------

@pytest.mark.parametrize("damage", [lambda p: _truncate(p, 1000), _flip,
                                    lambda p: p.write_text("hello\n")])
def test_checkpoint_reader_raises_checkpoint_error(copy, damage):
    path = copy / "checkpoint.npz"
    damage(path)
    with pytest.raises(checkpoint.CheckpointError) as e:
        checkpoint.load(path)
    assert str(e.value).startswith(f"{path}: unreadable checkpoint (")


def test_resume_from_a_truncated_checkpoint_is_refused(copy, capsys, monkeypatch):
    def refuse(args):
        raise AssertionError("the backend started")
    monkeypatch.setattr("crowndemo.cli.record.start_backend", refuse)
    (copy / "metadata.json").unlink()                 # as if interrupted: the checkpoint decides
    _truncate(copy / "checkpoint.npz", 1000)
    before = _files(copy / "snapshots")
    argv = ["record", "quick-2d", "--recordings", str(copy.parent), "--resume", "--no-render"]
    assert main(argv + SETS) == 2
    err = _one_error(capsys)
    assert f"{copy / 'checkpoint.npz'}: unreadable checkpoint" in err
    assert "without --resume" in err
    assert _files(copy / "snapshots") == before        # nothing removed or written
