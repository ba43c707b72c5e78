"""One explicit MPS step (method.md §3, S14-S21), assembled from the terms the scene uses, and
the simulator that owns the fields and runs steps to an end time."""
from __future__ import annotations

import copy
import math
import time as _time
from array import array
from collections import Counter
from dataclasses import dataclass, field
from typing import Callable, Dict, Optional, Sequence

import numpy as np

from . import surface_tension, timestep
from .coefficients import Coefficients
from .grid import CellGrid
from .health import Health, HealthReport, InstabilityError, count_kinds
from .lattice import LatticeConstants, wall_layers
from .neighbours import SLOTS
from .operators import Operators
from .params import Model, Numerics, ParameterError, Physics
from .plane_floor import PlaneFloor
from .pressure import Pressure
from .state import FLUID, ParticleState
from .symmetry import Symmetry, image_room, mirror_whole
from .terms import CLOSE_SLOTS, Predictor


# codes of RunStats.bound_log; the order of older checkpoints' codes kept
BINDINGS = timestep.LIMIT_NAMES[:5] + ("fixed", "frame") + timestep.LIMIT_NAMES[5:]
# the stages of a step, as timed by Simulator.time_stages (crowndemo bench)
STAGES = ("grid", "predictor", "collision", "density", "corrector", "health")


@dataclass
class RunStats:
    steps: int = 0
    time: float = 0.0
    dt_min: float = math.inf
    dt_max: float = 0.0
    binding: Counter = field(default_factory=Counter)   # limit name -> steps it bound
    dt_log: array = field(default_factory=lambda: array("d"))     # dt of every step
    bound_log: array = field(default_factory=lambda: array("B"))  # its binding limit (index)
    wall_seconds: float = 0.0
    first_step_seconds: float = 0.0   # the first step of a simulator compiles its kernels
    energy_start: Optional[float] = None
    health: HealthReport = field(default_factory=HealthReport)
    peak_max_speed: float = 0.0            # the largest of every step's health figures
    peak_max_density_excess: float = 0.0

    def note(self, report: HealthReport) -> None:
        """Take one step's health report (the last one, and into the peaks)."""
        self.health = report
        self.peak_max_speed = max(self.peak_max_speed, report.max_speed)
        self.peak_max_density_excess = max(self.peak_max_density_excess,
                                           report.max_density_excess)

    def as_dict(self) -> dict:
        h = self.health
        regular = self.dt_max > 0      # a step not cut short to land on a frame
        return {"steps": self.steps, "time_s": self.time,
                "dt_min_s": self.dt_min if regular else None,
                "dt_max_s": self.dt_max if regular else None, "binding_limits": dict(self.binding),
                "wall_seconds": self.wall_seconds,
                "health": {"max_speed_m_s": h.max_speed,
                           "max_density_excess": h.max_density_excess,
                           "peak_max_speed_m_s": self.peak_max_speed,
                           "peak_max_density_excess": self.peak_max_density_excess,
                           "energy_J": h.energy, "energy_start_J": self.energy_start,
                           "left_domain": dict(h.left), "nonfinite": h.nonfinite}}


CAPACITY_STEP = 2.0 ** 0.25     # capacities are 1024 x 2^(k/4): at most 19 % unused


def capacity_bucket(particles: int) -> int:
    """The capacity allocated for ``particles``: the next of 1024, 1024 x 2^(1/4), ... Field
    shapes are part of Taichi's offline-cache key, so scenes whose sizes fall in one bucket
    load each other's compiled kernels (a first step of ~5 s instead of ~36 s, BENCHMARKS.md)."""
    c = 1024
    while c < particles:
        c = int(math.ceil(c * CAPACITY_STEP))
    return c


CELLS_PER_PARTICLE = 96        # allocated (at most FIELD_ENTRIES_MAX entries in all)
CELLS_PER_PARTICLE_MIN = 16    # held at every capacity up to max_particles


