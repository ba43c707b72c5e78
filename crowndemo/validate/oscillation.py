"""The mode-2 oscillation of a free drop measured from its particles: a deformation signal per
frame, then its angular frequency and decay rate (against method.md §7, Rayleigh-Lamb)."""
from __future__ import annotations

import math
from typing import Sequence, Tuple

import numpy as np


def deformation(pos: np.ndarray) -> float:
    """The drop's mode-2 second moment: <x^2> - <y^2> (2D), <z^2> - (<x^2> + <y^2>)/2 (3D),
    about its centre. Zero for a disc (ball); proportional to the mode's amplitude."""
    p = np.asarray(pos, dtype=float)
    p = p - p.mean(axis=0)
    m = (p * p).mean(axis=0)
    return float(m[0] - m[1]) if p.shape[1] == 2 else float(m[2] - 0.5 * (m[0] + m[1]))


def _residual(t: np.ndarray, s: np.ndarray, omega: float, decay: float) -> float:
    """Least-squares residual of s ~ c + exp(-decay t) (A sin omega t + B cos omega t)."""
    e = np.exp(-decay * t)
    basis = np.stack([np.ones_like(t), e * np.sin(omega * t), e * np.cos(omega * t)], axis=1)
    coef, *_ = np.linalg.lstsq(basis, s, rcond=None)
    return float(np.sum((basis @ coef - s) ** 2))


def fit(t: Sequence[float], s: Sequence[float]) -> Tuple[float, float]:
    """(omega, decay) of s(t) ~ c + B exp(-decay t) sin(omega t + phi), c an equilibrium
    offset: a first omega from the spacing of the crossings of the mean, then the least-squares
    (omega, decay) on grids refined three times around the best. nan when the signal crosses
    its mean fewer than twice (no oscillation to measure)."""
    t, s = np.asarray(t, dtype=float), np.asarray(s, dtype=float)
    d = s - s.mean()
    k = np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]
    if len(k) < 2:
        return math.nan, math.nan
    cross = t[k] - d[k] * (t[k + 1] - t[k]) / (d[k + 1] - d[k])
    omega = math.pi / float(np.mean(np.diff(cross)))
    span = t[-1] - t[0]
    decay, w_half, g_half = 0.0, 0.3 * omega, 5.0 / span
    for _ in range(4):
        best = min((_residual(t, s, w, g), w, g)
                   for w in np.linspace(max(omega - w_half, 1e-9), omega + w_half, 25)
                   for g in np.linspace(decay - g_half, decay + g_half, 25))
        _, omega, decay = best
        w_half, g_half = w_half / 6, g_half / 6
    return float(omega), float(decay)
