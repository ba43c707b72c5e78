"""The block reductions and prefix sums (core/blocks.py) against numpy, on the CPU and on each
GPU arch that Taichi finds. Applied here straight to an array, the helpers cut it into groups
of BLOCK entries: the sizes fill none, one and several groups, the last one part full, so the
parallel stage and the serial stage above it both count."""
import numpy as np
import pytest
import taichi as ti

from crowndemo import backend
from crowndemo.backend import BackendError
from crowndemo.core.blocks import (BLOCK, add, blocks_for, exclusive_scan, groups_for, larger,
                                   reduce_blocks, smaller)

LARGEST = 3 * BLOCK + 5                  # four groups, the last one part full
SIZES = [0, 1, BLOCK - 1, BLOCK, BLOCK + 1, 3 * BLOCK, LARGEST]


@ti.func
def _zero():
    return 0


@ti.func
def _far_up():
    return ti.Vector([3.0e38, 3.0e38])


@ti.data_oriented
class _Bench:
    def __init__(self):
        self.ints = ti.field(ti.i32, LARGEST)
        self.vecs = ti.Vector.field(2, ti.f32, LARGEST)
        self.int_groups = ti.field(ti.i32, groups_for(LARGEST))
        self.vec_groups = ti.Vector.field(2, ti.f32, groups_for(LARGEST))
        self.int_out = ti.field(ti.i32, shape=())
        self.vec_out = ti.Vector.field(2, ti.f32, shape=())

    @ti.kernel
    def int_sum(self, count: ti.i32):
        reduce_blocks(self.ints, count, self.int_groups, self.int_out, add, _zero)

    @ti.kernel
    def int_max(self, count: ti.i32):
        reduce_blocks(self.ints, count, self.int_groups, self.int_out, larger, _zero)

    @ti.kernel
    def vec_min(self, count: ti.i32):
        reduce_blocks(self.vecs, count, self.vec_groups, self.vec_out, smaller, _far_up)

    @ti.kernel
    def scan(self, count: ti.i32):
        exclusive_scan(self.ints, count, self.int_groups, self.int_out)


def outcomes(bench: _Bench, count: int) -> list:
    """(what, got, want) for each helper on ``count`` random entries."""
    rng = np.random.default_rng(count)
    ints = rng.integers(0, 1000, LARGEST).astype(np.int32)
    vecs = rng.uniform(-5.0, 5.0, (LARGEST, 2)).astype(np.float32)
    bench.ints.from_numpy(ints)
    bench.vecs.from_numpy(vecs)
    out = []
    bench.int_sum(count)
    out.append(("sum", bench.int_out[None], int(ints[:count].sum())))
    bench.int_max(count)
    out.append(("max", bench.int_out[None], int(ints[:count].max()) if count else 0))
    bench.vec_min(count)
    want = vecs[:count].min(axis=0) if count else np.full(2, 3.0e38, np.float32)
    out.append(("min", bench.vec_out[None].to_numpy().tolist(), want.tolist()))
    bench.scan(count)
    got = bench.ints.to_numpy()
    want = np.concatenate([[0], np.cumsum(ints[:count], dtype=np.int64)[:-1]]) if count else []
    out.append(("scan", got[:count].tolist(), list(want)))
    out.append(("past count, untouched", got[count:].tolist(), ints[count:].tolist()))
    out.append(("scan total", bench.int_out[None], int(ints[:count].sum())))
    return out


@pytest.fixture(scope="module")
def bench():
    return _Bench()


def test_blocks_for_counts_partial_blocks():
    assert [blocks_for(n) for n in (0, 1, BLOCK, BLOCK + 1)] == [0, 1, 1, 2]
    assert groups_for(0) == 1 and groups_for(BLOCK * BLOCK + 1) == BLOCK + 1


@pytest.mark.parametrize("count", SIZES)
def test_reductions_and_scan_match_numpy(bench, count):
    for what, got, want in outcomes(bench, count):
        assert got == want, what


GPU_ARCHS = ("vulkan", "cuda")


@pytest.mark.parametrize("arch", GPU_ARCHS)
def test_reductions_and_scan_on_the_gpu_arch(arch):
    """The same on each GPU arch that Taichi finds (lavapipe's Vulkan on a machine without a
    GPU; tests/test_gpu_arch.py): there every stage is a device task and the serial one runs
    on one GPU thread."""
    try:
        backend.init(arch)
    except BackendError as e:
        backend.init("cpu")
        pytest.skip(f"no {arch} device for Taichi: {e}")
    try:
        bench = _Bench()
        wrong = [(count, what) for count in SIZES
                 for what, got, want in outcomes(bench, count) if got != want]
    finally:
        backend.init("cpu")          # the session's backend (resets Taichi)
    assert wrong == []
