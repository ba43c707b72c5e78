"""ParaView export (crowndemo.record.vtk): files parsed back give the written arrays exactly,
and `crowndemo export` of a preset without a recording records it first and exports every
frame, the .pvd listing each with its time."""
import json

import numpy as np

from crowndemo.cli import main
from crowndemo.record import snapshots, vtk


def test_round_trip_3d_f64(tmp_path):
    rng = np.random.default_rng(7)
    n = 1000
    snap = {"pos": rng.normal(size=(n, 3)), "vel": rng.normal(size=(n, 3)),
            "pressure": rng.random(n), "number_density": rng.random(n),
            "kind": rng.integers(0, 4, n).astype(np.int32), "id": np.arange(n, dtype=np.int32)}
    vtk.write(tmp_path / "a.vtp", snap, time=1.25e-3)
    back = vtk.read(tmp_path / "a.vtp")
    assert back["time"] == 1.25e-3
    assert back["points"].dtype == np.float64 and np.array_equal(back["points"], snap["pos"])
    assert np.array_equal(back["velocity"], snap["vel"])
    for k in ("pressure", "number_density", "kind", "id"):
        assert np.array_equal(back[k], snap[k]), k
    assert np.array_equal(back["connectivity"], np.arange(n))
    assert np.array_equal(back["offsets"], np.arange(1, n + 1))      # one vertex per cell
    vtk.write_pvd(tmp_path / "s.pvd", [(0.0, "a.vtp"), (1.0 / 3.0, "b.vtp")])
    assert vtk.read_pvd(tmp_path / "s.pvd") == [(0.0, "a.vtp"), (1.0 / 3.0, "b.vtp")]


def test_export_records_first_then_round_trips(tmp_path, capsys):
    rec = tmp_path / "rec"
    argv = ["export", "quick-2d", "--vtk", "--recordings", str(rec), "--quiet",
            "--set", "scene.t_end=5e-5", "--set", "scene.frame_interval=2.5e-5"]
    assert main(argv) == 0
    assert "no recording" in capsys.readouterr().err
    meta = json.loads((rec / "quick-2d" / "metadata.json").read_text())
    assert meta["complete"]
    entries = vtk.read_pvd(rec / "quick-2d" / "vtk" / "quick-2d.pvd")
    assert [t for t, _ in entries] == [f["time_s"] for f in meta["frames"]] == [0.0, 2.5e-5, 5e-5]
    for (t, name), f in zip(entries, meta["frames"]):
        snap = snapshots.read(rec / "quick-2d" / f["file"])
        back = vtk.read(rec / "quick-2d" / "vtk" / name)
        assert back["time"] == t == snap["time"]
        assert np.array_equal(back["points"][:, :2], snap["pos"])       # 2D: x, y and z = 0
        assert not back["points"][:, 2].any()
        assert np.array_equal(back["velocity"][:, :2], snap["vel"])
        assert np.array_equal(back["id"], snap["id"])
    # the final frame moved: the simulated positions, not the initial lattice
    first = vtk.read(rec / "quick-2d" / "vtk" / entries[0][1])["points"]
    last = vtk.read(rec / "quick-2d" / "vtk" / entries[-1][1])["points"]
    assert np.abs(last - first).max() > 1e-5
    # exporting again from the recording does not run anything and gives the same files
    assert main(argv[:5]) == 0
    assert "no recording" not in capsys.readouterr().err
    assert vtk.read_pvd(rec / "quick-2d" / "vtk" / "quick-2d.pvd") == entries
    # an interrupted recording exports what it has and says how to resume it
    meta.update(complete=False, status="interrupted")
    (rec / "quick-2d" / "metadata.json").write_text(json.dumps(meta))
    assert main(argv[:5]) == 0
    err = capsys.readouterr().err
    assert "(the recording is interrupted)" in err and "record quick-2d --resume" in err
