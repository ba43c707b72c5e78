"""The session (crowndemo.control): a second run with other values reuses the compiled
simulator (no new Simulator, no kernel compiled again) and gives, on one thread, the same
result bit for bit as a fresh simulator; a bigger scene reallocates once, with headroom."""
import numpy as np
import pytest

from crowndemo import backend, config
from crowndemo.control import HEADROOM, Session, compiled_kernels
from crowndemo.core import simulator_for
from crowndemo.core.step import capacity_bucket

SHORT = ["scene.t_end=6e-5", "scene.frame_interval=3e-5"]         # the drop touches the film at 0.05 ms (U = 8 m/s)


@pytest.fixture(scope="module")
def one_thread():
    backend.init("cpu", seed=1, single_thread=True)
    yield backend.current()
    backend.init("cpu")


def run(sim, t_end):
    sim.run(t_end)
    return sim.state.dump(), sim.stats


def test_second_run_reuses_kernels_and_matches_a_fresh_simulator(one_thread):
    first = config.load("quick-2d", "draft", SHORT)
    # other speed, film and liquid; a thinner film and a slower drop: fewer particles
    second = config.load("quick-2d", "draft", SHORT + ["scene.speed=6", "scene.film=1.0e-3",
                                                       "scene.liquid=milk"])
    scene1, scene2 = first.build_scene(), second.build_scene()
    assert len(scene2.pos) < len(scene1.pos) and scene2.physics.nu != scene1.physics.nu

    session = Session()
    run(session.load(scene1), first.t_end)
    kernels = compiled_kernels()
    sim = session.load(scene2)
    got, stats = run(sim, second.t_end)
    assert session.constructions == 1 and session.reallocations == 0
    assert compiled_kernels() == kernels, "the second run compiled kernels"
    assert "reused" in session.events[-1]

    fresh = simulator_for(scene2)
    want, fresh_stats = run(fresh, second.t_end)
    assert compiled_kernels() > kernels         # a new Simulator does compile: the count is live
    assert stats.steps == fresh_stats.steps > 0 and stats.time == fresh_stats.time
    assert list(stats.dt_log) == list(fresh_stats.dt_log)
    for k in want:
        assert np.array_equal(got[k], want[k]), k
    assert stats.dt_min < 0.2 * scene2.physics.l0 / 6.0 * 1.0001   # Courant at >= 6 m/s


def test_bigger_scene_reallocates_once_with_headroom(one_thread):
    small = config.load("quick-2d", "draft", SHORT + ["scene.film=1.0e-3"]).build_scene()
    big = config.load("quick-2d", "draft", SHORT + ["scene.film=2.0e-3"]).build_scene()
    session = Session()
    session.load(small)
    sim = session.load(big)
    assert session.constructions == 2 and session.reallocations == 1
    assert sim.state.capacity == capacity_bucket(int(np.ceil(HEADROOM * len(big.pos))))
    assert session.load(small) is sim and session.constructions == 2   # fits: reused
    assert sim.state.count == len(small.pos)


def test_models_get_their_own_simulators(one_thread):
    a = config.load("quick-2d", "draft", SHORT).build_scene()
    b = config.load("quick-2d", "draft", SHORT + ["scene.liquid={nu: 0}"]).build_scene()
    session = Session()
    sa, sb = session.load(a), session.load(b)
    assert sa is not sb and session.simulators == 2 and sb.model.viscosity is False


def test_capacity_buckets_share_compiled_kernels():
    """Capacities come in steps of 2^(1/4) from 1024 (at most 19 % unused): sizes within a step
    get the same field shapes, which Taichi's offline cache keys the compiled kernels on."""
    sizes = [1, 1024, 1025, 5000, 290_000, 300_000, 386_470, 15_548_809]
    for n in sizes:
        c = capacity_bucket(n)
        assert n <= c <= max(1024, 1.19 * n + 1)
        assert capacity_bucket(c) == c                      # a bucket is its own bucket
    assert capacity_bucket(290_000) == capacity_bucket(300_000)
    buckets = [capacity_bucket(n) for n in range(1000, 200_000, 997)]
    assert buckets == sorted(buckets) and len(set(buckets)) < 30
