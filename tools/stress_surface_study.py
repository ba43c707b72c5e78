"""The surface-stress member's resting-drop diagnostics of VALIDATION.md ("What the surface
layer does" and after, issue 23), reproducible:

    .venv/bin/python tools/stress_surface_study.py drop DIM R/l0 T_MS [--base first|member]
                          [--surface zero|neighbours|virial|own|own-spacing|blend|eos|cumulative]
                          [--pair-kernel quartic|smooth|smooth2|smooth25|smooth3] [--core X]
                          [--isotropic-core]
                          [--tangential-moment] [--every MS] [--disorder X]
                          [--membrane [--membrane-ref G]] [--own-factor F] [--own-per-area]
                          [--virial-moment] [--theta-slope C] [--profile]
                          [--tolman DELTA] [--tolman-form pair|particle|smoothed|lagged]
                          [--tolman-steps N] [--tolman-lag K]
                          [--tolman-pass DELTA [--tolman-fit]]
                          [--nu NU] [--sound-factor F] [--re-ratio X] [--relaxed-start P]
                          [--pressure-filter] [--gradient mps|dn] [--numerics KEY=VALUE ...]
                          [--continuity] [--surface-pairs [product|mean]] [--pair-band B]
                          [--tension-factor F] [--torque-free yes|no]
    .venv/bin/python tools/stress_surface_study.py case CASE R/l0[,R/l0...] [the same options]
    .venv/bin/python tools/stress_surface_study.py stretch S[,S...] [--pair-kernel smooth]
    .venv/bin/python tools/stress_surface_study.py depth DIM R/l0[,R/l0...]
    .venv/bin/python tools/stress_surface_study.py energy R/l0 [--base member] [--relaxed-start P]
                          [--amplitude A] [the drop options]

``--base first`` (the default): the first member, whose figures the study tables up to
2026-12-05 give: f_d = 1 - (r/re)^4 and P = 0 on the free surface (``first_member``, through
the member's two hooks, stress._pair_weight and stress._surface_pressure; its runs agree with
the tables within the drops' run-to-run scatter, ~1 %, not to the digit). ``--base member``:
the member as stress.py has it (f_d = (1 - (r/H)^4)^2, H = 3 l0, and the free surface's own
normal stress, C4, and in 3D the curvature correction C5). ``--surface`` and ``--pair-kernel``
replace the base's choice.

``drop``: a resting drop (R = 1 mm, nu = 1e-4, the sum form) run for T_MS ms; every 0.5 ms the
inside pressure (EOS, r < R/2) against Young-Laplace, the total radial tension force against the
Laplace pull ((d - 1) sigma / R times the drop's area), the surface layer (|g| l0 > 1/4): its
size, mean radius, mean nearest-neighbour spacing, the share of it at P = 0, its mean pressure,
the share of the pull it carries; the drop's largest radius and the pull's radius (the radius
of each particle weighted by its radial tension force: where the pull acts), the virial's
A_d/A and V_d/V (VALIDATION.md, "What sets the inside pressure") and the ratio of the pressure's
virial to the tension's (1 at rest); ``--profile`` adds P n/n0 over P_in in shells. ``case``: one
row of a stress-* validation case (validate/tension_cases.py). ``stretch``: the tension a flat
2D surface carries by the member's formulas when its outer layer's spacing is S l0, alone and
with the tangential moment (``flat_tension``; numpy, no Taichi). ``depth``: where the
member's tension and its pull sit under a lattice ball's surface, with C3 as the member has it
and with ``--surface-pairs`` (``pull_depth``; numpy). ``energy``: where the 3D
oscillating drop's kinetic energy goes (the mode's flow, the rest; ``energy``'s docstring).

Experiments, not member options (VALIDATION.md says what each did):
``--surface zero``: P = 0 on the free surface (S17/M3 alone); ``--surface neighbours``:
free-surface particles (P = 0 after S17/M3) take the w-weighted mean
pressure of their pressurised fluid neighbours before the stress passes; ``--surface virial``:
the same times n0/n_i (at most 3), so that P_i n_i/n0 is the neighbours' pressure;
``--surface own``: after the passes they take the normal stress their own tension carries,
P_i = F rho l0 max(0, a_i . g_i/|g_i|), F = ``--own-factor`` (default 1: the member's C4);
with ``--own-per-area`` (and ``--tangential-moment``) divided by c_i, the area the particle
holds; ``--surface own-spacing``: the own normal stress times (l0/s_i)^(d-1), s_i i's nearest
neighbour along the surface (own_pressure_member);
``--surface blend``: the smaller of the two (neighbours' mean, own normal stress);
``--surface eos``: the EOS (S17) of the number density over the share of a full neighbourhood
the particle has, theta = 1 - C |g| l0 (``--theta-slope`` C, fitted on lattice faces);
``--surface cumulative`` (``--base member``): after C4 a free-surface particle adds the
w-weighted mean C4 pressure of its free-surface neighbours outward of it (a third pass);
``--continuity``: every fluid particle's pressure is the EOS of a number density carried by the
continuity equation instead of S17's sum (continuity_pressure_member; a third pass);
``--surface-pairs [product|mean]`` (``--base member``, re = 2.1 l0): C3's pair terms times
omega_i omega_j (the default) or (omega_i + omega_j)/2, C1's surface weights, so the pull
lands on the surface layer that carries the tension, a rescaled on the flat lattice with the
same weights (surface_pairs_member; VALIDATION.md "The
mode's stiffness, force by force"); with it ``--pair-band B``: the pairs' omega = clamp((1 -
n/n0) / B, 0, 1) rather than C1's band 2 (1 - beta), a rescaled with it (VALIDATION.md "The
mean weight's unsteady pressure"); ``--tension-factor F``: the member's a times F;
``--torque-free yes|no`` (with ``--numerics stress_pairs=surface``): C3b's T_i through L_i
or not, in place of the neighbourhood's (stress.StressTension.torque_free; VALIDATION.md
"C3's surface pairs");
``--core X``: the repulsive core's zero (stress.CORE, default 0.75);
``--isotropic-core``: below the core's zero the pair repels along r_ij with (|g_i| + |g_j|)
instead of through the tangential projection, so a surface particle cannot sink into a gap;
``--tangential-moment``: after pass 1 each surface particle's g (so its tension) is scaled by
c_i = B0 / B_i, B_i = sum_j |g_j| l0 (|r_ij|^2 - (r_ij . n_i)^2) / l0^2 f_d(r_ij) over fluid j,
the surface's tangential moment about i (packing raises it), B0 its value at a flat lattice
face's outer particle; c in [1/X, X], X = ``--moment-clamp`` (default 4); a third pass,
drops only, ``--base first`` only.
``--virial-moment``: the tangential moment's c_i from the unweighted moment, c_i = M0/M_i,
M_i = sum_j r_t^2 f_d over every neighbour (the tension virial's own), M0 a flat face's;
``--membrane``: each pair's stress (T_i + T_j) weighted by phi_ij = 2 min(|g_i|, |g_j|) /
(|g_i| + |g_j|) (or, with ``--membrane-ref G``, min(1, |g_i| l0/G) min(1, |g_j| l0/G)), so
the tension acts between surface particles only (an inner particle, g = 0, takes none of the
pull), a rescaled so that a flat lattice face still carries sigma (membrane_ratio).
``--tolman DELTA``: C5's delta (StressTension.tolman_delta) in place of the neighbourhood's
(params.STRESS_NEIGHBOURHOODS), 0 for the member before C5 (``--base first`` runs without C5
unless given); ``--tolman-form particle``: C5's s_i on particle i's whole pull instead of on
each T in the pairs (tolman_particle_member: no Marangoni term), ``smoothed``: the member's
with s_i smoothed over the surface within re (tolman_smoothed_member, a third pass),
``lagged``: s_i through a first-order lag of ``--tolman-steps N`` steps from its first
step's value (tolman_lagged_member); ``--tolman-lag K``: the member's lag of s_i in capillary
times (StressTension.tolman_lag; 0: s_i of the last step, the member to 2026-12-07, on which
the particle, smoothed and lagged probes ran and run unless K is given; but for the frames:
then a refresh for output set s_i too, now it leaves it); ``--tolman-pass DELTA``: the study
that led to C5 (C5 off): s_i from this step's normals in a third pass between pass 1 and
pass 2 (tolman_member), with ``--tolman-fit`` H_i from the curvature member's surface fit
instead of the normals' divergence (tolman_fit_member).
``--nu NU``: the oscillating drop's kinematic viscosity (``case stress-drop-oscillation-*``,
``energy``; tension_cases.OSCILLATION_NU, 1e-5); ``--sound-factor F``: every drop's sound
speed F times drop_sound_speed's (the compression under the cohesion 1 % / F^2);
``--re-ratio X``: every drop's re = X l0 (the cases' 2.1; tools/mode_power_study.py), with
the member's constants there (params.STRESS_NEIGHBOURHOODS: since 2026-12-07 at 3.1 l0 F from
the lattice and delta 0.9 in 2D, so the 3.1 l0 rows before, with F = 1, take ``--c4-factor 1``
and in 2D ``--tolman 0``; since 2026-12-07's third session in 3D H = 4.1, F = 1 and delta
1.25, so the 3D rows at 3.1 l0 before take ``--pair-support 3 --c4-factor lattice --tolman
0.8``; 2D keeps H = 3), elsewhere the seed neighbourhood's (admit_neighbourhood);
``--c4-factor F``: with ``--base member``, C4's pressure F rho l0 max(0, a_i . g_i/|g_i|) in
place of the neighbourhood's F; ``lattice``: F = n0/(2 d G l0) at the run's re, the flat
lattice face's balance (lattice.face_balance_factor: 1.011 in 3D at 2.1 l0, 1.187 at 3.1
l0);
``--pair-support H``: C3's pair support H l0 in place of the neighbourhood's
(params.STRESS_NEIGHBOURHOODS: 3, or 4.1 in 3D at 3.1 l0), the lattice normalisers following
it (VALIDATION.md "re = 3.1 l0 completed, and re = 4.0 l0": re + l0 holds the surface at re =
4.0 l0);
``--relaxed-start P``: the 3D oscillating drop starts from its disordered start relaxed at
rest for P periods (relaxed_start: a liquid without the melt), fitted from t = 0.
``--pressure-filter``: every step the pressurised particles' EOS pressure is replaced by its
Shepard mean over the pressurised fluid particles about them (neighbours_pressure_member,
filtered), before the surface's own; ``--numerics KEY=VALUE``: the drops' params.Numerics
with KEY set (e.g. collision=0; ``drop``'s on its own sum form); ``--disorder X``: ``drop``'s
start disordered as the 3D cases' (0.15; default a lattice); ``--amplitude A``: ``energy``'s
mode amplitude (the case's 0.1);
``--gradient dn``: the pressure gradient's pair term the number density's derivative
(dn_gradient) instead of S11's.
``--pair-kernel``: the divergence's pair weight: ``quartic`` the first member's 1 - (r/re)^4,
``smooth`` (1 - (r/re)^4)^2 (zero slope at re), ``smooth2`` / ``smooth25`` / ``smooth3`` the
same with support 2 / 2.5 / 3 l0 (smooth3 is the member's), each with its K_d and a from the
lattice (pair_normalisers); the tangential moment follows quartic or smooth.
The levers compose (e.g. --tangential-moment --surface own).
Runs on one thread (``--threads``) so that it can run beside a long recording."""
import argparse
import contextlib
import functools
import math
import time
from typing import Optional

