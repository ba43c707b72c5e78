"""Where the oscillating drop's mode-2 energy goes, force by force and layer by layer (issue 23,
VALIDATION.md "Where the mode's energy goes"), reproducible:

    .venv/bin/python tools/mode_power_study.py DIM R/l0 [--periods P] [--kick K] [--nu NU]
                          [--frames F] [--numerics KEY=VALUE ...] [--sound-factor S]
                          [--sigma-factor S] [--re-ratio X] [--c4-factor F|lattice]
                          [--pair-support H] [--tolman DELTA]
                          [--tolman-form pair|particle|smoothed|lagged] [--tolman-steps N]
                          [--tolman-lag K] [--surface-pairs [product|mean]]
                          [--pair-band B] [--tension-factor F] [--torque-free yes|no]
                          [--threads N]

The drop of the case stress-drop-oscillation-DIMd (validate/tension_cases.py: its start, its
numerics with V1, nu = 1e-5 unless --nu), run P mode-2 periods (default 5). With --kick K the
mode's start velocity (scenes/drop.oscillating_drop's, amplitude 0.1) is added once more at
K periods, to the drop as it then is: a second start on a liquid that has oscillated and
settled, without the first start's melt. --sound-factor S: the drop's sound speed times S;
--sigma-factor S: sigma times S (water's 0.0728 N/m; the frequency follows sqrt(S), the sound
speed too, as the case's rule sets it, and Lamb's rate does not); --re-ratio X: re = X l0
(the case's 2.1; the member's constants there, params.STRESS_NEIGHBOURHOODS, or F = 1 and
2.1 l0's delta where it has none); --c4-factor F|lattice: C4's factor F in place of the
neighbourhood's, or the flat lattice face's balance at the run's re
(tools/stress_surface_study.py's option); --pair-support H: C3's pair support H l0 in place
of the neighbourhood's (params.STRESS_NEIGHBOURHOODS: 3, or 4.1 in 3D at 3.1 l0); --tolman
DELTA: C5's delta in place of the
neighbourhood's (0 compiles C5 out); --tolman-form / --tolman-steps: C5's probes (s_i on
i's whole pull, smoothed over the surface, or lagged N steps); --tolman-lag K: the member's
lag of C5 in capillary times (0: none, the member to 2026-12-07); all as in
tools/stress_surface_study.py; --surface-pairs, --tension-factor, --torque-free: its options
of those names
(C3's pairs within the surface layer; the member's tension times F). F frames a period
(default 40); at each:

- the mode's flow: the velocities of every fluid particle (a thrown-out one too) about their
  mean fitted by a linear field v = G d; G's symmetric traceless part is mode 2's flow u_m
  (exactly, for a linear mode); E_m, its kinetic energy;
- the rest's kinetic energy: of the velocities less their mean and the fitted G d (what no
  linear field carries: the particles' own motion, and any other mode's);
- each force's power on that flow, m sum_i a_i . u_m(x_i): the pressure gradient (the sum
  form, method.md M2, of the frame's EOS pressure, S21), the viscous term (V1 or S12, method.md
  §3b, of the frame's velocities), the surface stress (the member's a_i of the last step);
  the pressure's zeroth-order part, the sum form's -(d / (n0 rho)) 2 P_i sum_j r_ij w / r^2
  (nil for a uniform P on the lattice's interior; at the free surface the push that C4's
  pressure balances the stress's pull with), a part of the pressure's, not added to the sum;
  and each split by layer: the free surface (n < beta n0), and the fluid under it at depth
  < 1.5 l0, 1.5-2.5 l0 and deeper (the distance to the nearest free-surface particle); the
  stress's and the zeroth-order part's power also split along the colour gradient g_i (C1)
  and across it (a particle without g: all across);
- each force's power on every particle's motion (the velocities less their mean), and the
  kinetic energy.

Per period: each force's work on the mode's flow over the period, over the period's mean
E_m (a loss at Lamb's rate gamma is -4 gamma T of it; the period that ends at the kick has
it in its last frame and is not read). Over the periods read (from the kick on; without
one, from where the case's fit starts: the second period in 3D, the first in 2D): each
force's mean work, layer by layer; the decay from the peaks of E_m, one a half period,
gamma = -ln(E_peak(k + 1) / E_peak(k)) / (2 T); each force's share of the mode's stiffness
and damping: its generalised force on the mode's shape xi = G_hat d (G_hat the start's flow's
symmetric traceless part, |G_hat| = 1), Q_f = m sum_i a_i . xi_i, fitted as -K_f q - C_f q_dot
+ b_f against the mode's coordinate q (from the second moment, ``mode_coordinate``), so that
M q_ddot = sum_f Q_f with M = m sum |xi|^2: K_f / (M omega_R^2) is the force's part of (omega /
omega_R)^2 (VALIDATION.md "The mode's stiffness, force by force"); and the deformation's fit
(the case's, validate/oscillation.py). From each peak of E_m to the next: the kinetic energy's change
beside each force's work on every particle's motion (in the continuum the pressure's and the
stress's would be nil, the drop round at both ends; VALIDATION.md "The surface's push and
pull along its normal"). numpy over the pairs within re (a few thousand particles: seconds
a frame); the pressure and the stress are those of the frame's positions and the last
step's r*, so the split is a diagnostic, not the step's own bookkeeping.
"""
from __future__ import annotations

