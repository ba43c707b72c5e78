"""A sweep's journal: the points done, one JSON line each, written as they arrive, so that an
interrupted sweep (Ctrl-C, a lost machine) loses at most the points in flight and ``--resume``
runs only the missing ones. The first line names the sweep (preset, quality, overrides);
resuming another sweep into the same file is refused."""
from __future__ import annotations

import json
import os
from typing import Dict

from ..strictjson import finite_or_none
from .sweep import Point

NAME = "points.jsonl"


class JournalError(ValueError):
    """A journal that does not belong to this sweep, or cannot be read."""


class Journal:
    """The points of one sweep in ``folder``/points.jsonl: ``done`` holds those read back on
    resume (by (film, speed)); ``add`` appends one and flushes it to the disk."""

    def __init__(self, folder: str, identity: dict, resume: bool = False):
        self.path = os.path.join(folder, NAME)
        self.identity = finite_or_none(identity)
        self.done: Dict[tuple, Point] = {}
        if resume and os.path.exists(self.path):
            self._read()
        else:
            os.makedirs(folder, exist_ok=True)
            with open(self.path, "w") as f:
                f.write(json.dumps({"sweep": self.identity}) + "\n")

    def _read(self) -> None:
        with open(self.path) as f:
            lines = [line for line in f.read().splitlines() if line.strip()]
        try:
            head = json.loads(lines[0])["sweep"] if lines else None
        except (ValueError, KeyError, TypeError):
            head = None
        if head != self.identity:
            raise JournalError(f"{self.path}: written by another sweep ({head}); this one is "
                               f"{self.identity}: resume with the same preset, --quality and "
                               "--set, or leave out --resume to start afresh")
        for n, line in enumerate(lines[1:], start=2):
            try:
                p = Point.from_dict(json.loads(line))
            except (ValueError, KeyError, TypeError):
                if n == len(lines):          # a last line cut short by the interruption
                    break
                raise JournalError(f"{self.path}, line {n}: not a point: {line[:80]!r}") from None
            self.done[p.key] = p
        with open(self.path, "w") as f:      # rewrite without a torn last line
            f.write(json.dumps({"sweep": self.identity}) + "\n")
            for p in self.done.values():
                f.write(json.dumps(finite_or_none(p.as_dict())) + "\n")

    def add(self, point: Point) -> None:
        self.done[point.key] = point
        with open(self.path, "a") as f:
            f.write(json.dumps(finite_or_none(point.as_dict())) + "\n")
            f.flush()
            os.fsync(f.fileno())


__all__ = ["Journal", "JournalError", "NAME"]