import numpy as np
import taichi as ti

from crowndemo import backend
from crowndemo.core.surface_tension import stress as _stress


def neighbours_pressure_member(base, scaled: bool = False, filtered: bool = False):
    """``base`` with the ``--surface neighbours`` pass (module docstring); ``scaled``: the
    ``--surface virial`` one (times n0/n_i). ``filtered`` (``--pressure-filter``) instead:
    before the surface's own pressure, each fluid particle with P_i > 0 takes the Shepard mean
    of the pressurised fluid particles about it, itself included, P_i <- sum_j P_j W_ij /
    sum_j W_ij, W = (1 - r/re)^2 (W_ii = 1): the particle-scale pressure noise averaged over
    the kernel."""
    from crowndemo.core.operators import weight
    from crowndemo.core.state import FLUID

    @ti.data_oriented
    class NeighbourPressureStress(base):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.p_new = ti.field(float, self.state.capacity)

        def boundary_pressure(self, dt: float = 0.0) -> None:
            self._neighbours_pressure()
            self._commit()
            super().boundary_pressure(dt)

        @ti.func
        def _pressurised(self, i, j, rij, r2, acc: ti.template()):
            if self.state.kind[j] == FLUID and self.state.pressure[j] > 0.0:
                w = 0.0
                if ti.static(filtered):
                    w = (1.0 - ti.sqrt(r2) / self.coef.re[None]) ** 2
                else:
                    w = weight(ti.sqrt(r2), self.coef.re[None])
                acc += ti.Vector([w * self.state.pressure[j], w])

        @ti.kernel
        def _neighbours_pressure(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                p_i = self.state.pressure[i]
                self.p_new[i] = p_i
                # filtered: the pressurised particles, themselves counted (W_ii = 1); else
                # the free surface's (P = 0), from their neighbours alone
                if self.state.kind[i] == FLUID and (p_i > 0.0) == ti.static(filtered):
                    acc = ti.Vector([p_i, 1.0]) if ti.static(filtered) else ti.Vector([0.0, 0.0])
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._pressurised, acc)
                    if acc[1] > 0.0:
                        self.p_new[i] = acc[0] / acc[1]
                        if ti.static(scaled):
                            self.p_new[i] *= ti.min(
                                self.coef.n0[None] / ti.max(self.state.density[i], 1e-30), 3.0)

        @ti.kernel
        def _commit(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                self.state.pressure[i] = self.p_new[i]

    return NeighbourPressureStress


@ti.func
def own_normal_stress(rho, l0, a, g):
    """rho l0 max(0, a . g/|g|): the normal stress a surface particle's own tension a carries
    per area l0^(d-1) (``--surface own``); 0 where g = 0."""
    out = 0.0
    if g.norm() > 0.0:
        out = rho * l0 * ti.max(a.dot(g) / g.norm(), 0.0)
    return out


def own_pressure_member(base, factor: float, per_area: bool = False, spacing: bool = False):
    """``base`` with the ``--surface own`` pass (module docstring); ``per_area``: divided by
    the tangential moment's c_i (the area a surface particle holds, over l0^2); ``spacing``
    (``--surface own-spacing``): times (l0 / s_i)^(d-1), s_i the distance to i's nearest
    fluid neighbour along its surface (|r_ij . n_i| < |r_ij| / 2): the force over the area the
    particle holds, so a stretched layer's pressure falls and a packed one's rises."""
    from crowndemo.core.state import FLUID

    @ti.data_oriented
    class OwnPressureStress(base):
        def boundary_pressure(self, dt: float = 0.0) -> None:
            super().boundary_pressure(dt)
            self._own_pressure()

        @ti.func
        def _nearest_along(self, i, j, rij, r2, acc: ti.template()):
            if self.state.kind[j] == FLUID:
                n = self.colour[i].normalized()
                if ti.abs(rij.dot(n)) < 0.5 * ti.sqrt(r2):
                    acc = ti.min(acc, ti.sqrt(r2))

        @ti.kernel
        def _own_pressure(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                g = self.colour[i]
                if self.state.kind[i] == FLUID and self.state.pressure[i] <= 0.0 and g.norm() > 0.0:
                    l0 = self.coef.l0[None]
                    p = factor * own_normal_stress(self.coef.rho[None], l0, self.accel[i], g)
                    if ti.static(per_area):
                        p /= self.share[i]
                    if ti.static(spacing):
                        near = 2.0 * l0
                        self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                     self._nearest_along, near)
                        p *= (l0 / ti.min(ti.max(near, 0.5 * l0), 2.0 * l0)) ** (self.dim - 1)
                    self.state.pressure[i] = p

    return OwnPressureStress


def admit_neighbourhood(re_over_l0: float) -> None:
    """Lets the study run the stress member at an re it has no constants for
    (params.STRESS_NEIGHBOURHOODS refuses it): with the seed neighbourhood's, F = 1 and 2.1
    l0's deltas, unless --c4-factor / --tolman set others (how the study ran re = 4.0 l0)."""
    import crowndemo.core.params as params
    try:
        params.stress_neighbourhood(re_over_l0)
    except params.ParameterError:
        seed = params.STRESS_NEIGHBOURHOODS[params.SEED_NEIGHBOURHOOD]   # F = 1 there
        params.STRESS_NEIGHBOURHOODS[re_over_l0] = {k: dict(v) for k, v in seed.items()}


def set_pair_support(h_l0: float) -> None:
    """``--pair-support H``: C3's pair support H l0 in every neighbourhood and dimension, read
    at call time (by Model.of, the lattice normalisers and C3's kernel)."""
    import crowndemo.core.params as params
    for own in params.STRESS_NEIGHBOURHOODS.values():
        own["pair_support"] = {2: h_l0, 3: h_l0}


def tolman_delta_member(base, delta: float):
    """``base`` with C5's delta ``delta`` (l0) in place of its neighbourhood's (``--tolman``;
    StressTension.tolman_delta, read at __init__; 0 compiles C5 out)."""
    return ti.data_oriented(type("TolmanDeltaStress", (base,), {"tolman_delta": float(delta)}))


def tolman_form_member(base, form: str, steps: float, lag=None):
    """``base`` with C5's ``--tolman-form`` (pair: the member's own) and ``--tolman-lag`` (None:
    the member's TOLMAN_LAG for the pair form, 0 for the probes, measured without it)."""
    if lag is None and form != "pair":
        lag = 0.0
    if lag is not None:
        base = ti.data_oriented(type("TolmanLagStress", (base,), {"tolman_lag": float(lag)}))
    if form == "particle":
        return tolman_particle_member(base)
    if form == "smoothed":
        return tolman_smoothed_member(base)
    if form == "lagged":
        return tolman_lagged_member(base, steps)
    return base


def tolman_particle_member(base):
    """``--tolman-form particle``: C5's s_i taken on particle i's whole pull, a_i = s_i (K_d /
    rho) sum_j (T_i + T_j) r_ij f_d, instead of on each particle's own T in the pairs (the
    member's (s_i T_i + s_j T_j)). The member's form is the divergence of s T, which holds
    the Marangoni term T . grad s: a tension varying along the surface with its curvature
    pulls the surface toward the flatter parts, and on an oscillating drop that flow is
    viscous work. This one scales the pull where it acts and has no such term; its pairs are
    no longer antisymmetric (momentum is kept only as far as s_i ~ s_j)."""
    from crowndemo.core.state import FLUID

    class TolmanParticleStress(base):
        @ti.func
        def _pair_tension(self, i, j, gi, gj, rij):
            f = _stress.stress_times(gi, rij)
            if self.state.kind[j] == FLUID:
                f += _stress.stress_times(gj, rij)
            return f * self._tension(i)
    return ti.data_oriented(TolmanParticleStress)


def _c5_pass_member(base):
    """``base`` with the member's passes and ``_c5_pass`` between pass 2 and C4, where pass 2
    has left C5's next s_i in tolman_next and C4 has yet to take it."""
    class C5PassStress(base):
        def boundary_pressure(self, dt: float = 0.0) -> None:
            self._colour()
            if self.symmetry is not None:
                self._sync_images()
            self._divergence()
            self._c5_pass()
            self._surface_pressure(dt)
    return C5PassStress


def tolman_smoothed_member(base):
    """``--tolman-form smoothed``: C5's s_i replaced, before it is used, by its Shepard mean
    over i and its surface neighbours within re (those with |g| l0 > NORMAL_MIN, weighted by
    C1's f(r)), so s varies over the surface on the scale of re rather than particle by
    particle (a third pass; the pairs stay the member's, antisymmetric)."""
    from crowndemo.core.state import FLUID

    class TolmanSmoothedStress(_c5_pass_member(base)):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.tolman_mean = ti.field(float, self.state.capacity)

        def _c5_pass(self) -> None:
            self._smooth()

        @ti.func
        def _mean_pair(self, i, j, rij, r2, acc: ti.template()):
            if self.state.kind[j] == FLUID and \
                    self.colour[j].norm() * self.coef.l0[None] > _stress.NORMAL_MIN:
                w = _stress.stress_kernel(ti.sqrt(r2), self.coef.re[None])
                acc += ti.Vector([w * self.tolman_next[j], w])

        @ti.kernel
        def _smooth(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                s = self.tolman_next[i]
                if self.state.kind[i] == FLUID and \
                        self.colour[i].norm() * self.coef.l0[None] > _stress.NORMAL_MIN:
                    acc = ti.Vector([s, 1.0])               # i itself, f(0) = 1
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._mean_pair, acc)
                    s = acc[0] / acc[1]
                self.tolman_mean[i] = s
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                self.tolman_next[i] = self.tolman_mean[i]
    return ti.data_oriented(TolmanSmoothedStress)


def tolman_lagged_member(base, steps: float):
    """``--tolman-form lagged --tolman-steps N``: C5's s_i follows this step's value through a
    first-order lag of N steps, s <- s + (s_now - s) / N, from the value of i's first step:
    the static curvature's correction without following the mode's own (a probe: N steps is
    no physical time). i's first step is the member's: its carried s_i is still UNSET."""
    from crowndemo.core.state import FLUID

    class TolmanLaggedStress(_c5_pass_member(base)):
        def _c5_pass(self) -> None:
            self._lag(1.0 / steps)

        @ti.kernel
        def _lag(self, rate: float):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.state.kind[i] == FLUID and self.tolman[i] > _stress.UNSET:
                    self.tolman_next[i] = self.tolman[i] + rate * (
                        self.tolman_next[i] - self.tolman[i])
    return ti.data_oriented(TolmanLaggedStress)


def c4_factor_value(arg: str, dim: int, re_over_l0: float) -> float:
    """``--c4-factor``'s F (printed): a number, or ``lattice``, lattice.face_balance_factor at
    the run's re (this tool's and tools/mode_power_study.py's option)."""
    from crowndemo.core.lattice import face_balance_factor
    factor = face_balance_factor(dim, re_over_l0) if arg == "lattice" else float(arg)
    print(f"C4's factor {factor:.4f}", flush=True)
    return factor


def c4_factor_member(base, factor: float):
    """``base`` (the member) with C4's pressure F rho l0 max(0, a_i . g_i/|g_i|), F =
    ``factor``, in place of its neighbourhood's (``--c4-factor``; StressTension.c4_factor)."""
    return ti.data_oriented(type("C4FactorStress", (base,), {"c4_factor": float(factor)}))


def eos_pressure_member(base, slope: float):
    """``base`` with ``--surface eos``: a free-surface particle (n_i < beta n0, P = 0 by M3)
    takes the EOS (S17) of its number density over the share of a full neighbourhood it has,
    P_i = max(0, c^2 rho (n_i / (theta_i n0) - 1)), theta_i = max(1 - C |g_i| l0, 0.3), g_i the
    raw colour gradient (C1 without omega), C = ``slope`` fitted on lattice half-spaces of
    several faces; so the surface layer carries the inside pressure and answers its own
    density (packing raises it, stretching lowers it)."""
    from crowndemo.core.state import FLUID

    @ti.data_oriented
    class EosPressureStress(base):
        def boundary_pressure(self, dt: float = 0.0) -> None:
            super().boundary_pressure(dt)
            self._eos_surface()

        @ti.kernel
        def _eos_surface(self):
            n0, beta = self.coef.n0[None], self.coef.beta[None]
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                n = self.state.density[i]
                if self.state.kind[i] == FLUID and n < beta * n0:
                    w = self._surface_weight(i)
                    g = 0.0
                    if w > 0.0:
                        g = self.colour[i].norm() / w * self.coef.l0[None]
                    theta = ti.max(1.0 - slope * g, 0.3)
                    self.state.pressure[i] = ti.max(
                        self.coef.c2[None] * self.coef.rho[None] * (n / (theta * n0) - 1.0), 0.0)

    return EosPressureStress


def continuity_pressure_member(base):
    """``base`` with ``--continuity`` (a probe, tools only): the EOS (S17) of a number density
    carried by the continuity equation, n_c <- n_c (1 - dt div u*), div u*_i = d / n_i sum_j
    (u_j - u_i) . r_ij w / r^2 (a third pass, over re), from n0 at each particle's first step,
    for every fluid particle in place of S17/M3's summed n: a surface particle's missing
    neighbours no longer read as tension, so the layer within re of the free surface carries
    the pressure it is compressed to (as weakly compressible SPH's density by the continuity
    equation); C4 still acts where n_c's pressure is 0. dt = 0 (a frame's refresh) advances
    nothing. For the drops (no plane floor: its layers are not in the divergence)."""
    from crowndemo.core.operators import gradient_pair, weight
    from crowndemo.core.state import FLUID, GONE

    @ti.data_oriented
    class ContinuityPressureStress(base):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.carried_n = self.state.carry("continuity_n", ti.field(float,
                                                                        self.state.capacity), 0.0)

        def boundary_pressure(self, dt: float = 0.0) -> None:
            self._continuity(dt)
            super().boundary_pressure(dt)

        @ti.func
        def _continuity_pair(self, i, j, rij, r2, acc: ti.template()):
            if self.state.kind[j] != GONE:
                acc += (self.state.vel[j] - self.state.vel[i]).dot(gradient_pair(   # S11's
                    1.0, rij, r2, weight(ti.sqrt(r2), self.coef.re[None])))

        @ti.kernel
        def _continuity(self, dt: float):
            n0, c2, rho = self.coef.n0[None], self.coef.c2[None], self.coef.rho[None]
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.state.kind[i] == FLUID:
                    nc = self.carried_n[i]
                    if nc <= 0.0:
                        nc = n0
                    if dt > 0.0:
                        acc = 0.0
                        self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                     self._continuity_pair, acc)
                        div = self.dim / ti.max(self.state.density[i], 0.5 * n0) * acc
                        nc *= 1.0 - dt * div
                        self.carried_n[i] = nc
                    self.state.pressure[i] = ti.max(c2 * rho * (nc - n0) / n0, 0.0)

    return ContinuityPressureStress


