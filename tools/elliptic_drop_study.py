"""The pressure's work on a free drop's linear flow without surface tension (issue 23,
VALIDATION.md "The surface's push and pull along its normal"): Monaghan's (1994) elliptic drop
in 3D, reproducible:

    .venv/bin/python tools/elliptic_drop_study.py R/l0 [--strain-rate G] [--nu NU]
                          [--strain S] [--disorder D] [--threads N]

A ball of radius 1 mm (the drop cases' R) released with u = G x, G = g diag(-1, -1, 2), no
surface tension, no gravity, the sum form (M2) and V1, the sound speed 20 times the fastest
start speed 2 g R; run to the strain S = g t (default 0.3). In the continuum the flow stays
linear and the pressure, nil at the free surface, does no work on a divergence-free flow: the
linear flow's kinetic energy falls by the viscous work alone. At 31 frames: E_lin, the kinetic
energy of the fitted linear field's symmetric traceless part u_m (as tools/mode_power_study.py
fits it), the rest's kinetic energy, and the pressure's (its zeroth-order part's) and the
viscous term's work on u_m so far, over E_lin at the start (tools/mode_power_study.forces).
With --disorder 0 (the default here) the ball is the lattice cut; off it, the disorder's own
pressure spreads the drop, which no surface tension holds.
"""
import argparse
import importlib.util
import os
from dataclasses import replace

import numpy as np

R = 1.0e-3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scale", type=float, metavar="R/l0")
    ap.add_argument("--strain-rate", type=float, default=200.0, metavar="G", help="g [1/s]")
    ap.add_argument("--nu", type=float, default=1.0e-6)
    ap.add_argument("--strain", type=float, default=0.3)
    ap.add_argument("--disorder", type=float, default=0.0, metavar="D", help="in l0")
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    from crowndemo import backend
    backend.init("cpu", threads=a.threads)
    from crowndemo.core import Numerics, Physics
    from crowndemo.scenes.base import assemble
    from crowndemo.scenes.drop import ball
    from crowndemo.validate.cases import simulator
    here = os.path.dirname(os.path.abspath(__file__))
    spec = importlib.util.spec_from_file_location("mode_power_study",
                                                  os.path.join(here, "mode_power_study.py"))
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)

    l0, g = R / a.scale, a.strain_rate
    t_end = a.strain / g
    pts = ball(3, R, l0, a.disorder)
    vel = pts @ (g * np.diag([-1.0, -1.0, 2.0])).T
    c = 20.0 * 2.0 * g * R
    physics = Physics(dim=3, l0=l0, v_max=2.0 * g * R, gravity=0.0, sound_speed=c, rho=1000.0,
                      nu=a.nu, sigma=0.0)
    numerics = replace(Numerics(), pressure_gradient="sum", viscosity="central")
    scene = assemble("elliptic-drop", physics, numerics, pts, vel, None,
                     (tuple([-6.0 * R] * 3), tuple([6.0 * R] * 3)), t_end, {"walls": []})
    sim = simulator(scene)
    mass = sim.lattice.mass
    rows = []

    def on_frame(s, index: int) -> None:
        _, _, x, v, p, d, u, G, um = tool.linear_flow(s)
        acc = tool.forces(s, x, v, p, "central")
        rows.append([s.stats.time, 0.5 * mass * (um * um).sum(),
                     0.5 * mass * ((u - d @ G.T) ** 2).sum()]
                    + [mass * (acc[q] * um).sum() for q in ("pressure", "zeroth", "viscosity")]
                    + [np.trace(G)])

    sim.run(t_end, frame_times=np.linspace(0.0, t_end, 31), on_frame=on_frame)
    r = np.array(rows)
    t, E0 = r[:, 0], r[0, 1]
    work = [np.concatenate([[0.0], np.cumsum(0.5 * (r[1:, k] + r[:-1, k]) * np.diff(t))])
            for k in (3, 4, 5)]
    print(f"3D elliptic drop, R/l0 = {a.scale:g}, {len(pts)} particles, disorder {a.disorder:g} "
          f"l0, g = {g:g} 1/s, nu = {a.nu:g} m^2/s, c = {c:.3g} m/s, to the strain {a.strain:g}")
    print("t (ms) | E_lin / E0 | the rest's / E0 | work on u_m so far / E0: pressure (its "
          "zeroth-order part), viscosity | div u (1/s)")
    for k in range(0, len(t), 5):
        print(f"{t[k] * 1e3:.3f} | {r[k, 1] / E0:.4f} | {r[k, 2] / E0:.4f} | "
              f"{work[0][k] / E0:+.4f} ({work[1][k] / E0:+.4f}), {work[2][k] / E0:+.4f} | "
              f"{r[k, 6]:+.1f}")


if __name__ == "__main__":
    main()
