"""Recordings: snapshots, metadata.json, checkpoints and resume (crowndemo.record).

One thread, so that a resumed run can be compared bit for bit with an uninterrupted one.
The scene is quick-2d cut to 0.1 ms with a frame every 25 us: the drop touches the film at
0.05 ms, so the resumed part includes the impact.
"""
import json
import os
import signal

import numpy as np
import pytest

from crowndemo import backend, config
from crowndemo.control import Session
from crowndemo.core.state import FLUID
from crowndemo.interrupt import StopRequest
from crowndemo.record import files, record_preset, snapshots
from crowndemo.record import checkpoint as ckpt
from crowndemo.record.checkpoint import load as load_checkpoint
from crowndemo.record.checkpoint import save as save_checkpoint
from crowndemo.record.runlog import RunLog

T_END, INTERVAL = 1.0e-4, 2.5e-5
SETS = [f"scene.t_end={T_END}", f"scene.frame_interval={INTERVAL}"]


@pytest.fixture(scope="module")
def one_thread():
    backend.init("cpu", seed=1, single_thread=True)
    yield backend.current()
    backend.init("cpu")          # the session default for the other files


@pytest.fixture(scope="module")
def preset(one_thread):
    return config.load("quick-2d", "draft", SETS)


@pytest.fixture(scope="module")
def uninterrupted(preset, tmp_path_factory):
    folder = tmp_path_factory.mktemp("rec") / "quick-2d"
    res = record_preset(preset, folder, session=Session())
    return res, res.sim.save_state()


class SigintAt:
    """A frame sink that sends this process a real SIGINT at one frame."""

    def __init__(self, index):
        self.index, self.closed = index, None

    def frame(self, sim, index, time):
        if index == self.index:
            os.kill(os.getpid(), signal.SIGINT)

    def close(self, status):
        self.closed = status


def same_state(a, b):
    for k in a["particles"]:
        assert np.array_equal(a["particles"][k], b["particles"][k]), k
    assert np.array_equal(a["health_counters"], b["health_counters"])
    sa, sb = a["stats"], b["stats"]
    assert (sa.steps, sa.time, sa.dt_min, sa.dt_max) == (sb.steps, sb.time, sb.dt_min, sb.dt_max)
    assert list(sa.dt_log) == list(sb.dt_log) and list(sa.bound_log) == list(sb.bound_log)
    assert sa.binding == sb.binding and sa.health == sb.health
    assert (sa.peak_max_speed, sa.peak_max_density_excess) == (sb.peak_max_speed,
                                                               sb.peak_max_density_excess)


def test_metadata_and_snapshots_of_a_complete_recording(uninterrupted, preset):
    res, state = uninterrupted
    meta = json.loads((res.folder / files.METADATA).read_text())
    assert meta["complete"] is True and meta["status"] == "complete"
    times = [0.0] + [k * INTERVAL for k in range(1, 5)]
    assert [f["time_s"] for f in meta["frames"]] == times
    assert [f["index"] for f in meta["frames"]] == [0, 1, 2, 3, 4]
    assert meta["simulated_s"] == pytest.approx(T_END, rel=1e-12)
    s = state["stats"]
    assert meta["steps"] == s.steps == len(s.dt_log) > 0
    assert sum(meta["dt"]["binding_limits"].values()) == s.steps
    assert meta["dt"]["min_s"] <= meta["dt"]["max_s"]
    counts = meta["particles"]["initial"]
    assert counts["fluid"] + counts["wall"] + counts["dummy"] == counts["total"] == len(res.scene.pos)
    assert meta["left_out"] == res.scene.info["left_out"]
    assert meta["parameters"]["crown"]["speed"] == 8.0
    assert meta["health"]["peak_max_speed_m_s"] >= meta["health"]["max_speed_m_s"] > 0
    assert set(meta["versions"]) == {"crowndemo", "taichi", "numpy", "python"}
    assert meta["backend"]["single_thread"] is True
    for f in meta["frames"]:
        snap = snapshots.read(res.folder / f["file"])
        assert snap["time"] == f["time_s"] and snap["index"] == f["index"]
        assert (snap["kind"] == FLUID).all() and len(snap["id"]) == counts["fluid"]
    # the last frame lands on t_end: the snapshot is the final state, in id order
    final = res.sim.snapshot()
    fluid = final["kind"] == FLUID
    assert np.array_equal(snap["pos"], final["pos"][fluid])
    assert np.array_equal(snap["vel"], final["vel"][fluid])
    assert not list(res.folder.rglob(".*tmp*"))        # no temporary file left


