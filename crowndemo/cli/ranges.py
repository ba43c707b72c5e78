"""Range checks of command-line numbers against the preset schema's fields, and the rounding
that keeps a printed bound true (shared by ``info`` and ``scene``)."""
from __future__ import annotations

import math

from ..config.schema import Field
from ..core.params import ParameterError


def in_range(field: Field, value) -> bool:
    """Whether ``value`` is a finite number inside a schema Field's range."""
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value) and field.in_range(value))


def check_range(key: str, value, field: Field, source: str = "command line") -> None:
    """ParameterError naming ``key`` when ``value`` is outside the schema Field's range."""
    if not in_range(field, value):
        raise ParameterError(key, value, field.allowed(), source)


def ceil3(x: float) -> float:
    """``x`` rounded up to 3 significant digits: a ">=" bound that, printed, still passes."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.ceil(x / step * (1 - 1e-12)) * step


def floor3(x: float) -> float:
    """``x`` rounded down to 3 significant digits: a "<=" bound that, printed, still passes."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x / step * (1 + 1e-12)) * step
