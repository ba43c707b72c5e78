"""Deep merge of preset documents, keeping where every value came from.

A document is plain nested dicts; its ``origin`` maps each key path (a tuple) to the source
that wrote it (a file's label or ``--set``). Merging ``over`` onto ``base``:

- mappings merge key by key, recursively; anything else (numbers, strings, lists) replaces;
- a key set to null (``~``) removes the base's value, so the default applies again (its origin
  stays, naming who removed it);
- alternatives: ``scene.speed`` and ``scene.height`` say the same thing two ways, so giving
  one of them removes the other from the base (``2m-drop`` extends ``3m-drop`` with a height);
- texts (``title``, ``description``) replace as a whole: a new English title must not keep
  the parent's Japanese one.
"""
from __future__ import annotations

import copy
from typing import Any, Dict, Tuple

Path = Tuple[str, ...]
Origin = Dict[Path, str]

SET_SOURCE = "--set"            # the source of ``--set`` overrides
DEFAULT_SOURCE = "default"      # the source of a value nobody wrote: the schema's default

ALTERNATIVES = {("scene",): (("speed", "height"),)}
ATOMIC = {("title",), ("description",)}


def origin_of(data: Any, label: str, path: Path = ()) -> Origin:
    """Every key path of ``data`` (mappings and leaves) attributed to ``label``."""
    out: Origin = {}
    if isinstance(data, dict):
        for k, v in data.items():
            p = path + (k,)
            out[p] = label
            out.update(origin_of(v, label, p))
    return out


def _drop(origin: Origin, path: Path) -> None:
    n = len(path)
    for p in [p for p in origin if p[:n] == path]:
        del origin[p]


def deep_merge(base: dict, base_origin: Origin, over: dict,
               over_origin: Origin) -> Tuple[dict, Origin]:
    """(data, origin) of ``over`` merged onto ``base``; neither input is changed."""
    data = copy.deepcopy(base)
    origin = dict(base_origin)
    _merge_into(data, origin, over, over_origin, ())
    return data, origin


def _merge_into(data: dict, origin: Origin, over: dict, over_origin: Origin, path: Path) -> None:
    for group in ALTERNATIVES.get(path, ()):
        if any(over.get(k) is not None for k in group):
            for k in group:
                if k not in over and k in data:
                    del data[k]
                    _drop(origin, path + (k,))
    for key, value in over.items():
        p = path + (key,)
        if value is None:
            data.pop(key, None)
            _drop(origin, p)
            if p in over_origin:       # the removal keeps its author: what a parent's rung
                origin[p] = over_origin[p]   # sets for this key does not come back over it
            continue
        if isinstance(value, dict):
            if not isinstance(data.get(key), dict) or p in ATOMIC:
                data[key] = {}
                _drop(origin, p)
            if p in over_origin and p not in origin:     # a new mapping: its writer
                origin[p] = over_origin[p]
            _merge_into(data[key], origin, value, over_origin, p)
        else:
            data[key] = copy.deepcopy(value)
            _drop(origin, p)
            if p in over_origin:
                origin[p] = over_origin[p]


__all__ = ["deep_merge", "origin_of", "ALTERNATIVES", "ATOMIC", "SET_SOURCE", "DEFAULT_SOURCE"]
