"""Health of the run, reduced on the device every step: non-finite values, maximum speed,
number-density excess, particles that left the domain (parked with a reason, counted), and
kinetic + gravitational energy. ``check`` turns a broken limit into an ``InstabilityError``."""

import math
from dataclasses import dataclass, field
from typing import Dict, List

import numpy as np
import taichi as ti

from .blocks import BLOCK, add, blocks_for, groups_for, larger, reduce_blocks
from .coefficients import Coefficients
from .state import FLUID, GONE, ParticleState

AXES = "xyz"
F_SPEED2, F_EXCESS, F_KINETIC, F_POTENTIAL = range(4)
I_NONFINITE = 0          # then one counter per exit reason


@ti.func
def finite(x) -> bool:
    """Exponent bits not all set: neither Inf nor NaN (by bits, immune to fast-math)."""
    ok = True
    if ti.static(ti.lang.impl.get_runtime().default_fp == ti.f64):
        ok = ((ti.bit_cast(x, ti.u64) >> 52) & 0x7FF) != 0x7FF
    else:
        ok = (ti.bit_cast(x, ti.u32) & 0x7F800000) != 0x7F800000
    return ok


@ti.func
def zero():
    return 0.0


@ti.func
def fluid_max(state: ti.template(), values: ti.template(), blocks: ti.template(),
              groups: ti.template(), out: ti.template()):
    """out[None] = the largest values[i] >= 0 over the fluid particles, by blocks
    (blocks.py): ``blocks`` holds blocks_for(capacity) entries, ``groups`` groups_for of that.
    Called at a kernel's top level."""
    n = state.n[None]
    for b in range(blocks_for(n)):
        top = 0.0
        for i in range(b * BLOCK, ti.min(n, (b + 1) * BLOCK)):
            if state.kind[i] == FLUID:
                top = ti.max(top, values[i])
        blocks[b] = top
    reduce_blocks(blocks, blocks_for(n), groups, out, larger, zero)


def exit_reasons(dim: int) -> List[str]:
    """Reason codes: 0 none, 1 + 2 axis + side for 'left through x-' etc."""
    return ["none"] + [f"left through {AXES[a]}{s}" for a in range(dim) for s in "-+"]


class InstabilityError(RuntimeError):
    """The run broke a health limit; names the step, the time, what broke and a remedy."""

    def __init__(self, step: int, time: float, what: str, binding: str, dt: float, remedy: str):
        self.step, self.time, self.what, self.binding, self.dt, self.remedy = \
            step, time, what, binding, dt, remedy
        self.particles = 0      # the simulator's particle count, set by Simulator.step
        super().__init__(
            f"unstable at step {step} (t = {time * 1e3:.4g} ms): {what}; the time step "
            f"dt = {dt:.3g} s was bound by the {binding} limit. Remedy: {remedy}")


@dataclass
class HealthReport:
    max_speed: float = 0.0
    max_density_excess: float = 0.0
    kinetic: float = 0.0
    potential: float = 0.0
    nonfinite: int = 0
    left: Dict[str, int] = field(default_factory=dict)   # cumulative, by reason

    @property
    def energy(self) -> float:
        return self.kinetic + self.potential

    @property
    def left_total(self) -> int:
        return sum(self.left.values())


