"""The bookkeeping of one recording that is not in the simulator: the frames written, wall
times and the starts (a resumed run adds one); health peaks are in the simulator's RunStats.
Saved inside the checkpoint, so a resumed run continues it."""
from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from datetime import datetime, timezone
from typing import List, Optional


@dataclass
class RunLog:
    frames: List[dict] = field(default_factory=list)   # index, time_s, file, wall_s, crown
    setup_seconds: float = 0.0        # summed over the starts
    starts: List[dict] = field(default_factory=list)   # started (UTC), from_step, setup_s
    stopped_by: Optional[str] = None  # "ctrl-c" | "max-steps" when interrupted

    def __post_init__(self):
        self._stamp = time.perf_counter()

    def start(self, from_step: int, setup_s: float) -> None:
        self.setup_seconds += setup_s
        self.starts.append({"started_utc": datetime.now(timezone.utc).isoformat(
            timespec="seconds"), "from_step": from_step, "setup_seconds": setup_s})
        self._stamp = time.perf_counter()

    def add_frame(self, index: int, time_s: float, file: str) -> None:
        """A frame whose files are written; wall_s: wall time since the previous frame."""
        now = time.perf_counter()
        self.frames = [f for f in self.frames if f["index"] < index]
        self.frames.append({"index": index, "time_s": time_s, "file": file,
                            "wall_s": now - self._stamp})
        self._stamp = now

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict) -> "RunLog":
        known = set(cls.__dataclass_fields__)
        return cls(**{k: v for k, v in data.items() if k in known})   # older: peaks here


__all__ = ["RunLog"]