import argparse
import math
from dataclasses import replace
from typing import Dict

import numpy as np
import yaml


def pair_sum(n: int, i: np.ndarray, j: np.ndarray, f_ij: np.ndarray, sign: float) -> np.ndarray:
    """sum_j f_ij over both members of each pair: f on i, sign f on j (f_ji = sign f_ij)."""
    out = np.zeros((n,) + f_ij.shape[1:])
    np.add.at(out, i, f_ij)
    np.add.at(out, j, sign * f_ij)
    return out


def forces(sim, x: np.ndarray, v: np.ndarray, p: np.ndarray,
           viscosity: str) -> Dict[str, np.ndarray]:
    """The pressure gradient (the sum form, M2, or the corrected form, M2c, where the simulator
    runs it: each particle's omega from these pairs, a drop's), its zeroth-order part
    (``zeroth``, the sum form's) and the viscous term (the member ``viscosity``: V1 or S12)
    [m/s^2], numpy over the pairs within re (validate/clusters.close_pairs)."""
    from crowndemo.core.lattice import surface_weight, weight
    from crowndemo.core.params import FABRIC_DET_MIN
    from crowndemo.core.viscosity import member
    from crowndemo.validate.clusters import close_pairs
    lat, ph = sim.lattice, sim.physics
    dim, re, n0, rho = ph.dim, lat.re, lat.n0, ph.rho
    i, j, r2 = close_pairs(x, re, with_d2=True)
    rij = x[j] - x[i]
    w = weight(np.sqrt(r2), re)
    n = len(x)
    # M2: a_i = -d / (n0 rho) sum_j (P_i + P_j) r_ij w / r^2, r_ij = x_j - x_i (antisymmetric)
    acc_p = -dim / (n0 * rho) * pair_sum(n, i, j, ((p[i] + p[j]) * w / r2)[:, None] * rij, -1)
    if sim.numerics.pressure_gradient == "corrected":
        # M2c: (P_i L_i + P_j L_j) r_ij w / r^2, L_i = omega I + (1 - omega) (tr M_i/d) M_i^-1
        g = (w / r2)[:, None] * rij
        fabric = pair_sum(n, i, j, g[:, :, None] * rij[:, None, :], 1)
        omega = surface_weight(pair_sum(n, i, j, w, 1), n0, sim.numerics.free_surface_beta(dim))
        iso = np.trace(fabric, axis1=1, axis2=2) / dim
        L = np.repeat(np.eye(dim)[None], n, axis=0)
        full = (omega < 1.0) & (iso > 0.0)
        full[full] &= np.linalg.det(fabric[full]) > FABRIC_DET_MIN * iso[full] ** dim
        L[full] = (omega[full, None, None] * np.eye(dim) + (1.0 - omega[full, None, None])
                   * iso[full, None, None] * np.linalg.inv(fabric[full]))
        f = (p[i, None] * np.einsum("kab,kb->ka", L[i], g)
             + p[j, None] * np.einsum("kab,kb->ka", L[j], g))
        acc_p = -dim / (n0 * rho) * pair_sum(n, i, j, f, -1)
    # its split: (P_j - P_i) r_ij w / r^2 (the gradient, S11) + 2 P_i r_ij w / r^2 (this part)
    acc_zero = -dim / (n0 * rho) * 2.0 * p[:, None] * pair_sum(n, i, j,
                                                                (w / r2)[:, None] * rij, -1)
    du = v[j] - v[i]
    if viscosity == "central":      # V1's pair term: ((du . r) r / r^2) w
        f = ((du * rij).sum(axis=1) * w / r2)[:, None] * rij
    else:                           # S12's: (u_j - u_i) w
        f = du * w[:, None]
    acc_v = ph.nu * member(viscosity).factor(dim) / (lat.lambda0 * n0) * pair_sum(n, i, j, f, -1)
    return {"pressure": acc_p, "viscosity": acc_v, "zeroth": acc_zero}


