"""Connected groups of particles (liquid bodies and droplets) with numpy only: particles closer
than a link distance belong to one group. A cell list finds the candidate pairs, a
hook-and-compress union-find labels the groups."""
from __future__ import annotations

import itertools

import numpy as np


def close_pairs(pos: np.ndarray, link: float) -> tuple[np.ndarray, np.ndarray]:
    """Every pair (i < j) with |r_i - r_j| < link, found through cells of side ``link``."""
    pos = np.asarray(pos, dtype=float)
    n, dim = pos.shape
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    cell = np.floor((pos - pos.min(axis=0)) / link).astype(np.int64)
    dims = cell.max(axis=0) + 3                       # a spare cell on each side
    cell += 1
    stride = np.cumprod(np.concatenate([[1], dims[:-1]]))
    key = cell @ stride
    order = np.argsort(key, kind="stable")
    skey = key[order]
    firsts, lasts = [], []
    for off in itertools.product((-1, 0, 1), repeat=dim):
        nkey = key + np.asarray(off) @ stride
        lo = np.searchsorted(skey, nkey, "left")
        hi = np.searchsorted(skey, nkey, "right")
        cnt = hi - lo
        i = np.repeat(np.arange(n), cnt)
        start = np.repeat(lo - np.concatenate([[0], np.cumsum(cnt)[:-1]]), cnt)
        j = order[start + np.arange(cnt.sum())]
        keep = i < j
        i, j = i[keep], j[keep]
        near = np.einsum("ij,ij->i", pos[i] - pos[j], pos[i] - pos[j]) < link * link
        firsts.append(i[near])
        lasts.append(j[near])
    return np.concatenate(firsts), np.concatenate(lasts)


def label_groups(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Group label per particle (the smallest index in its group) from the linked pairs."""
    label = np.arange(n)
    while True:
        li, lj = label[i], label[j]
        differ = li != lj
        if not differ.any():
            return label
        lo, hi = np.minimum(li[differ], lj[differ]), np.maximum(li[differ], lj[differ])
        np.minimum.at(label, hi, lo)                  # hook the larger root to the smaller
        while True:                                   # compress: point at the root
            nxt = label[label]
            if np.array_equal(nxt, label):
                break
            label = nxt


def groups(pos: np.ndarray, link: float) -> np.ndarray:
    """Group label per particle, particles closer than ``link`` being linked."""
    i, j = close_pairs(pos, link)
    return label_groups(len(pos), i, j)
