"""Strict JSON for every file and --json output: NaN and infinities, which JSON lacks, are
written as null; numpy numbers as plain numbers."""
from __future__ import annotations

import json
import math
from typing import IO, Any, Optional

import numpy as np


def finite_or_none(x: Any) -> Any:
    """``x`` with non-finite floats as None and numpy scalars as Python numbers (recursively
    through dicts, lists and tuples; keys become strings)."""
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {str(k): finite_or_none(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [finite_or_none(v) for v in x]
    return x


def _number(x: Any) -> Optional[float]:
    """json's fallback for other number types (numpy arrays' scalars and the like)."""
    return finite_or_none(float(x))


def dumps(data: Any, indent: int = 2) -> str:
    return json.dumps(finite_or_none(data), indent=indent, allow_nan=False, default=_number)


def dump(data: Any, f: IO[str], indent: int = 2) -> None:
    json.dump(finite_or_none(data), f, indent=indent, allow_nan=False, default=_number)


__all__ = ["finite_or_none", "dumps", "dump"]
