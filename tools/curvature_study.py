"""Issue 23's curvature estimate, studied on particle spheres and cylinders (numpy, no Taichi).

    python tools/curvature_study.py [--support 2.1,3,4] [--radii 8,12,16]

Particles at unit spacing (l0 = 1) in two arrangements of each shape:
- ``lattice``: the cubic lattice points inside the radius (the scenes' own drops, a staircase
  surface);
- ``shells``: concentric shells (cylinders) one spacing apart, each covered by points about one
  spacing apart (a Fibonacci sphere; rings along the cylinder), the outermost centres at
  R - 1/2, so that the liquid's surface, half a spacing outside the centres, is at R.
The estimate (a candidate for the curvature-based model):
1. the outward normal n_i = -sum_j grad W(r_ij) (Wendland C2, support h), normalised, for the
   particles where its length is at least a quarter of the largest (the surface layer);
2. the curvature kappa_i = div_s n, the divergence of the normal in i's tangent plane, by
   weighted least squares over the neighbours that have a normal (the plane's 2x2 moments, so
   that a one-sided neighbourhood is no bias).
Printed: kappa R / 2 (sphere) or kappa R (cylinder) over the outermost layer's particles:
median and the 10-90 % range; 1 is the liquid surface's value, R / (R - 1/2) the centres'.
"""
from __future__ import annotations

import argparse

import numpy as np


def lattice(R: float, shape: str) -> np.ndarray:
    n = int(R) + 2
    axes = [np.arange(-n, n + 1)] * 2 + [np.arange(-n, n + 1) if shape == "sphere"
                                        else np.arange(-3 * n, 3 * n + 1)]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3).astype(float)
    r = np.linalg.norm(g if shape == "sphere" else g[:, :2], axis=1)
    return g[r <= R - 0.5]


def shells(R: float, shape: str) -> np.ndarray:
    pts, r = [], R - 0.5
    length = 6 * (int(R) + 2)
    while r > 0.4:
        if shape == "sphere":
            m = max(int(round(4 * np.pi * r * r)), 4)
            k = np.arange(m) + 0.5
            polar, azim = np.arccos(1 - 2 * k / m), np.pi * (1 + 5 ** 0.5) * k
            pts.append(r * np.c_[np.cos(azim) * np.sin(polar), np.sin(azim) * np.sin(polar),
                                 np.cos(polar)])
        else:
            m = max(int(round(2 * np.pi * r)), 3)
            for z in np.arange(-length, length + 1):
                a = 2 * np.pi * (np.arange(m) + 0.5 * (z % 2)) / m
                pts.append(np.c_[r * np.cos(a), r * np.sin(a), np.full(m, float(z))])
        r -= 1.0
    if shape == "sphere":
        pts.append(np.zeros((1, 3)))
    else:
        pts.append(np.c_[np.zeros((2 * length + 1, 2)), np.arange(-length, length + 1)])
    return np.concatenate(pts)


def pairs(p: np.ndarray, h: float):
    """Neighbour pairs (i, j), i != j, closer than h: a cell hash in numpy."""
    cell = np.floor(p / h).astype(np.int64)
    cell -= cell.min(axis=0)
    dims = cell.max(axis=0) + 3
    key = (cell[:, 0] * dims[1] + cell[:, 1]) * dims[2] + cell[:, 2]
    order = np.argsort(key)
    skey = key[order]
    I, J = [], []
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                k = key + (dx * dims[1] + dy) * dims[2] + dz
                lo, hi = np.searchsorted(skey, k, "left"), np.searchsorted(skey, k, "right")
                cnt = hi - lo
                i = np.repeat(np.arange(len(p)), cnt)
                j = order[np.repeat(lo, cnt) + np.arange(cnt.sum()) - np.repeat(
                    np.cumsum(cnt) - cnt, cnt)]
                I.append(i)
                J.append(j)
    i, j = np.concatenate(I), np.concatenate(J)
    r = np.linalg.norm(p[i] - p[j], axis=1)
    keep = (r < h) & (i != j)
    return i[keep], j[keep]


