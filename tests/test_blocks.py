"""The block reductions and prefix sums (core/blocks.py) against numpy. Applied here straight
to an array, the helpers cut it into groups of BLOCK entries: the sizes fill none, one and
several groups, the last one part full, so the parallel stage and the serial stage above it
both count."""
import numpy as np
import pytest
import taichi as ti

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


@pytest.fixture(scope="module")
def bench():
    return _Bench()


def test_blocks_for_counts_partial_blocks():
    assert [blocks_for(n) for n in (0, 1, BLOCK, BLOCK + 1)] == [0, 1, 1, 2]
    assert groups_for(0) == 1 and groups_for(BLOCK * BLOCK + 1) == BLOCK + 1


@pytest.mark.parametrize("count", SIZES)
def test_reductions_match_numpy(bench, count):
    rng = np.random.default_rng(count)
    ints = rng.integers(0, 1000, LARGEST).astype(np.int32)
    vecs = rng.uniform(-5.0, 5.0, (LARGEST, 2)).astype(np.float32)
    bench.ints.from_numpy(ints)
    bench.vecs.from_numpy(vecs)
    bench.int_sum(count)
    assert bench.int_out[None] == int(ints[:count].sum())
    bench.int_max(count)
    assert bench.int_out[None] == (int(ints[:count].max()) if count else 0)
    bench.vec_min(count)
    want = vecs[:count].min(axis=0) if count else np.full(2, 3.0e38, np.float32)
    assert np.array_equal(bench.vec_out[None].to_numpy(), want)


@pytest.mark.parametrize("count", SIZES)
def test_exclusive_scan_matches_numpy(bench, count):
    rng = np.random.default_rng(count + 1)
    ints = rng.integers(0, 9, LARGEST).astype(np.int32)
    bench.ints.from_numpy(ints)
    bench.scan(count)
    got = bench.ints.to_numpy()
    want = np.concatenate([[0], np.cumsum(ints[:count], dtype=np.int64)[:-1]]) if count else []
    assert np.array_equal(got[:count], want)
    assert np.array_equal(got[count:], ints[count:])      # entries past count untouched
    assert bench.int_out[None] == int(ints[:count].sum())
