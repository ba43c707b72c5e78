"""Per-particle fields in one registry, so that a re-sort permutes every one of them at once."""

from typing import Dict

import numpy as np
import taichi as ti

FLUID, WALL, DUMMY, GONE = 0, 1, 2, 3
KIND_NAMES = {FLUID: "fluid", WALL: "wall", DUMMY: "dummy", GONE: "gone"}

# Taichi's CPU backend cuts a parallel ``for k in range(n)`` into one contiguous piece per
# thread (its pass make_cpu_multithreaded_range_for), not into blocks taken on demand. Particles
# in cell order put the floor's wall and dummy layers in the first half and the fluid in the
# second, so one thread did nearly all of a fluid pass (1.16 cores busy of 2, BENCHMARKS.md).
# ``spread`` deals chunks of SPREAD_CHUNK particles to the threads in turn instead.
SPREAD_CHUNK = 256


def _cpu_threads() -> int:
    """Threads a CPU range-for is cut into; 1 on a GPU arch (blocks are scheduled there)."""
    cfg = ti.lang.impl.current_cfg()
    return max(int(cfg.cpu_max_num_threads), 1) if cfg.arch in (ti.x64, ti.arm64) else 1


def field_nbytes(f: ti.Field) -> int:
    """Bytes held by a Taichi field."""
    elem = 8 if f.dtype in (ti.f64, ti.i64) else 4
    comps = f.n * (f.m if hasattr(f, "m") else 1) if isinstance(f, ti.MatrixField) else 1
    return int(np.prod(f.shape)) * comps * elem