def test_every_frame_carries_its_crown_metrics(uninterrupted, preset):
    """metadata.json's frames hold the crown metrics (sheet coherence among them) of their
    snapshot's fluid, as validate.crown_metrics measures them (issue 21: per frame)."""
    from crowndemo.strictjson import finite_or_none
    from crowndemo.validate.crown_metrics import measure
    from crowndemo.validate.verdicts import film_limit
    res, _ = uninterrupted
    meta = json.loads((res.folder / files.METADATA).read_text())
    s = preset.scene
    edge = film_limit(res.scene.info, preset.l0)
    for f in meta["frames"]:
        snap = snapshots.read(res.folder / f["file"])
        want = measure(snap["pos"], f["time_s"], s["film"], s["drop"], preset.l0, edge=edge)
        assert f["crown"] == json.loads(json.dumps(finite_or_none(want.as_dict())))
    assert meta["frames"][0]["crown"]["sheet_coherence"] == 0.0   # only the falling drop is raised
    last = meta["frames"][-1]["crown"]
    assert 0.0 <= last["sheet_coherence"] <= 1.0 and last["raised_particles"] > 0


def test_ctrl_c_then_resume_is_bit_identical(uninterrupted, preset, tmp_path):
    folder = tmp_path / "quick-2d"
    stop = StopRequest()
    sink = SigintAt(2)
    with stop.catching():
        res = record_preset(preset, folder, [sink], session=Session(), stop=stop)
    assert res.status == "interrupted" and sink.closed == "interrupted"
    meta = json.loads((folder / files.METADATA).read_text())
    assert meta["complete"] is False and meta["status"] == "interrupted"
    assert meta["stopped_by"] == "ctrl-c"
    assert [f["index"] for f in meta["frames"]] == [0, 1, 2]
    ck = load_checkpoint(folder / files.CHECKPOINT)
    assert ck.next_frame == 3
    assert ck.time > 2 * INTERVAL and ck.steps == res.sim.stats.steps   # one step after frame 2
    resumed = record_preset(preset, folder, resume=True, session=Session())   # a new simulator
    assert resumed.complete
    same_state(uninterrupted[1], resumed.sim.save_state())
    meta = json.loads((folder / files.METADATA).read_text())
    assert meta["complete"] is True and [f["index"] for f in meta["frames"]] == [0, 1, 2, 3, 4]
    assert len(meta["wall_seconds"]["starts"]) == 2
    for f in meta["frames"]:
        a = snapshots.read(uninterrupted[0].folder / f["file"])
        b = snapshots.read(folder / f["file"])
        for k in snapshots.FIELDS:
            assert np.array_equal(a[k], b[k]), (f["file"], k)


def _without(fp: dict, paths) -> dict:
    out = json.loads(json.dumps(fp))
    for path in paths:
        d = out
        for k in path[:-1]:
            d = d[k]
        del d[path[-1]]
    return out


def test_resume_of_a_checkpoint_made_before_a_key_existed(uninterrupted, preset, tmp_path):
    """A checkpoint whose fingerprint lacks the keys added since (ADDED_KEYS) continues where
    the preset holds the values that ran before them, and ends as the uninterrupted run; one
    whose preset now departs from such a value is refused, naming the key."""
    from crowndemo.record import RecordError
    from crowndemo.record.recorder import ADDED_KEYS, SAME, fingerprint
    folder = tmp_path / "quick-2d"
    assert record_preset(preset, folder, session=Session(), max_steps=50).status == "interrupted"
    path = folder / files.CHECKPOINT
    ck = load_checkpoint(path)
    now = fingerprint(preset, "f32")

    def value(p):
        d = now
        for k in p:
            d = d[k]
        return d
    same = [p for p, before in ADDED_KEYS.items() if before is SAME or before == value(p)]
    assert {p[-1] for p in same} >= {"surface_tension", "viscosity", "predictor_list",
                                     "wall_model", "mirror_planes", "symmetry"}
    save_checkpoint(path, ck.saved, ck.log, ck.next_frame, _without(ck.fingerprint, same))
    resumed = record_preset(preset, folder, resume=True, session=Session())
    assert resumed.complete
    same_state(uninterrupted[1], resumed.sim.save_state())
    # quick-2d collides particles at 0.5 l0; before numerics.collision there were no collisions
    assert value(("crown", "numerics", "collision")) == 0.5
    save_checkpoint(path, ck.saved, ck.log, ck.next_frame,
                    _without(ck.fingerprint, [("crown", "numerics", "collision")]))
    os.remove(folder / files.METADATA)     # the complete recording's: the checkpoint decides
    with pytest.raises(RecordError, match=r"numerics\.collision: 0\.0 -> 0\.5"):
        record_preset(preset, folder, resume=True, session=Session())


