"""The frame sink: what the recorder calls at each frame time and at the end of a run.

A sink is any object with ``frame(sim, index, time)`` (the simulator stands at frame ``index``,
simulated time ``time`` in s; the sink may read it but must not step it) and ``close(status)``
(the run ended: "complete", "interrupted" or "unstable: <message>"). Snapshots, the
checkpoint, metadata.json and a renderer are all sinks; the recorder calls them in order.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from ..core.step import Simulator


@runtime_checkable
class FrameSink(Protocol):
    def frame(self, sim: Simulator, index: int, time: float) -> None: ...

    def close(self, status: str) -> None: ...


COMPLETE, INTERRUPTED, RUNNING = "complete", "interrupted", "running"


def unstable(message: str) -> str:
    return f"unstable: {message}"


__all__ = ["FrameSink", "COMPLETE", "INTERRUPTED", "RUNNING", "unstable"]