@ti.data_oriented
class ParticleState:
    """Fixed capacity, an active count, structure-of-arrays fields.

    Persistent fields (position, velocity, pressure, number density, kind, id, exit reason) are
    registered and permuted together by ``permute``; scratch fields are recomputed every step.
    """

    def __init__(self, dim: int, capacity: int):
        self.dim, self.capacity = dim, int(capacity)
        self.n = ti.field(ti.i32, shape=())           # active particles
        # mirror images of particles near symmetry planes, in slots [n, n + n_images): in the
        # grid and its walks only (core/symmetry.py); 0 without planes
        self.n_images = ti.field(ti.i32, shape=())
        self.threads = _cpu_threads()
        self.chunks_per_thread = ti.field(ti.i32, shape=())    # see spread
        self._persistent: Dict[str, ti.Field] = {}
        self._carried: Dict[str, ti.Field] = {}       # members' fields: see ``carry``
        self._initial: Dict[str, float] = {}
        self.pos = self._register("pos", ti.Vector.field(dim, float, self.capacity))
        self.vel = self._register("vel", ti.Vector.field(dim, float, self.capacity))
        self.pressure = self._register("pressure", ti.field(float, self.capacity))
        self.density = self._register("number_density", ti.field(float, self.capacity))
        self.kind = self._register("kind", ti.field(ti.i32, self.capacity))
        self.pid = self._register("id", ti.field(ti.i32, self.capacity))
        self.exit_reason = self._register("exit_reason", ti.field(ti.i32, self.capacity))
        # scratch: one per element type, shared by the permutation and the step's passes
        self.scratch_vec = ti.Vector.field(dim, float, self.capacity)
        self.scratch_float = ti.field(float, self.capacity)
        self.scratch_int = ti.field(ti.i32, self.capacity)

    def _register(self, name: str, f):
        self._persistent[name] = f
        return f

    def carry(self, name: str, f: ti.Field, initial: float = 0.0) -> ti.Field:
        """A model member's per-particle field that lasts from one step to the next (the
        surface stress's lagged curvature factor): set to ``initial`` now and by ``load``,
        permuted with the persistent fields and saved by ``dump``, not in snapshots; a
        checkpoint without it (an older one) leaves it as it is."""
        self._carried[name] = f
        self._initial[name] = initial
        f.fill(initial)
        return f

    @property
    def count(self) -> int:
        return int(self.n[None])

    def nbytes_per_particle(self) -> int:
        fields = list(self._persistent.values()) + [self.scratch_vec, self.scratch_float,
                                                    self.scratch_int]
        return sum(field_nbytes(f) for f in fields) // self.capacity

    # ---- bulk load / read back ---------------------------------------------------------
    def load(self, pos: np.ndarray, vel: np.ndarray, kind: np.ndarray) -> None:
        n = len(pos)
        if n > self.capacity:
            raise ValueError(f"{n} particles exceed the capacity {self.capacity}")
        pad = lambda a, shape, dt: np.concatenate(
            [np.asarray(a, dtype=dt).reshape((n,) + shape),
             np.zeros((self.capacity - n,) + shape, dtype=dt)])
        fdt = np.float64 if ti.lang.impl.current_cfg().default_fp == ti.f64 else np.float32
        self.pos.from_numpy(pad(pos, (self.dim,), fdt))
        self.vel.from_numpy(pad(vel, (self.dim,), fdt))
        kinds = pad(kind, (), np.int32)
        kinds[n:] = GONE
        self.kind.from_numpy(kinds)
        self.pid.from_numpy(np.arange(self.capacity, dtype=np.int32))
        zero_f = np.zeros(self.capacity, dtype=fdt)
        self.pressure.from_numpy(zero_f)
        self.density.from_numpy(zero_f)
        self.exit_reason.from_numpy(np.zeros(self.capacity, dtype=np.int32))
        for name, f in self._carried.items():
            f.fill(self._initial[name])
        self._set_count(n)

    def _set_count(self, n: int) -> None:
        self.n[None] = n
        self.n_images[None] = 0
        self.chunks_per_thread[None] = n // (SPREAD_CHUNK * self.threads)

    @ti.func
    def in_grid(self):
        """Slots the cell grid holds: the particles and their mirror images."""
        return self.n[None] + self.n_images[None]

    @ti.func
    def spread(self, k):
        """The particle that index k of a parallel ``for k in range(n)`` handles: a one-to-one
        map of [0, n) that gives thread t the chunks t, t + T, t + 2T, ... (T threads) of the
        whole range, so every thread gets its share of each region. Per-particle results do
        not depend on it; it only balances the threads (identity on one thread or a GPU)."""
        i = k
        if ti.static(self.threads > 1):
            m = self.chunks_per_thread[None]
            q = k // SPREAD_CHUNK
            if q < m * self.threads:      # the tail past the last full round keeps its place
                i = ((q % m) * self.threads + q // m) * SPREAD_CHUNK + k % SPREAD_CHUNK
        return i

    def snapshot(self) -> Dict[str, np.ndarray]:
        """Every persistent field as numpy, in particle-id order (independent of any re-sort)."""
        n = self.count
        pid = self.pid.to_numpy()[:n]
        order = np.argsort(pid, kind="stable")
        return {name: f.to_numpy()[:n][order] for name, f in self._persistent.items()}

    # ---- a restartable copy (checkpoints) ----------------------------------------------
    def dump(self) -> Dict[str, np.ndarray]:
        """Every persistent field in storage order, the first n entries: with ``restore`` a
        run continues exactly as if it had not stopped."""
        n = self.count
        return {name: f.to_numpy()[:n] for name, f in {**self._persistent,
                                                       **self._carried}.items()}

    def restore(self, arrays: Dict[str, np.ndarray]) -> None:
        """Put back what ``dump`` returned; the slots beyond n become GONE."""
        missing = sorted(set(self._persistent) - set(arrays))
        if missing:
            raise ValueError(f"particle state lacks {', '.join(missing)}")
        n = len(arrays["kind"])
        if n > self.capacity:
            raise ValueError(f"{n} particles exceed the capacity {self.capacity}")
        for name, f in {**self._persistent, **self._carried}.items():
            if name not in arrays:         # a carried field an older checkpoint lacks
                continue
            full, a = f.to_numpy(), np.asarray(arrays[name])
            if a.shape != (n,) + full.shape[1:] or a.dtype != full.dtype:
                raise ValueError(f"particle field {name}: {a.dtype}{list(a.shape)} does not fit "
                                 f"{full.dtype}{[n] + list(full.shape[1:])} (another precision "
                                 "or dimension?)")
            full[:n] = a
            if name == "kind":
                full[n:] = GONE
            f.from_numpy(full)
        self._set_count(n)

    # ---- the one permutation of every persistent field -----------------------------------
    def permute(self, order: ti.Field) -> None:
        """Field[k] <- Field[order[k]] for k < n, for every persistent field."""
        for f in list(self._persistent.values()) + list(self._carried.values()):
            scratch = (self.scratch_vec if isinstance(f, ti.MatrixField)
                       else self.scratch_int if f.dtype == ti.i32 else self.scratch_float)
            self._gather(f, scratch, order)

    @ti.kernel
    def _gather(self, f: ti.template(), scratch: ti.template(), order: ti.template()):
        for k in range(self.n[None]):
            scratch[k] = f[order[k]]
        for k in range(self.n[None]):
            f[k] = scratch[k]