def mode_coordinate(d: np.ndarray, u: np.ndarray, G_hat: np.ndarray) -> tuple:
    """Mode 2's coordinate q and its rate for positions d and velocities u about the centre:
    x = (I + q G_hat) x_round (G_hat symmetric traceless, |G_hat| = 1) makes the second moment
    S = sum d d^T = s0 I + 2 q s0 G_hat + O(q^2), s0 = tr S / dim; so q = S : G_hat / (2 s0),
    and q_dot the same of dS/dt = sum (d u^T + u d^T)."""
    S, s0 = d.T @ d, float((d * d).sum()) / d.shape[1]
    dS = d.T @ u + u.T @ d
    return float((S * G_hat).sum()) / (2.0 * s0), float((dS * G_hat).sum()) / (2.0 * s0)


def fit_stiffness(q: np.ndarray, q_dot: np.ndarray, force: np.ndarray) -> tuple:
    """(K, C): a force's generalised force on the mode fitted as -K q - C q_dot + b over the
    frames (least squares; b takes a steady part, such as a drop's Laplace pull on a mode of
    nonzero mean)."""
    basis = np.stack([q, q_dot, np.ones_like(q)], axis=1)
    coef = np.linalg.lstsq(basis, force, rcond=None)[0]
    return -float(coef[0]), -float(coef[1])


def stiffness(rows: list, keep: np.ndarray, names: tuple, layers: tuple,
              omega_ref: float) -> None:
    """Each force's share of the mode's stiffness and damping (``fit_stiffness`` over the frames
    kept): M q_ddot = sum_f Q_f, so omega^2 + gamma^2 = sum K_f / M and the amplitude's decay
    gamma = sum C_f / (2 M). Printed: K_f / (M omega_ref^2) (their sum is (omega /
    omega_ref)^2 up to gamma^2) and C_f / (2 M) [1/s], for the whole drop and by layer."""
    rows = [r for r, k in zip(rows, keep) if k]
    q, q_dot = (np.array([r[k] for r in rows]) for k in ("q", "q_dot"))
    M = float(np.mean([r["M"] for r in rows]))

    def share(key) -> tuple:
        K, C = fit_stiffness(q, q_dot, np.array([r[key] for r in rows]))
        return K / (M * omega_ref ** 2), C / (2.0 * M)

    print(f"the mode's stiffness and damping, force by force (fitted over {len(rows)} frames: "
          f"K / (M omega_R^2), C / 2M in 1/s; by layer: " + ", ".join(layers) + "):")
    for f in names + ("zeroth", "stress normal", "zeroth normal"):
        k, c = share(("Q", f))
        by = [share(("Q", f, layer)) for layer in layers] if f in names + ("zeroth",) else []
        print(f"  {f}: {k:+.3f}, {c:+.1f}" + (" (" + " ".join(
            f"{kk:+.3f}/{cc:+.1f}" for kk, cc in by) + ")" if by else ""))
    total = [sum(share(("Q", f))[k] for f in names) for k in (0, 1)]
    print(f"  sum: {total[0]:+.3f} (omega {math.sqrt(max(total[0], 0.0)) - 1:+.2%} against "
          f"omega_R, up to gamma^2), decay {total[1]:.1f} 1/s")


