"""Ctrl-C as a request: the first SIGINT asks the run to stop after the current step (the step
is never cut in half, so what is saved is a consistent state); a second one stops at once."""
from __future__ import annotations

import signal
import sys
import threading
from contextlib import contextmanager
from typing import Iterator, Optional


class StopRequest:
    """``requested`` turns true on the first Ctrl-C while ``catching()`` is active."""

    def __init__(self, notice: Optional[str] = None):
        self.requested = False
        self.notice = notice          # printed on stderr at the first Ctrl-C

    def request(self) -> None:
        self.requested = True

    def _handler(self, signum, frame) -> None:
        if self.requested:            # the second Ctrl-C: stop now
            raise KeyboardInterrupt
        self.requested = True
        if self.notice:
            print(self.notice, file=sys.stderr, flush=True)

    @contextmanager
    def catching(self) -> Iterator["StopRequest"]:
        """Route SIGINT to this request (main thread only; elsewhere a no-op)."""
        if threading.current_thread() is not threading.main_thread():
            yield self
            return
        previous = signal.signal(signal.SIGINT, self._handler)
        try:
            yield self
        finally:
            signal.signal(signal.SIGINT, previous)


class StopRun(Exception):
    """Raised from a step callback to end a run early; ``by`` says why (max-steps, ctrl-c)."""

    def __init__(self, by: str = "max-steps"):
        super().__init__(by)
        self.by = by


def stop_if_asked(steps: int, max_steps: Optional[int], stop: Optional[StopRequest]) -> None:
    """Raise StopRun when the run has reached ``max_steps`` or Ctrl-C asked it to stop."""
    if max_steps is not None and steps >= max_steps:
        raise StopRun("max-steps")
    if stop is not None and stop.requested:
        raise StopRun("ctrl-c")


__all__ = ["StopRequest", "StopRun", "stop_if_asked"]
