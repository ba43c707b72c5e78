"""``ParticleState.spread``: the loop-index-to-particle map that balances Taichi's CPU threads.

Taichi cuts a CPU ``for k in range(n)`` into one contiguous piece of ceil(n / T) indices per
thread (at least 512). ``spread`` must be one-to-one on [0, n) (every particle handled once),
and must give each thread's piece its share of every region of the particle range, so that
a pass whose work sits in one region (the fluid above the floor's wall layers) keeps every
thread busy.
"""

import numpy as np
import pytest
import taichi as ti

from crowndemo.core.state import SPREAD_CHUNK, ParticleState

CAPACITY = 40_000


def spread_of(n: int, threads: int) -> np.ndarray:
    """spread(k) for k in [0, n), from a state that believes it has ``threads`` threads."""
    state = ParticleState(3, CAPACITY)
    state.threads = threads                # before the first kernel: a compile-time value
    state._set_count(n)
    out = ti.field(ti.i32, CAPACITY)

    @ti.kernel
    def fill():
        for k in range(state.n[None]):
            out[k] = state.spread(k)

    fill()
    return out.to_numpy()[:n]


@pytest.mark.parametrize("threads", [1, 2, 3, 4])
@pytest.mark.parametrize("n", [0, 1, 255, 256, 511, 512, 513, 2047, 5000, 37_001])
def test_spread_is_a_permutation(n, threads):
    got = spread_of(n, threads)
    assert np.array_equal(np.sort(got), np.arange(n))
    if threads == 1:
        assert np.array_equal(got, np.arange(n))


@pytest.mark.parametrize("threads", [2, 3, 4])
def test_each_thread_gets_its_share_of_every_region(threads):
    n = 37_001
    got = spread_of(n, threads)
    piece = max(-(-n // threads), 512)          # Taichi's static cut of the loop range
    for t in range(threads):
        handled = got[t * piece:(t + 1) * piece]
        # of the top half of the particles (the "fluid"), this thread handles ~1/T: within
        # one round of chunks (T x SPREAD_CHUNK particles) of an exact share
        top = int((handled >= n // 2).sum())
        assert abs(top - (n - n // 2) / threads) <= threads * SPREAD_CHUNK
        # and so does every eighth of the range
        for e in range(8):
            lo = e * (n // 8)
            share = int(((handled >= lo) & (handled < lo + n // 8)).sum())
            assert abs(share - (n // 8) / threads) <= threads * SPREAD_CHUNK