def default_max_cells(particles: int) -> int:
    """The cell grid's size limit for a number of particles (the cell side grows past it).
    A film on a wide floor fills a flat box thinly: the booth 3m-drop (643k particles) needs
    3.1 M cells of side re/2 before the splash rises. Under a limit of 2 per particle its cells
    grew to 0.69 re, the walks visited 2.6 times the candidates and the step took 1.6 times
    as long. After the splash the box grows tall and stays sparse: the seed rung's spray
    reaches 62 mm above a 1 mm film by 4 ms, 114 M cells of side re/2 for 1.23 M particles.
    Under 16 per particle the side grew to 1.9 l0 and the step took 1.7 times as long as with
    96 (BENCHMARKS.md). A cell costs 8 bytes; only the cells in use are scanned (2 x 3 passes
    a step), so a compact scene pays nothing for the room."""
    return max(min(CELLS_PER_PARTICLE * particles, FIELD_ENTRIES_MAX - 1), 4096)


# Taichi 1.7.4 indexes a field's entries with 32-bit integers: a field of 2^31 entries or more
# crashed it (a segmentation fault at the first kernel, 2026-11-23), so none may have more
FIELD_ENTRIES_MAX = 2 ** 31 - 1


def capacity_for(scene) -> int:
    """The particles a simulator must hold for ``scene``: its particles, and room for their
    mirror images when it has symmetry planes (symmetry.image_room), within the widest walk's
    reach (re, or the surface stress's pair support: Model.wide_walk)."""
    planes = scene.numerics.mirror_planes
    reach = scene.physics.re * Model.of(scene.physics, scene.numerics).wide_walk
    return len(scene.pos) + image_room(scene.pos, planes, reach)


def entries_per_particle(model: Model) -> int:
    """The most entries per particle of capacity held by one field of a simulator for
    ``model``, the cell grid's fields apart (capped at FIELD_ENTRIES_MAX, default_max_cells):
    the cells it holds at least (CELLS_PER_PARTICLE_MIN), the neighbour list's slots, the
    close-pair list's slots."""
    m = CELLS_PER_PARTICLE_MIN
    if model.neighbour_list:
        m = max(m, SLOTS[model.dim])
    if model.collision:
        m = max(m, CLOSE_SLOTS)
    return m


def max_particles(model: Model) -> int:
    """The most particles one simulator for ``model`` holds: every field below
    FIELD_ENTRIES_MAX entries (38.3 M in 3D with the neighbour list, whose 56 slots bind)."""
    return (FIELD_ENTRIES_MAX - 1) // entries_per_particle(model)


def _put(field, start: int, values: np.ndarray) -> None:
    """field[start : start + len(values)] = values (a Taichi field, the rest kept)."""
    full = field.to_numpy()
    full[start:start + len(values)] = values
    field.from_numpy(full)


