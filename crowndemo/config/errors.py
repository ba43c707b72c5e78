"""PresetError: one mistake in a preset file or a ``--set`` override, found before any kernel
runs. It names where the value came from (a file, or ``--set``), the key path, the value, why
it is refused and what is allowed:

    presets/mine.yaml: scene.film = -0.001: not > 0; allowed: > 0 and <= 0.1 m
"""
from __future__ import annotations

import difflib
import math
from typing import Any, Iterable, Optional

MISSING = object()          # the value of a key that was never given


class PresetError(ValueError):
    """A bad preset: ``source`` (file or ``--set``), ``key`` (dotted path, or None for a
    mistake about the whole file), ``value``, ``why`` and ``allowed``."""

    def __init__(self, source: str, key: Optional[str], value=MISSING, why: str = "",
                 allowed: str = ""):
        self.source, self.key, self.value, self.why, self.allowed = \
            source, key, value, why, allowed
        super().__init__(self.message())

    def message(self) -> str:
        head = f"{self.source}: "
        if self.key is not None:
            head += f"{self.key} = {format_value(self.value)}: "
        text = head + self.why
        if self.allowed:
            text += f"; allowed: {self.allowed}"
        return text


def format_value(value: Any) -> str:
    """A value as it would be written in YAML (short), or ``(missing)``."""
    if value is MISSING:
        return "(missing)"
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        return repr(value)
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, dict):
        inner = ", ".join(f"{k}: {format_value(v)}" for k, v in list(value.items())[:4])
        return "{" + inner + (", ..." if len(value) > 4 else "") + "}"
    if isinstance(value, list):
        inner = ", ".join(format_value(v) for v in value[:4])
        return "[" + inner + (", ..." if len(value) > 4 else "") + "]"
    return repr(value)


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """' (did you mean 'film'?)' for the closest of ``choices``, or ''."""
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


__all__ = ["PresetError", "MISSING", "format_value", "did_you_mean"]