def linear_flow(sim) -> tuple:
    """The frame's fluid (pressures refreshed) and its velocities about their mean fitted by a
    linear field v = G d: (snapshot, fluid mask, x, v, P, d = x - mean, u = v - mean, G, u_m),
    u_m = d G_s^T with G_s G's symmetric traceless part (mode 2's flow)."""
    from crowndemo.core.state import FLUID
    sim.refresh_pressure()
    snap = sim.snapshot()
    fluid = snap["kind"] == FLUID
    x, v, p = (snap[k][fluid].astype(float) for k in ("pos", "vel", "pressure"))
    d, u = x - x.mean(axis=0), v - v.mean(axis=0)
    G = np.linalg.lstsq(d, u, rcond=None)[0].T
    Gs = 0.5 * (G + G.T)
    Gs -= np.trace(Gs) / len(Gs) * np.eye(len(Gs))
    return snap, fluid, x, v, p, d, u, G, d @ Gs.T


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dim", type=int, choices=(2, 3))
    ap.add_argument("scale", type=float, metavar="R/l0")
    ap.add_argument("--periods", type=float, default=5.0)
    ap.add_argument("--kick", type=float, default=0.0, metavar="K")
    ap.add_argument("--nu", type=float, default=None)
    ap.add_argument("--frames", type=int, default=40, metavar="F")
    ap.add_argument("--numerics", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--sound-factor", type=float, default=1.0)
    ap.add_argument("--sigma-factor", type=float, default=1.0)
    ap.add_argument("--re-ratio", type=float, default=None, help="re / l0 (default: the case's)")
    ap.add_argument("--c4-factor", default=None, metavar="F|lattice",
                    help="C4's factor (the member's 1), or 'lattice': the face balance at re")
    ap.add_argument("--pair-support", type=float, default=None, metavar="H",
                    help="C3's pair support in l0 (the neighbourhood's unless given: "
                    "params.STRESS_NEIGHBOURHOODS: 3, or 4.1 in 3D at 3.1 l0)")
    ap.add_argument("--tolman", type=float, default=None, metavar="DELTA",
                    help="C5's delta in l0 (the neighbourhood's unless given; 0: C5 off)")
    ap.add_argument("--tolman-form", choices=("pair", "particle", "smoothed", "lagged"),
                    default="pair", help="C5's form (tools/stress_surface_study.py's option)")
    ap.add_argument("--tolman-steps", type=float, default=1000.0, metavar="N",
                    help="--tolman-form lagged: the lag in steps")
    ap.add_argument("--tolman-lag", type=float, default=None, metavar="K",
                    help="C5's lag in capillary times (stress_surface_study --tolman-lag)")
    ap.add_argument("--surface-pairs", nargs="?", const="product", default=None,
                    choices=("product", "mean"),
                    help="C3's pairs weighted by omega_i omega_j or their mean "
                    "(stress_surface_study's option)")
    ap.add_argument("--pair-band", type=float, default=0.0, metavar="B",
                    help="--surface-pairs: the pairs' omega = clamp((1 - n/n0)/B, 0, 1) "
                         "(stress_surface_study.py; 0: C1's own)")
    ap.add_argument("--tension-factor", type=float, default=None, metavar="F",
                    help="the member's tension (a) times F")
    ap.add_argument("--torque-free", choices=("yes", "no"), default=None,
                    help="with --numerics stress_pairs=surface: C3b's T_i through L_i or not "
                         "(stress_surface_study's option)")
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    from crowndemo import backend
    backend.init("cpu", threads=a.threads)
    if a.pair_support is not None:
        from stress_surface_study import set_pair_support
        set_pair_support(a.pair_support)
    from crowndemo.core import Numerics
    from crowndemo.core.state import FLUID
    from crowndemo.scenes.drop import drop_sound_speed, oscillating_drop
    from crowndemo.core.params import WATER
    from crowndemo.validate import oscillation
    from crowndemo.validate import tension_cases as tc
    from crowndemo.validate.cases import simulator

    numerics = tc.oscillation_numerics(Numerics())
    for kv in a.numerics:
        key, value = kv.split("=", 1)
        numerics = replace(numerics, **{key: yaml.safe_load(value)})
    numerics = numerics.validate("--numerics")
    l0 = tc.R / a.scale
    nu = tc.OSCILLATION_NU if a.nu is None else a.nu
    sigma = WATER["sigma"] * a.sigma_factor
    c = drop_sound_speed(l0, sigma, WATER["rho"]) * a.sound_factor
    scene = oscillating_drop(dim=a.dim, radius=tc.R, l0=l0, nu=nu, periods=a.periods,
                             numerics=numerics, disorder=tc.DISORDER[a.dim], sound_speed=c,
                             sigma=sigma)
    if a.re_ratio is not None:
        from stress_surface_study import admit_neighbourhood
        admit_neighbourhood(a.re_ratio)       # an re the member has no constants for: F = 1
        scene = replace(scene, physics=replace(scene.physics, re_ratio=a.re_ratio).validate())
    period, lamb = scene.info["period_s"], scene.info["decay_1_s"]
    start_u = scene.vel[scene.kind == FLUID].copy()
    start_x = scene.pos[scene.kind == FLUID]
    G0 = np.linalg.lstsq(start_x - start_x.mean(axis=0), start_u, rcond=None)[0].T
    if a.c4_factor is not None:
        import crowndemo.core.surface_tension as family
        from stress_surface_study import c4_factor_member, c4_factor_value
        factor = c4_factor_value(a.c4_factor, a.dim, scene.physics.re_ratio)
        family.MODELS["stress"] = c4_factor_member(family.MODELS["stress"], factor)
    if a.tolman is not None:
        import crowndemo.core.surface_tension as family
        from stress_surface_study import tolman_delta_member
        family.MODELS["stress"] = tolman_delta_member(family.MODELS["stress"], a.tolman)
    if a.tolman_form != "pair" or a.tolman_lag is not None:
        import crowndemo.core.surface_tension as family
        from stress_surface_study import tolman_form_member
        family.MODELS["stress"] = tolman_form_member(family.MODELS["stress"], a.tolman_form,
                                                     a.tolman_steps, a.tolman_lag)
    if a.pair_band and a.surface_pairs is None:
        raise SystemExit("--pair-band: with --surface-pairs only")
    if a.surface_pairs is not None or a.tension_factor is not None:
        import crowndemo.core.surface_tension as family
        from stress_surface_study import surface_pairs_member, tension_factor_member
        if a.surface_pairs is not None:
            family.MODELS["stress"] = surface_pairs_member(
                family.MODELS["stress"], a.dim, scene.physics.re_ratio,
                numerics.free_surface_beta(a.dim), a.surface_pairs, a.pair_band)
        if a.tension_factor is not None:
            family.MODELS["stress"] = tension_factor_member(family.MODELS["stress"],
                                                            a.tension_factor)
    if a.torque_free is not None:
        if "stress_pairs=surface" not in a.numerics:
            raise SystemExit("--torque-free: with --numerics stress_pairs=surface only")
        import crowndemo.core.surface_tension as family
        from stress_surface_study import torque_free_member
        family.MODELS["stress"] = torque_free_member(family.MODELS["stress"],
                                                     a.torque_free == "yes")
    sim = simulator(scene)
    mass, beta = sim.lattice.mass, numerics.free_surface_beta(a.dim)
    # the mode's shape for the stiffness: xi = G_hat d, G_hat the start's flow's symmetric
    # traceless part with |G_hat| = 1 (mode 2 of a drop is exactly a linear field)
    G_hat = 0.5 * (G0 + G0.T)
    G_hat -= np.trace(G_hat) / a.dim * np.eye(a.dim)
    G_hat /= np.linalg.norm(G_hat)
    kick_frame = int(round(a.kick * a.frames)) if a.kick > 0 else -1
    layers = ("surface", "under 1.5 l0", "1.5-2.5 l0", "deeper")
    rows = []

    def on_frame(s, index: int) -> None:
        if index == kick_frame:         # the start's mode velocity once more, about the centre
            st = s.state
            count = st.count
            pos, vel = st.pos.to_numpy(), st.vel.to_numpy()
            fluid = st.kind.to_numpy()[:count] == FLUID
            d = pos[:count][fluid] - pos[:count][fluid].mean(axis=0)
            vel[:count][fluid] += (d @ G0.T).astype(vel.dtype)
            st.vel.from_numpy(vel)
        snap, fluid, x, v, p, d, u, G, um = linear_flow(s)
        acc = forces(s, x, v, p, numerics.viscosity)
        order = np.argsort(s.state.pid.to_numpy()[:s.state.count], kind="stable")
        acc["stress"] = s.surface_tension.accel.to_numpy()[:s.state.count][order][fluid]
        # the surface's pull (stress) and push (zeroth) along the colour gradient's direction
        g = s.surface_tension.colour.to_numpy()[:s.state.count][order][fluid].astype(float)
        gl = np.linalg.norm(g, axis=1)
        n_hat = np.where(gl[:, None] > 0, g / np.maximum(gl, 1e-300)[:, None], 0.0)
        for q in ("stress", "zeroth"):
            acc[q + " normal"] = (acc[q] * n_hat).sum(axis=1)[:, None] * n_hat
        surface = snap["number_density"][fluid] < beta * s.lattice.n0   # M3, the step's n
        depth = np.full(len(x), np.inf)
        if surface.any():
            for k in range(0, len(x), 512):
                depth[k:k + 512] = np.sqrt(((x[k:k + 512, None] - x[None, surface]) ** 2)
                                           .sum(axis=2)).min(axis=1)
        masks = (surface, ~surface & (depth < 1.5 * l0),
                 ~surface & (depth >= 1.5 * l0) & (depth < 2.5 * l0),
                 ~surface & (depth >= 2.5 * l0))
        rest = u - d @ G.T              # what no linear field carries: the particles' own motion
        row = {"t": s.stats.time, "E_m": 0.5 * mass * float((um * um).sum()),
               "E_rest": 0.5 * mass * float((rest * rest).sum()),
               "deformation": oscillation.deformation(x)}
        row["E_kin"] = 0.5 * mass * float((u * u).sum())
        # the mode's coordinate q (x = (I + q G_hat) x_round: S = s0 I + 2 q s0 G_hat), its
        # rate, its mass M = m sum |xi|^2 and each force's generalised force m sum a . xi
        xi = d @ G_hat.T
        row["q"], row["q_dot"] = mode_coordinate(d, u, G_hat)
        row["M"] = mass * float((xi * xi).sum())
        for name, a_i in acc.items():
            power = mass * (a_i * um).sum(axis=1)
            gen = mass * (a_i * xi).sum(axis=1)
            row[name] = float(power.sum())
            row[(name, "all")] = mass * float((a_i * u).sum())   # on every particle's motion
            row[("Q", name)] = float(gen.sum())
            for layer, m in zip(layers, masks):
                row[(name, layer)] = float(power[m].sum())
                row[("Q", name, layer)] = float(gen[m].sum())
        rows.append(row)

    frames = np.linspace(0.0, scene.t_end, int(round(a.frames * a.periods)) + 1)
    sim.run(scene.t_end, frame_times=frames, on_frame=on_frame)
    t = np.array([r["t"] for r in rows])
    E = np.array([r["E_m"] for r in rows])
    names = ("pressure", "viscosity", "stress")      # the sum's terms
    shown = names + ("zeroth",)                       # and the pressure's zeroth-order part
    print(f"{a.dim}D drop, R/l0 = {a.scale:g}, {int(scene.kind.size)} particles, nu = {nu:g}, "
          f"sigma = {sigma:g} N/m, c = {c:.3g} m/s, {numerics.viscosity} viscosity; "
          f"omega = {scene.info['omega_rad_s']:.1f} rad/s, T = {period * 1e3:.3f} ms, "
          f"Lamb's decay {lamb:.1f} 1/s (a loss of {4 * lamb * period:.2f} mean E_m a period; "
          f"the exact viscous mode's {scene.info['decay_exact_1_s']:.1f} 1/s, "
          f"{scene.info['omega_exact_rad_s']:.1f} rad/s)"
          + (f"; kicked at {a.kick:g} T" if a.kick > 0 else ""))
    print("period | work on the mode's flow / the period's mean E_m: pressure, viscosity, stress, "
          "sum | by layer (" + ", ".join(layers) + "): pressure; stress | the pressure's "
          "zeroth-order part, by layer | the rest's mean kinetic energy / E_m's")
    peaks, tops, after = [], [], []    # E_m's peak a period, the peak's frame, the works
    # read from the kick on, else where the case's fit starts (after a disordered start's melt)
    first = int(round(a.kick)) if a.kick > 0 else (1 if tc.DISORDER[a.dim] > 0 else 0)
    for k in range(int(round(a.periods))):
        m = (t >= k * period - 1e-12) & (t <= (k + 1) * period + 1e-12)
        mean_E = E[m].mean()
        work = {q: np.trapezoid([r[q] for r, keep in zip(rows, m) if keep], t[m]) / mean_E
                for q in list(shown) + ["stress normal", "zeroth normal"]
                + [(q, layer) for q in shown for layer in layers]}
        peaks.append(E[m].max())
        work["rest"] = float(np.mean([r["E_rest"] for r, keep in zip(rows, m) if keep])) / mean_E
        if k >= first:
            after.append(work)
            tops.append(int(np.flatnonzero(m)[np.argmax(E[m])]))
        cut = " (ends at the kick: not read)" if a.kick > 0 and k == first - 1 else ""
        print(f"{k} | {work['pressure']:+.2f} {work['viscosity']:+.2f} {work['stress']:+.2f} "
              f"{sum(work[q] for q in names):+.2f} | "
              + " ".join(f"{work[('pressure', layer)]:+.2f}" for layer in layers) + "; "
              + " ".join(f"{work[('stress', layer)]:+.2f}" for layer in layers) + " | "
              + f"{work['zeroth']:+.2f} ("
              + " ".join(f"{work[('zeroth', layer)]:+.2f}" for layer in layers) + ") | "
              + f"{work['rest']:.2f}" + cut)
    mean = {q: float(np.mean([w[q] for w in after])) for q in after[0]}
    print(f"mean over the periods from {first}: " + ", ".join(
        f"{q} {mean[q]:+.2f} (" + " ".join(f"{mean[(q, layer)]:+.2f}" for layer in layers) + ")"
        for q in shown) + f"; sum (of the first three) {sum(mean[q] for q in names):+.2f}; "
          f"the rest's kinetic energy {mean['rest']:.2f} E_m")
    print("along the colour gradient / across it (the rest): " + ", ".join(
        f"{q} {mean[q + ' normal']:+.2f} / {mean[q] - mean[q + ' normal']:+.2f}"
        for q in ("stress", "zeroth")))
    # from one peak of E_m to the next (the drop round, its surface energy at its least):
    # the kinetic energy's change and each force's work on every particle's motion
    for k0, k1 in zip(tops, tops[1:]):
        seg = slice(k0, k1 + 1)
        mean_E = E[seg].mean()
        w = {q: np.trapezoid([r[(q, "all")] for r in rows[seg]], t[seg]) / mean_E for q in names}
        dK = (rows[k1]["E_kin"] - rows[k0]["E_kin"]) / mean_E
        print(f"E_m's peaks at {t[k0] / period:.2f} -> {t[k1] / period:.2f} T: the kinetic "
              f"energy's change {dK:+.2f}; the work on every particle's motion: "
              + ", ".join(f"{q} {w[q]:+.2f}" for q in names)
              + f" (sum {sum(w.values()):+.2f}; mean E_m's, E_m = {mean_E:.3g} J; the "
              f"pressure's and stress's work on it {(w['pressure'] + w['stress']) * mean_E:.3g} J)")
    gammas = [-math.log(peaks[k + 1] / peaks[k]) / (2 * period)
              for k in range(first, len(peaks) - 1)]
    print("decay from E_m's peaks, period by period from " + str(first) + ": "
          + " ".join(f"{g:.1f}" for g in gammas)
          + f" 1/s (mean {np.mean(gammas):.1f}; Lamb's {lamb:.1f})")
    fit = t >= first * period - 1e-12
    stiffness(rows, fit, names, layers, scene.info["omega_rad_s"])
    omega, decay = oscillation.fit(t[fit], np.array([r["deformation"] for r in rows])[fit])
    ref = scene.info["omega_rad_s"]
    print(f"the deformation's fit from period {first} on (as the case's): {omega:.1f} rad/s "
          f"({omega / ref - 1:+.2%} against Rayleigh's {ref:.1f}), decay {decay:.1f} 1/s")


if __name__ == "__main__":
    main()
