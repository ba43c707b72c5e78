"""Reductions and prefix sums over blocks, parallel on every arch and free of atomics.

Every whole-array reduction of the step (the grid's bounds, the cell-count scan, the health
stats, the largest relative speed) runs in three stages: each thread walks one block of
BLOCK entries, each thread of a second loop walks one group of BLOCK block results, and one
thread combines the groups. The last, serial, stage walks count / BLOCK^2 entries: 15 at the
seed's 15.5 M particles, 240 at the 250 M cells that its grid may use. With only two stages
the serial walk had n / BLOCK entries (15 k and 240 k): negligible on the CPU, but one GPU
thread walking 240 k entries of global memory takes tens of milliseconds, longer than a whole
step's budget at 5e8 particle-steps/s. No atomics: on Taichi 1.7.4's Vulkan arch (lavapipe)
an atomic add on a reduced counter spoiled the whole loop's results (tests/test_gpu_arch.py).

The helpers are ``ti.func``s with top-level loops: call them at a kernel's top level, after the
loop that filled the per-block values.
"""

import taichi as ti

BLOCK = 1024


@ti.pyfunc
def blocks_for(count):
    """Blocks of BLOCK entries that hold ``count`` entries."""
    return (count + BLOCK - 1) // BLOCK


def groups_for(count: int) -> int:
    """Length of the ``groups`` field that ``reduce_blocks``/``exclusive_scan`` need for at
    most ``count`` values (at least 1, so a field can be made)."""
    return max(blocks_for(int(count)), 1)


@ti.func
def reduce_blocks(values: ti.template(), count, groups: ti.template(), out: ti.template(),
                  op: ti.template(), identity: ti.template()):
    """out[None] = identity() op values[0] op ... op values[count - 1], for an associative
    and commutative ``op(a, b)``; ``groups`` holds at least blocks_for(count) entries."""
    for g in range(blocks_for(count)):
        acc = identity()
        for b in range(g * BLOCK, ti.min(count, (g + 1) * BLOCK)):
            acc = op(acc, values[b])
        groups[g] = acc
    for _ in range(1):      # serial: count / BLOCK entries
        acc = identity()
        for g in range(blocks_for(count)):
            acc = op(acc, groups[g])
        out[None] = acc


@ti.func
def exclusive_scan(values: ti.template(), count, groups: ti.template(), total: ti.template()):
    """values[k] <- values[0] + ... + values[k - 1] for k < count, in place; total[None] <- the
    sum of all. Integer values; ``groups`` holds at least blocks_for(count) entries."""
    for g in range(blocks_for(count)):
        s = 0
        for b in range(g * BLOCK, ti.min(count, (g + 1) * BLOCK)):
            s += values[b]
        groups[g] = s
    for _ in range(1):      # serial: count / BLOCK entries
        run = 0
        for g in range(blocks_for(count)):
            s = groups[g]
            groups[g] = run
            run += s
        total[None] = run
    for g in range(blocks_for(count)):
        run = groups[g]
        for b in range(g * BLOCK, ti.min(count, (g + 1) * BLOCK)):
            s = values[b]
            values[b] = run
            run += s


@ti.func
def add(a, b):
    return a + b


@ti.func
def larger(a, b):
    return ti.max(a, b)


@ti.func
def smaller(a, b):
    return ti.min(a, b)