@ti.data_oriented
class Health:
    def __init__(self, state: ParticleState, coef: Coefficients):
        self.state, self.coef, self.dim = state, coef, state.dim
        self.reasons = exit_reasons(self.dim)
        self.fstats = ti.field(float, 4)
        self.istats = ti.field(ti.i32, 1 + len(self.reasons))
        blocks = blocks_for(state.capacity)
        # per block: speed^2 and excess (largest), kinetic and potential energy (sums); and
        # the counts of non-finite particles and of particles parked per exit reason
        self.block_stats = ti.Vector.field(4, float, blocks)
        self.block_counts = ti.Vector.field(1 + 2 * self.dim, ti.i32, blocks)
        self.group_stats = ti.Vector.field(4, float, groups_for(blocks))
        self.group_counts = ti.Vector.field(1 + 2 * self.dim, ti.i32, groups_for(blocks))
        self.total_stats = ti.Vector.field(4, float, shape=())
        self.total_counts = ti.Vector.field(1 + 2 * self.dim, ti.i32, shape=())

    def reset(self) -> None:
        self.istats.fill(0)

    def counters(self) -> np.ndarray:
        """The cumulative counters (non-finite, then particles parked per exit reason)."""
        return self.istats.to_numpy()

    def set_counters(self, values: np.ndarray) -> None:
        """Put back what ``counters`` returned (a restarted run keeps counting from there)."""
        values = np.asarray(values, dtype=np.int32)
        if values.shape != tuple(self.istats.shape):
            raise ValueError(f"health counters: {values.shape} does not fit {self.istats.shape}")
        self.istats.from_numpy(values)

    @ti.kernel
    def _reduce(self):
        """Per block of particles, then over the blocks (blocks.py), with no atomic on a stat:
        on Taichi 1.7.4's Vulkan arch (lavapipe) an atomic add on the counters inside either
        loop spoiled that whole loop's results (max speed 0 while the drop fell at 8 m/s; one
        block's exit counts of three; tests/test_gpu_arch.py)."""
        for b in range(blocks_for(self.state.n[None])):
            speed2, excess, kinetic, potential = 0.0, 0.0, 0.0, 0.0
            counts = self._no_counts()     # non-finite, then parked per exit reason 1..2d
            m, n0 = self.coef.mass[None], self.coef.n0[None]
            g = self.coef.gravity[None]
            for i in range(b * BLOCK, ti.min(self.state.n[None], (b + 1) * BLOCK)):
                if self.state.kind[i] == FLUID:
                    x, u = self.state.pos[i], self.state.vel[i]
                    bad = not finite(self.state.pressure[i])
                    for k in ti.static(range(self.dim)):
                        if not (finite(x[k]) and finite(u[k])):
                            bad = True
                    if bad:
                        counts[I_NONFINITE] += 1
                    else:
                        reason = 0
                        for k in ti.static(range(self.dim)):
                            if x[k] < self.coef.domain_lo[None][k]:
                                reason = 1 + 2 * k
                            elif x[k] > self.coef.domain_hi[None][k]:
                                reason = 2 + 2 * k
                        if reason != 0:       # park it: out of the grid and the passes, counted
                            self.state.kind[i] = GONE
                            self.state.exit_reason[i] = reason
                            self.state.vel[i] = ti.Vector.zero(float, self.dim)
                            for k in ti.static(range(1, 1 + 2 * self.dim)):
                                if reason == k:
                                    counts[k] += 1
                        else:
                            u2 = u.dot(u)
                            speed2 = ti.max(speed2, u2)
                            excess = ti.max(excess, self.state.density[i] / n0 - 1.0)
                            kinetic += 0.5 * m * u2
                            potential -= m * g.dot(x)
            self.block_stats[b] = ti.Vector([speed2, excess, kinetic, potential])
            self.block_counts[b] = counts
        blocks = blocks_for(self.state.n[None])
        reduce_blocks(self.block_stats, blocks, self.group_stats, self.total_stats,
                      self._combine_stats, self._no_stats)
        reduce_blocks(self.block_counts, blocks, self.group_counts, self.total_counts,
                      add, self._no_counts)
        for _ in range(1):
            total, counts = self.total_stats[None], self.total_counts[None]
            for k in ti.static(range(4)):
                self.fstats[k] = total[k]
            for k in ti.static(range(2 * self.dim)):     # reason 1 + k, cumulative
                self.istats[2 + k] = self.istats[2 + k] + counts[1 + k]
            self.istats[I_NONFINITE] = counts[I_NONFINITE]

    @ti.func
    def _combine_stats(self, a, b):
        return ti.Vector([ti.max(a[F_SPEED2], b[F_SPEED2]), ti.max(a[F_EXCESS], b[F_EXCESS]),
                          a[F_KINETIC] + b[F_KINETIC], a[F_POTENTIAL] + b[F_POTENTIAL]])

    @ti.func
    def _no_stats(self):
        return ti.Vector([0.0, 0.0, 0.0, 0.0])

    @ti.func
    def _no_counts(self):
        return ti.Vector.zero(ti.i32, 1 + 2 * self.dim)

    def measure(self) -> HealthReport:
        self._reduce()
        f, n = self.fstats.to_numpy(), self.istats.to_numpy()
        return HealthReport(max_speed=math.sqrt(max(float(f[F_SPEED2]), 0.0)),
                            max_density_excess=float(f[F_EXCESS]), kinetic=float(f[F_KINETIC]),
                            potential=float(f[F_POTENTIAL]), nonfinite=int(n[I_NONFINITE]),
                            left={r: int(c) for r, c in zip(self.reasons[1:], n[2:]) if c})

    @staticmethod
    def check(report: HealthReport, *, step: int, time: float, dt: float, binding: str,
              sound_speed: float, max_mach: float, max_density_excess: float,
              n_fluid: int, max_out_fraction: float) -> None:
        """Raise InstabilityError for the first broken limit."""
        remedy = ("lower the Courant/acoustic safety numbers (courant, acoustic), raise the "
                  "sound speed, or refine l0; a user-fixed dt must respect the limits")
        what = None
        if report.nonfinite:
            what = f"{report.nonfinite} fluid particles have non-finite position, velocity or pressure"
        elif report.max_speed > speed_limit(sound_speed, max_mach):
            what = (f"maximum speed {report.max_speed:.4g} m/s exceeds max_mach * c = "
                    f"{speed_limit(sound_speed, max_mach):.4g} m/s (weak compressibility lost)")
        elif report.max_density_excess > max_density_excess:
            what = (f"number-density excess n/n0 - 1 = {report.max_density_excess:.3g} exceeds "
                    f"the limit {max_density_excess:g}")
        elif n_fluid and report.left_total > max_out_fraction * n_fluid:
            what = (f"{report.left_total} of {n_fluid} fluid particles left the domain "
                    f"({', '.join(f'{v} {k}' for k, v in report.left.items())}), over the "
                    f"allowed fraction {max_out_fraction:g}")
            remedy = "enlarge the domain, or check the scene's walls and initial speeds"
        if what:
            raise InstabilityError(step, time, what, binding, dt, remedy)


def speed_limit(sound_speed: float, max_mach: float) -> float:
    """The speed past which a run stops, weak compressibility lost (S8): max_mach * c."""
    return max_mach * sound_speed


def starts_too_fast(speed: float, sound_speed: float, max_mach: float) -> bool:
    """A scene that starts at ``speed`` would stop at its first step: a drop gains speed as
    it falls, so reaching the limit at the start is enough."""
    return speed >= speed_limit(sound_speed, max_mach)


def count_kinds(kind: np.ndarray) -> Dict[str, int]:
    from .state import KIND_NAMES
    return {name: int((kind == k).sum()) for k, name in KIND_NAMES.items()}
