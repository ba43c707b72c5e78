"""The 3D oscillating drop of the stress-drop-oscillation-3d case (validate/tension_cases.py),
run with a watch on the lattice it started from (VALIDATION.md, "A disordered start for the 3D
drops"; issue 23):

    .venv/bin/python tools/drop_order_study.py R/l0[,R/l0...] [--disorder A] [--periods P]
                          [--amplitude A] [--nu NU] [--threads N] [--numerics KEY=VALUE ...]

Per frame (every 1/8 period printed): the mode-2 deformation of the drop's own particles
(tension_cases.drop_particles), the particles thrown out of it, the cubic order of the
particles at r < R - 2 l0 (over their bonds shorter than 1.25 l0, the mean of (x^4 + y^4 +
z^4)/r^4 of the bond, mapped so that 1 is the start lattice's six axis bonds and 0 bonds
pointing every way (3/5); a local measure, blind to the drop's own strain), the centre of
mass's distance from its start over R, the total momentum over (N U_ref), U_ref the start's
largest speed (a pair force cannot change it; it changes where a particle leaves the domain),
and the largest speed over U_ref. At the end the frequency and decay fitted as the case fits
them, and from the second period on, against Rayleigh and Lamb."""
import argparse
import math
import time
from dataclasses import replace

import numpy as np

from crowndemo import backend
from crowndemo.core import Numerics
from crowndemo.scenes.drop import oscillating_drop
from crowndemo.validate import oscillation
from crowndemo.validate.cases import simulator
from crowndemo.validate.tension_cases import DISORDER, R, drop_particles, stress_numerics


def cubic_order(p: np.ndarray, l0: float, radius: float) -> float:
    """(<(x^4 + y^4 + z^4)/r^4> - 3/5) / (2/5) over the bonds shorter than 1.25 l0 from the
    particles within ``radius`` of the centre of mass (module docstring)."""
    c = p - p.mean(axis=0)
    inner = np.flatnonzero((c * c).sum(axis=1) < radius * radius)
    sums, count = 0.0, 0
    for i in inner:      # a brute-force bond search, vectorised per particle
        d = p - p[i]
        r2 = (d * d).sum(axis=1)
        near = (r2 > 0) & (r2 < (1.25 * l0) ** 2)
        b = d[near]
        sums += float(((b ** 4).sum(axis=1) / r2[near] ** 2).sum())
        count += int(near.sum())
    return (sums / max(count, 1) - 0.6) / 0.4


def run(scale: float, disorder: float, periods: float, changes: dict, amplitude: float,
        nu: float) -> None:
    l0 = R / scale
    numerics = replace(stress_numerics(Numerics()), **changes)
    scene = oscillating_drop(dim=3, radius=R, l0=l0, nu=nu, periods=periods,
                             numerics=numerics, disorder=disorder, amplitude=amplitude)
    sim = simulator(scene)
    period = 2 * math.pi / scene.info["omega_rad_s"]
    rows, t, deform = [], [], []
    start = {}

    def watch(s, index: int) -> None:
        snap = s.snapshot()
        p, v = snap["pos"].astype(float), snap["vel"].astype(float)
        if not start:
            start.update(c=p.mean(axis=0), u=float(np.linalg.norm(v, axis=1).max()) or (
                0.1 * R * scene.info["omega_rad_s"]))      # at rest: the mode's at 0.1 R
        t.append(s.stats.time)
        keep = drop_particles(p, snap["kind"])
        deform.append(oscillation.deformation(p[keep]))
        order = cubic_order(p, l0, R - 2 * l0)
        drift = float(np.linalg.norm(p.mean(axis=0) - start["c"])) / R
        momentum = float(np.linalg.norm(v.sum(axis=0))) / (len(v) * start["u"])
        speed = float(np.linalg.norm(v, axis=1).max()) / start["u"]
        rows.append((s.stats.time / period, deform[-1], order, drift, momentum))
        if index % 5 == 0:
            print(f"  t = {s.stats.time / period:5.3f} periods: deformation {deform[-1]:+.3e}, "
                  f"order {order:.3f}, drift {drift:.2e} R, momentum {momentum:.2e}, "
                  f"{int(len(p) - keep.sum())} thrown out, largest speed {speed:.2f}",
                  flush=True)

    t0 = time.time()
    print(f"R/l0 = {scale:g}: {scene.counts()['fluid']:,} particles, disorder {disorder:g} l0",
          flush=True)
    sim.run(scene.t_end, frame_times=np.linspace(0, scene.t_end, int(40 * periods) + 1),
            on_frame=watch)
    omega, decay = oscillation.fit(t, deform)
    ref, ref_decay = scene.info["omega_rad_s"], scene.info["decay_1_s"]
    later = np.asarray(t) >= period       # the same fit from the second period on
    omega1, decay1 = oscillation.fit(np.asarray(t)[later], np.asarray(deform)[later])
    print(f"R/l0 = {scale:g}, from the second period on: omega {omega1:.1f} rad/s "
          f"({omega1 / ref - 1:+.2%}), decay {decay1:.0f} 1/s", flush=True)
    print(f"R/l0 = {scale:g}: omega {omega:.1f} rad/s against {ref:.1f} ({omega / ref - 1:+.2%}), "
          f"decay {decay:.0f} 1/s against {ref_decay:.0f}; order {rows[0][2]:.3f} -> "
          f"{rows[-1][2]:.3f}; {sim.stats.steps:,} steps, {time.time() - t0:.0f} s", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scales", help="R/l0, comma-separated")
    ap.add_argument("--disorder", type=float, default=DISORDER[3])
    ap.add_argument("--periods", type=float, default=3.0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--amplitude", type=float, default=0.1, help="the mode's (0: at rest)")
    ap.add_argument("--nu", type=float, default=1.0e-5, help="the case's 1e-5 m^2/s")
    ap.add_argument("--numerics", nargs="*", default=[], metavar="KEY=VALUE",
                    help="Numerics fields changed from the case's (numbers only)")
    a = ap.parse_args()
    changes = {k: float(v) for k, v in (kv.split("=", 1) for kv in a.numerics)}
    backend.init("cpu", threads=a.threads)
    for s in a.scales.split(","):
        run(float(s), a.disorder, a.periods, changes, a.amplitude, a.nu)


if __name__ == "__main__":
    main()
