"""Particles that leave the domain are parked, counted by reason, and abort the run past a
fraction; nothing is dropped silently."""
import numpy as np
import pytest

from crowndemo.core import GONE, InstabilityError, Numerics, Physics, Simulator


def _free_particles(n_out: int, n_total: int, fraction: float):
    """A line of far-apart fluid particles (no neighbours) without gravity; the first n_out move
    at 1 m/s towards x+ and leave the domain [-0.01, 0.01]^2 after ~10 ms."""
    l0 = 1.0e-3
    physics = Physics(dim=2, l0=l0, v_max=2.0, nu=0.0, sigma=0.0, gravity=0.0)
    numerics = Numerics(max_out_fraction=fraction)
    pos = np.zeros((n_total, 2))
    pos[:, 1] = np.linspace(-0.008, 0.008, n_total)     # 16 mm / n apart: > re for n <= 7
    vel = np.zeros((n_total, 2))
    vel[:n_out, 0] = 1.0
    sim = Simulator(physics, numerics, capacity=n_total)
    sim.configure(physics, numerics, ((-0.01, -0.01), (0.01, 0.01)))
    sim.load(pos, vel, np.zeros(n_total, dtype=np.int32))
    return sim


def test_leaving_particles_are_parked_and_counted():
    sim = _free_particles(n_out=2, n_total=6, fraction=0.5)
    sim.run(0.02)
    h = sim.stats.health
    assert h.left == {"left through x+": 2}
    snap = sim.snapshot()
    assert (snap["kind"][:2] == GONE).all() and (snap["exit_reason"][:2] == 2).all()
    assert (snap["kind"][2:] != GONE).all()
    assert sim.counts()["gone"] == 2


def test_too_many_leaving_particles_abort_the_run():
    sim = _free_particles(n_out=3, n_total=6, fraction=0.2)
    with pytest.raises(InstabilityError, match="left the domain"):
        sim.run(0.02)
    assert sim.stats.health.left_total == 3


def test_run_stats_keep_the_peak_of_every_step():
    """RunStats holds the largest max speed and density excess over the run (the summaries,
    recordings and the stability report read them there): equal to the maximum over every
    step's report, not the last one. A falling column: the speed grows, then the front slows."""
    from crowndemo.core import simulator_for
    from crowndemo.scenes import dam_break
    sim = simulator_for(dam_break(dim=2, a=0.02, l0=2e-3))
    speeds = [sim.stats.health.max_speed]
    excess = [sim.stats.health.max_density_excess]

    def on_step(s):
        speeds.append(s.stats.health.max_speed)
        excess.append(s.stats.health.max_density_excess)
    sim.run(0.03, on_step=on_step)
    assert sim.stats.peak_max_speed == max(speeds) > 0.1
    assert sim.stats.peak_max_density_excess == max(excess)
    assert sim.stats.as_dict()["health"]["peak_max_speed_m_s"] == max(speeds)
