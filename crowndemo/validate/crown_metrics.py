"""Crown metrics measured from the fluid particles of one frame of a drop-on-film run, and the
crown / no-crown verdict (method.md §6-7).

Geometry of the crown scene (``crowndemo.scenes.crown``): the drop's axis is x = 0 (and
y = 0), the floor surface z = 0, the undisturbed film surface z = h. In 2D the 'radius' is
|x| and the two sides of the slice are the two 'sectors'.

The rules, each a few lines below:
- the film surface: the built thickness h, or the far film's surface where the far film
  has swollen above it (``film_surface``, of the main body below; reported as
  ``film_swell``);
- raised liquid: particles more than 2 l0 above the undisturbed film surface, and nearer the
  axis than ``edge`` when one is given (inside a trimmed film's free edge, which slumps and
  rises on its own, or inside the container's side walls: by 4 ms the liquid in a corner of
  the 3m-drop booth run stood 2 l0 above the film at r = 55 mm, and the rule took it for the
  crown's foot; ``verdicts.film_limit``);
- the main body is the largest group of particles linked at 1.5 l0; every other group above
  the film is an ejected droplet;
- base radius: per azimuthal sector, the outermost raised particle of the main body in the
  root band h + 2 l0 < z < h + 5 l0 (the foot of the crown wall), the median over sectors;
  the foot is the part of the band continuous (radial gaps of at most 2 l0) with the wall
  standing just above it (h + 5 l0 to h + 8 l0): spray that landed on the film beyond the
  crown is linked to the body through the film, but it is not the crown's foot;
- rim height: in azimuthal bins of about 2 l0 of arc (the two sides in 2D), the highest
  particle of the main body outside half the base radius, above h; the median over bins (the
  rim between the fingers when fingers are narrow);
- rim thickness: per sector, the radial extent (+ l0) of the main body in the top fifth of that
  sector's wall; the median;
- sheet coherence (issue 21): the fraction of the raised liquid that lies in the largest body
  of fluid particles linked closer than 1.6 l0 (the film and the crown wall standing on it);
  1 for a wall that is one sheet, falling as it breaks into spray; nan when nothing is raised;
- jets: the local maxima of the rim height around the azimuth (bins of about 2 l0 of arc),
  each at least 2 l0 above both neighbouring minima, and ejected droplets do not count (3D);
- verdict: a crown when a wall stands outside the drop's footprint (base radius > D/2) and
  rises at least D/4 above the film (rim height >= D/4), as a sheet (rim thickness < rim
  height). Otherwise no crown (a dent or a crater rim).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from ..core.symmetry import mirror_whole
from .clusters import whole_groups

RAISED_L0 = 2.0        # raised liquid: more than this many l0 above the film surface
ROOT_TOP_L0 = 5.0      # the root band of the crown wall ends this many l0 above the surface
ABOVE_TOP_L0 = 8.0     # the wall just above the root band: up to this many l0 above it
FOOT_GAP_L0 = 2.0      # a radial gap wider than this parts the foot from liquid beyond it
LINK_L0 = 1.5          # particles closer than this many l0 belong to one body
COHERENCE_LINK_L0 = 1.6   # the sheet-coherence link (issue 21's definition)
JET_PROMINENCE_L0 = 2.0
CROWN_MIN_HEIGHT_D = 0.25
CROWN_MIN_BASE_D = 0.5


def film_edge(extent: Optional[float], l0: float) -> Optional[float]:
    """Where the effects of a film's edge (a trimmed film's free edge, or the container's
    walls at ``extent`` from the axis) begin: 10 % of ``extent`` or 5 l0 inside it."""
    if extent is None:
        return None
    return extent - max(0.1 * extent, 5.0 * l0)


@dataclass
class CrownMetrics:
    time: float
    base_radius: float          # m (nan when nothing is raised)
    rim_height: float           # m above the undisturbed film surface
    rim_thickness: float        # m
    jets: int                   # fingers along the rim (3D; 0 in 2D)
    droplets: int               # ejected groups apart from the main body
    droplet_particles: int
    raised_particles: int
    crown: bool
    verdict: str                # one line: why crown or no crown
    sheet_coherence: float = math.nan   # raised liquid in the one body / all raised (0..1)
    film_swell: float = 0.0     # m: the far film's surface above the built film's (film_surface)

    def as_dict(self) -> dict:
        return asdict(self)


def film_surface(z: np.ndarray, axial: np.ndarray, film: float, l0: float,
                 edge: Optional[float]) -> float:
    """The undisturbed film's surface as it stands: the built thickness ``film``, or higher
    where the film far from the impact has swollen (the top layer's centres, 99th percentile,
    + l0/2, in the ring from 0.75 ``edge`` to ``edge``; without an edge, ``film``). The seed's
    potential surface tension swells a film at D/l0 = 100 (VALIDATION.md, "The seed rung"):
    measured from the built surface, the whole film would read as raised liquid. ``z`` and
    ``axial`` are of the film's body only (the main body): spray flying over the ring is not
    the film (at 3.5-4 ms of the seed rung it put the 99th percentile 23-27 mm up)."""
    if edge is None:
        return film
    ring = (axial >= 0.75 * edge) & (axial < edge)
    if np.count_nonzero(ring) < 16:
        return film
    return max(film, float(np.percentile(z[ring], 99)) + 0.5 * l0)


def _sectors(theta: np.ndarray, n: int) -> np.ndarray:
    return np.minimum(((theta + math.pi) / (2 * math.pi) * n).astype(int), n - 1)


def _per_sector(values: np.ndarray, sector: np.ndarray, n: int, fn) -> np.ndarray:
    out = np.full(n, np.nan)
    for s in np.unique(sector):
        out[s] = fn(values[sector == s])
    return out


def _segments(r: np.ndarray, gap: float) -> Tuple[np.ndarray, np.ndarray]:
    """The sorted ``r`` cut where consecutive values lie more than ``gap`` apart: the first and
    last value of each segment."""
    rs = np.sort(r)
    cut = np.flatnonzero(np.diff(rs) > gap)
    return rs[np.r_[0, cut + 1]], rs[np.r_[cut, len(rs) - 1]]


def _foot(r_root: np.ndarray, r_above: np.ndarray, gap: float) -> float:
    """The outer end of the crown wall's foot in one sector: of the radial segments of the
    root band (``r_root``), those within ``gap`` of the wall just above the band (the largest
    segment of ``r_above``); the outermost root particle when nothing stands above the band.
    Liquid that has landed on the film beyond the crown (a bump linked to the film) stands in
    the root band but not above it, apart from the foot: it is not the base."""
    if len(r_above) == 0:
        return float(r_root.max())
    lo_a, hi_a = _segments(r_above, gap)
    counts = [np.count_nonzero((r_above >= a) & (r_above <= b)) for a, b in zip(lo_a, hi_a)]
    k = int(np.argmax(counts))
    lo, hi = _segments(r_root, gap)
    near = (hi >= lo_a[k] - gap) & (lo <= hi_a[k] + gap)
    return float(hi[near].max()) if near.any() else float(r_root.max())


def count_jets(rim: np.ndarray, prominence: float) -> int:
    """Peaks of a periodic profile that stand ``prominence`` above the lowest point between
    them and the next peak on either side (nan bins are gaps at the film level)."""
    h = np.where(np.isfinite(rim), rim, np.nanmin(rim) if np.isfinite(rim).any() else 0.0)
    n = len(h)
    if n < 3:
        return 0
    # walk round the ring from its lowest point, counting rises and falls of the prominence
    start = int(np.argmin(h))
    ring = np.concatenate([h[start:], h[:start], h[start:start + 1]])
    peaks, low, high, rising = 0, ring[0], ring[0], True
    for v in ring[1:]:
        if rising:
            high = max(high, v)
            if high - v >= prominence and high - low >= prominence:
                peaks += 1
                rising, low = False, v
        else:
            low = min(low, v)
            if v - low >= prominence:
                rising, high = True, v
    return peaks


def measure(pos: np.ndarray, time: float, film: float, drop: float, l0: float,
            sectors: Optional[int] = None, edge: Optional[float] = None,
            planes: Sequence[int] = ()) -> CrownMetrics:
    """The metrics of one frame from the fluid particle positions ``pos`` (N x dim); with
    ``edge``, liquid farther than that from the axis is never 'raised' (see the rules). With
    symmetry ``planes`` (axes), ``pos`` is the simulated part and the metrics are the mirrored
    whole's (its bodies grouped without building them: ``clusters.whole_groups``)."""
    part = np.asarray(pos, dtype=float)
    dim = part.shape[1]
    pos = mirror_whole({"pos": part}, planes)["pos"]
    z = pos[:, -1]
    axial = np.hypot(pos[:, 0], pos[:, 1]) if dim == 3 else np.abs(pos[:, 0])
    built = film
    label, coherence_label = whole_groups(part, (LINK_L0 * l0, COHERENCE_LINK_L0 * l0), planes)
    ids, counts = np.unique(label, return_counts=True)
    main = label == ids[np.argmax(counts)]
    film = film_surface(z[main], axial[main], film, l0, edge)
    raised = z > film + RAISED_L0 * l0
    if edge is not None:
        raised &= axial < edge
    nan = math.nan
    if not raised.any():
        return CrownMetrics(time, nan, 0.0, nan, 0, 0, 0, 0, False,
                            "no crown: nothing stands 2 l0 above the film", nan,
                            film - built)
    drops = raised & ~main
    n_drops = len(np.unique(label[drops]))
    r = axial
    if dim == 3:
        theta = np.arctan2(pos[:, 1], pos[:, 0])
    else:
        theta = np.where(pos[:, 0] >= 0, 0.5 * math.pi, -0.5 * math.pi)
    body = raised & main
    coherence = sheet_coherence(coherence_label, raised)
    if not body.any():          # only what is apart from the film is raised (the falling drop)
        return CrownMetrics(time, nan, 0.0, nan, 0, n_drops, int(drops.sum()),
                            int(raised.sum()), False, "no crown: nothing raised stands on the "
                            "film (the liquid above it is apart from it)", coherence,
                            film - built)
    root = body & (z < film + ROOT_TOP_L0 * l0)
    if not root.any():
        root = body
    n_sec = 2 if dim == 2 else (sectors or 16)
    sec = _sectors(theta, n_sec)
    above = body & (z >= film + ROOT_TOP_L0 * l0) & (z < film + ABOVE_TOP_L0 * l0)
    feet = np.full(n_sec, np.nan)
    for s_ in np.unique(sec[root]):
        feet[s_] = _foot(r[root & (sec == s_)], r[above & (sec == s_)], FOOT_GAP_L0 * l0)
    base = float(np.nanmedian(feet))
    wall = body & (r > 0.5 * base)
    if not wall.any():
        wall = body
    n_az = max(16, int(2 * math.pi * base / (2 * l0))) if dim == 3 else 2
    profile = _per_sector(z[wall], _sectors(theta[wall], n_az), n_az, np.max)
    rim_height = float(np.nanmedian(profile)) - film
    thick = np.full(n_sec, np.nan)
    for s in np.unique(sec[wall]):
        m = wall & (sec == s)
        zs = z[m]
        upper = zs >= film + 0.8 * (zs.max() - film)
        thick[s] = np.ptp(r[m][upper]) + l0
    rim_thickness = float(np.nanmedian(thick))
    jets = count_jets(profile, JET_PROMINENCE_L0 * l0) if dim == 3 else 0
    crown = (base > CROWN_MIN_BASE_D * drop and rim_height >= CROWN_MIN_HEIGHT_D * drop
             and rim_thickness < rim_height)
    if crown:
        why = (f"crown: a sheet {rim_thickness * 1e3:.2g} mm thick rises {rim_height * 1e3:.3g} mm "
               f"(>= D/4 = {CROWN_MIN_HEIGHT_D * drop * 1e3:.3g} mm) at r = {base * 1e3:.3g} mm "
               f"(> D/2)")
    else:
        why = (f"no crown: the rim rises {rim_height * 1e3:.3g} mm (a crown needs >= D/4 = "
               f"{CROWN_MIN_HEIGHT_D * drop * 1e3:.3g} mm) at r = {base * 1e3:.3g} mm (needs > "
               f"D/2), {rim_thickness * 1e3:.2g} mm thick (needs < its height)")
    return CrownMetrics(time, base, rim_height, rim_thickness, jets, n_drops,
                        int(drops.sum()), int(raised.sum()), bool(crown), why, coherence,
                        film - built)


def sheet_coherence(label: np.ndarray, raised: np.ndarray) -> float:
    """The fraction of the ``raised`` fluid particles that belong to the largest group of the
    fluid (``label``: its groups linked closer than COHERENCE_LINK_L0 l0); nan when none is
    raised."""
    n_raised = int(np.count_nonzero(raised))
    if n_raised == 0:
        return math.nan
    ids, counts = np.unique(label, return_counts=True)
    body = label == ids[np.argmax(counts)]
    return float(np.count_nonzero(raised & body)) / n_raised
