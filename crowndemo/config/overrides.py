"""``--set KEY.PATH=VALUE`` overrides, applied on top of a loaded preset (they win over every
file in its ``extends`` chain and over the quality rung). VALUE is read as YAML: ``7``,
``1e-3``, ``true``, ``water``; an empty value or ``null`` restores the default."""
from __future__ import annotations

import re
from typing import Iterable, List, Tuple

from .errors import PresetError
from .loader import Document
from .merge import SET_SOURCE, deep_merge, origin_of
from .yamlio import parse_scalar

SOURCE = SET_SOURCE
_SEGMENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_-]*$")
EXAMPLE = "KEY.PATH=VALUE, e.g. scene.speed=7.0 or quality.draft.l0=4e-4"


def parse(item: str) -> Tuple[Tuple[str, ...], object]:
    """'scene.speed=7' -> (('scene', 'speed'), 7)."""
    if "=" not in item:
        raise PresetError(SOURCE, item.strip() or "(empty)", why="no value: write KEY=VALUE",
                          allowed=EXAMPLE)
    key, text = item.split("=", 1)
    key = key.strip()
    parts = tuple(key.split("."))
    if not key or not all(_SEGMENT.match(p) for p in parts):
        raise PresetError(SOURCE, key or "(empty key)", text, "not a dotted key path",
                          EXAMPLE)
    if parts[0] == "extends":
        raise PresetError(SOURCE, key, text, "extends cannot be changed with --set",
                          "write a preset file with extends: and name it instead")
    value = parse_scalar(text, f"{SOURCE} {key}", parts)
    return parts, value


def apply(doc: Document, items: Iterable[str]) -> Document:
    """A new Document with the overrides merged on top; their source is ``--set``."""
    items = list(items or ())
    if not items:
        return doc
    parsed: List[Tuple[Tuple[str, ...], object]] = [parse(i) for i in items]
    data, origin = doc.data, doc.origin
    for parts, value in parsed:        # one at a time: a later --set wins over an earlier one
        over: dict = {}
        node = over
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = value
        over_origin = {parts[:i]: SOURCE for i in range(1, len(parts) + 1)}
        if isinstance(value, dict):
            over_origin.update(origin_of(value, SOURCE, parts))
        data, origin = deep_merge(data, origin, over, over_origin)
    ranks = dict(doc.ranks)
    ranks[SOURCE] = max(ranks.values(), default=-1) + 1
    return Document(doc.name, doc.path, doc.label, data, origin, doc.chain + [SOURCE], ranks)


__all__ = ["parse", "apply", "SOURCE"]