def test_checkpoint_keeps_every_run_statistic(uninterrupted, tmp_path):
    state = uninterrupted[1]
    assert state["stats"].peak_max_density_excess > state["stats"].health.max_density_excess
    save_checkpoint(tmp_path / "c.npz", state, RunLog(), 5, {})
    assert load_checkpoint(tmp_path / "c.npz").saved["stats"] == state["stats"]


def test_older_checkpoint_peaks_come_from_its_run_log(uninterrupted):
    stats = uninterrupted[1]["stats"]
    d = ckpt._stats_json(stats)
    del d["peak_max_speed"], d["peak_max_density_excess"]
    old_log = {"peak_max_speed": 12.5, "peak_max_density_excess": 0.25}
    back = ckpt._stats_from(d, np.asarray(stats.dt_log), np.asarray(stats.bound_log), old_log)
    assert (back.peak_max_speed, back.peak_max_density_excess) == (12.5, 0.25)


def test_resumed_run_reports_the_peaks_of_the_whole_run(uninterrupted, preset, tmp_path):
    # measured: the density excess peaks at the impact, step 47 of 57; stop after it
    full = uninterrupted[1]["stats"]
    folder = tmp_path / "quick-2d"
    first = record_preset(preset, folder, session=Session(), max_steps=50)
    assert first.status == "interrupted"
    assert first.sim.stats.peak_max_density_excess == full.peak_max_density_excess
    resumed = record_preset(preset, folder, resume=True, session=Session())
    assert resumed.complete and resumed.sim.stats.steps == full.steps
    s = resumed.sim.stats
    assert (s.peak_max_speed, s.peak_max_density_excess) == (full.peak_max_speed,
                                                             full.peak_max_density_excess)
    got = json.loads((folder / files.METADATA).read_text())["health"]
    want = json.loads((uninterrupted[0].folder / files.METADATA).read_text())["health"]
    for k in ("peak_max_speed_m_s", "peak_max_density_excess"):
        assert got[k] == want[k], k


def test_a_frame_sees_the_wall_time_so_far(preset):
    """The checkpoint written at a frame holds the stepping wall time up to that frame (it held
    the time of earlier runs only, so a run killed and resumed from it under-counted)."""
    from crowndemo.core import simulator_for
    sim = simulator_for(preset.build_scene())
    frames = [0.0, 2 * INTERVAL, T_END]
    seen = []
    stats = sim.run(T_END, frames, on_frame=lambda s, i: seen.append(s.stats.wall_seconds))
    assert len(seen) == 3 and seen[0] < seen[1] < seen[2]
    assert seen[1] > 0.0 and seen[2] == pytest.approx(stats.wall_seconds, rel=0.05)


def test_resume_refuses_other_parameters(uninterrupted, tmp_path):
    from crowndemo.record import RecordError
    other = config.load("quick-2d", "draft", SETS + ["scene.speed=6"])
    with pytest.raises(RecordError, match=r"scene|speed"):
        record_preset(other, uninterrupted[0].folder, resume=True)
    with pytest.raises(RecordError, match="no checkpoint"):
        record_preset(other, tmp_path / "none", resume=True)


def test_unstable_run_keeps_frames_and_says_so(preset, tmp_path):
    # abort when a speed exceeds 0.21 c = 8.4 m/s: the 8 m/s drop passes it at the impact
    r = config.load("quick-2d", "draft", SETS + ["numerics.max_mach=0.21"])
    res = record_preset(r, tmp_path / "q", session=Session())
    assert res.status.startswith("unstable: ") and "exceeds max_mach" in res.status
    meta = json.loads((tmp_path / "q" / files.METADATA).read_text())
    assert meta["complete"] is False and meta["status"] == res.status
    assert meta["frames"] and meta["frames"][0]["index"] == 0
    assert all((tmp_path / "q" / f["file"]).is_file() for f in meta["frames"])
    assert res.sim.stats.health.max_speed > 0.21 * r.physics.c


def test_atomic_write_leaves_no_partial_file(tmp_path):
    target = tmp_path / "frame.npz"
    files.atomic_write(target, lambda f: f.write(b"old"))

    def broken(f):
        f.write(b"half")
        raise OSError("disk full")
    with pytest.raises(OSError):
        files.atomic_write(target, broken)
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["frame.npz"]