def free_marked_member(base):
    """``base`` with ``free`` (1 for the fluid particles S17/M3 left at P = 0) and ``_mark``,
    which sets it; the ``--surface blend`` and ``cumulative`` members call it first."""
    from crowndemo.core.state import FLUID

    @ti.data_oriented
    class FreeMarkedStress(base):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.free = ti.field(ti.i32, self.state.capacity)

        @ti.kernel
        def _mark(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                self.free[i] = 1 if (self.state.kind[i] == FLUID
                                     and self.state.pressure[i] <= 0.0) else 0

    return FreeMarkedStress


def cumulative_pressure_member(base):
    """``base`` (the member, with C4) with ``--surface cumulative``: after C4, a free-surface
    particle also takes the w-weighted mean C4 pressure of its fluid neighbours outward of it
    (r_ij . g_i < -|r_ij|/2, g pointing into the liquid), so the layer below the surface carries
    the pull of the layer above as well as its own (the pressure summed from the outside in);
    a third pass, tools only."""
    from crowndemo.core.operators import weight
    from crowndemo.core.state import FLUID

    @ti.data_oriented
    class CumulativePressureStress(free_marked_member(base)):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.p_own = ti.field(float, self.state.capacity)

        def boundary_pressure(self, dt: float = 0.0) -> None:
            self._mark()
            super().boundary_pressure(dt)
            self._keep()
            self._cumulate()

        @ti.kernel
        def _keep(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                self.p_own[i] = self.state.pressure[i] if self.free[i] == 1 else 0.0

        @ti.func
        def _outward(self, i, j, rij, r2, acc: ti.template()):
            if self.state.kind[j] == FLUID and self.free[j] == 1:
                g = self.colour[i]
                if rij.dot(g) < -0.5 * ti.sqrt(r2) * g.norm():
                    w = weight(ti.sqrt(r2), self.coef.re[None])
                    acc += ti.Vector([w * self.p_own[j], w])

        @ti.kernel
        def _cumulate(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.free[i] == 1 and self.colour[i].norm() > 0.0:
                    acc = ti.Vector([0.0, 0.0])
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._outward, acc)
                    if acc[1] > 0.0:
                        self.state.pressure[i] = self.p_own[i] + acc[0] / acc[1]

    return CumulativePressureStress


def blend_pressure_member(base):
    """``base`` with ``--surface blend``: a free-surface particle (P = 0 after S17/M3) takes the
    smaller of its pressurised neighbours' mean (``--surface neighbours``) and the normal stress
    its own tension carries (``--surface own``, F = 1)."""
    member = free_marked_member(neighbours_pressure_member(base))

    @ti.data_oriented
    class BlendPressureStress(member):
        def boundary_pressure(self, dt: float = 0.0) -> None:
            self._mark()
            super().boundary_pressure(dt)
            self._blend()

        @ti.kernel
        def _blend(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                if self.free[i] == 1:
                    own = own_normal_stress(self.coef.rho[None], self.coef.l0[None],
                                            self.accel[i], self.colour[i])
                    self.state.pressure[i] = ti.min(self.state.pressure[i], own)

    return BlendPressureStress


def isotropic_core_member(base):
    """``base`` with the ``--isotropic-core`` pair (module docstring)."""
    from crowndemo.core.state import FLUID, GONE
    from crowndemo.core.surface_tension.stress import stress_times

    @ti.data_oriented
    class IsotropicCoreStress(base):
        @ti.func
        def _divergence_pair(self, i, j, rij, r2, acc: ti.template()):
            kind_j = self.state.kind[j]
            if kind_j != GONE:
                fd = self._pair_weight(ti.sqrt(r2))
                if fd >= 0.0:
                    f = stress_times(self.colour[i], rij)
                    if kind_j == FLUID:
                        f += stress_times(self.colour[j], rij)
                    acc += f * fd
                else:
                    s = self.colour[i].norm()
                    if kind_j == FLUID:
                        s += self.colour[j].norm()
                    acc += s * rij * fd

    return IsotropicCoreStress


def membrane_weight(gi, gj, ref):
    """phi_ij (``--membrane``) of |g_i| l0, |g_j| l0: 2 min / sum with ref = 0, else
    min(1, |g_i| l0/ref) min(1, |g_j| l0/ref)."""
    if ref <= 0.0:
        return 2.0 * min(gi, gj) / (gi + gj) if gi + gj > 0 else 0.0
    return min(1.0, gi / ref) * min(1.0, gj / ref)


def membrane_ratio(dim: int, ref: float = 0.0, re_over_l0: float = 2.1,
                   kernel: str = "quartic") -> float:
    """a_membrane / a: the flat lattice face's normaliser a (lattice.stress_normaliser) with
    each pair's stress weighted by phi_ij (``membrane_weight``, ``membrane_member``), over the
    base's a (pair weight ``kernel``: the first member's quartic, or the member's smooth3)."""
    f = pair_kernel(kernel)
    reach = re_over_l0 * max(PAIR_SUPPORT.get(kernel, 1.0), 1.0)
    return cut_sum(dim, f, re_over_l0, reach) / cut_sum(
        dim, f, re_over_l0, reach, phi=lambda gi, gj: membrane_weight(gi, gj, ref))


def membrane_member(base, dim: int, ref: float, kernel: str = "quartic"):
    """``base`` with the ``--membrane`` pair (module docstring); ``kernel``: the base's pair
    weight, for the ratio of normalisers."""
    from crowndemo.core.state import FLUID, GONE
    from crowndemo.core.surface_tension.stress import stress_times
    ratio = membrane_ratio(dim, ref, kernel=kernel)

    @ti.data_oriented
    class MembraneStress(base):
        @ti.func
        def _divergence_pair(self, i, j, rij, r2, acc: ti.template()):
            kind_j = self.state.kind[j]
            if kind_j != GONE:
                f = stress_times(self.colour[i], rij)
                phi = 1.0
                if kind_j == FLUID:
                    f += stress_times(self.colour[j], rij)
                    gi, gj = self.colour[i].norm(), self.colour[j].norm()
                    phi = 0.0
                    if ti.static(ref > 0.0):
                        l0 = self.coef.l0[None]
                        phi = ti.min(1.0, gi * l0 / ref) * ti.min(1.0, gj * l0 / ref)
                    elif gi + gj > 0.0:
                        phi = 2.0 * ti.min(gi, gj) / (gi + gj)
                acc += ratio * phi * f * self._pair_weight(ti.sqrt(r2))

    return MembraneStress


def _layer_omega(dim: int, re_over_l0: float, beta: float, layers: int) -> np.ndarray:
    """C1's omega of the layers k = 0, 1, ... of a flat lattice half-space (l0 = 1)."""
    from crowndemo.core.lattice import layer_number_densities, surface_weight
    return surface_weight(layer_number_densities(dim, re_over_l0, layers), 1.0, beta)


SURFACE_PAIRS = ("product", "mean")     # --surface-pairs' weights: omega_i omega_j, their mean


def pair_band_beta(beta: float, band: float) -> float:
    """The beta' whose omega band 2 (1 - beta') is ``--pair-band``'s B (``beta`` itself for B =
    0), so that surface_weight(n, n0, beta') = clamp((1 - n/n0) / B, 0, 1)."""
    return beta if band <= 0.0 else 1.0 - 0.5 * band


def pair_omega(form: str, oi, oj):
    """A pair's weight of ``--surface-pairs`` from its particles' omega (numpy or Taichi)."""
    return oi * oj if form == "product" else 0.5 * (oi + oj)


def surface_pairs_ratio(dim: int, re_over_l0: float, beta: float, form: str = "product"
                        ) -> float:
    """a_pairs / a: the flat lattice face's normaliser (lattice.stress_normaliser's cut sum)
    with each pair's term weighted by ``pair_omega`` (``surface_pairs_member``)."""
    plain, weighted = cut_sums(dim, re_over_l0, beta, form)
    return plain / weighted


def cut_sums(dim: int, re_over_l0: float, beta: float, form: str = "product") -> tuple:
    """lattice.stress_normaliser's cut sum over a flat lattice face (l0 = 1; a = 1 / (K_d
    sum)), plain and with each pair's term times ``pair_omega`` of the two layers' omega
    (lattice.stress_cut_sums)."""
    from crowndemo.core.lattice import (colour_gradient_column, stress_cut_sums,
                                        stress_pair_support)
    layers = len(colour_gradient_column(dim, 1.0, re_over_l0)) + int(
        math.ceil(stress_pair_support(dim, 1.0, re_over_l0))) + 1
    om = _layer_omega(dim, re_over_l0, beta, layers)
    return stress_cut_sums(dim, re_over_l0, om, lambda a, b: pair_omega(form, a, b))


def surface_pairs_member(base, dim: int, re_over_l0: float, beta: float,
                         form: str = "product", band: float = 0.0):
    """``base`` with ``--surface-pairs FORM``: C3's pair terms times omega_i omega_j
    (``product``) or (omega_i + omega_j)/2 (``mean``), C1's surface weights, so the divergence
    is taken among the particles that carry the tension and the pull lands on the surface
    layer rather than a spacing under it (wholly with the product, half of the next layer's
    share with the mean); a rescaled so that a flat lattice face still carries sigma
    (``surface_pairs_ratio``). C5's sums as the member's. ``band`` > 0 (``--pair-band B``):
    the pairs' omega = clamp((1 - n/n0) / B, 0, 1) in place of C1's band 2 (1 - beta) (C1's g
    unchanged), a from the flat lattice's layers with that band."""
    from crowndemo.core.surface_tension import stress as S
    from crowndemo.core.pressure import surface_weight
    pair_beta = pair_band_beta(beta, band)
    ratio = surface_pairs_ratio(dim, re_over_l0, pair_beta, form)

    @ti.data_oriented
    class SurfacePairsStress(base):
        @ti.func
        def _band_weight(self, i):
            return surface_weight(self.state.density[i], self.coef.n0[None], pair_beta)

        @ti.func
        def _divergence_pair(self, i, j, rij, r2, acc: ti.template()):
            if self.state.kind[j] != S.GONE:
                r = ti.sqrt(r2)
                gi, gj = self.colour[i], self.colour[j]
                oi, oj = self._band_weight(i), self._band_weight(j)
                w = ratio * 0.5 * (oi + oj)
                if ti.static(form == "product"):
                    w = ratio * oi * oj
                acc.a += self._pair_tension(i, j, gi, gj, rij) * self._pair_weight(r) * w
                if ti.static(self.delta > 0.0):
                    g_min = S.NORMAL_MIN / self.coef.l0[None]
                    if r < self.coef.re[None] and gj.norm() > g_min and gi.norm() > g_min:
                        acc.h += S.normal_divergence_terms(
                            gi.normalized(), gj.normalized(), rij,
                            S.stress_kernel(r, self.coef.re[None]))

    return SurfacePairsStress


def tension_factor_member(base, factor: float):
    """``base`` with its tension times ``factor`` (``--tension-factor``: a -> factor a, C3's
    pull and so C4's pressure; C1 and C5's curvature unchanged)."""
    @ti.data_oriented
    class ScaledStress(base):
        @ti.func
        def _pair_weight(self, r):
            return factor * base._pair_weight(self, r)

    return ScaledStress


def torque_free_member(base, on: bool):
    """``base`` with C3b's pairs torque-free or not (``--torque-free yes|no``: in place of the
    neighbourhood's choice, stress.StressTension.torque_free)."""
    @ti.data_oriented
    class TorqueFreeStress(base):
        torque_free = on

    return TorqueFreeStress


def pull_depth(dim: int, scale: float, beta: float, surface_pairs: str = "",
               band: float = 0.0) -> dict:
    """Where the member's tension and its pull sit in a lattice ball of R/l0 = ``scale`` (l0 =
    1; numpy, C1-C3 without C4 and C5): the |g|-weighted depth of the tension under the
    volume's radius, the inward force's weighted depth and its shares at depths 0-1, 1-2 and
    over 2 l0, and the whole inward pull over Laplace's, (d - 1) sigma / R times the area at
    the volume's radius; with ``surface_pairs`` (a form) and ``band``, C3 as
    ``surface_pairs_member`` has it."""
    from crowndemo.core.lattice import (LatticeConstants, stress_kernel, stress_pair_kernel,
                                        stress_pair_support, surface_weight, weight)
    from crowndemo.scenes.drop import ball
    from crowndemo.validate.clusters import close_pairs
    lat = LatticeConstants.compute(dim, 1.0, 2.1, 1.0, 1.0)
    H = stress_pair_support(dim, 1.0, 2.1)
    x = ball(dim, scale, 1.0)
    x = x - x.mean(axis=0)
    i, j, r2 = close_pairs(x, H, with_d2=True)
    r, rij = np.sqrt(r2), x[j] - x[i]
    n = np.zeros(len(x))
    w = np.where(r < lat.re, weight(np.minimum(r, lat.re), lat.re), 0.0)
    np.add.at(n, i, w)
    np.add.at(n, j, w)
    omega = surface_weight(n, lat.n0, beta)
    f = (stress_kernel(r, lat.re) * (r < lat.re))[:, None] * rij
    g = np.zeros_like(x)
    np.add.at(g, i, f)
    np.add.at(g, j, -f)
    g *= omega[:, None] * lat.stress_K
    gl = np.linalg.norm(g, axis=1)
    T = np.zeros((len(x), dim, dim))
    on = gl > 0
    T[on] = gl[on, None, None] * np.eye(dim) - g[on, :, None] * g[on, None, :] / gl[on, None, None]
    fd = stress_pair_kernel(r, H) * np.where(r < 1.0, (r - 0.75) / 0.25, 1.0)
    if surface_pairs:
        pair_beta = pair_band_beta(beta, band)
        om = surface_weight(n, lat.n0, pair_beta)
        fd = fd * pair_omega(surface_pairs, om[i], om[j]) * surface_pairs_ratio(
            dim, 2.1, pair_beta, surface_pairs)
    pair = np.einsum("kab,kb->ka", T[i] + T[j], rij) * fd[:, None]
    acc = np.zeros_like(x)
    np.add.at(acc, i, pair)
    np.add.at(acc, j, -pair)
    radius = np.linalg.norm(x, axis=1)
    R = (len(x) / (math.pi if dim == 2 else 4.0 * math.pi / 3.0)) ** (1.0 / dim)  # volume's
    depth = R - radius
    pull = -(acc * x).sum(axis=1) / np.maximum(radius, 1e-12)
    bins = ((0.0, 1.0), (1.0, 2.0), (2.0, np.inf))
    area = 2.0 * math.pi * R if dim == 2 else 4.0 * math.pi * R * R
    whole = pull.sum() * lat.stress_Kd * lat.stress_a / ((dim - 1) / R * area)  # sigma = rho = 1
    return {"tension": float((gl * depth).sum() / gl.sum()), "whole": float(whole),
            "pull": float((pull * depth).sum() / pull.sum()),
            "shares": [float(pull[(depth >= lo) & (depth < hi)].sum() / pull.sum())
                       for lo, hi in bins]}


def depth(dim: int, scales: str, beta: float, band: float = 0.0) -> None:
    """``depth``: ``pull_depth`` at each R/l0, the member's C3 and ``--surface-pairs``'s (with
    ``--pair-band``'s band)."""
    for scale in (float(v) for v in scales.split(",")):
        for pairs in ("",) + SURFACE_PAIRS:
            d = pull_depth(dim, scale, beta, pairs, band)
            print(f"{dim}D lattice ball R/l0 = {scale:g}, C3 " + (f"--surface-pairs {pairs}"
                  if pairs else "the member's") + f": tension at {d['tension']:.2f} l0 under "
                  f"the volume's radius, pull at {d['pull']:.2f} l0; the pull's shares at 0-1 "
                  "/ 1-2 / > 2 l0: " + " / ".join(f"{v:.2f}" for v in d["shares"])
                  + f"; the whole pull {d['whole']:.3f} of Laplace's")


def lattice_moment(dim: int, beta: float, re_over_l0: float = 2.1,
                   kernel: str = "quartic") -> float:
    """B0: the tangential moment (``tangential_moment_member``) of an outer particle of a flat
    lattice face, from the lattice's colour column (lattice.colour_gradient_column) times
    omega of each layer (C1)."""
    from crowndemo.core import lattice
    offs = lattice.lattice_offsets(dim, 1.0, re_over_l0)
    r = np.linalg.norm(offs, axis=1)
    column = lattice.colour_gradient_column(dim, 1.0, re_over_l0)
    g = column * _layer_omega(dim, re_over_l0, beta, len(column))
    fd = pair_kernel(kernel)(r, re_over_l0)
    layer = np.round(-offs[:, -1]).astype(int)                  # j's layer, i in layer 0
    tangential = (offs[:, :-1] ** 2).sum(axis=1)
    return float(sum(g[k] * t * f for k, t, f in zip(layer, tangential, fd)
                     if 0 <= k < len(g)))


def lattice_virial_moment(dim: int, re_over_l0: float = 2.1) -> float:
    """M0: the unweighted tangential moment sum_j r_t^2 f_d (``--virial-moment``) of an outer
    particle of a flat lattice face, in l0^2."""
    from crowndemo.core import lattice
    offs = lattice.lattice_offsets(dim, 1.0, re_over_l0)
    fd = pair_kernel("quartic")(np.linalg.norm(offs, axis=1), re_over_l0)
    below = offs[:, -1] <= 1e-9
    return float(((offs[below, :-1] ** 2).sum(axis=1) * fd[below]).sum())


def tangential_moment_member(base, beta: float, dim: int, virial: bool = False,
                             clamp: float = 4.0, kernel: str = "quartic"):
    """``base`` with the ``--tangential-moment`` pass (module docstring); ``virial``: the
    ``--virial-moment`` one."""
    from crowndemo.core.state import FLUID, GONE
    if virial and kernel != "quartic":
        raise SystemExit("--virial-moment: with the member's pair kernel only")
    B0 = lattice_virial_moment(dim) if virial else lattice_moment(dim, beta, kernel=kernel)

    @ti.data_oriented
    class TangentialMomentStress(base):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.share = ti.field(float, self.state.capacity)

        def boundary_pressure(self, dt: float = 0.0) -> None:
            if self.symmetry is not None:
                raise SystemExit("--tangential-moment: drops only (no symmetry planes)")
            self._colour()
            self._moment()
            self._scale()
            self._divergence()

        @ti.func
        def _moment_pair(self, i, j, rij, r2, acc: ti.template()):
            l0 = self.coef.l0[None]
            n = self.colour[i].normalized()
            fd = 0.0
            if ti.static(kernel == "smooth"):
                fd = _stress.stress_pair_kernel(ti.sqrt(r2), self.coef.re[None], l0)
            else:
                fd = quartic_pair_kernel(ti.sqrt(r2), self.coef.re[None], l0)
            moment = (r2 - rij.dot(n) ** 2) / (l0 * l0) * fd
            if ti.static(virial):
                if self.state.kind[j] != GONE:
                    acc += moment
            elif self.state.kind[j] == FLUID:
                acc += self.colour[j].norm() * l0 * moment

        @ti.kernel
        def _moment(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                c = 1.0
                if self.state.kind[i] == FLUID and self.colour[i].norm() > 0.0:
                    b = 0.0
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._moment_pair, b)
                    if b > 0.0:
                        c = ti.min(ti.max(B0 / b, 1.0 / clamp), clamp)
                self.share[i] = c

        @ti.kernel
        def _scale(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                self.colour[i] *= self.share[i]

    return TangentialMomentStress


def drop(dim: int, scale: float, t_ms: float, every_ms: float, profile: bool = False,
         changes: Optional[dict] = None, disorder: float = 0.0) -> None:
    from crowndemo.core.params import Numerics, with_values
    from crowndemo.scenes.drop import resting_drop
    from crowndemo.validate.cases import simulator
    R, t_end = 1.0e-3, t_ms * 1e-3
    l0 = R / scale
    numerics = with_values(Numerics(pressure_gradient="sum", surface_tension="stress"),
                           **(changes or {}))
    scene = resting_drop(dim=dim, radius=R, l0=l0, t_end=t_end, nu=1.0e-4, numerics=numerics,
                         disorder=disorder)
    sim = simulator(scene)
    sigma, rho, n0 = sim.physics.sigma, sim.physics.rho, sim.lattice.n0
    laplace = (dim - 1) * sigma / R
    area = 2 * math.pi * R if dim == 2 else 4 * math.pi * R * R
    print(f"{dim}D drop, R/l0 = {scale:g}, {len(scene.pos)} particles")
    next_t = 0.0
    while sim.stats.time < t_end:
        sim.step()
        if sim.stats.time < next_t:
            continue
        next_t += every_ms * 1e-3
        sim.refresh_pressure()
        st, n = sim.surface_tension, sim.state.n[None]
        pos = sim.state.pos.to_numpy()[:n].astype(float)
        P = sim.state.pressure.to_numpy()[:n]
        acc = st.accel.to_numpy()[:n].astype(float)
        g = np.linalg.norm(st.colour.to_numpy()[:n].astype(float), axis=1) * l0
        d = pos - pos.mean(axis=0)
        r = np.linalg.norm(d, axis=1)
        pull = -(acc * d / r[:, None]).sum(axis=1) * rho * l0 ** dim
        surf = g > 0.25
        nd = sim.state.density.to_numpy()[:n] / sim.coef.n0[None]
        P_in = P[r < R / 2].mean()
        tension_virial = -(acc * d).sum() * rho * l0 ** dim          # -sum_i r_i . F_i
        area_d = tension_virial / ((dim - 1) * sigma * area)          # A_d / A
        volume_d = (P * nd).sum() / (P_in * n)                        # V_d / V
        ps = pos[surf]
        gap = np.linalg.norm(ps[:, None] - ps[None], axis=2)
        np.fill_diagonal(gap, np.inf)
        print(f"t = {sim.stats.time * 1e3:5.2f} ms  P_in / Laplace {P_in / laplace:.3f}"
              f"  pull / Laplace pull {pull.sum() / (laplace * area):.3f}"
              f"  surface: {surf.sum()} particles, r / R {r[surf].mean() / R:.3f},"
              f" spacing / l0 {gap.min(axis=1).mean() / l0:.3f},"
              f" at P = 0 {(P[surf] <= 0).mean():.2f},"
              f" P / Laplace {P[surf].mean() / laplace:.3f},"
              f" pull share {pull[surf].sum() / pull.sum():.2f}  r_max / R {r.max() / R:.3f},"
              f" pull's radius / R {(pull * r).sum() / pull.sum() / R:.3f},"
              f" virial: A_d/A {area_d:.3f} V_d/V {volume_d:.3f}"
              f" pressure/tension {dim * (P * nd).sum() * l0 ** dim / tension_virial:.3f}",
              flush=True)
        if profile:
            edges = R - l0 * np.arange(0.0, 4.01, 0.5)[::-1] - 0.25 * l0
            edges = np.append(edges, 2 * R)
            rows = []
            for lo, hi in zip(edges[:-1], edges[1:]):
                m = (r >= lo) & (r < hi)
                if m.any():
                    share = (P[m] * nd[m]).mean() / P_in
                    rows.append(f"{(lo - R) / l0:+.2f}: {m.sum()} x {share:.2f}"
                                f" (n/n0 {nd[m].mean():.2f})")
            print("   P n/n0 / P_in by (r - R)/l0 from: " + "; ".join(rows), flush=True)


PAIR_KERNELS = {      # f_d(q), q = r/support, for --pair-kernel (the member's is "quartic", C3)
    "quartic": lambda q: 1.0 - q ** 4,
    "smooth": lambda q: (1.0 - q ** 4) ** 2,       # zero slope at the support's edge
    "smooth2": lambda q: (1.0 - q ** 4) ** 2,      # the same, its support 2 l0
    "smooth25": lambda q: (1.0 - q ** 4) ** 2,     # support 2.5 l0 (stretch only: beyond r*)
    "smooth3": lambda q: (1.0 - q ** 4) ** 2,      # support 3 l0 (stretch only)
}
PAIR_SUPPORT = {"smooth2": 2.0 / 2.1, "smooth25": 2.5 / 2.1, "smooth3": 3.0 / 2.1}


def pair_kernel(name: str):
    """f_d(r, re) of PAIR_KERNELS[name], 0 beyond its support (re times PAIR_SUPPORT; no core:
    as lattice.stress_pair_kernel)."""
    def f(r, re):
        h = re * PAIR_SUPPORT.get(name, 1.0)
        r = np.asarray(r, dtype=float)
        return np.where(r < h, PAIR_KERNELS[name](np.minimum(r, h) / h), 0.0)
    return f


def cut_sum(dim: int, kernel, re: float = 2.1, reach: float = None, phi=None) -> float:
    """The sum lattice.stress_normaliser inverts, l0 = 1: over the layers k of a flat lattice
    face and the lattice offsets r (|r| < reach, default re) from layer k to a layer k' >= 0
    with r_x > 0, r_x^2 f_d(|r|) (|g_k| + |g_k'|), each term times phi(|g_k|, |g_k'|) if
    given; |g| the colour column (lattice.colour_gradient_column, support re)."""
    from crowndemo.core import lattice
    offs = lattice.lattice_offsets(dim, 1.0, reach or re)
    f = kernel(np.linalg.norm(offs, axis=1), re)
    g = lattice.colour_gradient_column(dim, 1.0, re)
    total = 0.0
    for k in range(len(g)):
        for off, ff in zip(offs, f):
            kj = k - int(round(off[-1]))
            if off[0] > 0 and kj >= 0:
                gj = g[kj] if kj < len(g) else 0.0
                total += off[0] ** 2 * ff * (g[k] + gj) * (phi(g[k], gj) if phi else 1.0)
    return total


def pair_normalisers(dim: int, name: str, re: float = 2.1) -> tuple:
    """(K_d, a) for the pair kernel ``name`` in units of l0 = 1, as lattice.stress_gradient_norm
    and lattice.stress_normaliser compute them for the member's."""
    from crowndemo.core import lattice
    kernel = pair_kernel(name)
    reach = re * max(PAIR_SUPPORT.get(name, 1.0), 1.0)
    r = np.linalg.norm(lattice.lattice_offsets(dim, 1.0, reach), axis=1)
    Kd = dim / float((r ** 2 * kernel(r, re)).sum())
    return Kd, 1.0 / (Kd * cut_sum(dim, kernel, re, reach))


@ti.func
def quartic_pair_kernel(r, re, l0):
    """The first member's f_d = 1 - (r/re)^4 (``--base first``, ``--pair-kernel quartic``),
    times the core below l0."""
    q = ti.min(r / re, 1.0)
    f = 1.0 - q * q * q * q
    if r < l0:
        f *= (r / l0 - _stress.CORE) / (1.0 - _stress.CORE)
    return f


def kernel_ratio(dim: int, name: str) -> float:
    """K_d a of the pair kernel ``name`` (pair_normalisers) over the member's (lattice.py):
    the factor its pair weight takes in place of the member's."""
    from crowndemo.core import lattice
    Kd, a = pair_normalisers(dim, name)
    return Kd * a / (lattice.stress_gradient_norm(dim, 1.0, 2.1, lattice.stress_pair_kernel,
                                                  lattice.stress_pair_support(dim, 1.0, 2.1))
                     * lattice.stress_normaliser(dim, 1.0, 2.1))


def kernel_member(base, dim: int, name: str):
    """``base`` with ``--pair-kernel NAME``: the pair weight (stress._pair_weight) f_d of
    PAIR_KERNELS[name], the core below l0 as the member's, its K_d and a from the lattice
    (pair_normalisers) in place of the member's. "quartic" is the first member's
    1 - (r/re)^4; the smooth ones (1 - (r/h)^4)^2 with h = re x PAIR_SUPPORT (smooth3: the
    member's)."""
    ratio = kernel_ratio(dim, name)
    h = PAIR_SUPPORT.get(name, 1.0)
    quartic = name == "quartic"

    @ti.data_oriented
    class KernelStress(base):
        @ti.func
        def _pair_weight(self, r):
            f = 0.0
            if ti.static(quartic):
                f = quartic_pair_kernel(r, self.coef.re[None], self.coef.l0[None])
            else:
                f = _stress.stress_pair_kernel(r, h * self.coef.re[None], self.coef.l0[None])
            return ratio * f

    return KernelStress


def tolman_member(base, delta: float):
    """``base`` with ``--tolman-pass DELTA`` (the study that led to C5, with C5 itself off):
    each free-surface particle's tension (its g, so T_i)
    times s_i = clamp(1 - DELTA l0 H_i, 1/2, 3/2), H_i the mean curvature from the unit
    normals n = g/|g| of its neighbours, C5's (stress.normal_divergence_terms: H_i = -sum_j
    n_j . r_t f / sum_j |r_t|^2 f since 2026-12-06; VALIDATION's "C5" figures of this study
    were read with the whole (n_j - n_i) . r_ij in the numerator; r_t: r_ij's part in i's
    tangent plane; 1/r on a sphere or a circle of radius r): a
    Tolman-like correction sigma (1 - delta H) for a surface of tension that sits DELTA l0
    inside the liquid's. A third pass between pass 1 and pass 2; the pairs stay antisymmetric."""
    from crowndemo.core.state import FLUID, GONE

    @ti.data_oriented
    class TolmanStress(base):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            self.tolman = ti.field(float, self.state.capacity)

        def boundary_pressure(self, dt: float = 0.0) -> None:
            self._colour()
            if self.symmetry is not None:
                self._sync_images()
            self._curvature()
            self._apply()
            if self.symmetry is not None:
                self._sync_images()
            self._divergence()
            self._surface_pressure(dt)

        @ti.func
        def _curvature_pair(self, i, j, rij, r2, acc: ti.template()):
            gj = self.colour[j]
            if self.state.kind[j] != GONE and gj.norm() > 0.0:    # C5's sums, no threshold
                acc += _stress.normal_divergence_terms(
                    self.colour[i].normalized(), gj.normalized(), rij,
                    _stress.stress_kernel(ti.sqrt(r2), self.coef.re[None]))

        @ti.kernel
        def _curvature(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                s = 1.0
                if self.state.kind[i] == FLUID and self.colour[i].norm() > 0.0:
                    acc = ti.Vector([0.0, 0.0])
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._curvature_pair, acc)
                    s = _stress.tolman_factor(acc, delta * self.coef.l0[None])
                self.tolman[i] = s

        @ti.kernel
        def _apply(self):
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                self.colour[i] *= self.tolman[i]

    return TolmanStress


def tolman_fit_member(base, delta: float):
    """``--tolman-pass DELTA --tolman-fit``: as tolman_member, H_i from the curvature member's
    least-squares surface fit (curvature.py: frame, monomials, fit_curvature, the outer layer
    only; s_i = 1 where i lies under the layer or the fit is singular)."""
    from crowndemo.core.operators import weight
    from crowndemo.core.state import FLUID, WALL
    from crowndemo.core.surface_tension import curvature as cv

    @ti.data_oriented
    class TolmanFitStress(tolman_member(base, delta)):
        def __init__(self, model, grid, coef):
            super().__init__(model, grid, coef)
            k = 3 if self.dim == 2 else 6
            self.fit_sums = ti.types.struct(m=ti.types.matrix(k, k, float),
                                            b=ti.types.vector(k, float), f=ti.types.matrix(
                                                self.dim, self.dim, float), count=ti.i32,
                                            out=ti.i32)

        @ti.func
        def _fit_pair(self, i, j, rij, r2, acc: ti.template()):
            kind_j = self.state.kind[j]
            if kind_j == FLUID or kind_j == WALL:
                x = acc.f @ (rij / self.coef.l0[None])
                h = x[self.dim - 1]
                if h > cv.LAYER:
                    acc.out += 1
                elif h > -cv.LAYER and kind_j == FLUID:
                    phi = cv.monomials(x)
                    w = weight(ti.sqrt(r2), self.coef.re[None])
                    acc.m += w * phi.outer_product(phi)
                    acc.b += w * h * phi
                    acc.count += 1

        @ti.kernel
        def _curvature(self):
            k = ti.static(3 if self.dim == 2 else 6)
            w_self = weight(self.coef.l0[None], self.coef.re[None])
            for at in range(self.state.n[None]):
                i = self.state.spread(at)
                s = 1.0
                g = self.colour[i]
                if self.state.kind[i] == FLUID and g.norm() > 0.0:
                    acc = self.fit_sums(m=ti.Matrix.zero(float, k, k), b=ti.Vector.zero(float, k),
                                        f=cv.frame(-g.normalized()), count=0, out=0)
                    acc.m[0, 0] += w_self
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._fit_pair, acc)
                    if acc.out == 0 and acc.count + 1 >= k:
                        c, ok = cv.solve_spd(acc.m, acc.b)
                        if ok == 1:
                            cap = ti.static(float(self.dim - 1))
                            kap = ti.min(ti.max(cv.fit_curvature(c), -cap), cap)
                            s = ti.min(ti.max(1.0 - delta * kap / cap, 0.5), 1.5)
                self.tolman[i] = s

    return TolmanFitStress


def zero_surface_member(base):
    """``base`` without the member's free-surface pressure (C4): P = 0 there, as S17/M3 leave
    it (the first member's; the --surface levers start from it)."""
    @ti.data_oriented
    class ZeroSurfaceStress(base):
        def _surface_pressure(self, dt: float) -> None:
            pass

    return ZeroSurfaceStress


def first_member(dim: int):
    """The first member (``--base first``, the figures of VALIDATION.md up to 2026-12-05):
    f_d = 1 - (r/re)^4 and P = 0 on the free surface."""
    from crowndemo.core.surface_tension.stress import StressTension
    return kernel_member(zero_surface_member(StressTension), dim, "quartic")


def _strip(s: float, beta: float, re: float, width: int, kernel: str):
    """``flat_tension``'s strip: positions p, r_ij = p_j - p_i (d), |r_ij|, |g|, unit g, f_d."""
    from crowndemo.core import lattice
    K = lattice.stress_gradient_norm(2, 1.0, re)
    n0 = lattice.weight(np.linalg.norm(lattice.lattice_offsets(2, 1.0, re), axis=1), re).sum()
    outer = [(i * s, 0.0) for i in range(-int(width / s), int(width / s) + 1)]
    below = [(float(i), -float(k)) for k in range(1, 8) for i in range(-width, width + 1)]
    p = np.array(outer + below)
    d = p[None] - p[:, None]
    r = np.linalg.norm(d, axis=2)
    np.fill_diagonal(r, np.inf)
    n = np.where(r < re, re / r - 1.0, 0.0).sum(axis=1)       # number density (S1)
    g = K * (d * np.where(r < re, (1.0 - r / re) ** 3, 0.0)[..., None]).sum(axis=1)   # C1
    g *= lattice.surface_weight(n, n0, beta)[:, None]
    gn = np.linalg.norm(g, axis=1)
    unit = g / np.maximum(gn, 1e-30)[:, None]
    fd = pair_kernel(kernel)(r, re)
    fd = np.where(r < 1.0, fd * (np.minimum(r, 1.0) - 0.75) / 0.25, fd)            # the core
    return p, d, r, gn, unit, fd


def _strip_moment(d, r, gn, unit, fd):
    """The tangential moment B_i = sum_j |g_j| r_t^2 f_d of every strip particle."""
    rt2 = np.where(np.isfinite(r), r, 0.0) ** 2 - (d * unit[:, None]).sum(axis=2) ** 2
    return (gn[None] * rt2 * fd).sum(axis=1)


@functools.lru_cache(maxsize=None)
def _flat_moment(beta: float, re: float, width: int, kernel: str) -> float:
    """B0 of ``flat_tension``: the tangential moment of the lattice strip's outer particle at
    the origin (s = 1)."""
    p, d, r, gn, unit, fd = _strip(1.0, beta, re, width, kernel)
    return float(_strip_moment(d, r, gn, unit, fd)[np.argmin(np.abs(p).sum(axis=1))])


def flat_tension(s: float, beta: float, re: float = 2.1, width: int = 60,
                 moment_power: float = 0.0, kernel: str = "quartic") -> float:
    """The tension a flat 2D lattice surface transmits when its outer layer's in-plane spacing
    is s l0 (the layers below on the lattice), by the member's C1-C3 (core included) with the
    pair kernel ``kernel``, over sigma: the x force of the pairs across a vertical cut, averaged
    over cut positions, in a strip 2 width l0 long and 8 layers deep (the top four counted, away
    from the bottom's own surface). ``moment_power`` p: each g scaled by c^p, c = B0/B the
    tangential moment's (``--tangential-moment``; B0 the outer particle's at s = 1). numpy
    only; l0 = 1."""
    Kd, a = pair_normalisers(2, kernel, re)
    p, d, r, gn, unit, fd = _strip(s, beta, re, width, kernel)
    if moment_power:
        B0 = _flat_moment(beta, re, width, kernel)
        B = _strip_moment(d, r, gn, unit, fd)
        c = np.where(B > 0, np.clip(B0 / np.maximum(B, 1e-30), 0.25, 4.0), 1.0)
        gn = gn * c ** moment_power
    top, mid = p[:, 1] > -3.5, np.abs(p[:, 0]) < width / 3
    forces = []
    for c in np.linspace(-3.0, 3.0, 240, endpoint=False) + 0.01234:
        L = np.flatnonzero(top & mid & (p[:, 0] < c))
        Rr = np.flatnonzero(top & (np.abs(p[:, 0]) < width / 2) & (p[:, 0] > c))
        rij = d[np.ix_(L, Rr)]
        Ti = gn[L][:, None, None] * (rij - unit[L][:, None] * (unit[L][:, None] * rij).sum(
            axis=-1, keepdims=True))
        Tj = gn[Rr][None, :, None] * (rij - unit[Rr][None] * (unit[Rr][None] * rij).sum(
            axis=-1, keepdims=True))
        forces.append(a * Kd * (((Ti + Tj)[..., 0]) * fd[np.ix_(L, Rr)]).sum())
    return float(np.mean(forces))


def stretch(spacings: str, beta: float, kernel: str) -> None:
    for s in spacings.split(","):
        t = [flat_tension(float(s), beta, moment_power=q, kernel=kernel) for q in (0.0, 1.0, 2.0)]
        print(f"outer layer at {float(s):.2f} l0: tension / sigma {t[0]:.3f}; with the moment"
              f" (g c) {t[1]:.3f}, (g c^2) {t[2]:.3f}", flush=True)


def relaxed_start(l0: float, periods: float) -> np.ndarray:
    """``--relaxed-start P``: the 3D case's disordered drop (its start, tension_cases.DISORDER)
    run at rest for P mode-2 periods with nu = 1e-4 (the resting drops' viscosity, which damps
    the start's melt), its particles about their centre: a liquid start without a melt."""
    from crowndemo.core import Numerics
    from crowndemo.scenes.drop import resting_drop
    from crowndemo.validate import tension_cases as tc
    from crowndemo.validate.cases import simulator
    t0 = time.time()
    rest = resting_drop(dim=3, radius=tc.R, l0=l0, nu=1.0e-4, t_end=periods * tc.mode2_period(3),
                        numerics=tc.stress_numerics(Numerics()), disorder=tc.DISORDER[3])
    sim = simulator(rest)
    sim.run(rest.t_end)
    snap = sim.snapshot()
    pos = snap["pos"].astype(float)
    keep = tc.drop_particles(pos, snap["kind"])
    v = snap["vel"][keep].astype(float)
    p = pos[keep] - pos[keep].mean(axis=0)
    print(f"relaxed start: {periods:g} periods at rest, {keep.sum()} of {len(keep)} particles "
          f"kept, rms speed {math.sqrt((v * v).sum(axis=1).mean()):.3g} m/s, r_max / R "
          f"{np.linalg.norm(p, axis=1).max() / tc.R:.4f}; {time.time() - t0:.0f} s", flush=True)
    return p


@contextlib.contextmanager
def relaxed_drop(l0: float, periods: float):
    """Within it the drop scenes start from relaxed_start's particles (scenes/drop.disordered
    replaced, put back after): yields the disorder to give the scene, 0 (no melt to fit past)."""
    from crowndemo.scenes import drop as drop_scene
    start = relaxed_start(l0, periods)
    disordered = drop_scene.disordered
    drop_scene.disordered = lambda pts, l0_, amount, seed=0: start
    try:
        yield 0.0
    finally:
        drop_scene.disordered = disordered


def case(name: str, scales: str, relaxed: float = 0.0) -> None:
    """One row per R/l0 of a stress-* case; ``relaxed`` > 0 (``--relaxed-start``, the 3D
    oscillating drop only): the drop starts from relaxed_start's particles, fitted from t = 0
    (no melt to skip)."""
    from crowndemo.core import Numerics
    from crowndemo.validate.tension_cases import tension_cases
    chosen = {c.name: c for c in tension_cases()}[name]
    for s in scales.split(","):
        t0 = time.time()
        l0 = 1.0e-3 / float(s)
        if relaxed > 0.0:
            with relaxed_drop(l0, relaxed) as disorder:     # the case fits from t = 0
                out = chosen.run(l0, chosen.base(Numerics()), disorder=disorder)
        else:
            out = chosen.run(l0, chosen.base(Numerics()))
        extra = ", ".join(f"{k} {v:.4g}" for k, v in out.extra.items())
        print(f"{name} R/l0 = {s}: {out.measured:.4g} against {out.reference:.4g}, error "
              f"{out.error:.2%}; {extra}; {time.time() - t0:.0f} s", flush=True)


def dn_gradient(dim: int, re_over_l0: float = 2.1):
    """``--gradient dn``: the pressure gradient's pair term (S11's r_ij w / r^2 in the sum
    form) replaced by the number density's own derivative, -w'(r) r_ij / r = (w + 1) r_ij /
    r^2 for w = re/r - 1, times n0 / (n0 + N0) (N0 the lattice's neighbours within re) so
    that a lattice still reads a linear field's gradient (d/n0 sum (w + 1) r r / r^2 =
    (n0 + N0)/n0 on it): with P_i + P_j the pair force of an EOS energy of the number
    densities, as a Hamiltonian MPS has it (Suzuki et al. 2007); a study, patched into
    core/pressure.py before its kernels compile."""
    from crowndemo.core.lattice import lattice_offsets, n0_lambda0
    n0 = n0_lambda0(dim, 1.0, re_over_l0)[0]
    scale = n0 / (n0 + len(lattice_offsets(dim, 1.0, re_over_l0)))

    global GRADIENT_PROFILE
    GRADIENT_PROFILE = scale          # term_powers' pressure force follows

    @ti.func
    def pair(dphi, rij, r2, w):
        return dphi / r2 * (w + 1.0) * scale * rij
    return pair


GRADIENT_PROFILE = None     # dn_gradient's scale when the study replaced S11's pair term


def term_powers(sim, snap, keep: np.ndarray, u: np.ndarray) -> dict:
    """Each force's power on the drop particles' motion u (about their mean), per particle
    [W]: m sum_i a_i . u_i over ``keep`` for the pressure gradient (the sum form, S11 with
    P_i + P_j, from the snapshot's P), the viscous term (S12, nu times the Laplacian of u)
    and the surface stress (the member's a_i of the last step); and each one's rms [m/s^2].
    With ``--gradient dn`` the pressure's pair term is dn_gradient's.
    numpy over every pair (a drop of a few thousand particles); the positions are the step's
    end, P and the stress of its r*, so the split is a diagnostic, not the step's bookkeeping."""
    from crowndemo.core.lattice import weight
    from crowndemo.core.state import FLUID
    lat, ph = sim.lattice, sim.physics
    dim, re, n0, rho = ph.dim, lat.re, lat.n0, ph.rho
    fluid = snap["kind"] == FLUID
    x, v, p = (snap[k][fluid].astype(float) for k in ("pos", "vel", "pressure"))
    rij = x[None, :, :] - x[:, None, :]                  # x_j - x_i
    r = np.linalg.norm(rij, axis=2)
    np.fill_diagonal(r, np.inf)
    w = weight(r, re)                                   # S10 (0 on the diagonal, r = inf)
    profile = w if GRADIENT_PROFILE is None else np.where(r < re, (w + 1.0) * GRADIENT_PROFILE,
                                                          0.0)       # dn_gradient's
    acc = {"pressure": -dim / (n0 * rho) * np.einsum(
               "ij,ijk->ik", (p[:, None] + p[None, :]) * profile / r ** 2, rij),
           "viscosity": ph.nu * 2 * dim / (lat.lambda0 * n0) * (
               np.einsum("ij,jk->ik", w, v) - w.sum(axis=1)[:, None] * v)}
    n = sim.state.count
    order = np.argsort(sim.state.pid.to_numpy()[:n], kind="stable")
    acc["surface stress"] = sim.surface_tension.accel.to_numpy()[:n][order][fluid].astype(float)
    inside = keep[fluid]
    out = {}
    for name, a in acc.items():
        a = a[inside]
        out[name] = (lat.mass * float((a * u).sum()) / len(u),
                     math.sqrt(float((a * a).sum(axis=1).mean())))
    total = sum(acc.values())[inside]
    out["sum"] = (lat.mass * float((total * u).sum()) / len(u),
                  math.sqrt(float((total * total).sum(axis=1).mean())))
    return out


def energy(scale: float, relaxed: float, every: int = 5, amplitude: float = 0.1) -> None:
    """``energy R/l0``: the 3D oscillating drop (the case's, nu = OSCILLATION_NU, 3 periods;
    with ``--relaxed-start P`` from relaxed_start's particles, else from the case's disordered
    start) and where its kinetic energy goes. Each frame (40 a period, every EVERY-th printed)
    the drop's velocities about its mean are fitted by a linear field v = G d and split into
    the mode's strain (G's symmetric traceless part: mode 2's flow is exactly this), the
    breathing (its trace) and the rotation (its antisymmetric part); the rest is the
    non-linear motion, of which the share a cubic polynomial field fits is smooth (higher
    modes) and the remainder the particles' own (noise): its rms speed on the free surface
    (n < beta n0) and by depth under it (the distance to the nearest free-surface particle),
    and its correlation between neighbours closer than 1.3 l0. Then the deformation's fit, as
    the case's. ``amplitude``: the mode's (``--amplitude``)."""
    from crowndemo.core import Numerics
    from crowndemo.scenes import drop as drop_scene
    from crowndemo.validate import oscillation
    from crowndemo.validate import tension_cases as tc
    from crowndemo.validate.cases import simulator
    l0 = tc.R / scale
    with (relaxed_drop(l0, relaxed) if relaxed > 0.0 else
          contextlib.nullcontext(tc.DISORDER[3])) as disorder:
        scene = drop_scene.oscillating_drop(dim=3, radius=tc.R, l0=l0, nu=tc.OSCILLATION_NU,
                                            periods=3.0, amplitude=amplitude,
                                            numerics=tc.stress_numerics(Numerics()),
                                            disorder=disorder)
    sim = simulator(scene)
    period = 2 * math.pi / scene.info["omega_rad_s"]
    x_pow = [(a,) for a in range(3)] + [(a, b) for a in range(3) for b in range(a, 3)] + [
        (a, b, c) for a in range(3) for b in range(a, 3) for c in range(b, 3)]
    rows = []

    def watch(s, index: int) -> None:
        snap = s.snapshot()
        pos = snap["pos"].astype(float)
        keep = tc.drop_particles(pos, snap["kind"])
        rows.append((s.stats.time, oscillation.deformation(pos[keep])))
        if index % every:
            return                  # the fit needs every frame's deformation, the split not
        d = pos[keep] - pos[keep].mean(axis=0)
        v = snap["vel"][keep].astype(float)
        v = v - v.mean(axis=0)
        G = np.linalg.lstsq(d, v, rcond=None)[0].T           # v ~ G d
        S = 0.5 * (G + G.T)
        tr = np.trace(S) / 3.0
        parts = [S - tr * np.eye(3), tr * np.eye(3), 0.5 * (G - G.T)]
        ke = 0.5 * (v * v).sum()
        shares = [0.5 * ((d @ M.T) ** 2).sum() / ke for M in parts]
        rest = v - d @ G.T
        x = d / tc.R
        mons = np.stack([np.ones(len(x))] + [np.prod(x[:, list(m)], axis=1) for m in x_pow],
                        axis=1)
        smooth = mons @ np.linalg.lstsq(mons, rest, rcond=None)[0]
        e_rest, e_smooth = 0.5 * (rest * rest).sum(), 0.5 * (smooth * smooth).sum()
        print(f"t/T {s.stats.time / period:5.2f}  KE / start's {ke / start_ke[0]:.3f}: mode "
              f"{shares[0]:.3f}, breathing {shares[1]:.3f}, rotation {shares[2]:.4f}, "
              f"non-linear {e_rest / ke:.3f} (smooth {e_smooth / max(e_rest, 1e-30):.2f} "
              f"of it; its rms speed {math.sqrt(2 * e_rest / len(d)):.3g} m/s)", flush=True)
        noise = rest - smooth
        surface = snap["number_density"][keep] < beta_n0
        if surface.any() and (~surface).any():     # each inner particle's depth under it
            gap = d[~surface][:, None, :] - d[surface][None, :, :]
            depth = np.zeros(len(d))
            depth[~surface] = np.sqrt((gap * gap).sum(axis=2)).min(axis=1) / l0
            bands = [("free surface (n < beta n0)", surface),
                     ("depth < 2 l0", ~surface & (depth < 2.0)),
                     ("2-3 l0", ~surface & (depth >= 2.0) & (depth < 3.0)),
                     (">= 3 l0", ~surface & (depth >= 3.0))]
            # the noise's correlation between neighbours (r < 1.3 l0): 1 smooth, 0 random,
            # < 0 neighbours moving against each other
            sep = d[:, None, :] - d[None, :, :]
            near = np.triu((sep * sep).sum(axis=2) < (1.3 * l0) ** 2, k=1)
            a, b = np.nonzero(near)
            corr = (noise[a] * noise[b]).sum() / math.sqrt(
                (noise[a] ** 2).sum() * (noise[b] ** 2).sum())
            print("          particle-scale rms speed: " + ", ".join(
                f"{name} ({m.sum()}) {math.sqrt((noise[m] ** 2).sum(axis=1).mean()):.3g}"
                for name, m in bands if m.any()) + f" m/s; its correlation between "
                f"neighbours {corr:.2f}", flush=True)
        powers = term_powers(s, snap, keep, v)
        print("          power on the particles' motion per particle (W), rms acceleration "
              "(m/s^2): " + ", ".join(f"{k} {pw:+.3g}, {ra:.3g}" for k, (pw, ra)
                                      in powers.items()), flush=True)

    beta_n0 = sim.numerics.free_surface_beta(3) * sim.lattice.n0
    v0 = sim.snapshot()["vel"].astype(float)
    start_ke = [0.5 * float(((v0 - v0.mean(axis=0)) ** 2).sum())]
    print(f"3D oscillating drop, R/l0 = {scale:g}, the mode's largest speed "
          f"{np.linalg.norm(v0, axis=1).max():.3g} m/s", flush=True)
    sim.run(scene.t_end, frame_times=np.linspace(0, scene.t_end, 121), on_frame=watch)
    t, s = np.array(rows).T
    after = t >= (0.0 if relaxed > 0.0 else period) - 1e-12
    omega, decay = oscillation.fit(t[after], s[after])
    print(f"the deformation's fit (from t = {t[after][0] / period:g} T): omega / Rayleigh "
          f"{omega / scene.info['omega_rad_s']:.4f}, decay {decay:.1f} 1/s (Lamb "
          f"{scene.info['decay_1_s']:.0f})", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("what", choices=("drop", "case", "stretch", "energy", "depth"))
    ap.add_argument("args", nargs="+")
    ap.add_argument("--base", choices=("first", "member"), default="first",
                    help="first: the first member (1 - (r/re)^4, P = 0 on the surface); "
                         "member: the member as it is (stress.py)")
    ap.add_argument("--surface", choices=("zero", "neighbours", "virial", "own", "own-spacing",
                                          "blend", "eos", "cumulative"),
                    default=None, help="the free surface's pressure (default: the base's)")
    ap.add_argument("--own-factor", type=float, default=1.0)
    ap.add_argument("--c4-factor", default=None,
                    help="--base member: C4's factor F (a number, or 'lattice': n0/(2 d G l0) "
                         "at the run's re, lattice.face_balance_factor); default the "
                         "neighbourhood's")
    ap.add_argument("--own-per-area", action="store_true")
    ap.add_argument("--theta-slope", type=float, default=None,
                    help="--surface eos: C in theta = 1 - C |g| l0 (default 0.72 2D, 0.62 3D)")
    ap.add_argument("--core", type=float, default=None)
    ap.add_argument("--isotropic-core", action="store_true")
    ap.add_argument("--tangential-moment", action="store_true")
    ap.add_argument("--virial-moment", action="store_true")
    ap.add_argument("--moment-clamp", type=float, default=4.0)
    ap.add_argument("--pair-kernel", choices=tuple(PAIR_KERNELS), default=None,
                    help="the divergence's pair weight (default: the base's)")
    ap.add_argument("--membrane", action="store_true")
    ap.add_argument("--surface-pairs", nargs="?", const="product", default=None,
                    choices=SURFACE_PAIRS, help="C3's pair terms times omega_i omega_j "
                    "(product) or their mean, a rescaled on the lattice")
    ap.add_argument("--pair-band", type=float, default=0.0, metavar="B",
                    help="--surface-pairs: the pairs' omega = clamp((1 - n/n0)/B, 0, 1) "
                         "(0: C1's own, B = 2 (1 - beta))")
    ap.add_argument("--tension-factor", type=float, default=None, metavar="F",
                    help="the member's tension (a) times F")
    ap.add_argument("--torque-free", choices=("yes", "no"), default=None,
                    help="with --numerics stress_pairs=surface: C3b's T_i through L_i or not "
                         "(default: the neighbourhood's; stress.StressTension.torque_free)")
    ap.add_argument("--membrane-ref", type=float, default=0.0)
    ap.add_argument("--tolman", type=float, default=None,
                    help="C5's delta (l0) for this run's dimension (default: the base's; "
                         "--base first: 0)")
    ap.add_argument("--tolman-steps", type=float, default=1000.0, metavar="N",
                    help="--tolman-form lagged: the lag in steps")
    ap.add_argument("--tolman-lag", type=float, default=None, metavar="K",
                    help="C5's lag in capillary times (the member's TOLMAN_LAG unless given; "
                         "0 for the probes of --tolman-form unless given)")
    ap.add_argument("--tolman-form", choices=("pair", "particle", "smoothed", "lagged"),
                    default="pair",
                    help="C5's s on each T in the pairs (the member's), on particle i's "
                         "whole pull (tolman_particle_member: no Marangoni term), or the "
                         "member's with s smoothed over the surface within re "
                         "(tolman_smoothed_member), or lagged by --tolman-steps "
                         "(tolman_lagged_member)")
    ap.add_argument("--tolman-pass", type=float, default=None, metavar="DELTA",
                    help="the study's C5: a third pass, s_i of this step (tolman_member); "
                         "C5 itself off")
    ap.add_argument("--tolman-fit", action="store_true",
                    help="--tolman-pass: H from the least-squares surface fit")
    ap.add_argument("--nu", type=float, default=None,
                    help="case stress-drop-oscillation-* and energy: the drop's kinematic "
                         "viscosity [m^2/s] (default: tension_cases.OSCILLATION_NU, 1e-5)")
    ap.add_argument("--re-ratio", type=float, default=None,
                    help="every drop's re / l0 (the cases' 2.1)")
    ap.add_argument("--pair-support", type=float, default=None, metavar="H",
                    help="C3's pair support in l0 (the neighbourhood's unless given: "
                    "params.STRESS_NEIGHBOURHOODS: 3, or 4.1 in 3D at 3.1 l0)")
    ap.add_argument("--sound-factor", type=float, default=None,
                    help="every drop's sound speed times this (scenes/drop.drop_sound_speed)")
    ap.add_argument("--relaxed-start", type=float, default=0.0, metavar="P",
                    help="case stress-drop-oscillation-3d and energy: start from the "
                         "disordered drop relaxed at rest for P periods (relaxed_start), "
                         "fitted from t = 0")
    ap.add_argument("--numerics", action="append", default=[], metavar="KEY=VALUE",
                    help="the drops' numerics with KEY (a params.Numerics field) set to VALUE "
                         "(read as YAML), e.g. collision=0 (tension_cases.stress_numerics); "
                         "repeatable")
    ap.add_argument("--gradient", choices=("mps", "dn"), default="mps",
                    help="the pressure gradient's pair term: S11's (mps) or the number "
                         "density's derivative (dn_gradient)")
    ap.add_argument("--pressure-filter", action="store_true",
                    help="the pressurised particles' pressure Shepard-filtered every step "
                         "(neighbours_pressure_member, filtered)")
    ap.add_argument("--continuity", action="store_true",
                    help="a probe: every fluid particle's pressure from a number density "
                         "carried by the continuity equation (continuity_pressure_member)")
    ap.add_argument("--amplitude", type=float, default=0.1,
                    help="energy: the mode's relative amplitude (the case's 0.1)")
    ap.add_argument("--disorder", type=float, default=0.0, metavar="X",
                    help="drop: the start's disorder (scenes/drop.resting_drop; the 3D cases' "
                         "0.15, validate/tension_cases.DISORDER)")
    ap.add_argument("--every", type=float, default=0.5, help="drop: print every EVERY ms")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--profile", action="store_true",
                    help="drop: P n/n0 over the inside pressure in shells l0/2 thick")
    a = ap.parse_args()
    if not (math.isfinite(a.pair_band) and 0.0 <= a.pair_band <= 1.0):
        raise SystemExit(f"--pair-band {a.pair_band}: allowed: 0 (C1's own band) to 1")
    if a.pair_band > 0.0 and not (a.surface_pairs or a.what == "depth"):
        raise SystemExit("--pair-band: with --surface-pairs (or depth) only")
    if a.what == "stretch":
        from crowndemo.core import Numerics
        stretch(a.args[0], Numerics().free_surface_beta(2), a.pair_kernel or "quartic")
        return
    if a.what == "depth":
        from crowndemo.core import Numerics
        depth(int(a.args[0]), a.args[1], Numerics().free_surface_beta(int(a.args[0])),
              a.pair_band)
        return
    backend.init("cpu", threads=a.threads)
    import crowndemo.core.surface_tension as family
    import crowndemo.core.surface_tension.stress as stress
    from crowndemo.core import Numerics
    if a.pair_support is not None:
        set_pair_support(a.pair_support)
    if a.core is not None:
        stress.CORE = a.core          # read when the member's kernels compile
    dim = (int(a.args[0]) if a.what == "drop" else 3 if a.what == "energy"
           else int(a.args[0].rsplit("-", 1)[1][0]))
    member = first_member(dim) if a.base == "first" else stress.StressTension
    if a.base == "member" and a.surface not in (None, "cumulative"):
        member = zero_surface_member(member)
    if a.surface == "cumulative" and a.base != "member":
        raise SystemExit("--surface cumulative: --base member only (it builds on C4)")
    kernel = a.pair_kernel or ("quartic" if a.base == "first" else "smooth3")
    if a.tangential_moment or a.virial_moment:
        if a.base != "first" or kernel not in ("quartic", "smooth"):
            raise SystemExit("the moments: --base first, --pair-kernel quartic or smooth only")
        member = tangential_moment_member(member, Numerics().free_surface_beta(dim), dim,
                                          virial=a.virial_moment, clamp=a.moment_clamp,
                                          kernel=kernel)
    if a.pair_kernel is not None:
        if a.membrane or a.isotropic_core:
            raise SystemExit("--pair-kernel: not with --membrane or --isotropic-core")
        member = kernel_member(member, dim, a.pair_kernel)
    if a.membrane:
        member = membrane_member(member, dim, a.membrane_ref, kernel)
    if a.isotropic_core:
        member = isotropic_core_member(member)
    if a.surface == "blend":
        member = blend_pressure_member(member)
    elif a.surface == "cumulative":
        member = cumulative_pressure_member(member)
    elif a.surface == "eos":
        slope = a.theta_slope if a.theta_slope is not None else (0.72 if dim == 2 else 0.62)
        member = eos_pressure_member(member, slope)
    elif a.surface in ("neighbours", "virial"):
        member = neighbours_pressure_member(member, scaled=a.surface == "virial")
    elif a.surface in ("own", "own-spacing"):
        if a.own_per_area and not a.tangential_moment:
            raise SystemExit("--own-per-area needs --tangential-moment")
        member = own_pressure_member(member, a.own_factor, a.own_per_area,
                                     spacing=a.surface == "own-spacing")
    if not (math.isfinite(a.amplitude) and a.amplitude > 0.0):
        raise SystemExit(f"--amplitude {a.amplitude}: allowed: > 0 (the start's kinetic energy "
                         "is the split's unit)")
    if a.pressure_filter:
        member = neighbours_pressure_member(member, filtered=True)
    if a.continuity:
        member = continuity_pressure_member(member)
    if a.gradient == "dn":
        from crowndemo.core import pressure
        pressure.gradient_pair = dn_gradient(dim)

    if a.re_ratio is not None:
        admit_neighbourhood(a.re_ratio)
    if a.tolman is not None or a.base == "first" or a.tolman_pass is not None:
        member = tolman_delta_member(member, 0.0 if a.tolman is None else a.tolman)
    member = tolman_form_member(member, a.tolman_form, a.tolman_steps, a.tolman_lag)
    if a.tolman_pass is not None:
        if a.tolman is not None:
            raise SystemExit("--tolman-pass: not with --tolman")
        member = (tolman_fit_member if a.tolman_fit else tolman_member)(member, a.tolman_pass)
    if a.c4_factor is not None:
        if a.base != "member" or a.surface is not None:
            raise SystemExit("--c4-factor: --base member without --surface")
        from crowndemo.core import Physics
        factor = c4_factor_value(a.c4_factor, dim, a.re_ratio or Physics.re_ratio)
        member = c4_factor_member(member, factor)
    if a.surface_pairs:
        if a.base != "member" or (a.re_ratio or 2.1) != 2.1:
            raise SystemExit("--surface-pairs: --base member at re = 2.1 l0 only")
        member = surface_pairs_member(member, dim, 2.1, Numerics().free_surface_beta(dim),
                                      a.surface_pairs, a.pair_band)
    if a.tension_factor is not None:
        member = tension_factor_member(member, a.tension_factor)
    if a.torque_free is not None:
        if "stress_pairs=surface" not in a.numerics:
            raise SystemExit("--torque-free: with --numerics stress_pairs=surface only")
        member = torque_free_member(member, a.torque_free == "yes")
    family.MODELS["stress"] = member
    if a.relaxed_start > 0.0 and a.what != "energy" and (
            a.what != "case" or a.args[0] != "stress-drop-oscillation-3d"):
        raise SystemExit("--relaxed-start: case stress-drop-oscillation-3d or energy only")
    if a.nu is not None:
        if a.what != "energy" and (a.what != "case" or "oscillation" not in a.args[0]):
            raise SystemExit("--nu: case stress-drop-oscillation-2d|3d or energy only")
        from crowndemo.validate import tension_cases
        tension_cases.OSCILLATION_NU = a.nu
    if a.sound_factor is not None:
        from crowndemo.scenes import drop as drop_scene
        sound_speed = drop_scene.drop_sound_speed
        drop_scene.drop_sound_speed = lambda *args: a.sound_factor * sound_speed(*args)
    if a.re_ratio is not None:
        from dataclasses import replace as _replace
        from crowndemo.scenes import drop as drop_scene
        assemble = drop_scene.assemble
        drop_scene.assemble = lambda name, physics, *rest: assemble(
            name, _replace(physics, re_ratio=a.re_ratio).validate("--re-ratio"), *rest)
    changes = {}
    if a.numerics:
        import yaml
        from crowndemo.core.params import with_values
        from crowndemo.validate import tension_cases
        changes = {k: yaml.safe_load(v) for k, v in (kv.split("=", 1) for kv in a.numerics)}
        base_numerics = tension_cases.stress_numerics
        tension_cases.stress_numerics = lambda n: with_values(base_numerics(n), **changes)
    if a.what == "drop":
        drop(int(a.args[0]), float(a.args[1]), float(a.args[2]), a.every, a.profile, changes,
             a.disorder)
    elif a.what == "energy":
        energy(float(a.args[0]), a.relaxed_start, amplitude=a.amplitude)
    else:
        case(a.args[0], a.args[1], a.relaxed_start)


if __name__ == "__main__":
    main()
