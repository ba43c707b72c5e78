"""The sound-speed rule of a crown preset: c = k x the scene's speed scale (method.md S8), k the
preset key ``scene.sound_speed_factor`` unless ``scene.sound_speed`` gives c itself.

The seed used k = 5 (Mach 0.2 at the impact speed U; ``core.params.SOUND_SPEED_FACTOR``, kept
by scenes built without a preset). A splash is faster than U: the ejecta at contact reach 4-5 U
at D/l0 = 100 and more as the spacing refines, so at k = 5 the 3m-drop stops at contact in 2D
at D/l0 = 100 (42 m/s > c = 40 m/s). The default k was chosen by the sound-speed study
(``python -m crowndemo.validate.sound_speed``, VALIDATION.md "Sound speed"): the cheapest k
whose runs finish at every D/l0 from 30 to 111 and whose crown (base radius, rim height) and
bulk density stay close to those at k = 20.
"""
from __future__ import annotations

SEED_FACTOR = 5.0              # the seed's c = 5 U (method.md S8)
DEFAULT_FACTOR = 10.0          # the crown presets' default (VALIDATION.md "Sound speed")
FACTOR_RANGE = (2.0, 100.0)    # scene.sound_speed_factor: c/U from Mach 0.5 to 0.01 at U


def sound_speed(factor: float, speed: float) -> float:
    """c = factor x speed (m/s)."""
    return factor * speed


__all__ = ["SEED_FACTOR", "DEFAULT_FACTOR", "FACTOR_RANGE", "sound_speed"]
