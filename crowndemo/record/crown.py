"""The crown-metrics sink: at every frame the crown metrics of the fluid particles
(``validate.crown_metrics.measure``: base radius, rim height and thickness, jets, droplets,
sheet coherence, the verdict) enter that frame's entry of the run log, and so metadata.json's
``frames`` (and a checkpoint, which a resumed run continues)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..core.state import FLUID
from ..strictjson import finite_or_none
from ..validate.crown_metrics import measure
from ..validate.verdicts import film_limit
from .runlog import RunLog

if TYPE_CHECKING:
    from ..config.resolve import Resolved
    from ..core.step import Simulator
    from ..scenes.base import Scene


class CrownSink:
    """Measures the crown at every frame into the run log's entry of that frame (the snapshot
    sink, which writes the entry, runs first)."""

    def __init__(self, resolved: Resolved, scene: Scene, log: RunLog):
        s = resolved.scene
        self.film, self.drop, self.l0 = s["film"], s["drop"], resolved.l0
        self.edge = film_limit(scene.info, resolved.l0)
        self.log = log

    def frame(self, sim: Simulator, index: int, time: float) -> None:
        snap = sim.snapshot()               # a half or quarter run: measured as the whole
        m = measure(snap["pos"][snap["kind"] == FLUID], time, self.film, self.drop, self.l0,
                    edge=self.edge, planes=sim.model.mirror_planes)
        for entry in reversed(self.log.frames):
            if entry["index"] == index:
                entry["crown"] = finite_or_none(m.as_dict())
                break

    def close(self, status: str) -> None:
        pass


__all__ = ["CrownSink"]
