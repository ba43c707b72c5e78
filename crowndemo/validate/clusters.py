"""Connected groups of particles (liquid bodies and droplets) with numpy only: particles closer
than a link distance belong to one group. A cell list finds the candidate pairs, a
hook-and-compress union-find labels the groups. A half or quarter run (symmetry planes,
core/symmetry.py) is grouped as the mirrored whole without building it (``whole_groups``)."""
from __future__ import annotations

import itertools
from typing import List, Sequence, Tuple

import numpy as np

from ..core.symmetry import plane_sets


def _half_offsets(dim: int) -> List[Tuple[int, ...]]:
    """The neighbour-cell offsets of one half space (lexicographically positive): with the
    cell itself they meet every pair of adjacent cells once."""
    return [o for o in itertools.product((-1, 0, 1), repeat=dim) if o > (0,) * dim]


def close_pairs(pos: np.ndarray, link: float, with_d2: bool = False):
    """Every pair (i < j or, across cells, once) with |r_i - r_j| < link, found through cells
    of side ``link``; with ``with_d2`` also the squared distances."""
    pos = np.asarray(pos, dtype=float)
    n, dim = pos.shape
    if n < 2:
        empty = np.zeros(0, np.int64)
        return (empty, empty, np.zeros(0)) if with_d2 else (empty, empty)
    cell = np.floor((pos - pos.min(axis=0)) / link).astype(np.int64)
    dims = cell.max(axis=0) + 3                       # a spare cell on each side
    cell += 1
    stride = np.cumprod(np.concatenate([[1], dims[:-1]]))
    key = cell @ stride
    order = np.argsort(key, kind="stable")
    skey = key[order]
    firsts, lasts, d2s = [], [], []
    for off in [(0,) * dim] + _half_offsets(dim):
        nkey = key + np.asarray(off) @ stride
        lo = np.searchsorted(skey, nkey, "left")
        hi = np.searchsorted(skey, nkey, "right")
        cnt = hi - lo
        i = np.repeat(np.arange(n), cnt)
        start = np.repeat(lo - np.concatenate([[0], np.cumsum(cnt)[:-1]]), cnt)
        j = order[start + np.arange(cnt.sum())]
        if not any(off):                              # within the cell: each pair once
            keep = i < j
            i, j = i[keep], j[keep]
        d = pos[i] - pos[j]
        d2 = np.einsum("ij,ij->i", d, d)
        near = d2 < link * link
        firsts.append(i[near])
        lasts.append(j[near])
        d2s.append(d2[near])
    i, j = np.concatenate(firsts), np.concatenate(lasts)
    return (i, j, np.concatenate(d2s)) if with_d2 else (i, j)


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


def _coset_table(k: int) -> np.ndarray:
    """rep[s, m]: for a set s of reflections (a bitmask over the 2^k reflection codes) that a
    group is linked to its own image by, the smallest code in the coset of reflection m modulo
    the subgroup that s generates (XOR closure): copies m and m' of a group are one group
    exactly when their codes share the coset."""
    codes = 2 ** k
    rep = np.zeros((2 ** codes, codes), np.int64)
    for s in range(2 ** codes):
        sub = {0} | {c for c in range(codes) if s >> c & 1}
        while True:
            more = sub | {a ^ b for a in sub for b in sub}
            if more == sub:
                break
            sub = more
        for m in range(codes):
            rep[s, m] = min(m ^ c for c in sub)
    return rep


def whole_groups(part: np.ndarray, links: Sequence[float], planes: Sequence[int] = ()
                 ) -> List[np.ndarray]:
    """Group labels of the whole scene, one array per link in ``links``, for the particles of
    ``part`` (the simulated side x > 0 and/or y > 0 of a scene mirror-symmetric about the
    ``planes``, axes) and their mirror copies, in ``mirror_whole``'s order (the part, then its
    copy across each set of planes). The grouping runs on the part and its images within the
    longest link of the planes only: a path between two particles of the whole folds into the
    part without getting longer (a reflection keeps distances), so the part's groups are the
    whole's; a group linked to its own image across a set of planes is one group with that
    copy, any other copy is a group of its own. Without planes: ``groups`` per link."""
    part = np.asarray(part, dtype=float)
    planes, n = tuple(planes), len(part)
    reach = max(links)
    src, code, ext = [np.arange(n)], [np.zeros(n, np.int64)], [part]
    for c, axes in enumerate(plane_sets(planes), start=1):
        near = np.flatnonzero(np.all(part[:, list(axes)] < reach, axis=1))
        img = part[near].copy()
        img[:, list(axes)] *= -1
        src.append(near), code.append(np.full(len(near), c, np.int64)), ext.append(img)
    src, code = np.concatenate(src), np.concatenate(code)
    i, j, d2 = close_pairs(np.concatenate(ext), reach, with_d2=True)
    rep = _coset_table(len(planes))
    out = []
    for link in links:
        sel = d2 < link * link
        a, b, rel = src[i[sel]], src[j[sel]], code[i[sel]] ^ code[j[sel]]
        label = label_groups(n, a, b)
        linked = np.zeros(n, np.int64)               # per root: the reflections it meets
        np.bitwise_or.at(linked, label[a], np.left_shift(1, rel))
        s = linked[label]
        out.append(np.concatenate([label + n * rep[s, m] for m in range(2 ** len(planes))]))
    return out