def wendland(r, h):
    q = np.clip(r / h, 0.0, 1.0)
    return (1 - q) ** 4 * (1 + 4 * q)


def dwendland(r, h):
    q = np.clip(r / h, 0.0, 1.0)
    return -20.0 * q * (1 - q) ** 3 / h


def curvature(p: np.ndarray, h: float):
    """(kappa, has_normal) per particle (steps 1-2 of the docstring)."""
    i, j = pairs(p, h)
    N = len(p)
    d = p[i] - p[j]
    r = np.linalg.norm(d, axis=1)
    e = d / r[:, None]
    dw = dwendland(r, h)
    n = -np.stack([np.bincount(i, weights=dw * e[:, k], minlength=N) for k in range(3)], 1)
    length = np.linalg.norm(n, axis=1)
    has = length >= 0.25 * length.max()
    nhat = n / np.maximum(length, 1e-300)[:, None]
    a = np.where(np.abs(nhat[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(nhat, a)
    u /= np.maximum(np.linalg.norm(u, axis=1), 1e-300)[:, None]     # interior: n = 0
    v = np.cross(nhat, u)
    use = has[i] & has[j]
    w = np.where(use, wendland(r, h), 0.0)
    t = np.c_[np.einsum("ij,ij->i", -d, u[i]), np.einsum("ij,ij->i", -d, v[i])]   # x_j - x_i
    dn = nhat[j] - nhat[i]
    f = np.c_[np.einsum("ij,ij->i", dn, u[i]), np.einsum("ij,ij->i", dn, v[i])]

    def mean(x):
        return np.bincount(i, weights=w * x, minlength=N) / np.maximum(
            np.bincount(i, weights=w, minlength=N), 1e-300)
    mt = [mean(t[:, a]) for a in (0, 1)]
    M = [[mean(t[:, a] * t[:, b]) - mt[a] * mt[b] for b in (0, 1)] for a in (0, 1)]
    mf = [mean(f[:, a]) for a in (0, 1)]
    B = [[mean(f[:, a] * t[:, b]) - mf[a] * mt[b] for b in (0, 1)] for a in (0, 1)]
    det = M[0][0] * M[1][1] - M[0][1] * M[1][0]
    det = np.where(np.abs(det) > 1e-12, det, np.nan)
    df_u = (M[1][1] * B[0][0] - M[0][1] * B[0][1]) / det       # d(n.u)/du
    df_v = (-M[1][0] * B[1][0] + M[0][0] * B[1][1]) / det      # d(n.v)/dv
    return df_u + df_v, has


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--support", default="2.1,3,4", help="kernel supports h / l0")
    ap.add_argument("--radii", default="8,12,16", help="R / l0")
    args = ap.parse_args()
    print("| shape | particles | R/l0 | h/l0 | kappa / exact, median | 10-90 % | centres' |")
    print("|---|---|---|---|---|---|---|")
    for shape, exact in (("sphere", 2.0), ("cylinder", 1.0)):
        for kind, make in (("shells", shells), ("lattice", lattice)):
            for R in (float(x) for x in args.radii.split(",")):
                p = make(R, shape)
                radius = np.linalg.norm(p if shape == "sphere" else p[:, :2], axis=1)
                for h in (float(x) for x in args.support.split(",")):
                    kappa, has = curvature(p, h)
                    outer = has & (radius > R - 1.5)
                    if shape == "cylinder":
                        outer &= np.abs(p[:, 2]) < 2 * R     # away from the cut ends
                    k = kappa[outer] * R / exact
                    lo, mid, hi = np.nanpercentile(k, [10, 50, 90])
                    print(f"| {shape} | {kind} | {R:g} | {h:g} | {mid:.3f} | {lo:.3f}-{hi:.3f} "
                          f"| {R / (R - 0.5):.3f} |", flush=True)


if __name__ == "__main__":
    main()