class Simulator:
    """Holds one compiled step. ``configure`` changes run-time values without recompiling;
    the compiled terms (``Model``) are fixed at construction. Room for at least ``capacity``
    particles (``capacity_bucket`` of it)."""

    def __init__(self, physics: Physics, numerics: Numerics, capacity: int,
                 max_cells: Optional[int] = None):
        physics.validate()
        numerics.validate()
        self.model = Model.of(physics, numerics)
        dim = physics.dim
        limit = max_particles(self.model)
        if capacity > limit:
            raise ParameterError(
                "particles", capacity,
                f"at most {limit:,} for this model in {dim}D (Taichi indexes a field with "
                f"32-bit integers and the largest field holds "
                f"{entries_per_particle(self.model)} entries per particle); a coarser l0",
                source="simulator")
        if max_cells is not None and not 1 <= max_cells < FIELD_ENTRIES_MAX:
            raise ParameterError("max_cells", max_cells, f"1 to {FIELD_ENTRIES_MAX - 1:,}",
                                 source="simulator")
        capacity = min(capacity_bucket(capacity), limit)
        self.state = ParticleState(dim, capacity)
        self._auto_cells = max_cells is None    # then the cell limit follows the particles
        self.grid = CellGrid(self.state, max_cells or default_max_cells(capacity),
                             self.model.cells_per_re, self.model.wide_walk)
        self.coef = Coefficients(dim)
        self.operators = Operators(self.grid, self.coef)
        self.floor = PlaneFloor() if self.model.plane_floor else None   # else not allocated
        # mirror images across the symmetry planes (symmetry.py); None for a whole scene
        self.symmetry = (Symmetry(self.state, self.model.mirror_planes)
                         if self.model.mirror_planes else None)
        # the surface-tension member chosen by name (core/surface_tension/); None at sigma = 0
        self.surface_tension = surface_tension.create(self.model, self.grid, self.coef,
                                                      self.floor, self.symmetry)
        self.pressure = Pressure(self.model, self.grid, self.coef, self.floor,
                                 self.surface_tension)
        self.predictor = Predictor(self.model, self.grid, self.coef, self.floor,
                                   self.pressure.neighbours, self.surface_tension)
        # the density pass's lists hold the pairs at the positions the corrector moved from
        # (terms.py, the predictor's pairs from the list): False until a step has listed them
        self._lists_ready = False
        self.health = Health(self.state, self.coef)
        self.domain = (tuple([-math.inf] * dim), tuple([math.inf] * dim))
        self.on_floor = False       # a floor at z = 0 (configure's ``floor``)
        self.stats = RunStats()
        self.n_fluid = 0
        self.stage_seconds: Optional[Dict[str, float]] = None   # see time_stages
        self._stage_t = 0.0
        self.configure(physics, numerics)      # sets physics, numerics and lattice

    # ---- set-up --------------------------------------------------------------------------
    def configure(self, physics: Physics, numerics: Numerics,
                  domain: Optional[tuple] = None, floor: Optional[bool] = None) -> None:
        """New run-time values; the compiled model must stay the same. ``domain`` and
        ``floor`` (a floor at z = 0, scenes/base.py Scene.floor) stay as set before unless
        given."""
        physics.validate()
        numerics.validate()
        model = Model.of(physics, numerics)
        if model != self.model:
            raise ValueError(f"compiled model {self.model} cannot run {model}; "
                             "make a new Simulator")
        timestep.check_fixed_dt(physics, numerics, model)
        self.physics, self.numerics = physics, numerics
        self.lattice = LatticeConstants.compute(physics.dim, physics.l0, physics.re_ratio,
                                                physics.rho, physics.sigma)
        if domain is not None:
            self.domain = (tuple(domain[0]), tuple(domain[1]))
        if floor is not None:
            self.on_floor = bool(floor)
        big = 1e30
        lo = [max(v, -big) for v in self.domain[0]]
        hi = [min(v, big) for v in self.domain[1]]
        self.coef.set(physics, numerics, self.lattice, lo, hi, self.on_floor)
        if self.floor is not None:
            self.floor.set(physics.dim, physics.l0, self.lattice.re, wall_layers(physics.re_ratio),
                           reach=self.lattice.re * self.model.wide_walk)
        if self.symmetry is not None:
            self.symmetry.configure(self.lattice.re * self.model.wide_walk)
        self._lists_ready = False

    def load(self, pos: np.ndarray, vel: np.ndarray, kind: np.ndarray) -> None:
        self.state.load(pos, vel, kind)
        self._lists_ready = False
        if self._auto_cells:    # as for a simulator sized to these particles (same results)
            self.grid.set_cell_limit(default_max_cells(len(pos)))
        self.n_fluid = int((np.asarray(kind) == FLUID).sum())
        self.health.reset()
        self.stats = RunStats()
        self._last = self._measure()
        self.stats.energy_start = self._last.energy

    def save_state(self) -> dict:
        """What a restarted run needs to take exactly the same path: the persistent particle
        fields in storage order (the re-sort depends on it), the health counters, the run
        statistics (``steps`` drives the re-sort schedule) and the last health report (its
        max speed sets the next dt); and where the next predictor takes the density pass's
        lists (terms.py), those lists and the mirror images they name. The values of
        ``configure`` are not included."""
        saved = {"particles": self.state.dump(), "health_counters": self.health.counters(),
                 "stats": copy.deepcopy(self.stats), "n_fluid": self.n_fluid}
        if self._lists_ready:
            n = self.state.count
            lists = self.pressure.neighbours
            saved["lists"] = {"count": lists.count.to_numpy()[:n],
                              "index": lists.index.to_numpy()[:n]}
            if self.symmetry is not None:
                m = int(self.state.n_images[None])
                saved["lists"].update(source=self.symmetry.source.to_numpy()[n:n + m],
                                      mask=self.symmetry.mask.to_numpy()[n:n + m])
        return saved

    def restore_state(self, saved: dict) -> None:
        """Continue from ``save_state``'s result; call ``configure`` with the same values first."""
        self.state.restore(saved["particles"])
        self._lists_ready = False       # without saved lists (of its slots) the first step walks
        lists = saved.get("lists")
        if (lists is not None and self.predictor.takes_list
                and lists["index"].shape[1:] == (self.pressure.neighbours.slots,)):
            n = self.state.count
            _put(self.pressure.neighbours.count, 0, lists["count"])
            _put(self.pressure.neighbours.index, 0, lists["index"])
            if self.symmetry is not None:
                _put(self.symmetry.source, n, lists["source"])
                _put(self.symmetry.mask, n, lists["mask"])
                self.state.n_images[None] = len(lists["source"])
                self.symmetry.sync_motion()      # the images' fields from their sources
            self._lists_ready = True
        self.health.set_counters(saved["health_counters"])
        self.stats = copy.deepcopy(saved["stats"])
        self._last = self.stats.health
        self.n_fluid = int(saved["n_fluid"])

    # ---- the step ------------------------------------------------------------------------
    def time_stages(self, on: bool = True) -> None:
        """Time each stage of the step (STAGES) into ``stage_seconds``, from zero. It waits for
        the device after every stage, so it slows the step a little: for benchmarks only."""
        self.stage_seconds = dict.fromkeys(STAGES, 0.0) if on else None

    def _stage(self, name: Optional[str]) -> None:
        """End the stage ``name`` (None: start timing the step)."""
        if self.stage_seconds is not None:
            import taichi as ti
            ti.sync()
            now = _time.perf_counter()
            if name is not None:
                self.stage_seconds[name] += now - self._stage_t
            self._stage_t = now

    def _build(self, reorder: bool) -> None:
        """The cell grid at the current positions (with ``reorder``, the particles permuted into
        cell order first); with symmetry planes, the mirror images made and gridded too."""
        re = self.lattice.re
        sym = self.symmetry
        if sym is None:
            self.grid.build(re, reorder=reorder)
            return
        sym.clear()                    # the permutation moves particles only, never images
        if reorder:
            self.grid.build(re, reorder=True)
        wanted = sym.make_images()
        if wanted > sym.room:
            s = self.stats
            raise InstabilityError(
                s.steps, s.time, f"{wanted:,} mirror images are needed near the symmetry "
                f"planes, room for {sym.room:,}", BINDINGS[s.bound_log[-1]] if s.bound_log
                else "none", s.dt_log[-1] if s.dt_log else 0.0,
                "run the whole scene (scene.symmetry: full), or load it into a simulator of "
                "more capacity (symmetry.image_room)")
        self.grid.build(re, reorder=False)

    def step(self, dt_cap: float = math.inf) -> float:
        """Advance one step; returns dt. Raises InstabilityError on a broken health limit."""
        t_first = _time.perf_counter() if self.stats.steps == 0 else None
        k = self.stats.steps
        reorder = self.numerics.reorder_every > 0 and k % self.numerics.reorder_every == 0
        sym = self.symmetry
        self._stage(None)
        from_list = self._lists_ready and self.predictor.takes_list
        built = False
        if self.predictor.needs_neighbours:
            if from_list:                               # the last lists' pairs (terms.py)
                if sym is not None:
                    sym.sync_motion()                   # the images follow the corrector
            else:
                self._build(reorder)                    # neighbours at r^k
                built = True
            self._stage("grid")
        self.predictor.forces(from_list)                # S14 at r^k
        relative = None                                 # the relative Courant limit's speed
        if self.predictor.measures_relative_speed:
            relative = self.predictor.relative_speed()  # at r^k, u^k: the walk just read it
        dt, binding = timestep.choose(self.physics, self.numerics, self.model,
                                      self._last.max_speed, relative)
        if dt_cap < dt:
            dt, binding = dt_cap, "frame"
        self.predictor.run(dt, mark=self._stage,        # S15-S16
                           sync=sym.sync_velocity if sym is not None else None,
                           from_list=from_list)
        if sym is not None:
            sym.reflect()                               # nothing crosses a plane
        self._build(reorder and not built)              # at r*
        self._stage("grid")
        self.pressure.density_and_pressure(dt)          # S17 (M3)
        if self.predictor.takes_list:                   # the next predictor's pairs
            self._lists_ready = self.pressure.neighbours.complete()
        if sym is not None:
            sym.sync_pressure()                         # images' P_j for the corrector
        self._stage("density")
        self.pressure.correct(dt)                       # S18-S20
        if sym is not None:
            sym.reflect()
        self._stage("corrector")
        s = self.stats
        s.steps += 1
        s.time += dt
        if binding != "frame":      # a step cut short to land on a frame is not a limit
            s.dt_min, s.dt_max = min(s.dt_min, dt), max(s.dt_max, dt)
        s.binding[binding] += 1
        s.dt_log.append(dt)
        s.bound_log.append(BINDINGS.index(binding))
        self._last = self._measure()
        if t_first is not None:
            s.first_step_seconds = _time.perf_counter() - t_first
        self._stage("health")
        try:
            Health.check(self._last, step=s.steps, time=s.time, dt=dt, binding=binding,
                         sound_speed=self.physics.c, max_mach=self.numerics.max_mach,
                         max_density_excess=self.numerics.max_density_excess,
                         n_fluid=self.n_fluid, max_out_fraction=self.numerics.max_out_fraction)
        except InstabilityError as e:
            e.particles = self.state.count        # for reports of runs built out of sight
            raise
        return dt

    def _measure(self) -> HealthReport:
        report = self.health.measure()
        self.stats.note(report)
        return report

    def run(self, t_end: float, frame_times: Sequence[float] = (),
            on_frame: Optional[Callable[["Simulator", int], None]] = None,
            on_step: Optional[Callable[["Simulator"], None]] = None) -> RunStats:
        """Step until t_end, landing exactly on each of ``frame_times`` and calling
        ``on_frame(sim, index)`` there (frames at or before the current time fire at once)."""
        start = _time.perf_counter()
        frames = sorted(frame_times)
        fi = 0
        eps = 1e-12
        try:
            while True:
                while fi < len(frames) and frames[fi] <= self.stats.time + eps:
                    if on_frame:
                        # the wall time so far, for what on_frame saves (a checkpoint)
                        now = _time.perf_counter()
                        self.stats.wall_seconds += now - start
                        start = now
                        on_frame(self, fi)
                    fi += 1
                if self.stats.time >= t_end - eps:
                    break
                target = min(t_end, frames[fi]) if fi < len(frames) else t_end
                self.step(dt_cap=target - self.stats.time)
                if on_step:
                    on_step(self)
        finally:
            self.stats.wall_seconds += _time.perf_counter() - start
        return self.stats

    # ---- output --------------------------------------------------------------------------
    def refresh_pressure(self) -> None:
        """P^{k+1} from n^{k+1} at the current positions (S21), for output only."""
        self._build(reorder=False)
        self.pressure.density_and_pressure()
        # the next step walks: its result must not depend on whether the output looked (a
        # resumed run starts with a walk after the frame its checkpoint was saved at)
        self._lists_ready = False

    def snapshot(self) -> Dict[str, np.ndarray]:
        """The simulated particles (of a half or quarter with symmetry planes)."""
        return self.state.snapshot()

    def whole_snapshot(self) -> Dict[str, np.ndarray]:
        """``snapshot`` of the whole scene: a half or quarter mirrored across its planes
        (symmetry.mirror_whole); the same as ``snapshot`` without planes."""
        return mirror_whole(self.snapshot(), self.model.mirror_planes)

    def counts(self) -> Dict[str, int]:
        return count_kinds(self.state.kind.to_numpy()[: self.state.count])

    def memory_bytes(self) -> int:
        return (self.state.nbytes_per_particle() * self.state.capacity + self.grid.nbytes()
                + self.predictor.nbytes() + self.pressure.nbytes()
                + (self.surface_tension.nbytes() if self.surface_tension else 0)
                + (self.floor.nbytes() if self.floor else 0)
                + (self.symmetry.nbytes() if self.symmetry else 0))
